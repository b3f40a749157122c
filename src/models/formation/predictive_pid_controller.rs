//! `PredictivePidController`: paper 001's nonlinear predictive PID for formation flying: a nonlinear
//! predictive law (gains K1, K2 from the prediction horizon [T1, T2]) combined with a nonlinear
//! disturbance observer (gain c), written as a PID with nonlinear feed-forward N (paper 001 Eqs. 22,
//! 25, 26, 28, 39–47).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::predictive_control::predictive_gains;
use crate::math::relative_orbit::LeaderOrbit;
use crate::model::{check_derived, check_finite_state, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum, StateDecl};

declare_variables! {
    #[allow(non_snake_case)]
    pub struct PredictivePidControllerVars {
        // inputs
        0 => pos: Vec3 = [0.0; 3], Input, "m", "Measured relative position, LVLH";
        3 => vel: Vec3 = [0.0; 3], Input, "m/s", "Measured relative velocity, LVLH";
        6 => pos_ref: Vec3 = [0.0; 3], Input, "m", "Commanded relative position, LVLH";
        9 => vel_ref: Vec3 = [0.0; 3], Input, "m/s", "Commanded relative velocity, LVLH";
        12 => acc_ref: Vec3 = [0.0; 3], Input, "m/s2", "Commanded relative acceleration, LVLH";
        15 => leader_true_anomaly: Real = 0.0, Input, "rad", "Leader true anomaly nu (needed when eccentricity > 0)";
        // outputs
        20 => force: Vec3 = [0.0; 3], Output, "N", "Control force, LVLH";
        23 => dist_est: Vec3 = [0.0; 3], Output, "N", "Estimated disturbance force m d_hat, LVLH";
        26 => int_error: Vec3 = [0.0; 3], Output, "m.s", "Integral of the position error E (structure 0)";
        // parameters
        114 => T1: Real = 0.0, Parameter, "s", "Start of the prediction interval T1 ([NPPID-Formation]: 0)";
        115 => T2: Real = 5.0, Parameter, "s", "End of the prediction interval T2 = prediction horizon T";
        116 => c: Real = 5.0, Parameter, "1/s", "Disturbance-observer gain c (L = c I3), all axes unless c_* >= 0", NonNegative;
        117 => c_x: Real = -1.0, Parameter, "1/s", "Observer gain for axis x; < 0: use c";
        118 => c_y: Real = -1.0, Parameter, "1/s", "Observer gain for axis y; < 0: use c";
        119 => c_z: Real = -1.0, Parameter, "1/s", "Observer gain for axis z; < 0: use c";
        104 => mass: Real = 100.0, Parameter, "kg", "Follower mass m used by the controller ([NPPID-Formation])", Positive;
        100 => mu: Real = 3.986004418e14, Parameter, "m3/s2", "Gravitational parameter for the feed-forward G";
        101 => semi_major_axis: Real = 6.0e6, Parameter, "m", "Leader semi-major axis for the feed-forward G";
        102 => eccentricity: Real = 0.0, Parameter, "", "Leader eccentricity for the feed-forward G";
        150 => init_int_error: Vec3 = [0.0; 3], Parameter, "m.s", "Initial integral state E(0) (project addition; 0 in the paper)";
        120 => structure: Integer = 0, Parameter, "", "0 = PID form with integral state (Eq. 40); 1 = predictive law + disturbance-observer state (Eqs. 26, 28)", Choice(Structure::CODES);
        // calculated parameters
        200 => K1: Real = 0.0, CalculatedParameter, "1/s2", "Predictive gain K1 = Hbar33^-1 Hbar31";
        201 => K2: Real = 0.0, CalculatedParameter, "1/s", "Predictive gain K2 = Hbar33^-1 Hbar32";
        202 => P: Vec3 = [0.0; 3], CalculatedParameter, "N/m", "Proportional gain P = m (K1 + c K2)";
        205 => D: Vec3 = [0.0; 3], CalculatedParameter, "N.s/m", "Derivative gain D = m (K2 + c)";
        208 => I_g: Vec3 = [0.0; 3], CalculatedParameter, "N/(m.s)", "Integral gain I_g = m c K1";
    }
}

crate::param_enum! {
    /// Controller structure (`structure` parameter).
    pub enum Structure {
        /// 0: F = P e + D ė + I_g E + N, E advanced by E += e Δ.
        Pid = 0,
        /// 1: F = m (K1 e + K2 ė + acc_ref + G − d̂), d̂ = z + c ρ̇, ż = −c (K1 e + K2 ė + acc_ref).
        Observer = 1,
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct PredictivePidController {
    orbit: LeaderOrbit,
    c: Vector3<f64>,
    structure: Structure,
    /// Integral of the position error E (structure 0).
    int_e: Vector3<f64>,
    /// Observer auxiliary state z with d̂ = z + c ρ̇ (structure 1); set at the first step.
    z: Option<Vector3<f64>>,
}

/// Signals of one evaluation of the law.
struct Law {
    force: Vector3<f64>,
    d_hat: Vector3<f64>,
    e: Vector3<f64>,
    e_dot: Vector3<f64>,
    acc_ref: Vector3<f64>,
}

impl PredictivePidController {
    /// z(0) that makes structure 1 start from the same d̂(0) as structure 0 with E(0):
    /// d̂(0) = −c (ė + K2 e + K1 E(0)).
    fn z_initial(&self, v: &PredictivePidControllerVars, e: &Vector3<f64>, e_dot: &Vector3<f64>) -> Vector3<f64> {
        let d0 = -self.c.component_mul(&(e_dot + e * v.K2 + self.int_e * v.K1));
        d0 - self.c.component_mul(&v.vel)
    }

    fn law(&self, v: &PredictivePidControllerVars) -> Result<Law, String> {
        let e = v.pos_ref - v.pos;
        let e_dot = v.vel_ref - v.vel;
        let acc_ref = v.acc_ref;
        let g = self.orbit.g_term(v.leader_true_anomaly, &v.pos, &v.vel).map_err(|e| format!("feed-forward G: {e}"))?;
        let m = v.mass;
        let (k1, k2) = (v.K1, v.K2);
        let (force, d_hat) = match self.structure {
            Structure::Pid => {
                let n = (acc_ref + g) * m;
                let force = v.P.component_mul(&e) + v.D.component_mul(&e_dot) + v.I_g.component_mul(&self.int_e) + n;
                let d_hat = -self.c.component_mul(&(e_dot + e * k2 + self.int_e * k1));
                (force, d_hat)
            }
            Structure::Observer => {
                let z = self.z.unwrap_or_else(|| self.z_initial(v, &e, &e_dot));
                let d_hat = z + self.c.component_mul(&v.vel);
                let force = (e * k1 + e_dot * k2 + acc_ref + g - d_hat) * m;
                (force, d_hat)
            }
        };
        Ok(Law { force, d_hat, e, e_dot, acc_ref })
    }
}

impl Model for PredictivePidController {
    type Vars = PredictivePidControllerVars;
    const EVOLVING: &'static [&'static str] = &["int_e", "z"];
    const INFO: ModelInfo = ModelInfo {
        name: "PredictivePidController",
        description: "Nonlinear predictive PID (predictive law + disturbance observer) for leader-follower formation control",
        source: "[NPPID-Formation], Eqs. 22, 25, 26, 28, 39-47",
        equations_html: EQUATIONS_HTML,
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 300.0,
        default_step: 0.001,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut PredictivePidControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let structure = Structure::from_param("structure", v.structure)?;
        let (k1, k2) = predictive_gains(v.T1, v.T2)?;
        let c = Vector3::new(v.c_x, v.c_y, v.c_z).map(|ci| if ci < 0.0 { v.c } else { ci });
        let m = v.mass;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, v.eccentricity)?;
        (v.K1, v.K2) = (k1, k2);
        v.P = (Vector3::repeat(k1) + c * k2) * m;
        v.D = (Vector3::repeat(k2) + c) * m;
        v.I_g = c * (m * k1);
        Ok(PredictivePidController { orbit, c, structure, int_e: v.init_int_error, z: None })
    }

    fn outputs(&self, v: &mut PredictivePidControllerVars, _t: f64) -> ModelResult {
        let law = self.law(v)?;
        v.force = law.force;
        v.dist_est = law.d_hat * v.mass;
        v.int_error = self.int_e;
        Ok(())
    }

    fn step(&mut self, v: &PredictivePidControllerVars, _t: f64, h: f64) -> ModelResult {
        let law = self.law(v)?;
        match self.structure {
            // E(t_k + Δ) = E(t_k) + e(t_k) Δ (project choice)
            Structure::Pid => self.int_e += law.e * h,
            // z(t_k + Δ) = z(t_k) − c (K1 e + K2 ė + acc_ref)(t_k) Δ, z(0) from d̂(0) of structure 0
            Structure::Observer => {
                let z = self.z.unwrap_or_else(|| self.z_initial(v, &law.e, &law.e_dot));
                self.z = Some(z - self.c.component_mul(&(law.e * v.K1 + law.e_dot * v.K2 + law.acc_ref)) * h);
            }
        }
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("structure, observer gains and leader orbit", &(self.structure, self.c, self.orbit), &(fresh.structure, fresh.c, fresh.orbit))?;
        check_finite_state("integral and observer states", self.int_e.iter().chain(self.z.iter().flatten()))
    }

    // Model Exchange: E and z are the states (both published; the structure not in use keeps its
    // state constant). z starts as in Co-Simulation, from the inputs at the start (z_initial).
    const STATES: Option<&'static [StateDecl]> = Some(&[
        StateDecl::new("state_int_error_x", "m.s", "Continuous state: integral of the position error E_x (structure 0)").depends_on(&["pos_ref_x", "pos_x"]),
        StateDecl::new("state_int_error_y", "m.s", "Continuous state: integral of the position error E_y (structure 0)").depends_on(&["pos_ref_y", "pos_y"]),
        StateDecl::new("state_int_error_z", "m.s", "Continuous state: integral of the position error E_z (structure 0)").depends_on(&["pos_ref_z", "pos_z"]),
        StateDecl::new("state_z_x", "m/s2", "Continuous state: observer state z_x, d_hat = z + c vel (structure 1)")
            .depends_on(&["pos_ref_x", "pos_x", "vel_ref_x", "vel_x", "acc_ref_x"])
            .starting_from(&["pos_ref_x", "pos_x", "vel_ref_x", "vel_x"]),
        StateDecl::new("state_z_y", "m/s2", "Continuous state: observer state z_y (structure 1)")
            .depends_on(&["pos_ref_y", "pos_y", "vel_ref_y", "vel_y", "acc_ref_y"])
            .starting_from(&["pos_ref_y", "pos_y", "vel_ref_y", "vel_y"]),
        StateDecl::new("state_z_z", "m/s2", "Continuous state: observer state z_z (structure 1)")
            .depends_on(&["pos_ref_z", "pos_z", "vel_ref_z", "vel_z", "acc_ref_z"])
            .starting_from(&["pos_ref_z", "pos_z", "vel_ref_z", "vel_z"]),
    ]);
    fn get_states(&self, v: &PredictivePidControllerVars, x: &mut [f64]) {
        let z = self.z.unwrap_or_else(|| self.z_initial(v, &(v.pos_ref - v.pos), &(v.vel_ref - v.vel)));
        x[0..3].copy_from_slice(self.int_e.as_slice());
        x[3..6].copy_from_slice(z.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.int_e = Vector3::new(x[0], x[1], x[2]);
        self.z = Some(Vector3::new(x[3], x[4], x[5]));
    }
    fn derivatives(&self, v: &PredictivePidControllerVars, _t: f64, dx: &mut [f64]) -> ModelResult {
        let (e, e_dot) = (v.pos_ref - v.pos, v.vel_ref - v.vel);
        let (d_int, d_z) = match self.structure {
            Structure::Pid => (e, Vector3::zeros()),
            Structure::Observer => (Vector3::zeros(), -self.c.component_mul(&(e * v.K1 + e_dot * v.K2 + v.acc_ref))),
        };
        dx[0..3].copy_from_slice(d_int.as_slice());
        dx[3..6].copy_from_slice(d_z.as_slice());
        Ok(())
    }
}

const EQUATIONS_HTML: &str = "<pre>Hbar_ij = (T2^(i+j-1) - T1^(i+j-1)) / ((i-1)! (j-1)! (i+j-1))     (Eq. 22)\n\
K1 = Hbar33^-1 Hbar31,  K2 = Hbar33^-1 Hbar32   (T1 = 0: K1 = 10/(3 T^2), K2 = 5/(2 T))   (Eq. 25)\n\
e = pos_ref - pos,  e' = vel_ref - vel,  E = integral of e  (E += e(t_k) step in doStep)\n\
P = m (K1 + c K2),  D = m (K2 + c),  I_g = m c K1                     (Eqs. 41-43)\n\
N = m (acc_ref + G(pos, vel; nu))                                       (Eq. 44)\n\
structure 0:  F = P e + D e' + I_g E + N                                (Eq. 40)\n\
              dist_est = m d_hat,  d_hat = -c (e' + K2 e + K1 E)        (Eq. 39)\n\
structure 1:  F = m (K1 e + K2 e' + acc_ref + G - d_hat),  d_hat = z + c vel,\n\
              dz/dt = -c (K1 e + K2 e' + acc_ref)    (observer d_hat' = c (d - d_hat), Eq. 28)\n\
closed loop:  (s + c)(s^2 + K2 s + K1) = 0,  poles -c and (-1.25 +- 1.3307 j)/T for T1 = 0</pre>\n\
<p>Model Exchange: E and z are the continuous states state_int_error_* and state_z_* with dE/dt = e (structure 0) \
and dz/dt as above (structure 1); the other structure's state stays constant. The importer's solver integrates them \
(Co-Simulation uses the explicit Euler step shown).</p>\n\
<p>G is the plant's G (third row mu z/rho_f^3) from the controller's own mu, semi_major_axis, eccentricity and the \
leader_true_anomaly input. Per-axis observer gains c_x, c_y, c_z override c when >= 0. Structure 1 starts from \
d_hat(0) = -c (e'(0) + K2 e(0) + K1 E(0)), which makes both structures equal in continuous time.</p>";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn controller(t2: f64, c: f64, set: impl FnOnce(&mut PredictivePidControllerVars)) -> Fmu<PredictivePidController> {
        let mut k = Fmu::<PredictivePidController>::default();
        k.v.T2 = t2;
        k.v.c = c;
        set(&mut k.v);
        k.initialize(&Experiment::default()).unwrap();
        k
    }

    #[test]
    fn gains_of_the_four_cases() {
        // gains P, D, I_g of Eqs. 41-43 worked by hand (m = 100 kg)
        for (t2, c, p, d, ig) in [
            (5.0, 5.0, 263.333, 550.0, 66.6667),
            (25.0, 5.0, 50.5333, 510.0, 2.66667),
            (25.0, 25.0, 250.533, 2510.0, 13.3333),
            (25.0, 150.0, 1500.53, 15010.0, 80.0),
        ] {
            let k = controller(t2, c, |_| {});
            let v = &k.v;
            assert!((v.K1 - 10.0 / (3.0 * t2 * t2)).abs() < 1e-15 && (v.K2 - 2.5 / t2).abs() < 1e-15);
            for (got, want) in [(v.P.x, p), (v.D.y, d), (v.I_g.z, ig)] {
                assert!((got - want).abs() < 1e-5 * want, "case ({t2}, {c}): {got} vs {want}");
            }
        }
    }

    #[test]
    fn per_axis_observer_gain() {
        let k = controller(25.0, 5.0, |v| v.c_y = 150.0);
        assert!((k.v.D.x - 510.0).abs() < 1e-9 && (k.v.D.y - 15010.0).abs() < 1e-9 && (k.v.D.z - 510.0).abs() < 1e-9);
    }

    #[test]
    fn feed_forward_cancels_g_and_law_is_pid() {
        let mut k = controller(5.0, 5.0, |v| v.eccentricity = 0.1);
        let v = &mut k.v;
        (v.pos.x, v.pos.y, v.pos.z, v.vel.x, v.vel.y, v.vel.z) = (10.0, -20.0, 5.0, 0.1, 0.2, -0.3);
        (v.pos_ref.x, v.pos_ref.y, v.pos_ref.z) = (50.0, 40.0, 60.0);
        (v.acc_ref.x, v.leader_true_anomaly) = (0.01, 1.0);
        k.model_mut().int_e = Vector3::new(1.0, 2.0, 3.0);
        k.outputs(0.0).unwrap();
        let v = &k.v;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, 0.1).unwrap();
        let pos = Vector3::new(10.0, -20.0, 5.0);
        let vel = Vector3::new(0.1, 0.2, -0.3);
        let g = orbit.g_term(1.0, &pos, &vel).unwrap();
        let e = Vector3::new(40.0, 60.0, 55.0);
        let ed = -vel;
        let (k1, k2, c, m) = (10.0 / 75.0, 0.5, 5.0, 100.0);
        let want = (e * (k1 + c * k2) + ed * (k2 + c) + k.model().int_e * (c * k1) + Vector3::new(0.01, 0.0, 0.0) + g) * m;
        let got = Vector3::new(v.force.x, v.force.y, v.force.z);
        assert!((got - want).norm() < 1e-12 * want.norm(), "{got:?} vs {want:?}");
        let d_want = -(ed + e * k2 + k.model().int_e * k1) * (c * m);
        assert!((Vector3::new(v.dist_est.x, v.dist_est.y, v.dist_est.z) - d_want).norm() < 1e-12 * d_want.norm());
    }

    #[test]
    fn integral_advances_with_error_at_step_start() {
        let mut k = controller(5.0, 5.0, |v| v.init_int_error.z = 0.5);
        (k.v.pos_ref.x, k.v.pos.z) = (2.0, 1.0);
        k.step(0.0, 0.1).unwrap();
        k.outputs(0.1).unwrap();
        assert_eq!((k.v.int_error.x, k.v.int_error.y, k.v.int_error.z), (0.2, 0.0, 0.5 - 0.1));
    }

    /// Closed loop with the exact double integrator ë = −u + d (ρ̈ = F/m − G + d, feed-forward exact):
    /// both structures converge to d̂ = d and e = 0, and agree with each other to O(Δ).
    #[test]
    fn structures_agree_and_estimate_constant_disturbance() {
        let dt = 1e-3;
        let d = Vector3::new(1e-4, -2e-4, 3e-4);
        let sim = |structure: i32| {
            let mut k = controller(5.0, 5.0, |v| {
                v.structure = structure;
                v.mu = 1e-30; // G ≈ 0: the plant below is a pure double integrator
            });
            (k.v.pos_ref.x, k.v.pos_ref.y, k.v.pos_ref.z) = (50.0, 40.0, 60.0);
            let (mut p, mut vel) = (Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
            let mut trace = Vec::new();
            for step in 0..60_000 {
                (k.v.pos.x, k.v.pos.y, k.v.pos.z, k.v.vel.x, k.v.vel.y, k.v.vel.z) = (p.x, p.y, p.z, vel.x, vel.y, vel.z);
                k.outputs(step as f64 * dt).unwrap();
                let a = Vector3::new(k.v.force.x, k.v.force.y, k.v.force.z) / 100.0 + d;
                trace.push(p.x);
                k.step(step as f64 * dt, dt).unwrap();
                p += vel * dt + a * (0.5 * dt * dt);
                vel += a * dt;
            }
            k.outputs(60.0).unwrap();
            let est = Vector3::new(k.v.dist_est.x, k.v.dist_est.y, k.v.dist_est.z) / 100.0;
            (p, est, trace)
        };
        let (p0, est0, tr0) = sim(0);
        let (p1, est1, tr1) = sim(1);
        for (p, est) in [(p0, est0), (p1, est1)] {
            assert!((p - Vector3::new(50.0, 40.0, 60.0)).norm() < 1e-4, "{p:?}");
            assert!((est - d).norm() < 1e-3 * d.norm(), "{est:?}");
        }
        let diff = tr0.iter().zip(&tr1).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(diff < 0.05, "structures differ by {diff} m"); // O(Δ) rectangle-rule differences on a 50 m step
    }

    #[test]
    fn bad_parameters_are_rejected() {
        let mut k = Fmu::<PredictivePidController>::default();
        k.v.T2 = 0.0;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("T2"));
        let mut k = Fmu::<PredictivePidController>::default();
        k.v.c = -1.0;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("c"));
        let mut k = Fmu::<PredictivePidController>::default();
        k.v.structure = 3;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("structure"));
    }
}
