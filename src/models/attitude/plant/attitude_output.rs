//! The attitude matrix and output quaternion of a state (`AttitudePlant` methods over the kinematics of
//! `kinematics.rs`).

use nalgebra::{Matrix3, Quaternion};
use crate::math::attitude::{align_sign, attitude_matrix, quat, quat_from_dcm, quat_from_euler321};
use super::kinematics::{Kinematics, State, ATT};
use super::AttitudePlant;

impl AttitudePlant {
    /// Attitude matrix A (v_B = A v_R) of a state: A(q) in mode 0, the integrated DCM in mode 1,
    /// A321 of the state angles in modes 2 and 3 (paper 000 reads its angles as 321).
    pub(super) fn attitude(&self, x: &State) -> Matrix3<f64> {
        match self.kin {
            Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => attitude_matrix(&quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3])),
            Kinematics::Dcm => Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => attitude_matrix(&quat_from_euler321(x[ATT], x[ATT + 1], x[ATT + 2])),
        }
    }

    /// Output quaternion of a state (never sign-flipped in mode 0; sign-continuous in mode 1).
    pub(super) fn quaternion(&self, x: &State) -> Quaternion<f64> {
        match self.kin {
            Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3]),
            // Shepperd's quaternion of the state's A with the sign of the last accepted step's (equal to
            // q_dcm itself right after a step; a Model Exchange solver also evaluates in between)
            Kinematics::Dcm => {
                let prev = quat(self.q_dcm[0], self.q_dcm[1], self.q_dcm[2], self.q_dcm[3]);
                align_sign(quat_from_dcm(&Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9])), &prev).normalize()
            }
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => quat_from_euler321(x[ATT], x[ATT + 1], x[ATT + 2]),
        }
    }
}
