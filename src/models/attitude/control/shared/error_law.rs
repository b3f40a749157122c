//! Paper 000's attitude error signals and the per-axis linear law shared by PD, LQR and pole placement.

use nalgebra::Vector3;

use crate::math::attitude::{attitude_matrix, error_quaternion, euler321_from_quat, wrap_pi};
use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};

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

crate::param_enum! {
    /// Reading of paper 000's DCM error (`dcm_error` parameter of `PdController`). The paper prints
    /// e^D = (A_E[3,2], A_E[1,3], A_E[2,1]) with A_E = A(q) A(q_ref)ᵀ; it fixes neither the direction of
    /// its attitude matrix for the error (inertial → body or body → inertial) nor whether the skew part
    /// is meant. M = A(q) A(q_ref)ᵀ, N = A(q)ᵀ A(q_ref); every reading is ≈ commanded − actual angle for
    /// small attitude and error angles; they differ at large angles.
    pub enum DcmError {
        /// 0: e = (M[3,2], M[1,3], M[2,1]), the elements as printed (today's default).
        BodyElements = 0,
        /// 1: e = vex((M − Mᵀ)/2) = sin α · axis (equals the quaternion law e^Q).
        BodySkewHalf = 1,
        /// 2: e = vex(M − Mᵀ) = 2 sin α · axis (the skew part without the ½).
        BodySkewFull = 2,
        /// 3: e = −(M[2,3], M[3,1], M[1,2]): the printed elements of A(q_ref) A(q)ᵀ, sign set so that e ≈ commanded − actual.
        BodyTransposed = 3,
        /// 4: e = −(N[3,2], N[1,3], N[2,1]): the printed elements with the attitude matrix read as body → inertial.
        InertialElements = 4,
        /// 5: e = (N[2,3], N[3,1], N[1,2]): the printed elements of A(q_ref)ᵀ A(q).
        InertialTransposed = 5,
    }
}

impl DcmError {
    pub fn error(self, p: &AttitudeControllerPorts) -> Vector3<f64> {
        let (a, r) = (attitude_matrix(&p.q), attitude_matrix(&p.q_ref));
        let el = |m: &nalgebra::Matrix3<f64>| Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)]);
        let tr = |m: &nalgebra::Matrix3<f64>| Vector3::new(m[(1, 2)], m[(2, 0)], m[(0, 1)]);
        match self {
            DcmError::BodyElements => el(&(a * r.transpose())),
            DcmError::BodySkewHalf => {
                let m = a * r.transpose();
                (el(&m) - tr(&m)) * 0.5
            }
            DcmError::BodySkewFull => {
                let m = a * r.transpose();
                el(&m) - tr(&m)
            }
            DcmError::BodyTransposed => -tr(&(a * r.transpose())),
            DcmError::InertialElements => -el(&(a.transpose() * r)),
            DcmError::InertialTransposed => tr(&(a.transpose() * r)),
        }
    }
}

/// The per-axis linear law of paper 000's PD, LQR and pole-placement controllers:
/// T = k_e ⊙ e + k_w ⊙ ω, with e from `law` (≈ commanded minus actual angle). In the paper's
/// convention the rate gain k_w is negative (it adds +k_d·rate with k_d < 0).
pub fn linear_law(
    law: ErrorLaw,
    p: &AttitudeControllerPorts,
    k_e: &Vector3<f64>,
    k_w: &Vector3<f64>,
) -> Result<Vector3<f64>, String> {
    check_unit_quaternions(p)?;
    Ok(k_e.component_mul(&law.error(p)) + k_w.component_mul(&p.w))
}
