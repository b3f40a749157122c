//! The environment seen by `AttitudePlant`: the field in the body frame, the disturbance budget and the
//! external torque (methods over the free functions of `environment.rs`).

use nalgebra::{Matrix3, Vector3};
use super::environment::{Budget, Segment};
use super::variables::AttitudePlantVars;
use crate::math::environment::gravity_gradient;
use crate::math::surface_forces::{drag, radiation_pressure, solar_pressure};
use super::AttitudePlant;

impl AttitudePlant {
    /// Geomagnetic field in body axes, B_b = A B_R: the dipole of the circular orbit at t, or the input
    /// b_eci (environment_inputs = 1).
    pub(super) fn field_body(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>) -> Vector3<f64> {
        if v.environment_inputs == 1 {
            return a * v.b_eci;
        }
        a * self.d.orbit.field_ref(t)
    }

    /// Whether the external torque needs the attitude matrix.
    pub(super) fn budget_needs_attitude(&self, v: &AttitudePlantVars) -> bool {
        v.gg_enable == 1 || v.environment_inputs == 1 || v.residual_dipole != Vector3::zeros()
    }

    /// Gravity gradient (gg_enable), residual dipole, and with the environment inputs drag and solar
    /// pressure on the facets.
    pub(super) fn budget(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>) -> Budget {
        let mut b = Budget::default();
        let world = v.environment_inputs == 1;
        if v.gg_enable == 1 {
            b.gg = if world {
                let r = v.r.norm();
                gravity_gradient(v.mu / (r * r * r), &(a * (v.r / r)), &self.inertia)
            } else {
                gravity_gradient(self.d.n2, &(a * self.d.orbit.r_hat(t)), &self.inertia)
            };
        }
        if v.residual_dipole != Vector3::zeros() {
            b.residual = v.residual_dipole.cross(&self.field_body(v, t, a));
        }
        if world && self.d.has_facets {
            let v_rel = v.v - Vector3::z().cross(&v.r) * v.earth_rotation_rate;
            b.aero = drag(&self.d.facets, v.rho, &(a * v_rel));
            let to_sun = v.sun_eci * v.sun_distance - v.r;
            let d = to_sun.norm();
            let seen = if v.eclipse_shadows_srp == 1 { v.eclipse } else { 1.0 };
            let p = radiation_pressure(v.solar_flux, d, seen);
            b.srp = solar_pressure(&self.d.facets, p, &(a * (to_sun / d)));
        }
        b
    }

    /// Disturbance generator + input + the budget: τ_ext.
    pub(super) fn external(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>, seg: &Segment) -> Vector3<f64> {
        self.external_with(v, t, a, seg, None)
    }

    /// [`Self::external`] with the budget already computed (the outputs compute it once for both).
    pub(super) fn external_with(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>, seg: &Segment, budget: Option<&Budget>) -> Vector3<f64> {
        let mut tau = v.torque_dist + v.dist_const + seg.noise;
        if v.dist_sin_amp != Vector3::zeros() {
            let wt = v.dist_sin_freq * t;
            tau += Vector3::from_fn(|i, _| v.dist_sin_amp[i] * (wt + v.dist_sin_phase[i]).sin());
        }
        if v.gg_enable == 1 && v.environment_inputs == 0 && v.residual_dipole == Vector3::zeros() {
            // the papers' plant: the same operations as before the budget existed (bit for bit)
            tau += gravity_gradient(self.d.n2, &(a * self.d.orbit.r_hat(t)), &self.inertia);
        } else if self.budget_needs_attitude(v) {
            tau += match budget {
                Some(b) => b.torque(),
                None => self.budget(v, t, a).torque(),
            };
        }
        tau
    }
}
