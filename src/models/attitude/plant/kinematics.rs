//! Attitude representations of the plant state (`kinematics` parameter): state layout, kinematic
//! rates, the attitude matrix and quaternion of a state, and the projection after each internal step.

use nalgebra::{Matrix3, SVector, Vector3};

use crate::math::attitude::{align_sign, attitude_matrix, euler213_rates, orthonormalize, quat, quat_derivative, quat_from_dcm, quat_from_euler321, skew, wxyz};

crate::param_enum! {
    /// Kinematics option.
    pub enum Kinematics {
        /// 0: quaternion, renormalised after every internal step.
        Quaternion = 0,
        /// 1: direction cosine matrix.
        Dcm = 1,
        /// 2: paper 000's Euler-angle rates (213 rates, angles read as 321).
        Euler213Rates = 2,
        /// 3: linear small-angle double integrator per axis.
        LinearSmallAngle = 3,
        /// 4: quaternion kinematics with linear, decoupled dynamics I_ii ω̇_i = τ_i (paper 000's
        /// large-angle MRAC set-up: linear dynamics, nonlinear kinematics).
        QuaternionLinearDynamics = 4,
    }
}

impl Kinematics {
    /// Whether the attitude state is a quaternion (modes 0 and 4).
    pub fn is_quaternion(self) -> bool {
        matches!(self, Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics)
    }

    /// Whether the dynamics are the linear decoupled I_ii ẋ_i = τ_i (modes 3 and 4).
    pub fn linear_dynamics(self) -> bool {
        matches!(self, Kinematics::LinearSmallAngle | Kinematics::QuaternionLinearDynamics)
    }
}

/// Length of the state vector. Layout (unused entries stay 0):
/// - `ATT..ATT+9`: attitude — quaternion (w, x, y, z) in modes 0 and 4, the DCM A column-major in mode 1,
///   the angles (φ, θ, ψ) in modes 2 and 3;
/// - `W..W+3`: body rate ω (kinematics 0–2, 4) or the angle rates (φ̇, θ̇, ψ̇) (kinematics 3);
/// - `HW..HW+3`: wheel momentum h_w (actuator mode 1);
/// - `TW..TW+3`: lagged wheel torque τ_w (actuator mode 1 with T_w > 0).
pub const N: usize = 18;
pub const ATT: usize = 0;
pub const W: usize = 9;
pub const HW: usize = 12;
pub const TW: usize = 15;
pub type State = SVector<f64, N>;

pub fn v3(x: &State, i: usize) -> Vector3<f64> {
    Vector3::new(x[i], x[i + 1], x[i + 2])
}

/// The attitude part of the initial state for a 321 attitude.
pub fn initial_attitude(kin: Kinematics, x: &mut State, (r0, p0, y0): (f64, f64, f64)) -> Result<(), String> {
    let q0 = quat_from_euler321(r0, p0, y0);
    match kin {
        Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => x.as_mut_slice()[ATT..ATT + 4].copy_from_slice(&wxyz(&q0)),
        Kinematics::Dcm => x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(attitude_matrix(&q0).as_slice()),
        Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => {
            if kin == Kinematics::Euler213Rates && r0.cos().abs() < 1e-9 {
                return Err(format!("init_euler321_roll = {r0} is the singularity of the Euler-angle kinematics (kinematics = 2)"));
            }
            x.as_mut_slice()[ATT..ATT + 3].copy_from_slice(&[r0, p0, y0]);
        }
    }
    Ok(())
}

/// Attitude rates into `d` for body rate w (kinematics 0–2 and 4; in mode 3 w is the angle rate).
pub fn attitude_rates(kin: Kinematics, x: &State, w: &Vector3<f64>, d: &mut State) {
    match kin {
        Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => {
            let qdot = quat_derivative(&quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3]), w);
            // nalgebra stores (i, j, k, w); the state holds (w, x, y, z)
            (d[ATT], d[ATT + 1], d[ATT + 2], d[ATT + 3]) = (qdot.w, qdot.i, qdot.j, qdot.k);
        }
        Kinematics::Dcm => {
            // Ȧ = −[ω×] A (paper 000 Eq. 12)
            let a = Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]);
            let adot = -skew(w) * a;
            d.as_mut_slice()[ATT..ATT + 9].copy_from_slice(adot.as_slice());
        }
        Kinematics::Euler213Rates => {
            // paper 000 Eq. 8, corrected sign (213 rates)
            let r = euler213_rates(x[ATT], x[ATT + 2], w);
            d.fixed_rows_mut::<3>(ATT).copy_from(&r);
        }
        Kinematics::LinearSmallAngle => d.fixed_rows_mut::<3>(ATT).copy_from(w),
    }
}

/// Projection after every internal step: quaternion renormalisation (modes 0 and 4), optional DCM
/// re-orthonormalisation (mode 1); also updates the sign-continuous DCM quaternion.
pub fn post_step(kin: Kinematics, orthonormalize_dcm: bool, q_dcm: &mut [f64; 4], x: &mut State, t: f64) -> Result<(), String> {
    match kin {
        Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => {
            let n = x.fixed_rows::<4>(ATT).norm();
            if !(n > 0.0) {
                return Err(format!("quaternion norm became zero at t = {t}"));
            }
            x.fixed_rows_mut::<4>(ATT).unscale_mut(n);
        }
        Kinematics::Dcm => {
            let mut a = Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]);
            if orthonormalize_dcm {
                a = orthonormalize(&a);
                x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(a.as_slice());
            }
            let prev = quat(q_dcm[0], q_dcm[1], q_dcm[2], q_dcm[3]);
            // A drifts off SO(3) without re-orthonormalisation; report a unit quaternion
            let q = align_sign(quat_from_dcm(&a), &prev).normalize();
            *q_dcm = wxyz(&q);
        }
        Kinematics::Euler213Rates => {
            if x[ATT].cos().abs() < 1e-9 {
                return Err(format!("Euler-angle kinematics (mode 2) reached the singularity roll = ±90° at t = {t}"));
            }
        }
        Kinematics::LinearSmallAngle => {}
    }
    Ok(())
}
