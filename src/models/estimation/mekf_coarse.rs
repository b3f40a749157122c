//! Coarse re-initialisation of the `Mekf` (inputs `q_coarse`, `init_request`; parameter
//! `sigma_att_coarse`): at every filter sample at which `init_request` >= 0.5 the attitude estimate becomes
//! the coarse attitude (e.g. the `Triad`'s or `Quest`'s `q_est`, normalised, on the hemisphere of the
//! estimate) with the covariance σ² I, uncorrelated with the bias; the bias estimate and its covariance are
//! kept. It takes the place of the sample's attitude propagation and comes before the sample's updates, so
//! the sample's measurements update the coarse attitude. With a star-tracker latency the kept history
//! restarts at that sample: the transitions stored before it no longer lead to the estimate, and a
//! quaternion measured before the re-initialisation is not used (as one measured before the first sample).
//! With `init_request` = 0 nothing here reads `q_coarse` or changes the filter.

use nalgebra::Matrix3;

use super::{star_initialization, Est, MekfVars};
use crate::model::ModelResult;

/// Re-initialises the filter after the propagation of the current sample when `init_request` >= 0.5;
/// a non-finite request, or a zero or non-finite `q_coarse` with the request high, is an error naming
/// the input.
pub fn reinitialize(s: &mut Est, v: &MekfVars, var: f64) -> ModelResult {
    if !v.init_request.is_finite() {
        return Err(format!("input init_request = {} is not finite", v.init_request));
    }
    if v.init_request < 0.5 {
        return Ok(());
    }
    let q = v.q_coarse;
    if !q.coords.iter().all(|x| x.is_finite()) {
        return Err(format!("input q_coarse is not finite: [{}, {}, {}, {}] (init_request = {})", q.w, q.i, q.j, q.k, v.init_request));
    }
    let n = q.norm();
    if !(n > 1e-6) {
        return Err(format!("input q_coarse has norm {n}, expected a non-zero quaternion with init_request = {} (is it connected?)", v.init_request));
    }
    // the same operation as a first star-tracker measurement: the attitude block is the coarse variance,
    // the cross-covariance zero, the bias block untouched
    (s.q, s.p) = star_initialization(&s.q, &s.p, &(q / n), &(Matrix3::identity() * var));
    s.hist.clear();
    Ok(())
}
