//! Paper 000's attitude error signals and the per-axis linear law shared by PD, LQR and pole placement.

use nalgebra::Vector3;

use super::ports::{check_unit_quaternions, AttitudeControllerPorts};
use crate::math::attitude::{attitude_matrix, error_quaternion, euler321_from_quat, wrap_pi};

crate::param_enum! {
    /// Error signal (`error_law` parameter), ≈ commanded minus actual angle per axis.
    pub enum ErrorLaw {
        /// 0: e = 2 q_E,w q_E,v with q_E = q* ⊗ q_ref.
        Quaternion = 0,
        /// 1: e = (A_E[3,2], A_E[1,3], A_E[2,1]) with A_E = A(q) A(q_ref)ᵀ.
        Dcm = 1,
        /// 2: e = wrap(euler321(q_ref) − euler321(q)).
        Euler = 2,
    }
}

impl ErrorLaw {
    pub fn error(self, p: &AttitudeControllerPorts) -> Vector3<f64> {
        match self {
            // e^Q = 2 q_E,w q_E,v with q_E = q* ⊗ q_ref (paper 000 Eq. 35)
            ErrorLaw::Quaternion => {
                let e = error_quaternion(&p.q, &p.q_ref);
                e.vector() * (2.0 * e.w)
            }
            // A_E = A(q) A(q_ref)ᵀ, e^D = (A_E[3,2], A_E[1,3], A_E[2,1]) (paper 000 Eq. 13)
            ErrorLaw::Dcm => {
                let a = attitude_matrix(&p.q) * attitude_matrix(&p.q_ref).transpose();
                Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)])
            }
            // e^E = wrap(euler321(q_ref) − euler321(q)) (paper 000 Eqs. 2, 11)
            ErrorLaw::Euler => {
                let r = euler321_from_quat(&p.q_ref);
                let m = euler321_from_quat(&p.q);
                Vector3::new(wrap_pi(r[0] - m[0]), wrap_pi(r[1] - m[1]), wrap_pi(r[2] - m[2]))
            }
        }
    }
}

/// The per-axis linear law of paper 000's PD, LQR and pole-placement controllers:
/// T = k_e ⊙ e + k_w ⊙ ω, with e from `law` (≈ commanded minus actual angle). In the paper's
/// convention the rate gain k_w is negative (it adds +k_d·rate with k_d < 0).
pub fn linear_law(law: ErrorLaw, p: &AttitudeControllerPorts, k_e: &Vector3<f64>, k_w: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    check_unit_quaternions(p)?;
    Ok(k_e.component_mul(&law.error(p)) + k_w.component_mul(&p.w))
}
