//! The quaternion sliding-mode law of paper 003's controllers and the variable block they share
//! (`SlidingModeController`: fixed switching gain; `Type2FuzzySmcController`: gain scheduled per axis
//! by an interval type-2 fuzzy system).
//!
//! ```text
//! q_e = q_ref* ⊗ q, sign flipped so that q_e,w ≥ 0       (body relative to reference, short way)
//! ω_e = ω − A(q_e) ω_ref
//! s   = ω_e + λ q_e,v
//! q̇_e,v = ½ (q_e,w ω_e + q_e,v × ω_e)
//! T_eq = ω × (Î ω + h_w) − Î (λ q̇_e,v + ω_e × A(q_e) ω_ref)    (ṡ = 0 for the nominal model, ω_ref constant)
//! T   = T_eq − K ⊙ sat(s/Φ),   sat = clamp to [−1, 1] componentwise
//! ```
//! With T = T_eq − K ⊙ sat(s/Φ) on the nominal plant, Î ṡ = −K ⊙ sat(s/Φ) + (disturbance): outside the
//! boundary layer every |s_i| decreases while K_i exceeds the disturbance's share.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};

declare_variables! {
    /// Inputs, diagnostic outputs and parameters of every sliding-mode attitude controller besides the
    /// common ports: wheel momentum in (14–16), error quaternion, gain in use, sliding variable and
    /// equivalent control out (30–35, 39–44), full nominal inertia (100–102, 135–137), λ (109), k (130),
    /// Φ (131).
    pub struct SmcVariables {
        14 => h_wheel: Vec3 = [0.0; 3], Input, "N.m.s", "Reaction-wheel momentum h_w in body axes (wire from the plant; 0 = no wheels)";
        30 => q_err: Vec3 = [0.0; 3], Output, "", "Vector part of the error quaternion q_e = q_ref* (x) q, short way (q_e,w >= 0)";
        33 => k_gain: Vec3 = [0.0; 3], Output, "N.m", "Switching gain K in use per axis";
        39 => s: Vec3 = [0.0; 3], Output, "rad/s", "Sliding variable s = w_e + lambda q_e,v";
        42 => torque_eq: Vec3 = [0.0; 3], Output, "N.m", "Equivalent control T_eq";
        100 => inertia: Diag3 = [4.0, 5.0, 3.5], Parameter, "kg.m2", "Controller's nominal inertia, diagonal entries ([T2FSMC-LEO] plant default)", Positive;
        109 => lambda: Real = 0.2, Parameter, "1/s", "Sliding-surface slope lambda_s", Positive;
        130 => k_switch: Real = 0.005, Parameter, "N.m", "Switching gain k (GA-tuned; 0 = equivalent control only)", NonNegative;
        131 => boundary_layer: Real = 0.005, Parameter, "rad/s", "Boundary-layer width Phi of sat(s/Phi)", Positive;
        135 => inertia_xy: Real = 0.05, Parameter, "kg.m2", "Nominal inertia matrix entry xy (matrix entry, not product of inertia)";
        136 => inertia_xz: Real = -0.03, Parameter, "kg.m2", "Nominal inertia matrix entry xz";
        137 => inertia_yz: Real = 0.02, Parameter, "kg.m2", "Nominal inertia matrix entry yz";
    }
}

/// The sliding-mode law with its nominal inertia matrix Î, λ and Φ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SmcLaw {
    pub inertia: Matrix3<f64>,
    pub lambda: f64,
    pub phi: f64,
}

/// The signals of one evaluation of the law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmcSignals {
    /// q_e,v (short way)
    pub q_ev: Vector3<f64>,
    /// q̇_e,v
    pub q_ev_dot: Vector3<f64>,
    /// s = ω_e + λ q_e,v
    pub s: Vector3<f64>,
    /// T_eq
    pub t_eq: Vector3<f64>,
}

impl SmcVariables {
    /// The law from the parameters; refuses a nominal inertia matrix that is not positive definite.
    pub fn law(&self) -> Result<SmcLaw, String> {
        let d = self.inertia;
        let i = Matrix3::new(
            d.x,
            self.inertia_xy,
            self.inertia_xz,
            self.inertia_xy,
            d.y,
            self.inertia_yz,
            self.inertia_xz,
            self.inertia_yz,
            d.z,
        );
        if i.cholesky().is_none() {
            return Err(format!(
                "parameters inertia_xx/yy/zz = ({}, {}, {}), inertia_xy/xz/yz = ({}, {}, {}): the nominal inertia matrix is not positive definite",
                d.x, d.y, d.z, self.inertia_xy, self.inertia_xz, self.inertia_yz
            ));
        }
        Ok(SmcLaw {
            inertia: i,
            lambda: self.lambda,
            phi: self.boundary_layer,
        })
    }

    /// Writes the diagnostic outputs and returns the torque T = T_eq − K ⊙ sat(s/Φ); fails on a
    /// non-finite result.
    pub fn finish(&mut self, law: &SmcLaw, sig: &SmcSignals, k: &Vector3<f64>) -> Result<Vector3<f64>, String> {
        let torque = law.torque(sig, k);
        if !torque.iter().all(|t| t.is_finite()) {
            return Err(format!(
                "sliding-mode torque is not finite ({torque:?}); check the inputs q, w, q_ref, w_ref, h_wheel"
            ));
        }
        self.q_err = sig.q_ev;
        self.k_gain = *k;
        self.s = sig.s;
        self.torque_eq = sig.t_eq;
        Ok(torque)
    }
}

impl SmcLaw {
    /// Error quaternion, sliding variable and equivalent control for the inputs.
    pub fn signals(&self, p: &AttitudeControllerPorts, h_wheel: &Vector3<f64>) -> Result<SmcSignals, String> {
        check_unit_quaternions(p)?;
        let q = p.q.normalize();
        let q_ref = p.q_ref.normalize();
        let mut qe = q_ref.conjugate() * q;
        if qe.w < 0.0 {
            qe = -qe;
        }
        let qv: Vector3<f64> = qe.vector().into_owned();
        let a_e = attitude_matrix(&qe);
        let w_ref_b = a_e * p.w_ref; // A(q_e) ω_ref
        let w_e = p.w - w_ref_b;
        let s = w_e + qv * self.lambda;
        let qv_dot = (w_e * qe.w + qv.cross(&w_e)) * 0.5;
        let t_eq =
            p.w.cross(&(self.inertia * p.w + h_wheel)) - self.inertia * (qv_dot * self.lambda + w_e.cross(&w_ref_b));
        Ok(SmcSignals {
            q_ev: qv,
            q_ev_dot: qv_dot,
            s,
            t_eq,
        })
    }

    /// T = T_eq − K ⊙ sat(s/Φ).
    pub fn torque(&self, sig: &SmcSignals, k: &Vector3<f64>) -> Vector3<f64> {
        let sat = sig.s.map(|si| (si / self.phi).clamp(-1.0, 1.0));
        sig.t_eq - k.component_mul(&sat)
    }
}

/// The law's equations for the generated documentation.
pub const SMC_EQUATIONS_HTML: &str = "<pre>q_e   = q_ref* (x) q, sign flipped so that q_e,w >= 0   (body relative to reference, short way)\n\
w_e   = w - A(q_e) w_ref\n\
s     = w_e + lambda q_e,v\n\
q_e,v' = 1/2 (q_e,w w_e + q_e,v x w_e)\n\
T_eq  = w x (I w + h_w) - I (lambda q_e,v' + w_e x A(q_e) w_ref)     (ds/dt = 0 for the nominal model, constant w_ref)\n\
T     = T_eq - K (.) sat(s / Phi),   sat = clamp(., -1, 1) per axis</pre>\n\
<p>I is the controller's full nominal inertia matrix (inertia_xx/yy/zz and the off-diagonal matrix entries \
inertia_xy/xz/yz), h_w the wheel momentum input (h_wheel_*, 0 when not wired).</p>";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::{quat, quat_derivative, quat_from_euler321};
    use nalgebra::Quaternion;

    fn ports(
        q: Quaternion<f64>,
        w: Vector3<f64>,
        q_ref: Quaternion<f64>,
        w_ref: Vector3<f64>,
    ) -> AttitudeControllerPorts {
        AttitudeControllerPorts {
            q,
            w,
            q_ref,
            w_ref,
            ..Default::default()
        }
    }

    /// Rigid body with wheels, I ω̇ = T − ω × (Iω + h), h constant, q̇ = ½ q ⊗ ω: under T = T_eq the
    /// sliding variable (finite difference over a short RK4-integrated interval) does not change,
    /// also for a rotating reference q̇_ref = ½ q_ref ⊗ ω_ref with constant ω_ref.
    #[test]
    fn equivalent_control_keeps_s_constant_on_the_nominal_model() {
        let mut v = SmcVariables::default();
        let law = v.law().unwrap();
        let i_inv = law.inertia.try_inverse().unwrap();
        let h = Vector3::new(0.1, -0.05, 0.2);
        let w_ref = Vector3::new(0.01, -0.02, 0.015);
        let mut q = quat_from_euler321(0.3, -0.2, 0.5);
        let mut w = Vector3::new(0.05, -0.03, 0.02);
        let mut q_ref = quat_from_euler321(-0.1, 0.1, 0.2);
        let s0 = law.signals(&ports(q, w, q_ref, w_ref), &h).unwrap().s;
        let dt = 1e-3;
        // state derivative under the equivalent control
        let f = |q: Quaternion<f64>, w: Vector3<f64>, q_ref: Quaternion<f64>| {
            let t = law
                .signals(&ports(q.normalize(), w, q_ref.normalize(), w_ref), &h)
                .unwrap()
                .t_eq;
            (
                quat_derivative(&q, &w),
                i_inv * (t - w.cross(&(law.inertia * w + h))),
                quat_derivative(&q_ref, &w_ref),
            )
        };
        for _ in 0..2000 {
            let (a1, b1, c1) = f(q, w, q_ref);
            let (a2, b2, c2) = f(q + a1 * (dt / 2.0), w + b1 * (dt / 2.0), q_ref + c1 * (dt / 2.0));
            let (a3, b3, c3) = f(q + a2 * (dt / 2.0), w + b2 * (dt / 2.0), q_ref + c2 * (dt / 2.0));
            let (a4, b4, c4) = f(q + a3 * dt, w + b3 * dt, q_ref + c3 * dt);
            q += (a1 + a2 * 2.0 + a3 * 2.0 + a4) * (dt / 6.0);
            w += (b1 + b2 * 2.0 + b3 * 2.0 + b4) * (dt / 6.0);
            q_ref += (c1 + c2 * 2.0 + c3 * 2.0 + c4) * (dt / 6.0);
        }
        let s1 = law
            .signals(&ports(q.normalize(), w, q_ref.normalize(), w_ref), &h)
            .unwrap()
            .s;
        assert!(
            (s1 - s0).norm() < 1e-9 * s0.norm().max(1.0),
            "s moved from {s0:?} to {s1:?}"
        );
        // and the finish step writes the diagnostics
        let sig = law
            .signals(&ports(q.normalize(), w, q_ref.normalize(), w_ref), &h)
            .unwrap();
        let t = v.finish(&law, &sig, &Vector3::repeat(0.01)).unwrap();
        assert_eq!(v.s, sig.s);
        assert!((t - law.torque(&sig, &Vector3::repeat(0.01))).norm() == 0.0);
    }

    #[test]
    fn error_quaternion_takes_the_short_way_and_saturation_clamps() {
        let v = SmcVariables::default();
        let law = v.law().unwrap();
        // q and −q describe the same attitude: identical signals
        let q = quat_from_euler321(0.2, 0.1, -0.3);
        let q_ref = quat(1.0, 0.0, 0.0, 0.0);
        let w = Vector3::new(0.01, 0.0, -0.02);
        let a = law
            .signals(&ports(q, w, q_ref, Vector3::zeros()), &Vector3::zeros())
            .unwrap();
        let b = law
            .signals(&ports(-q, w, q_ref, Vector3::zeros()), &Vector3::zeros())
            .unwrap();
        assert!((a.s - b.s).norm() < 1e-15 && (a.q_ev - q.vector() * q.w.signum()).norm() < 1e-15);
        // far outside the boundary layer: T = T_eq − K sign(s)
        let k = Vector3::new(1.0, 2.0, 3.0);
        let t = law.torque(&a, &k);
        let expect = a.t_eq - k.component_mul(&a.s.map(f64::signum));
        assert!((t - expect).norm() < 1e-15);
    }

    #[test]
    fn indefinite_inertia_is_refused() {
        let v = SmcVariables {
            inertia_xy: 10.0,
            ..Default::default()
        };
        let e = v.law().unwrap_err();
        assert!(e.contains("inertia_xy"), "{e}");
    }
}
