//! Star-tracker latency compensation of the `Mekf` (parameter `st_latency`): the quaternion that arrives
//! at filter sample k was measured at sample s = k − d, d = st_latency / sample_period.
//!
//! The filter keeps a history of its last d + 1 samples: estimate (q̂_j, b̂_j), covariance P_j and the
//! error-state transition T_j from sample j − 1 to j (the propagation Φ_j followed by the (I − K H) of the
//! sample's undelayed sun/magnetometer updates). A delayed quaternion is an update of the oldest entry,
//! sample s: innovation ν = log(q̂_s* ⊗ q_meas) against the estimate of that instant, S = P_s,θθ + R,
//! K = P_s Hᵀ S⁻¹, δx_s = K ν (Joseph form), and the correction is carried to every later entry j with the
//! transition over the delay, M_j = T_j ⋯ T_{s+1} (Larsen's method):
//! δx_j = M_j δx_s (multiplicative reset of entry j), P_j ← P_j − M_j (P_s − P_s⁺) M_jᵀ.
//! Correcting the whole history (not only the current sample) keeps the next delayed measurement's
//! innovation against an estimate that already holds the earlier ones: for a linear system with the
//! star tracker as the only measurement this is the on-time filter exactly; sun/magnetometer updates
//! inside the delay used gains without the delayed information (suboptimal, the covariance stays the
//! actual filter's: Larsen's formula with their (I − K H)). Linearisation: the correction is small
//! against 1 rad (as every MEKF update) and Φ_j is not recomputed with the corrected bias (second order).

use std::collections::VecDeque;

use nalgebra::{Matrix3, Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::math::attitude_kalman::{joseph_update_with_gain, Matrix6};

/// At most this many filter samples of star-tracker latency (the history holds one more entry).
pub const MAX_DELAY_SAMPLES: usize = 1000;

/// The filter after sample k, as a delayed update needs it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    pub k: i64,
    pub q: Quaternion<f64>,
    pub b: Vector3<f64>,
    pub p: Matrix6,
    /// Error-state transition from sample k − 1 to k: the (I − K H) of the sample's undelayed updates times Φ.
    pub t: Matrix6,
}

/// The delay in filter samples of a latency: a whole number of sample periods (to a relative 1e-6 of
/// one period, so that a latency and a period given as decimals are accepted) and at most
/// [`MAX_DELAY_SAMPLES`]; otherwise an error naming the parameter.
pub fn delay_samples(latency: f64, period: f64) -> Result<usize, String> {
    let r = latency / period;
    let n = r.round();
    if (r - n).abs() > 1e-6 {
        return Err(format!(
            "parameter st_latency = {latency} s is {r} sample periods (sample_period = {period} s): it must be a whole number of sample periods"
        ));
    }
    if n > MAX_DELAY_SAMPLES as f64 {
        return Err(format!(
            "parameter st_latency = {latency} s is {n} sample periods of {period} s: at most {MAX_DELAY_SAMPLES} (the filter keeps one estimate per sample of the delay)"
        ));
    }
    Ok(n as usize)
}

/// Appends the filter after the current sample and drops what is older than d samples.
pub fn record(hist: &mut VecDeque<Entry>, d: usize, e: Entry) {
    hist.push_back(e);
    while hist.len() > d + 1 {
        hist.pop_front();
    }
}

/// M_j = T_j ⋯ T_{s+1} for every entry j after the oldest, s.
fn transitions(hist: &VecDeque<Entry>) -> Vec<Matrix6> {
    let mut acc = Matrix6::identity();
    hist.iter()
        .skip(1)
        .map(|e| {
            acc = e.t * acc;
            acc
        })
        .collect()
}

/// Replaces the covariance of the oldest entry by `p_new` in every later entry:
/// P_j ← P_j − M_j (P_s − p_new) M_jᵀ (symmetrised); `fix(entry, M_j)` corrects the estimate.
fn carry(hist: &mut VecDeque<Entry>, p_new: &Matrix6, mut fix: impl FnMut(&mut Entry, &Matrix6)) {
    let m = transitions(hist);
    let dp = hist[0].p - p_new;
    for (e, m) in hist.iter_mut().skip(1).zip(&m) {
        fix(e, m);
        let p = e.p - m * dp * m.transpose();
        e.p = (p + p.transpose()) * 0.5;
    }
}

/// The delayed star-tracker update of a history of d + 1 entries (the newest is the current sample):
/// (innovation ν, NIS νᵀ S⁻¹ ν) of the measurement taken at the oldest entry, or `None` when the history
/// is shorter (the measurement was taken before the filter's first sample: not used).
pub fn update(hist: &mut VecDeque<Entry>, d: usize, q_m: &Quaternion<f64>, r_st: &Matrix3<f64>) -> Result<Option<(Vector3<f64>, f64)>, String> {
    if hist.len() < d + 1 {
        return Ok(None);
    }
    let (nu, h) = super::star_innovation(&hist[0].q, q_m);
    let (dx, p_plus, nis, _) =
        joseph_update_with_gain(&hist[0].p, &h, r_st, &nu).ok_or("star-tracker update (delayed): innovation covariance is not positive definite")?;
    carry(hist, &p_plus, |e, m| super::apply_correction(&mut e.q, &mut e.b, &(m * dx)));
    Ok(Some((nu, nis)))
}

/// Initialisation from a delayed first measurement: the attitude at the oldest entry is the measurement
/// (its covariance the noise's, uncorrelated with the bias), carried to the later entries with the
/// rotation the filter propagated over the delay: q̂_j ← q_meas ⊗ q̂_s* ⊗ q̂_j. False when the measurement
/// was taken before the filter's first sample (not used).
pub fn initialize(hist: &mut VecDeque<Entry>, d: usize, q_m: &Quaternion<f64>, r_st: &Matrix3<f64>) -> bool {
    if hist.len() < d + 1 {
        return false;
    }
    let qs = hist[0].q;
    let (q_m, p_new) = super::star_initialization(&qs, &hist[0].p, q_m, r_st);
    carry(hist, &p_new, |e, _| e.q = (q_m * qs.conjugate() * e.q).normalize());
    true
}

/// A restored history: at most d + 1 consecutive entries ending at the current sample k, finite.
pub fn check(hist: &VecDeque<Entry>, d: usize, k: i64) -> Result<(), String> {
    if hist.len() > d + 1 {
        return Err(format!("restored state: star-tracker delay history of {} entries, at most {}", hist.len(), d + 1));
    }
    let consecutive = hist.iter().enumerate().all(|(i, e)| e.k == k - (hist.len() - 1 - i) as i64);
    let finite = hist.iter().all(|e| e.q.coords.iter().chain(e.b.iter()).chain(e.p.iter()).chain(e.t.iter()).all(|x| x.is_finite()));
    if !consecutive || !finite {
        return Err(format!("restored state: star-tracker delay history does not end at sample {k} or is not finite"));
    }
    Ok(())
}
