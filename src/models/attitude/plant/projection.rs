//! Model Exchange projection events of `AttitudePlant` (the invariants' drift and the projection;
//! the published states and time events are in `exchange.rs`).

use nalgebra::Matrix3;
use super::kinematics::{post_step, Kinematics, ATT};
use super::variables::AttitudePlantVars;
use crate::math::attitude::orthonormalize;
use super::exchange::ROUNDOFF;
use super::AttitudePlant;

impl AttitudePlant {
    fn drift(&self, v: &AttitudePlantVars) -> f64 {
        match self.kin {
            Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => (self.x.fixed_rows::<4>(ATT).norm() - 1.0).abs(),
            Kinematics::Dcm if v.dcm_orthonormalize == 1 => {
                let a = Matrix3::from_column_slice(&self.x.as_slice()[ATT..ATT + 9]);
                (a.transpose() * a - Matrix3::identity()).abs().max()
            }
            _ => 0.0,
        }
    }

    /// After an accepted solver step: follow the output quaternion's sign (DCM) and ask for an event
    /// when the representation has drifted.
    pub(super) fn needs_projection(&mut self, v: &AttitudePlantVars) -> bool {
        if self.kin == Kinematics::Dcm {
            let mut x = self.x;
            let _ = post_step(Kinematics::Dcm, false, &mut self.q_dcm, &mut x, 0.0);
        }
        self.drift(v) > self.d.projection_threshold
    }

    /// Event update: renormalise q (re-orthonormalise A); whether the state changed.
    pub(super) fn project(&mut self, v: &AttitudePlantVars, t: f64) -> Result<bool, String> {
        if self.drift(v) <= ROUNDOFF {
            return Ok(false); // already on the invariant: a repeated event pass changes nothing
        }
        let before = self.x;
        match self.kin {
            Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => post_step(self.kin, false, &mut self.q_dcm, &mut self.x, t)?,
            Kinematics::Dcm if v.dcm_orthonormalize == 1 => {
                let a = orthonormalize(&Matrix3::from_column_slice(&self.x.as_slice()[ATT..ATT + 9]));
                self.x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(a.as_slice());
                let mut x = self.x;
                post_step(Kinematics::Dcm, false, &mut self.q_dcm, &mut x, t)?;
            }
            _ => {}
        }
        Ok(self.x != before)
    }

    /// The Euler-angle chart (kinematics 2) is singular at roll = ±90°.
    pub(super) fn check_chart(&self, t: f64) -> Result<(), String> {
        if self.kin == Kinematics::Euler213Rates && self.x[ATT].cos().abs() < 1e-9 {
            return Err(format!("Euler-angle kinematics (mode 2) reached the singularity roll = ±90° at t = {t}"));
        }
        Ok(())
    }
}
