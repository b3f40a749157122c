//! `SingleAxisPlant` (paper 002): one body axis driven by a reaction wheel with a first-order lag and
//! torque saturation, plus a sinusoidal/constant disturbance.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::integrate::{Method, Stepper};
use crate::model::{check_derived, check_finite_state, Experiment, Model, ModelInfo, ModelResult, ParamEnum, StateDecl};

declare_variables! {
    pub struct SingleAxisPlantVars {
        0 => u: Real = 0.0, Input, "", "Wheel command u (dimensionless)";
        1 => torque_dist: Real = 0.0, Input, "N.m", "External disturbance torque, added to the internal M_d";
        10 => theta: Real = 0.0, Output, "rad", "Attitude angle theta about the axis";
        11 => omega: Real = 0.0, Output, "rad/s", "Angular rate omega";
        12 => wheel_torque: Real = 0.0, Output, "N.m", "Wheel torque T_c after the lag (before saturation)";
        13 => applied_torque: Real = 0.0, Output, "N.m", "Saturated control torque M_c acting on the body";
        14 => theta_deg: Real = 0.0, Output, "deg", "Attitude angle in degrees";
        100 => inertia: Real = 7.7, Parameter, "kg.m2", "Nominal inertia J ([Khatoonabadi-FO]; damaged digits, 7.7 is a project choice)", Positive;
        101 => inertia_scale: Real = 1.0, Parameter, "", "Uncertainty factor: J_true = inertia_scale J", Positive;
        102 => wheel_gain: Real = 1.0, Parameter, "", "Wheel gain K ([Khatoonabadi-FO]; 1 is a project choice)";
        103 => wheel_time_constant: Real = 0.2, Parameter, "s", "Wheel time constant T ([Khatoonabadi-FO])", Positive;
        104 => torque_limit: Real = 1.0, Parameter, "N.m", "Saturation T_sat of the wheel torque (project choice; 1e30 = no limit)", Limit;
        105 => md_amp: Real = 0.01, Parameter, "N.m", "Disturbance amplitude: M_d = md_amp sin(md_freq t) + md_const ([Khatoonabadi-FO] form)";
        106 => md_freq: Real = 0.1, Parameter, "rad/s", "Disturbance frequency";
        107 => md_const: Real = 0.0001, Parameter, "N.m", "Constant disturbance";
        108 => max_internal_step: Real = 0.001, Parameter, "s", "Internal step h ([Khatoonabadi-FO] Euler step; 0.001 is a project choice); at most 1e6 internal steps per doStep", Range(1e-6, 1000.0);
        109 => init_theta: Real = 0.0, Parameter, "rad", "Initial angle theta(0)";
        110 => init_omega: Real = 0.0, Parameter, "rad/s", "Initial rate omega(0)";
        120 => integrator: Integer = 1, Parameter, "", "Internal integrator: 1 = explicit Euler ([Khatoonabadi-FO], default), 0 = classical RK4, 2 = adaptive Dormand-Prince 5(4)", Choice(Method::CODES);
    }
}

/// State [θ, ω, T_c].
type State = Vector3<f64>;

#[derive(Clone, Serialize, Deserialize)]
pub struct SingleAxisPlant {
    x: State,
    j_true: f64,
    /// Integrator with its adaptive step proposal.
    stepper: Stepper,
}

fn saturate(v: &SingleAxisPlantVars, tc: f64) -> f64 {
    tc.clamp(-v.torque_limit, v.torque_limit)
}

impl SingleAxisPlant {
    fn derivative(&self, v: &SingleAxisPlantVars, t: f64, x: &State) -> State {
        let md = v.torque_dist + v.md_amp * (v.md_freq * t).sin() + v.md_const;
        Vector3::new(x[1], (saturate(v, x[2]) + md) / self.j_true, (v.wheel_gain * v.u - x[2]) / v.wheel_time_constant)
    }
}

impl Model for SingleAxisPlant {
    type Vars = SingleAxisPlantVars;
    const EVOLVING: &'static [&'static str] = &["x", "stepper.h_adapt"];
    const INFO: ModelInfo = ModelInfo {
        name: "SingleAxisPlant",
        description: "Single-axis spacecraft with first-order reaction-wheel lag, torque saturation and sinusoidal disturbance ([Khatoonabadi-FO])",
        source: "[Khatoonabadi-FO], Fig. 1, Eqs. 4, 7",
        equations_html: EQUATIONS_HTML,
        default_stop_time: 50.0,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SingleAxisPlantVars, exp: &Experiment) -> Result<Self, String> {
        let stepper = Stepper::for_plant(v.integrator, v.max_internal_step, exp)?;
        Ok(SingleAxisPlant { x: Vector3::new(v.init_theta, v.init_omega, 0.0), j_true: v.inertia * v.inertia_scale, stepper })
    }

    fn outputs(&self, v: &mut SingleAxisPlantVars, _t: f64) -> ModelResult {
        let x = self.x;
        (v.theta, v.omega, v.wheel_torque, v.applied_torque, v.theta_deg) = (x[0], x[1], x[2], saturate(v, x[2]), x[0].to_degrees());
        Ok(())
    }

    fn step(&mut self, v: &SingleAxisPlantVars, t: f64, h: f64) -> ModelResult {
        let (mut stepper, mut x) = (self.stepper, self.x);
        let this = &*self;
        stepper.advance(t, h, &[], &mut x, |_, _| move |tt: f64, xx: &State| this.derivative(v, tt, xx), |_, _| Ok(()))?;
        (self.stepper, self.x) = (stepper, x);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.stepper.check_against(&fresh.stepper)?;
        check_derived("inertia", &self.j_true, &fresh.j_true)?;
        check_finite_state("state vector", self.x.iter())
    }

    const STATES: Option<&'static [StateDecl]> = Some(&[
        StateDecl::new("state_theta", "rad", "Continuous state: attitude angle theta").depends_on(&["state_omega"]),
        StateDecl::new("state_omega", "rad/s", "Continuous state: angular rate omega").depends_on(&["state_wheel_torque", "torque_dist"]),
        StateDecl::new("state_wheel_torque", "N.m", "Continuous state: wheel torque T_c after the lag").depends_on(&["state_wheel_torque", "u"]),
    ]);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(self.x.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
    }
    fn derivatives(&self, v: &SingleAxisPlantVars, t: f64, dx: &mut [f64]) -> ModelResult {
        dx.copy_from_slice(self.derivative(v, t, &self.x).as_slice());
        Ok(())
    }
}

const EQUATIONS_HTML: &str = "<pre>d(theta)/dt = omega\n\
d(omega)/dt = (M_c + M_d) / J_true,      J_true = inertia_scale J\n\
d(T_c)/dt   = (K u - T_c) / T              ([Khatoonabadi-FO] Eq. 7)\n\
M_c         = clamp(T_c, -T_sat, T_sat)    ([Khatoonabadi-FO] Eq. 4; saturation after the lag)\n\
M_d         = torque_dist + md_amp sin(md_freq t) + md_const</pre>\n\
<p>Integration: explicit Euler (integrator = 1, default, [Khatoonabadi-FO]), classical RK4 (integrator = 0) or adaptive Dormand-Prince 5(4) (integrator = 2, tolerance from fmi2SetupExperiment) with \
ceil(step / max_internal_step) equal internal steps per communication step; Euler evaluates every right-hand side at t_n. \
Inputs are held over the communication step. theta(0) = init_theta, omega(0) = init_omega, T_c(0) = 0.</p>\n\
<p>Model Exchange: the states (theta, omega, T_c) are published as state_theta, state_omega, state_wheel_torque with \
the right-hand side above; the importer's solver integrates them (integrator and max_internal_step are not used).</p>";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn plant(setup: impl FnOnce(&mut SingleAxisPlantVars)) -> Fmu<SingleAxisPlant> {
        let mut p = Fmu::<SingleAxisPlant>::default();
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
            p.step(0.0, 0.001).unwrap();
            let (th1, om1, tq1) = (th + om * h, om + (tq / j) * h, tq + ((k * 0.3 - tq) / tc) * h);
            (th, om, tq) = (th1, om1, tq1);
        }
        p.outputs(2.0).unwrap();
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
            p.step(n as f64 * 0.01, 0.01).unwrap();
        }
        p.outputs(5.0).unwrap();
        let (t, tc, a) = (5.0f64, 0.2f64, 0.5 / 7.7);
        let th = a * (t * t / 2.0 - tc * t + tc * tc * (1.0 - (-t / tc).exp()));
        assert!((p.v.theta - th).abs() < 1e-12, "{} vs {th}", p.v.theta);
    }

    #[test]
    fn saturation_limits_applied_torque() {
        let mut p = plant(|v| v.u = 5.0);
        for n in 0..300 {
            p.step(n as f64 * 0.01, 0.01).unwrap();
            p.outputs((n + 1) as f64 * 0.01).unwrap();
            assert!(p.v.applied_torque.abs() <= 1.0);
        }
        assert!(p.v.wheel_torque > 4.9 && p.v.applied_torque == 1.0);
    }
}
