//! The plant's environment: disturbance generator (constant, sinusoid, seeded zero-order-held white
//! noise), gravity gradient and the geomagnetic field on a circular orbit, and the events (fault
//! onset, noise-hold boundaries) at which a communication step is cut.

use nalgebra::{Matrix3, Vector3};

use super::{AttitudePlant, AttitudePlantVars};
use crate::math::environment::gravity_gradient;
use crate::math::random::{hold_index, normal};
use crate::math::sample_grid::{beyond, exact_index, MAX_INDEX};

/// What is constant over one internal step (steps are cut at fault_time and at noise-hold boundaries).
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    pub faulted: bool,
    pub noise: Vector3<f64>,
}

/// Whether the noise generator runs (its hold boundaries are also time events under Model Exchange).
pub fn noise_on(v: &AttitudePlantVars) -> bool {
    v.dist_noise_std != Vector3::zeros()
}

/// Zero-order-held white noise of hold interval k: σ_i N(seed, k, i) (counter-based, `math::random`).
pub fn noise(v: &AttitudePlantVars, k: i64) -> Vector3<f64> {
    if !noise_on(v) {
        return Vector3::zeros();
    }
    let s = v.dist_noise_seed as i64;
    Vector3::from_fn(|i, _| v.dist_noise_std[i] * normal(s, k, i as u64))
}

/// Segment of the instant t (for outputs): fault active from fault_time on, noise interval ⌊t/T_n⌋.
/// Beyond 2^53 intervals (refused for a noise-on plant by the layer's time bound, `Model::time_grid`)
/// the last countable interval: a key only, no arithmetic follows.
pub fn segment_at(v: &AttitudePlantVars, t: f64) -> Segment {
    let k = hold_index(t, v.dist_noise_hold).unwrap_or(MAX_INDEX);
    Segment { faulted: t >= v.fault_time, noise: noise(v, k) }
}

/// Segment of an event-free piece starting at ts with length len (evaluated at its midpoint).
pub fn segment_of_piece(v: &AttitudePlantVars, ts: f64, len: f64) -> Segment {
    let mid = ts + 0.5 * len;
    let k = exact_index((mid / v.dist_noise_hold).floor()).unwrap_or(MAX_INDEX);
    Segment { faulted: mid >= v.fault_time, noise: noise(v, k) }
}

/// Breakpoints inside (t, t + h): fault onset and the noise-hold boundaries k T_n.
pub fn breakpoints(v: &AttitudePlantVars, t: f64, h: f64) -> Result<Vec<f64>, String> {
    let mut b = vec![v.fault_time];
    if noise_on(v) {
        let tn = v.dist_noise_hold;
        let k0 = hold_index(t, tn).ok_or_else(|| beyond("time", t, tn))? + 1; // |k| <= 2^53: no overflow
        let k1 = hold_index(t + h, tn).ok_or_else(|| beyond("step end", t + h, tn))?;
        if k1 - k0 > 1_000_000 {
            return Err(format!("dist_noise_hold = {tn} s gives more than 1e6 noise intervals in one step of {h} s"));
        }
        b.extend((k0..=k1).map(|k| k as f64 * tn));
    }
    Ok(b)
}

impl AttitudePlant {
    /// Geomagnetic field in body axes, B_b = A B_R(t).
    pub(super) fn field_body(&self, t: f64, a: &Matrix3<f64>) -> Vector3<f64> {
        a * self.d.orbit.field_ref(t)
    }

    /// Disturbance generator + gravity gradient + input: τ_ext.
    pub(super) fn external(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>, seg: &Segment) -> Vector3<f64> {
        let mut tau = v.torque_dist + v.dist_const + seg.noise;
        if v.dist_sin_amp != Vector3::zeros() {
            let wt = v.dist_sin_freq * t;
            tau += Vector3::from_fn(|i, _| v.dist_sin_amp[i] * (wt + v.dist_sin_phase[i]).sin());
        }
        if v.gg_enable == 1 {
            tau += gravity_gradient(self.d.n2, &(a * self.d.orbit.r_hat(t)), &self.inertia);
        }
        tau
    }
}
