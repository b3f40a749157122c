//! The plant's environment: disturbance generator (constant, sinusoid, seeded zero-order-held white
//! noise), gravity gradient and the geomagnetic field on a circular orbit or from the environment inputs,
//! drag and solar pressure on the facets, the residual dipole's torque, and the events (fault
//! onset and end, noise-hold boundaries) at which a communication step is cut.

use nalgebra::Vector3;

use super::variables::AttitudePlantVars;
use crate::math::environment::EARTH_RADIUS;
use crate::math::surface_forces::Wrench;
use crate::math::random::{hold_index, normal};
use crate::math::sample_grid::{beyond, exact_index, MAX_INDEX};

/// What is constant over one internal step (steps are cut at fault_time, fault_clear_time and at noise-hold
/// boundaries).
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

/// A fault_clear_time at or beyond this is "never": the faults are permanent (no time event).
pub const PERMANENT: f64 = 1e30;

/// Whether t lies in the fault window [fault_time, fault_clear_time) (the configured faults act).
pub fn fault_window(v: &AttitudePlantVars, t: f64) -> bool {
    t >= v.fault_time && t < v.fault_clear_time
}

/// Segment of the instant t (for outputs): fault active in [fault_time, fault_clear_time), noise interval ⌊t/T_n⌋.
/// Beyond 2^53 intervals (refused for a noise-on plant by the layer's time bound, `Model::time_grid`)
/// the last countable interval: a key only, no arithmetic follows.
pub fn segment_at(v: &AttitudePlantVars, t: f64) -> Segment {
    let k = hold_index(t, v.dist_noise_hold).unwrap_or(MAX_INDEX);
    Segment { faulted: fault_window(v, t), noise: noise(v, k) }
}

/// Segment of an event-free piece starting at ts with length len (evaluated at its midpoint).
pub fn segment_of_piece(v: &AttitudePlantVars, ts: f64, len: f64) -> Segment {
    let mid = ts + 0.5 * len;
    let k = exact_index((mid / v.dist_noise_hold).floor()).unwrap_or(MAX_INDEX);
    Segment { faulted: fault_window(v, mid), noise: noise(v, k) }
}

/// Breakpoints inside (t, t + h): fault onset and end, and the noise-hold boundaries k T_n.
pub fn breakpoints(v: &AttitudePlantVars, t: f64, h: f64) -> Result<Vec<f64>, String> {
    let mut b = vec![v.fault_time, v.fault_clear_time];
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

/// The external torques beyond the generator and the input (body axes): the disturbance budget.
#[derive(Clone, Copy, Debug, Default)]
pub struct Budget {
    pub gg: Vector3<f64>,
    pub aero: Wrench,
    pub srp: Wrench,
    pub residual: Vector3<f64>,
}

impl Budget {
    pub fn torque(&self) -> Vector3<f64> {
        self.gg + self.aero.torque + self.srp.torque + self.residual
    }
}

/// Whether the environment inputs have not been set yet: environment_inputs = 1 with r and b_eci both at
/// their start value 0. A master that reads the plant's outputs before it first sets its inputs (a
/// Gauss–Seidel master whose sensors come before the plant) then gets the state outputs and zero for what
/// depends on the environment; a step refuses the unset inputs (`check_world`).
pub fn world_unset(v: &AttitudePlantVars) -> bool {
    v.environment_inputs == 1 && v.r == Vector3::zeros() && v.b_eci == Vector3::zeros()
}

/// The environment inputs (environment_inputs = 1) checked before they are used: a position outside the
/// Earth, a unit sun vector when facets feel the sun, an eclipse factor in [0, 1], a density ≥ 0.
pub fn check_world(v: &AttitudePlantVars, facets: bool) -> Result<(), String> {
    if v.environment_inputs != 1 {
        return Ok(());
    }
    let r = v.r.norm();
    if !(r >= EARTH_RADIUS) {
        return Err(format!(
            "input r = {:?} m has norm {r} m, below the Earth's radius {EARTH_RADIUS} m (is it connected?)",
            v.r.as_slice()
        ));
    }
    if v.b_eci == Vector3::zeros() {
        return Err("input b_eci is zero: a geomagnetic field is expected (is it connected?)".into());
    }
    if !(v.rho >= 0.0) {
        return Err(format!("input rho = {} kg/m3: a density >= 0 is allowed", v.rho));
    }
    if !(0.0..=1.0).contains(&v.eclipse) {
        return Err(format!("input eclipse = {}: a visible fraction in [0, 1] is allowed", v.eclipse));
    }
    if facets {
        let n = v.sun_eci.norm();
        if (n - 1.0).abs() > 1e-3 {
            return Err(format!("input sun_eci has norm {n}, expected 1 (is it connected?)"));
        }
        if !(v.sun_distance > r) {
            return Err(format!("input sun_distance = {} m: a distance beyond the spacecraft's |r| = {r} m is allowed", v.sun_distance));
        }
    }
    Ok(())
}

