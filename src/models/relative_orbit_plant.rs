//! `RelativeOrbitPlant`: nonlinear leader–follower relative motion in the leader's LVLH frame with the
//! leader's true anomaly integrated inside (spec relative-orbit-plant.md; paper 001 Eqs. 3–4 with the
//! printed typos fixed).

use nalgebra::{SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::integrate::{Method, Stepper};
use crate::math::relative_orbit::LeaderOrbit;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct RelativeOrbitPlantVars {
        // inputs
        0 => force_x: Real = 0.0, Input, Continuous, "N", "Control force on the follower, LVLH x (radial)";
        1 => force_y: Real = 0.0, Input, Continuous, "N", "Control force, LVLH y (along-track)";
        2 => force_z: Real = 0.0, Input, Continuous, "N", "Control force, LVLH z (orbit normal)";
        3 => dist_x: Real = 0.0, Input, Continuous, "N", "Disturbance force, LVLH x (divided by mass inside)";
        4 => dist_y: Real = 0.0, Input, Continuous, "N", "Disturbance force, LVLH y (divided by mass inside)";
        5 => dist_z: Real = 0.0, Input, Continuous, "N", "Disturbance force, LVLH z (divided by mass inside)";
        // outputs
        10 => pos_x: Real = 0.0, Output, Continuous, "m", "Follower position relative to the leader, LVLH x";
        11 => pos_y: Real = 0.0, Output, Continuous, "m", "Relative position, LVLH y";
        12 => pos_z: Real = 0.0, Output, Continuous, "m", "Relative position, LVLH z";
        13 => vel_x: Real = 0.0, Output, Continuous, "m/s", "Relative velocity (time derivative in LVLH), x";
        14 => vel_y: Real = 0.0, Output, Continuous, "m/s", "Relative velocity, y";
        15 => vel_z: Real = 0.0, Output, Continuous, "m/s", "Relative velocity, z";
        16 => leader_true_anomaly: Real = 0.0, Output, Continuous, "rad", "Leader true anomaly nu (integrated, not wrapped)";
        17 => leader_radius: Real = 6.0e6, Output, Continuous, "m", "Leader orbit radius R(nu)";
        // parameters
        100 => mu: Real = 3.986004418e14, Parameter, Fixed, "m3/s2", "Gravitational parameter (project choice)";
        101 => semi_major_axis: Real = 6.0e6, Parameter, Fixed, "m", "Leader semi-major axis a (paper 001: 6000 km, below the Earth's radius, kept as printed)";
        102 => eccentricity: Real = 0.0, Parameter, Fixed, "", "Leader eccentricity e in [0, 1)";
        103 => nu0: Real = 0.0, Parameter, Fixed, "rad", "Leader true anomaly at the start time";
        104 => mass: Real = 100.0, Parameter, Fixed, "kg", "Follower mass m (paper 001)";
        105 => init_pos_x: Real = 0.0, Parameter, Fixed, "m", "Initial relative position x";
        106 => init_pos_y: Real = 0.0, Parameter, Fixed, "m", "Initial relative position y";
        107 => init_pos_z: Real = 0.0, Parameter, Fixed, "m", "Initial relative position z";
        108 => init_vel_x: Real = 0.0, Parameter, Fixed, "m/s", "Initial relative velocity x";
        109 => init_vel_y: Real = 0.0, Parameter, Fixed, "m/s", "Initial relative velocity y";
        110 => init_vel_z: Real = 0.0, Parameter, Fixed, "m/s", "Initial relative velocity z";
        111 => max_internal_step: Real = 0.001, Parameter, Fixed, "s", "Largest internal integration step";
        140 => integrator: Integer = 0, Parameter, Fixed, "", "Internal integrator: 0 = classical RK4, 1 = explicit Euler, 2 = adaptive Dormand-Prince 5(4) (tolerance from fmi2SetupExperiment, default 1e-8)";
    }
}

/// State [x, y, z, ẋ, ẏ, ż, ν].
type State = SVector<f64, 7>;

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct RelativeOrbitPlant {
    v: RelativeOrbitPlantVars,
    x: State,
    orbit: LeaderOrbit,
    /// Integrator chosen at initialization (None before).
    stepper: Option<Stepper>,
}

impl RelativeOrbitPlant {
    /// External acceleration (F + dist)/m with the inputs held.
    fn ext_accel(&self) -> Vector3<f64> {
        let v = &self.v;
        Vector3::new(v.force_x + v.dist_x, v.force_y + v.dist_y, v.force_z + v.dist_z) / v.mass
    }

    /// ẋ = (ρ̇, −G(ρ, ρ̇) + (F + dist)/m, θ̇(ν)).
    fn derivative(orbit: &LeaderOrbit, a_ext: &Vector3<f64>, x: &State) -> Result<State, String> {
        let rho = Vector3::new(x[0], x[1], x[2]);
        let rho_dot = Vector3::new(x[3], x[4], x[5]);
        let nu = x[6];
        let acc = orbit.relative_acceleration(nu, &rho, &rho_dot, a_ext)?;
        Ok(State::from_column_slice(&[rho_dot.x, rho_dot.y, rho_dot.z, acc.x, acc.y, acc.z, orbit.theta_dot(nu)]))
    }
}

impl Model for RelativeOrbitPlant {
    type Vars = RelativeOrbitPlantVars;
    const INFO: ModelInfo = ModelInfo {
        name: "RelativeOrbitPlant",
        description: "Nonlinear leader-follower relative orbital motion in LVLH (3 translational DOF), eccentric leader orbit",
        source: "paper 001 Eqs. 3-5 (typos fixed); shared/spec relative-orbit-plant.md",
        equations_html: "<pre>n    = sqrt(mu / a^3)\n\
dtheta/dt = n (1 + e cos nu)^2 / (1 - e^2)^(3/2),   dnu/dt = dtheta/dt\n\
d2theta/dt2 = -2 n^2 e sin nu (1 + e cos nu)^3 / (1 - e^2)^3\n\
R    = a (1 - e^2) / (1 + e cos nu)\n\
rho_f = sqrt((R + x)^2 + y^2 + z^2)\n\
x'' =  2 th' y' + th'' y + th'^2 x - mu (R + x)/rho_f^3 + mu/R^2 + (F_x + dist_x)/m\n\
y'' = -2 th' x' - th'' x + th'^2 y - mu y/rho_f^3 + (F_y + dist_y)/m\n\
z'' =                             - mu z/rho_f^3 + (F_z + dist_z)/m</pre>\n\
<p>LVLH: x radial outward, y along-track, z along the leader's angular momentum. mu/R^2 - mu (R + x)/rho_f^3 is \
evaluated without cancellation. Fixed-step RK4 (or explicit Euler) with ceil(step / max_internal_step) equal \
internal steps per communication step, or adaptive Dormand-Prince 5(4) with rtol = atol = the tolerance of fmi2SetupExperiment; inputs are held over the step; nu is not wrapped.</p>",
        feedthrough: Feedthrough::None,
        default_stop_time: 300.0,
        default_step: 0.001,
        variable_step: true,
    };

    fn vars(&self) -> &RelativeOrbitPlantVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut RelativeOrbitPlantVars {
        &mut self.v
    }

    fn initialize(&mut self, exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let method = Method::from_param(v.integrator)?;
        check::positive("max_internal_step", v.max_internal_step)?;
        check::positive("mass", v.mass)?;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, v.eccentricity)?;
        for (n, x) in [
            ("nu0", v.nu0),
            ("init_pos_x", v.init_pos_x),
            ("init_pos_y", v.init_pos_y),
            ("init_pos_z", v.init_pos_z),
            ("init_vel_x", v.init_vel_x),
            ("init_vel_y", v.init_vel_y),
            ("init_vel_z", v.init_vel_z),
        ] {
            check::finite(n, x)?;
        }
        let rho0 = Vector3::new(v.init_pos_x, v.init_pos_y, v.init_pos_z);
        orbit.differential_gravity(v.nu0, &rho0).map_err(|e| format!("initial state: {e}"))?;
        self.orbit = orbit;
        // adaptive tolerance from fmi2SetupExperiment (default 1e-8)
        self.stepper = Some(Stepper::new(method, self.v.max_internal_step, exp.tolerance.filter(|x| *x > 0.0).unwrap_or(1e-8)));
        self.x = State::from_column_slice(&[v.init_pos_x, v.init_pos_y, v.init_pos_z, v.init_vel_x, v.init_vel_y, v.init_vel_z, v.nu0]);
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let x = self.x;
        let r = self.orbit.radius(x[6]);
        let v = &mut self.v;
        (v.pos_x, v.pos_y, v.pos_z) = (x[0], x[1], x[2]);
        (v.vel_x, v.vel_y, v.vel_z) = (x[3], x[4], x[5]);
        v.leader_true_anomaly = x[6];
        v.leader_radius = r;
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let mut stepper = self.stepper.ok_or("plant was not initialized")?;
        let orbit = self.orbit;
        let a_ext = self.ext_accel();
        if !a_ext.iter().all(|c| c.is_finite()) {
            return Err("inputs force_* / dist_* are not finite".into());
        }
        let mut x = self.x;
        let mut err: Option<String> = None;
        let mut f = |_tt: f64, xx: &State| match Self::derivative(&orbit, &a_ext, xx) {
            Ok(d) => d,
            Err(e) => {
                err.get_or_insert(e);
                State::from_element(f64::NAN)
            }
        };
        let r = stepper.piece(&mut f, t, h, &mut x, |xx, tt| {
            if xx.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(format!("state became non-finite at t = {tt}")) }
        });
        if let Some(e) = err {
            return Err(format!("in the step from t = {t}: {e}"));
        }
        r?;
        self.x = x;
        self.stepper = Some(stepper);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::relative_orbit::true_anomaly_from_mean;

    fn plant(set: impl FnOnce(&mut RelativeOrbitPlantVars)) -> RelativeOrbitPlant {
        let mut p = RelativeOrbitPlant::default();
        set(&mut p.v);
        p.initialize(&Experiment::default()).unwrap();
        p
    }

    fn run(p: &mut RelativeOrbitPlant, t_end: f64, dt: f64, mut each: impl FnMut(f64, &State)) {
        let n = (t_end / dt).round() as usize;
        each(0.0, &p.x);
        for k in 0..n {
            p.do_step(k as f64 * dt, dt, &Experiment::default()).unwrap();
            each((k + 1) as f64 * dt, &p.x);
        }
    }

    #[test]
    fn origin_is_an_equilibrium_for_any_eccentricity() {
        for e in [0.0, 0.1, 0.6] {
            let mut p = plant(|v| {
                v.eccentricity = e;
                v.nu0 = 0.4;
                v.max_internal_step = 1.0;
            });
            let period = p.orbit.period();
            run(&mut p, period, 50.0, |_, x| assert!(x.fixed_rows::<6>(0).iter().all(|c| *c == 0.0), "e {e}: {x:?}"));
        }
    }

    #[test]
    fn jacobi_integral_is_conserved_circular() {
        // spec test 2: ρ(0) = (100, 0, 50) m, ρ̇(0) = (0, −0.2, 0.05) m/s, RK4 h = 0.1 s, one orbit
        let mut p = plant(|v| {
            (v.init_pos_x, v.init_pos_z) = (100.0, 50.0);
            (v.init_vel_y, v.init_vel_z) = (-0.2, 0.05);
            v.max_internal_step = 0.1;
        });
        let (mu, r, n) = (p.orbit.mu, p.orbit.a, p.orbit.n);
        let jacobi = |x: &State| {
            let (px, py, pz) = (x[0], x[1], x[2]);
            let rf = ((r + px).powi(2) + py * py + pz * pz).sqrt();
            let grav = -mu * (2.0 * r * px + px * px + py * py + pz * pz) / (rf * r * (r + rf));
            let phi = 0.5 * n * n * (px * px + py * py) + grav + mu / (r * r) * px;
            0.5 * (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]) - phi
        };
        let c0 = jacobi(&p.x);
        let bound = 1e-6 * 0.5 * (0.2f64.powi(2) + 0.05f64.powi(2));
        let mut worst = 0.0f64;
        let period = p.orbit.period();
        run(&mut p, (period / 10.0).round() * 10.0, 10.0, |_, x| worst = worst.max((jacobi(x) - c0).abs()));
        assert!(worst < bound, "Jacobi drift {worst} >= {bound}");
    }

    #[test]
    fn true_anomaly_follows_kepler() {
        // spec test 4: e = 0.1, ν(t) vs Kepler's equation with M = n t, one orbit, 1e-9 rad
        let mut p = plant(|v| {
            v.eccentricity = 0.1;
            v.max_internal_step = 0.1;
        });
        let n = p.orbit.n;
        let mut worst = 0.0f64;
        let period = p.orbit.period();
        run(&mut p, (period / 5.0).ceil() * 5.0, 5.0, |t, x| worst = worst.max((x[6] - true_anomaly_from_mean(n * t, 0.1)).abs()));
        assert!(worst < 1e-9, "nu error {worst}");
    }

    #[test]
    fn constant_force_and_disturbance_add_up() {
        // a short time after rest, ρ ≈ ½ (F + d)/m t²; Coriolis and gravity-gradient terms are O(n t) = 1.4e-3
        // and O(n² t²) relative
        let mut p = plant(|v| v.max_internal_step = 0.01);
        (p.v.force_x, p.v.force_y, p.v.dist_z, p.v.dist_x) = (1.0, -2.0, 0.5, 0.25);
        run(&mut p, 1.0, 0.1, |_, _| {});
        let expect = Vector3::new(1.25, -2.0, 0.5) / 100.0 * 0.5;
        let got = Vector3::new(p.x[0], p.x[1], p.x[2]);
        assert!((got - expect).norm() < 1.5e-3 * expect.norm(), "{got:?} vs {expect:?}");
    }

    #[test]
    fn euler_is_first_order() {
        // integrator 1: error against RK4 halves when the internal step halves
        let ref_state = {
            let mut p = plant(|v| {
                (v.init_pos_x, v.init_vel_y) = (100.0, 0.3);
                v.max_internal_step = 0.1;
            });
            run(&mut p, 200.0, 10.0, |_, _| {});
            p.x
        };
        let err = |h: f64| {
            let mut p = plant(|v| {
                (v.init_pos_x, v.init_vel_y) = (100.0, 0.3);
                v.max_internal_step = h;
                v.integrator = 1;
            });
            run(&mut p, 200.0, 10.0, |_, _| {});
            (p.x - ref_state).fixed_rows::<3>(0).norm()
        };
        let ratio = err(0.2) / err(0.1);
        assert!((1.8..2.2).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn adaptive_integrator_agrees_with_fine_rk4() {
        // 1 km radial offset, eccentric leader, 600 s: Dormand–Prince (tol 1e-12) vs RK4 0.01 s
        let run = |integrator: i32, step: f64| {
            let mut p = RelativeOrbitPlant::default();
            p.v.eccentricity = 0.1;
            p.v.init_pos_x = 1000.0;
            p.v.init_vel_y = -1.0;
            p.v.integrator = integrator;
            p.v.max_internal_step = step;
            let exp = Experiment { tolerance: Some(1e-12), ..Default::default() };
            p.initialize(&exp).unwrap();
            for k in 0..60 {
                p.do_step(k as f64 * 10.0, 10.0, &exp).unwrap();
            }
            p.x
        };
        let d = (run(2, 1.0) - run(0, 0.01)).fixed_rows::<3>(0).norm();
        assert!(d < 1e-6, "difference {d} m");
    }

    #[test]
    fn bad_parameters_are_rejected() {
        let mut p = RelativeOrbitPlant::default();
        p.v.eccentricity = 1.0;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("eccentricity"));
        let mut p = RelativeOrbitPlant::default();
        p.v.mass = 0.0;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("mass"));
        let mut p = RelativeOrbitPlant::default();
        p.v.integrator = 3;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("integrator"));
        let mut p = RelativeOrbitPlant::default();
        p.v.init_pos_x = -6.0e6;
        assert!(p.initialize(&Experiment::default()).is_err());
    }
}
