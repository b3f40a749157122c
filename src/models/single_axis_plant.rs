//! `SingleAxisPlant` (paper 002): one body axis driven by a reaction wheel with a first-order lag and
//! torque saturation, plus a sinusoidal/constant disturbance (spec attitude-plant.md §2).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::integrate::{Method, Stepper};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct SingleAxisPlantVars {
        0 => u: Real = 0.0, Input, Continuous, "", "Wheel command u (dimensionless)";
        1 => torque_dist: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, added to the internal M_d";
        10 => theta: Real = 0.0, Output, Continuous, "rad", "Attitude angle theta about the axis";
        11 => omega: Real = 0.0, Output, Continuous, "rad/s", "Angular rate omega";
        12 => wheel_torque: Real = 0.0, Output, Continuous, "N.m", "Wheel torque T_c after the lag (before saturation)";
        13 => applied_torque: Real = 0.0, Output, Continuous, "N.m", "Saturated control torque M_c acting on the body";
        14 => theta_deg: Real = 0.0, Output, Continuous, "deg", "Attitude angle in degrees";
        100 => inertia: Real = 7.7, Parameter, Fixed, "kg.m2", "Nominal inertia J (paper 002; damaged digits, 7.7 is a project choice)";
        101 => inertia_scale: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor: J_true = inertia_scale J";
        102 => wheel_gain: Real = 1.0, Parameter, Fixed, "", "Wheel gain K (paper 002; 1 is a project choice)";
        103 => wheel_time_constant: Real = 0.2, Parameter, Fixed, "s", "Wheel time constant T (paper 002)";
        104 => torque_limit: Real = 1.0, Parameter, Fixed, "N.m", "Saturation T_sat of the wheel torque (project choice; 1e30 = no limit)";
        105 => md_amp: Real = 0.01, Parameter, Fixed, "N.m", "Disturbance amplitude: M_d = md_amp sin(md_freq t) + md_const (paper 002 form)";
        106 => md_freq: Real = 0.1, Parameter, Fixed, "rad/s", "Disturbance frequency";
        107 => md_const: Real = 0.0001, Parameter, Fixed, "N.m", "Constant disturbance";
        108 => max_internal_step: Real = 0.001, Parameter, Fixed, "s", "Internal step h (paper 002 Euler step; 0.001 is a project choice)";
        109 => init_theta: Real = 0.0, Parameter, Fixed, "rad", "Initial angle theta(0)";
        110 => init_omega: Real = 0.0, Parameter, Fixed, "rad/s", "Initial rate omega(0)";
        120 => integrator: Integer = 1, Parameter, Fixed, "", "Internal integrator: 1 = explicit Euler (paper 002, default), 0 = classical RK4, 2 = adaptive Dormand-Prince 5(4)";
    }
}

/// State [θ, ω, T_c].
type State = Vector3<f64>;

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct SingleAxisPlant {
    v: SingleAxisPlantVars,
    x: State,
    j_true: f64,
    /// Integrator chosen at initialization (None before).
    stepper: Option<Stepper>,
}

impl SingleAxisPlant {
    fn saturate(&self, tc: f64) -> f64 {
        tc.clamp(-self.v.torque_limit, self.v.torque_limit)
    }

    fn derivative(&self, t: f64, x: &State) -> State {
        let v = &self.v;
        let md = v.torque_dist + v.md_amp * (v.md_freq * t).sin() + v.md_const;
        Vector3::new(x[1], (self.saturate(x[2]) + md) / self.j_true, (v.wheel_gain * v.u - x[2]) / v.wheel_time_constant)
    }
}

impl Model for SingleAxisPlant {
    type Vars = SingleAxisPlantVars;
    const INFO: ModelInfo = ModelInfo {
        name: "SingleAxisPlant",
        description: "Single-axis spacecraft with first-order reaction-wheel lag, torque saturation and sinusoidal disturbance (paper 002)",
        source: "shared/spec attitude-plant.md §2 (paper 002 Fig. 1, Eqs. 4, 7)",
        equations_html: "<pre>d(theta)/dt = omega\n\
d(omega)/dt = (M_c + M_d) / J_true,      J_true = inertia_scale J\n\
d(T_c)/dt   = (K u - T_c) / T              (paper 002 Eq. 7)\n\
M_c         = clamp(T_c, -T_sat, T_sat)    (paper 002 Eq. 4; saturation after the lag)\n\
M_d         = torque_dist + md_amp sin(md_freq t) + md_const</pre>\n\
<p>Integration: explicit Euler (integrator = 1, default, paper 002), classical RK4 (integrator = 0) or adaptive Dormand-Prince 5(4) (integrator = 2, tolerance from fmi2SetupExperiment) with \
ceil(step / max_internal_step) equal internal steps per communication step; Euler evaluates every right-hand side at t_n. \
Inputs are held over the communication step. theta(0) = init_theta, omega(0) = init_omega, T_c(0) = 0.</p>",
        feedthrough: Feedthrough::None,
        default_stop_time: 50.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &SingleAxisPlantVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut SingleAxisPlantVars {
        &mut self.v
    }

    fn initialize(&mut self, exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let method = Method::from_param(v.integrator)?;
        let j = check::positive("inertia", v.inertia)? * check::positive("inertia_scale", v.inertia_scale)?;
        check::finite("wheel_gain", v.wheel_gain)?;
        check::positive("wheel_time_constant", v.wheel_time_constant)?;
        check::limit("torque_limit", v.torque_limit)?;
        for (n, x) in [("md_amp", v.md_amp), ("md_freq", v.md_freq), ("md_const", v.md_const), ("init_theta", v.init_theta), ("init_omega", v.init_omega)] {
            check::finite(n, x)?;
        }
        check::positive("max_internal_step", v.max_internal_step)?;
        self.j_true = j;
        // adaptive tolerance from fmi2SetupExperiment (default 1e-8)
        self.stepper = Some(Stepper::new(method, self.v.max_internal_step, exp.tolerance.filter(|x| *x > 0.0).unwrap_or(1e-8)));
        self.x = Vector3::new(v.init_theta, v.init_omega, 0.0);
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let x = self.x;
        let mc = self.saturate(x[2]);
        let v = &mut self.v;
        (v.theta, v.omega, v.wheel_torque, v.applied_torque, v.theta_deg) = (x[0], x[1], x[2], mc, x[0].to_degrees());
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let mut stepper = self.stepper.ok_or("plant was not initialized")?;
        let mut x = self.x;
        let mut f = |tt: f64, xx: &State| self.derivative(tt, xx);
        stepper.piece(&mut f, t, h, &mut x, |xx, tt| {
            if xx.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(format!("state became non-finite at t = {tt}")) }
        })?;
        self.x = x;
        self.stepper = Some(stepper);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plant(setup: impl FnOnce(&mut SingleAxisPlantVars)) -> SingleAxisPlant {
        let mut p = SingleAxisPlant::default();
        setup(&mut p.v);
        p.initialize(&Experiment::default()).unwrap();
        p
    }

    #[test]
    fn euler_recursion_written_by_hand() {
        // Saturation inactive, M_d = 0, u = 0.3: x_{n+1} = x_n + h f(x_n) for the linear third-order system
        let mut p = plant(|v| {
            (v.md_amp, v.md_const, v.u) = (0.0, 0.0, 0.3);
        });
        let (j, k, tc, h) = (7.7, 1.0, 0.2, 0.001);
        let (mut th, mut om, mut tq) = (0.0f64, 0.0f64, 0.0f64);
        for n in 0..2000 {
            let _ = n;
            p.do_step(0.0, 0.001, &Experiment::default()).unwrap();
            let (th1, om1, tq1) = (th + om * h, om + (tq / j) * h, tq + ((k * 0.3 - tq) / tc) * h);
            (th, om, tq) = (th1, om1, tq1);
        }
        p.update_outputs(2.0).unwrap();
        // bit-identical: same operations in the same order
        assert_eq!((p.v.theta, p.v.omega, p.v.wheel_torque), (th, om, tq));
    }

    #[test]
    fn rk4_matches_closed_form_step_response() {
        // u = u0 step, no saturation, M_d = 0: T_c = K u0 (1 − e^{−t/T}),
        // θ(t) = (K u0 / J) [t²/2 − T t + T² (1 − e^{−t/T})]
        let mut p = plant(|v| {
            (v.md_amp, v.md_const, v.u, v.integrator) = (0.0, 0.0, 0.5, 0);
        });
        for n in 0..500 {
            p.do_step(n as f64 * 0.01, 0.01, &Experiment::default()).unwrap();
        }
        p.update_outputs(5.0).unwrap();
        let (t, tc, a) = (5.0f64, 0.2f64, 0.5 / 7.7);
        let th = a * (t * t / 2.0 - tc * t + tc * tc * (1.0 - (-t / tc).exp()));
        assert!((p.v.theta - th).abs() < 1e-12, "{} vs {th}", p.v.theta);
    }

    #[test]
    fn saturation_limits_applied_torque() {
        let mut p = plant(|v| v.u = 5.0);
        for n in 0..300 {
            p.do_step(n as f64 * 0.01, 0.01, &Experiment::default()).unwrap();
            p.update_outputs((n + 1) as f64 * 0.01).unwrap();
            assert!(p.v.applied_torque.abs() <= 1.0);
        }
        assert!(p.v.wheel_torque > 4.9 && p.v.applied_torque == 1.0);
    }
}
