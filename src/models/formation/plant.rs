//! `RelativeOrbitPlant`: nonlinear leader–follower relative motion in the leader's LVLH frame with the
//! leader's true anomaly integrated inside (paper 001 Eqs. 3–4 with the printed typos fixed).

use std::cell::RefCell;

use nalgebra::{SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::integrate::{Method, Stepper};
use crate::math::relative_orbit::LeaderOrbit;
use crate::model::{check_derived, check_finite_state, Experiment, Model, ModelInfo, ModelResult, ParamEnum, StateDecl};

declare_variables! {
    pub struct RelativeOrbitPlantVars {
        // inputs
        0 => force: Vec3 = [0.0; 3], Input, "N", "Control force on the follower, LVLH (x radial, y along-track, z orbit normal)";
        3 => dist: Vec3 = [0.0; 3], Input, "N", "Disturbance force, LVLH (divided by mass inside)";
        // outputs
        10 => pos: Vec3 = [0.0; 3], Output, "m", "Follower position relative to the leader, LVLH";
        13 => vel: Vec3 = [0.0; 3], Output, "m/s", "Relative velocity (time derivative in LVLH)";
        16 => leader_true_anomaly: Real = 0.0, Output, "rad", "Leader true anomaly nu (integrated, not wrapped)";
        17 => leader_radius: Real = 6.0e6, Output, "m", "Leader orbit radius R(nu)";
        // parameters
        100 => mu: Real = 3.986004418e14, Parameter, "m3/s2", "Gravitational parameter (project choice)", Positive;
        101 => semi_major_axis: Real = 6.0e6, Parameter, "m", "Leader semi-major axis a ([NPPID-Formation]: 6000 km, below the Earth's radius, kept as printed)", Positive;
        102 => eccentricity: Real = 0.0, Parameter, "", "Leader eccentricity e in [0, 1)";
        103 => nu0: Real = 0.0, Parameter, "rad", "Leader true anomaly at the start time";
        104 => mass: Real = 100.0, Parameter, "kg", "Follower mass m ([NPPID-Formation])", Positive;
        105 => init_pos: Vec3 = [0.0; 3], Parameter, "m", "Initial relative position";
        108 => init_vel: Vec3 = [0.0; 3], Parameter, "m/s", "Initial relative velocity";
        111 => max_internal_step: Real = 0.001, Parameter, "s", "Largest internal integration step; at most 1e6 internal steps per doStep", Range(1e-6, 1000.0);
        140 => integrator: Integer = 0, Parameter, "", "Internal integrator: 0 = classical RK4, 1 = explicit Euler, 2 = adaptive Dormand-Prince 5(4) (tolerance from fmi2SetupExperiment, default 1e-8)", Choice(Method::CODES);
    }
}

/// State [x, y, z, ẋ, ẏ, ż, ν].
type State = SVector<f64, 7>;

#[derive(Clone, Serialize, Deserialize)]
pub struct RelativeOrbitPlant {
    x: State,
    orbit: LeaderOrbit,
    /// Integrator with its adaptive step proposal.
    stepper: Stepper,
}

/// ẋ = (ρ̇, −G(ρ, ρ̇) + (F + dist)/m, θ̇(ν)).
fn derivative(orbit: &LeaderOrbit, a_ext: &Vector3<f64>, x: &State) -> Result<State, String> {
    let rho = Vector3::new(x[0], x[1], x[2]);
    let rho_dot = Vector3::new(x[3], x[4], x[5]);
    let nu = x[6];
    let acc = orbit.relative_acceleration(nu, &rho, &rho_dot, a_ext)?;
    Ok(State::from_column_slice(&[rho_dot.x, rho_dot.y, rho_dot.z, acc.x, acc.y, acc.z, orbit.theta_dot(nu)]))
}

impl Model for RelativeOrbitPlant {
    type Vars = RelativeOrbitPlantVars;
    const EVOLVING: &'static [&'static str] = &["x", "stepper.h_adapt"];
    const INFO: ModelInfo = ModelInfo {
        name: "RelativeOrbitPlant",
        description: "Nonlinear leader-follower relative orbital motion in LVLH (3 translational DOF), eccentric leader orbit",
        source: "[NPPID-Formation], Eqs. 3-5 with the printed typos fixed",
        equations_html: EQUATIONS_HTML,
        default_stop_time: 300.0,
        default_step: 0.001,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut RelativeOrbitPlantVars, exp: &Experiment) -> Result<Self, String> {
        let stepper = Stepper::for_plant(v.integrator, v.max_internal_step, exp)?;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, v.eccentricity)?;
        orbit.differential_gravity(v.nu0, &v.init_pos).map_err(|e| format!("initial state: {e}"))?;
        let (p, q) = (v.init_pos, v.init_vel);
        let x = State::from_column_slice(&[p.x, p.y, p.z, q.x, q.y, q.z, v.nu0]);
        Ok(RelativeOrbitPlant { x, orbit, stepper })
    }

    fn outputs(&self, v: &mut RelativeOrbitPlantVars, _t: f64) -> ModelResult {
        let x = self.x;
        v.pos = Vector3::new(x[0], x[1], x[2]);
        v.vel = Vector3::new(x[3], x[4], x[5]);
        v.leader_true_anomaly = x[6];
        v.leader_radius = self.orbit.radius(x[6]);
        Ok(())
    }

    fn step(&mut self, v: &RelativeOrbitPlantVars, t: f64, h: f64) -> ModelResult {
        let orbit = self.orbit;
        // external acceleration (F + dist)/m with the inputs held
        let a_ext = (v.force + v.dist) / v.mass;
        if !a_ext.iter().all(|c| c.is_finite()) {
            return Err("inputs force_* / dist_* are not finite".into());
        }
        let (mut stepper, mut x) = (self.stepper, self.x);
        // the right-hand side can fail (follower at the Earth's centre): keep the first message
        let err: RefCell<Option<String>> = RefCell::new(None);
        let r = stepper.advance(
            t,
            h,
            &[],
            &mut x,
            |_, _| {
                let err = &err;
                move |_tt: f64, xx: &State| match derivative(&orbit, &a_ext, xx) {
                    Ok(d) => d,
                    Err(e) => {
                        err.borrow_mut().get_or_insert(e);
                        State::from_element(f64::NAN)
                    }
                }
            },
            |_, _| Ok(()),
        );
        if let Some(e) = err.into_inner() {
            return Err(format!("in the step from t = {t}: {e}"));
        }
        r?;
        (self.stepper, self.x) = (stepper, x);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.stepper.check_against(&fresh.stepper)?;
        check_derived("leader orbit", &self.orbit, &fresh.orbit)?;
        check_finite_state("state vector", self.x.iter())
    }

    const STATES: Option<&'static [StateDecl]> = Some(&[
        // ẍ reads ẏ (Coriolis), ÿ reads ẋ, z̈ neither; gravity reads the whole position and nu
        StateDecl::new("state_pos_x", "m", "Continuous state: relative position x (radial)").depends_on(&["state_vel_x"]),
        StateDecl::new("state_pos_y", "m", "Continuous state: relative position y (along-track)").depends_on(&["state_vel_y"]),
        StateDecl::new("state_pos_z", "m", "Continuous state: relative position z (orbit normal)").depends_on(&["state_vel_z"]),
        StateDecl::new("state_vel_x", "m/s", "Continuous state: relative velocity x")
            .depends_on(&["force_x", "dist_x", "state_pos_x", "state_pos_y", "state_pos_z", "state_vel_y", "state_nu"]),
        StateDecl::new("state_vel_y", "m/s", "Continuous state: relative velocity y")
            .depends_on(&["force_y", "dist_y", "state_pos_x", "state_pos_y", "state_pos_z", "state_vel_x", "state_nu"]),
        StateDecl::new("state_vel_z", "m/s", "Continuous state: relative velocity z")
            .depends_on(&["force_z", "dist_z", "state_pos_x", "state_pos_y", "state_pos_z", "state_nu"]),
        StateDecl::new("state_nu", "rad", "Continuous state: leader true anomaly nu").depends_on(&["state_nu"]),
    ]);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(self.x.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
    }
    fn derivatives(&self, v: &RelativeOrbitPlantVars, _t: f64, dx: &mut [f64]) -> ModelResult {
        let a_ext = (v.force + v.dist) / v.mass;
        dx.copy_from_slice(derivative(&self.orbit, &a_ext, &self.x)?.as_slice());
        Ok(())
    }
}

const EQUATIONS_HTML: &str = "<pre>n    = sqrt(mu / a^3)\n\
dtheta/dt = n (1 + e cos nu)^2 / (1 - e^2)^(3/2),   dnu/dt = dtheta/dt\n\
d2theta/dt2 = -2 n^2 e sin nu (1 + e cos nu)^3 / (1 - e^2)^3\n\
R    = a (1 - e^2) / (1 + e cos nu)\n\
rho_f = sqrt((R + x)^2 + y^2 + z^2)\n\
x'' =  2 th' y' + th'' y + th'^2 x - mu (R + x)/rho_f^3 + mu/R^2 + (F_x + dist_x)/m\n\
y'' = -2 th' x' - th'' x + th'^2 y - mu y/rho_f^3 + (F_y + dist_y)/m\n\
z'' =                             - mu z/rho_f^3 + (F_z + dist_z)/m</pre>\n\
<p>LVLH: x radial outward, y along-track, z along the leader's angular momentum. mu/R^2 - mu (R + x)/rho_f^3 is \
evaluated without cancellation. Fixed-step RK4 (or explicit Euler) with ceil(step / max_internal_step) equal \
internal steps per communication step, or adaptive Dormand-Prince 5(4) with rtol = atol = the tolerance of fmi2SetupExperiment; inputs are held over the step; nu is not wrapped.</p>\n\
<p>Model Exchange: the state (x, y, z, x', y', z', nu) is published as state_pos_*, state_vel_*, state_nu with the \
right-hand side above; the importer's solver integrates it (integrator and max_internal_step are not used).</p>";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;
    use crate::math::relative_orbit::true_anomaly_from_mean;

    fn plant(set: impl FnOnce(&mut RelativeOrbitPlantVars)) -> Fmu<RelativeOrbitPlant> {
        let mut p = Fmu::<RelativeOrbitPlant>::default();
        set(&mut p.v);
        p.initialize(&Experiment::default()).unwrap();
        p
    }

    fn run(p: &mut Fmu<RelativeOrbitPlant>, t_end: f64, dt: f64, mut each: impl FnMut(f64, &State)) {
        let n = (t_end / dt).round() as usize;
        each(0.0, &p.model().x);
        for k in 0..n {
            p.step(k as f64 * dt, dt).unwrap();
            each((k + 1) as f64 * dt, &p.model().x);
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
            let period = p.model().orbit.period();
            run(&mut p, period, 50.0, |_, x| assert!(x.fixed_rows::<6>(0).iter().all(|c| *c == 0.0), "e {e}: {x:?}"));
        }
    }

    #[test]
    fn jacobi_integral_is_conserved_circular() {
        // ρ(0) = (100, 0, 50) m, ρ̇(0) = (0, −0.2, 0.05) m/s, RK4 h = 0.1 s, one orbit
        let mut p = plant(|v| {
            (v.init_pos.x, v.init_pos.z) = (100.0, 50.0);
            (v.init_vel.y, v.init_vel.z) = (-0.2, 0.05);
            v.max_internal_step = 0.1;
        });
        let (mu, r, n) = (p.model().orbit.mu, p.model().orbit.a, p.model().orbit.n);
        let jacobi = |x: &State| {
            let (px, py, pz) = (x[0], x[1], x[2]);
            let rf = ((r + px).powi(2) + py * py + pz * pz).sqrt();
            let grav = -mu * (2.0 * r * px + px * px + py * py + pz * pz) / (rf * r * (r + rf));
            let phi = 0.5 * n * n * (px * px + py * py) + grav + mu / (r * r) * px;
            0.5 * (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]) - phi
        };
        let c0 = jacobi(&p.model().x);
        let bound = 1e-6 * 0.5 * (0.2f64.powi(2) + 0.05f64.powi(2));
        let mut worst = 0.0f64;
        let period = p.model().orbit.period();
        run(&mut p, (period / 10.0).round() * 10.0, 10.0, |_, x| worst = worst.max((jacobi(x) - c0).abs()));
        assert!(worst < bound, "Jacobi drift {worst} >= {bound}");
    }

    #[test]
    fn true_anomaly_follows_kepler() {
        // e = 0.1, ν(t) vs Kepler's equation with M = n t, one orbit, 1e-9 rad
        let mut p = plant(|v| {
            v.eccentricity = 0.1;
            v.max_internal_step = 0.1;
        });
        let n = p.model().orbit.n;
        let mut worst = 0.0f64;
        let period = p.model().orbit.period();
        run(&mut p, (period / 5.0).ceil() * 5.0, 5.0, |t, x| worst = worst.max((x[6] - true_anomaly_from_mean(n * t, 0.1)).abs()));
        assert!(worst < 1e-9, "nu error {worst}");
    }

    #[test]
    fn constant_force_and_disturbance_add_up() {
        // a short time after rest, ρ ≈ ½ (F + d)/m t²; Coriolis and gravity-gradient terms are O(n t) = 1.4e-3
        // and O(n² t²) relative
        let mut p = plant(|v| v.max_internal_step = 0.01);
        (p.v.force.x, p.v.force.y, p.v.dist.z, p.v.dist.x) = (1.0, -2.0, 0.5, 0.25);
        run(&mut p, 1.0, 0.1, |_, _| {});
        let expect = Vector3::new(1.25, -2.0, 0.5) / 100.0 * 0.5;
        let got = Vector3::new(p.model().x[0], p.model().x[1], p.model().x[2]);
        assert!((got - expect).norm() < 1.5e-3 * expect.norm(), "{got:?} vs {expect:?}");
    }

    #[test]
    fn euler_is_first_order() {
        // integrator 1: error against RK4 halves when the internal step halves
        let ref_state = {
            let mut p = plant(|v| {
                (v.init_pos.x, v.init_vel.y) = (100.0, 0.3);
                v.max_internal_step = 0.1;
            });
            run(&mut p, 200.0, 10.0, |_, _| {});
            p.model().x
        };
        let err = |h: f64| {
            let mut p = plant(|v| {
                (v.init_pos.x, v.init_vel.y) = (100.0, 0.3);
                v.max_internal_step = h;
                v.integrator = 1;
            });
            run(&mut p, 200.0, 10.0, |_, _| {});
            (p.model().x - ref_state).fixed_rows::<3>(0).norm()
        };
        let ratio = err(0.2) / err(0.1);
        assert!((1.8..2.2).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn adaptive_integrator_agrees_with_fine_rk4() {
        // 1 km radial offset, eccentric leader, 600 s: Dormand–Prince (tol 1e-12) vs RK4 0.01 s
        let run = |integrator: i32, step: f64| {
            let mut p = Fmu::<RelativeOrbitPlant>::default();
            p.v.eccentricity = 0.1;
            p.v.init_pos.x = 1000.0;
            p.v.init_vel.y = -1.0;
            p.v.integrator = integrator;
            p.v.max_internal_step = step;
            let exp = Experiment { tolerance: Some(1e-12), ..Default::default() };
            p.initialize(&exp).unwrap();
            for k in 0..60 {
                p.step(k as f64 * 10.0, 10.0).unwrap();
            }
            p.model().x
        };
        let d = (run(2, 1.0) - run(0, 0.01)).fixed_rows::<3>(0).norm();
        assert!(d < 1e-6, "difference {d} m");
    }

    #[test]
    fn bad_parameters_are_rejected() {
        let mut p = Fmu::<RelativeOrbitPlant>::default();
        p.v.eccentricity = 1.0;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("eccentricity"));
        let mut p = Fmu::<RelativeOrbitPlant>::default();
        p.v.mass = 0.0;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("mass"));
        let mut p = Fmu::<RelativeOrbitPlant>::default();
        p.v.integrator = 3;
        assert!(p.initialize(&Experiment::default()).unwrap_err().contains("integrator"));
        let mut p = Fmu::<RelativeOrbitPlant>::default();
        p.v.init_pos.x = -6.0e6;
        assert!(p.initialize(&Experiment::default()).is_err());
    }
}
