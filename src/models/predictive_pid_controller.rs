//! `PredictivePidController`: paper 001's nonlinear predictive PID for formation flying: a nonlinear
//! predictive law (gains K1, K2 from the prediction horizon [T1, T2]) combined with a nonlinear
//! disturbance observer (gain c), written as a PID with nonlinear feed-forward N (spec controllers.md §2,
//! paper 001 Eqs. 22, 25, 26, 28, 39–47).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::predictive_control::predictive_gains;
use crate::math::relative_orbit::LeaderOrbit;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    #[allow(non_snake_case)]
    pub struct PredictivePidControllerVars {
        // inputs
        0 => pos_x: Real = 0.0, Input, Continuous, "m", "Measured relative position, LVLH x";
        1 => pos_y: Real = 0.0, Input, Continuous, "m", "Measured relative position, LVLH y";
        2 => pos_z: Real = 0.0, Input, Continuous, "m", "Measured relative position, LVLH z";
        3 => vel_x: Real = 0.0, Input, Continuous, "m/s", "Measured relative velocity, x";
        4 => vel_y: Real = 0.0, Input, Continuous, "m/s", "Measured relative velocity, y";
        5 => vel_z: Real = 0.0, Input, Continuous, "m/s", "Measured relative velocity, z";
        6 => pos_ref_x: Real = 0.0, Input, Continuous, "m", "Commanded relative position, x";
        7 => pos_ref_y: Real = 0.0, Input, Continuous, "m", "Commanded relative position, y";
        8 => pos_ref_z: Real = 0.0, Input, Continuous, "m", "Commanded relative position, z";
        9 => vel_ref_x: Real = 0.0, Input, Continuous, "m/s", "Commanded relative velocity, x";
        10 => vel_ref_y: Real = 0.0, Input, Continuous, "m/s", "Commanded relative velocity, y";
        11 => vel_ref_z: Real = 0.0, Input, Continuous, "m/s", "Commanded relative velocity, z";
        12 => acc_ref_x: Real = 0.0, Input, Continuous, "m/s2", "Commanded relative acceleration, x";
        13 => acc_ref_y: Real = 0.0, Input, Continuous, "m/s2", "Commanded relative acceleration, y";
        14 => acc_ref_z: Real = 0.0, Input, Continuous, "m/s2", "Commanded relative acceleration, z";
        15 => leader_true_anomaly: Real = 0.0, Input, Continuous, "rad", "Leader true anomaly nu (needed when eccentricity > 0)";
        // outputs
        20 => force_x: Real = 0.0, Output, Continuous, "N", "Control force, LVLH x";
        21 => force_y: Real = 0.0, Output, Continuous, "N", "Control force, LVLH y";
        22 => force_z: Real = 0.0, Output, Continuous, "N", "Control force, LVLH z";
        23 => dist_est_x: Real = 0.0, Output, Continuous, "N", "Estimated disturbance force m d_hat, x";
        24 => dist_est_y: Real = 0.0, Output, Continuous, "N", "Estimated disturbance force m d_hat, y";
        25 => dist_est_z: Real = 0.0, Output, Continuous, "N", "Estimated disturbance force m d_hat, z";
        26 => int_error_x: Real = 0.0, Output, Continuous, "m.s", "Integral of the position error E, x (structure 0)";
        27 => int_error_y: Real = 0.0, Output, Continuous, "m.s", "Integral of the position error E, y (structure 0)";
        28 => int_error_z: Real = 0.0, Output, Continuous, "m.s", "Integral of the position error E, z (structure 0)";
        // parameters
        100 => T1: Real = 0.0, Parameter, Fixed, "s", "Start of the prediction interval T1 (paper 001: 0)";
        101 => T2: Real = 5.0, Parameter, Fixed, "s", "End of the prediction interval T2 = prediction horizon T";
        102 => c: Real = 5.0, Parameter, Fixed, "1/s", "Disturbance-observer gain c (L = c I3), all axes unless c_* >= 0";
        103 => c_x: Real = -1.0, Parameter, Fixed, "1/s", "Observer gain for axis x; < 0: use c";
        104 => c_y: Real = -1.0, Parameter, Fixed, "1/s", "Observer gain for axis y; < 0: use c";
        105 => c_z: Real = -1.0, Parameter, Fixed, "1/s", "Observer gain for axis z; < 0: use c";
        106 => mass: Real = 100.0, Parameter, Fixed, "kg", "Follower mass m used by the controller (paper 001)";
        107 => mu: Real = 3.986004418e14, Parameter, Fixed, "m3/s2", "Gravitational parameter for the feed-forward G";
        108 => semi_major_axis: Real = 6.0e6, Parameter, Fixed, "m", "Leader semi-major axis for the feed-forward G";
        109 => eccentricity: Real = 0.0, Parameter, Fixed, "", "Leader eccentricity for the feed-forward G";
        110 => init_int_error_x: Real = 0.0, Parameter, Fixed, "m.s", "Initial integral state E(0), x (project addition; 0 in the paper)";
        111 => init_int_error_y: Real = 0.0, Parameter, Fixed, "m.s", "Initial integral state E(0), y";
        112 => init_int_error_z: Real = 0.0, Parameter, Fixed, "m.s", "Initial integral state E(0), z";
        120 => structure: Integer = 0, Parameter, Fixed, "", "0 = PID form with integral state (Eq. 40); 1 = predictive law + disturbance-observer state (Eqs. 26, 28)";
        // calculated parameters
        200 => K1: Real = 0.0, CalculatedParameter, Fixed, "1/s2", "Predictive gain K1 = Hbar33^-1 Hbar31";
        201 => K2: Real = 0.0, CalculatedParameter, Fixed, "1/s", "Predictive gain K2 = Hbar33^-1 Hbar32";
        202 => P_x: Real = 0.0, CalculatedParameter, Fixed, "N/m", "Proportional gain P = m (K1 + c K2), x";
        203 => P_y: Real = 0.0, CalculatedParameter, Fixed, "N/m", "Proportional gain, y";
        204 => P_z: Real = 0.0, CalculatedParameter, Fixed, "N/m", "Proportional gain, z";
        205 => D_x: Real = 0.0, CalculatedParameter, Fixed, "N.s/m", "Derivative gain D = m (K2 + c), x";
        206 => D_y: Real = 0.0, CalculatedParameter, Fixed, "N.s/m", "Derivative gain, y";
        207 => D_z: Real = 0.0, CalculatedParameter, Fixed, "N.s/m", "Derivative gain, z";
        208 => I_g_x: Real = 0.0, CalculatedParameter, Fixed, "N/(m.s)", "Integral gain I_g = m c K1, x";
        209 => I_g_y: Real = 0.0, CalculatedParameter, Fixed, "N/(m.s)", "Integral gain, y";
        210 => I_g_z: Real = 0.0, CalculatedParameter, Fixed, "N/(m.s)", "Integral gain, z";
    }
}

/// Controller structure (controllers.md §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Structure {
    /// F = P e + D ė + I_g E + N, E advanced by E += e Δ.
    Pid,
    /// F = m (K1 e + K2 ė + acc_ref + G − d̂), d̂ = z + c ρ̇, ż = −c (K1 e + K2 ė + acc_ref).
    Observer,
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct PredictivePidController {
    v: PredictivePidControllerVars,
    orbit: LeaderOrbit,
    c: Vector3<f64>,
    structure: Option<Structure>,
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
    fn k(&self) -> (f64, f64) {
        (self.v.K1, self.v.K2)
    }

    /// z(0) that makes structure 1 start from the same d̂(0) as structure 0 with E(0):
    /// d̂(0) = −c (ė + K2 e + K1 E(0)).
    fn z_initial(&self, e: &Vector3<f64>, e_dot: &Vector3<f64>, vel: &Vector3<f64>) -> Vector3<f64> {
        let (k1, k2) = self.k();
        let d0 = -self.c.component_mul(&(e_dot + e * k2 + self.int_e * k1));
        d0 - self.c.component_mul(vel)
    }

    fn law(&self) -> Result<Law, String> {
        let v = &self.v;
        let structure = self.structure.ok_or("controller was not initialized")?;
        let pos = Vector3::new(v.pos_x, v.pos_y, v.pos_z);
        let vel = Vector3::new(v.vel_x, v.vel_y, v.vel_z);
        let e = Vector3::new(v.pos_ref_x, v.pos_ref_y, v.pos_ref_z) - pos;
        let e_dot = Vector3::new(v.vel_ref_x, v.vel_ref_y, v.vel_ref_z) - vel;
        let acc_ref = Vector3::new(v.acc_ref_x, v.acc_ref_y, v.acc_ref_z);
        let g = self.orbit.g_term(v.leader_true_anomaly, &pos, &vel).map_err(|e| format!("feed-forward G: {e}"))?;
        let m = v.mass;
        let (k1, k2) = self.k();
        let (force, d_hat) = match structure {
            Structure::Pid => {
                let p = Vector3::new(v.P_x, v.P_y, v.P_z);
                let d = Vector3::new(v.D_x, v.D_y, v.D_z);
                let ig = Vector3::new(v.I_g_x, v.I_g_y, v.I_g_z);
                let n = (acc_ref + g) * m;
                let force = p.component_mul(&e) + d.component_mul(&e_dot) + ig.component_mul(&self.int_e) + n;
                let d_hat = -self.c.component_mul(&(e_dot + e * k2 + self.int_e * k1));
                (force, d_hat)
            }
            Structure::Observer => {
                let z = self.z.unwrap_or_else(|| self.z_initial(&e, &e_dot, &vel));
                let d_hat = z + self.c.component_mul(&vel);
                let force = (e * k1 + e_dot * k2 + acc_ref + g - d_hat) * m;
                (force, d_hat)
            }
        };
        Ok(Law { force, d_hat, e, e_dot, acc_ref })
    }
}

impl Model for PredictivePidController {
    type Vars = PredictivePidControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "PredictivePidController",
        description: "Paper 001 nonlinear predictive PID (predictive law + disturbance observer) for leader-follower formation control",
        source: "paper 001 Eqs. 22, 25, 26, 28, 39-47; shared/spec controllers.md §2",
        equations_html: "<pre>Hbar_ij = (T2^(i+j-1) - T1^(i+j-1)) / ((i-1)! (j-1)! (i+j-1))     (Eq. 22)\n\
K1 = Hbar33^-1 Hbar31,  K2 = Hbar33^-1 Hbar32   (T1 = 0: K1 = 10/(3 T^2), K2 = 5/(2 T))   (Eq. 25)\n\
e = pos_ref - pos,  e' = vel_ref - vel,  E = integral of e  (E += e(t_k) step in doStep)\n\
P = m (K1 + c K2),  D = m (K2 + c),  I_g = m c K1                     (Eqs. 41-43)\n\
N = m (acc_ref + G(pos, vel; nu))                                       (Eq. 44)\n\
structure 0:  F = P e + D e' + I_g E + N                                (Eq. 40)\n\
              dist_est = m d_hat,  d_hat = -c (e' + K2 e + K1 E)        (Eq. 39)\n\
structure 1:  F = m (K1 e + K2 e' + acc_ref + G - d_hat),  d_hat = z + c vel,\n\
              dz/dt = -c (K1 e + K2 e' + acc_ref)    (observer d_hat' = c (d - d_hat), Eq. 28)\n\
closed loop:  (s + c)(s^2 + K2 s + K1) = 0,  poles -c and (-1.25 +- 1.3307 j)/T for T1 = 0</pre>\n\
<p>G is the plant's G (third row mu z/rho_f^3) from the controller's own mu, semi_major_axis, eccentricity and the \
leader_true_anomaly input. Per-axis observer gains c_x, c_y, c_z override c when >= 0. Structure 1 starts from \
d_hat(0) = -c (e'(0) + K2 e(0) + K1 E(0)), which makes both structures equal in continuous time.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 300.0,
        default_step: 0.001,
        variable_step: true,
    };

    fn vars(&self) -> &PredictivePidControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut PredictivePidControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let structure = match check::choice("structure", self.v.structure, &[0, 1])? {
            0 => Structure::Pid,
            _ => Structure::Observer,
        };
        let v = &mut self.v;
        let (k1, k2) = predictive_gains(v.T1, v.T2)?;
        let c_all = check::non_negative("c", v.c)?;
        let mut c = Vector3::zeros();
        for (i, (n, ci)) in [("c_x", v.c_x), ("c_y", v.c_y), ("c_z", v.c_z)].into_iter().enumerate() {
            c[i] = if check::finite(n, ci)? < 0.0 { c_all } else { ci };
        }
        let m = check::positive("mass", v.mass)?;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, v.eccentricity)?;
        let e0 = Vector3::new(
            check::finite("init_int_error_x", v.init_int_error_x)?,
            check::finite("init_int_error_y", v.init_int_error_y)?,
            check::finite("init_int_error_z", v.init_int_error_z)?,
        );
        (v.K1, v.K2) = (k1, k2);
        let p = (Vector3::repeat(k1) + c * k2) * m;
        let d = (Vector3::repeat(k2) + c) * m;
        let ig = c * (m * k1);
        (v.P_x, v.P_y, v.P_z) = (p.x, p.y, p.z);
        (v.D_x, v.D_y, v.D_z) = (d.x, d.y, d.z);
        (v.I_g_x, v.I_g_y, v.I_g_z) = (ig.x, ig.y, ig.z);
        self.orbit = orbit;
        self.c = c;
        self.structure = Some(structure);
        self.int_e = e0;
        self.z = None;
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let law = self.law()?;
        let m = self.v.mass;
        let int_e = self.int_e;
        let v = &mut self.v;
        (v.force_x, v.force_y, v.force_z) = (law.force.x, law.force.y, law.force.z);
        (v.dist_est_x, v.dist_est_y, v.dist_est_z) = (m * law.d_hat.x, m * law.d_hat.y, m * law.d_hat.z);
        (v.int_error_x, v.int_error_y, v.int_error_z) = (int_e.x, int_e.y, int_e.z);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let law = self.law()?;
        let (k1, k2) = self.k();
        match self.structure.ok_or("controller was not initialized")? {
            // E(t_k + Δ) = E(t_k) + e(t_k) Δ (controllers.md §2, project choice)
            Structure::Pid => self.int_e += law.e * h,
            // z(t_k + Δ) = z(t_k) − c (K1 e + K2 ė + acc_ref)(t_k) Δ, z(0) from d̂(0) of structure 0
            Structure::Observer => {
                let vel = Vector3::new(self.v.vel_x, self.v.vel_y, self.v.vel_z);
                let z = self.z.unwrap_or_else(|| self.z_initial(&law.e, &law.e_dot, &vel));
                self.z = Some(z - self.c.component_mul(&(law.e * k1 + law.e_dot * k2 + law.acc_ref)) * h);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controller(t2: f64, c: f64, set: impl FnOnce(&mut PredictivePidControllerVars)) -> PredictivePidController {
        let mut k = PredictivePidController::default();
        k.v.T2 = t2;
        k.v.c = c;
        set(&mut k.v);
        k.initialize(&Experiment::default()).unwrap();
        k
    }

    #[test]
    fn gains_of_the_four_cases() {
        // spec controllers.md §2 table (m = 100 kg)
        for (t2, c, p, d, ig) in [
            (5.0, 5.0, 263.333, 550.0, 66.6667),
            (25.0, 5.0, 50.5333, 510.0, 2.66667),
            (25.0, 25.0, 250.533, 2510.0, 13.3333),
            (25.0, 150.0, 1500.53, 15010.0, 80.0),
        ] {
            let k = controller(t2, c, |_| {});
            let v = &k.v;
            assert!((v.K1 - 10.0 / (3.0 * t2 * t2)).abs() < 1e-15 && (v.K2 - 2.5 / t2).abs() < 1e-15);
            for (got, want) in [(v.P_x, p), (v.D_y, d), (v.I_g_z, ig)] {
                assert!((got - want).abs() < 1e-5 * want, "case ({t2}, {c}): {got} vs {want}");
            }
        }
    }

    #[test]
    fn per_axis_observer_gain() {
        let k = controller(25.0, 5.0, |v| v.c_y = 150.0);
        assert!((k.v.D_x - 510.0).abs() < 1e-9 && (k.v.D_y - 15010.0).abs() < 1e-9 && (k.v.D_z - 510.0).abs() < 1e-9);
    }

    #[test]
    fn feed_forward_cancels_g_and_law_is_pid() {
        let mut k = controller(5.0, 5.0, |v| v.eccentricity = 0.1);
        let v = &mut k.v;
        (v.pos_x, v.pos_y, v.pos_z, v.vel_x, v.vel_y, v.vel_z) = (10.0, -20.0, 5.0, 0.1, 0.2, -0.3);
        (v.pos_ref_x, v.pos_ref_y, v.pos_ref_z) = (50.0, 40.0, 60.0);
        (v.acc_ref_x, v.leader_true_anomaly) = (0.01, 1.0);
        k.int_e = Vector3::new(1.0, 2.0, 3.0);
        k.update_outputs(0.0).unwrap();
        let v = &k.v;
        let orbit = LeaderOrbit::new(v.mu, v.semi_major_axis, 0.1).unwrap();
        let pos = Vector3::new(10.0, -20.0, 5.0);
        let vel = Vector3::new(0.1, 0.2, -0.3);
        let g = orbit.g_term(1.0, &pos, &vel).unwrap();
        let e = Vector3::new(40.0, 60.0, 55.0);
        let ed = -vel;
        let (k1, k2, c, m) = (10.0 / 75.0, 0.5, 5.0, 100.0);
        let want = (e * (k1 + c * k2) + ed * (k2 + c) + k.int_e * (c * k1) + Vector3::new(0.01, 0.0, 0.0) + g) * m;
        let got = Vector3::new(v.force_x, v.force_y, v.force_z);
        assert!((got - want).norm() < 1e-12 * want.norm(), "{got:?} vs {want:?}");
        let d_want = -(ed + e * k2 + k.int_e * k1) * (c * m);
        assert!((Vector3::new(v.dist_est_x, v.dist_est_y, v.dist_est_z) - d_want).norm() < 1e-12 * d_want.norm());
    }

    #[test]
    fn integral_advances_with_error_at_step_start() {
        let mut k = controller(5.0, 5.0, |v| v.init_int_error_z = 0.5);
        (k.v.pos_ref_x, k.v.pos_z) = (2.0, 1.0);
        k.do_step(0.0, 0.1, &Experiment::default()).unwrap();
        k.update_outputs(0.1).unwrap();
        assert_eq!((k.v.int_error_x, k.v.int_error_y, k.v.int_error_z), (0.2, 0.0, 0.5 - 0.1));
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
            (k.v.pos_ref_x, k.v.pos_ref_y, k.v.pos_ref_z) = (50.0, 40.0, 60.0);
            let (mut p, mut vel) = (Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
            let mut trace = Vec::new();
            for step in 0..60_000 {
                (k.v.pos_x, k.v.pos_y, k.v.pos_z, k.v.vel_x, k.v.vel_y, k.v.vel_z) = (p.x, p.y, p.z, vel.x, vel.y, vel.z);
                k.update_outputs(step as f64 * dt).unwrap();
                let a = Vector3::new(k.v.force_x, k.v.force_y, k.v.force_z) / 100.0 + d;
                trace.push(p.x);
                k.do_step(step as f64 * dt, dt, &Experiment::default()).unwrap();
                p += vel * dt + a * (0.5 * dt * dt);
                vel += a * dt;
            }
            k.update_outputs(60.0).unwrap();
            let est = Vector3::new(k.v.dist_est_x, k.v.dist_est_y, k.v.dist_est_z) / 100.0;
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
        let mut k = PredictivePidController::default();
        k.v.T2 = 0.0;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("T2"));
        let mut k = PredictivePidController::default();
        k.v.c = -1.0;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("c"));
        let mut k = PredictivePidController::default();
        k.v.structure = 3;
        assert!(k.initialize(&Experiment::default()).unwrap_err().contains("structure"));
    }
}
