//! The ADCS mode logic as a pure law (not an FMU): the five modes, the transitions between them with their
//! priorities, hysteresis bands and dwell time, and the selection table the mode sets. `ModeManager`
//! (`mode_manager.rs`) evaluates [`ModeLogic::sample`] on its integer sample schedule; the unit tests
//! (`modes_tests.rs`, `modes_timing_tests.rs`) drive the law directly; the codes and the log text are in
//! `mode_codes.rs`.
//!
//! Modes (Integer codes): 0 SAFE, 1 DETUMBLE, 2 SUN_ACQUISITION, 3 DETERMINATION, 4 FINE_POINTING.
//! Reasons of a transition (Integer codes, 0 = none yet): 1 FAULT, 2 SAFE_REQUEST, 3 RATE_HIGH,
//! 4 DIVERGED_SIGMA, 5 DIVERGED_NIS, 6 RECOVER, 7 DETUMBLED, 8 TUMBLING, 9 SUN_ACQUIRED, 10 SUN_LOST,
//! 11 CONVERGED.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

pub use super::mode_codes::{num, Mode, Reason};

/// The thresholds and times of the law (the FMU's parameters of the same names; `period` = sample_period).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeParams {
    pub period: f64,
    pub rate_detumbled: f64,
    pub rate_tumbling: f64,
    pub rate_safe: f64,
    pub sun_angle_acquired: f64,
    pub sun_angle_lost: f64,
    pub sun_axis: [f64; 3],
    pub sigma_converged: f64,
    pub sigma_diverged: f64,
    pub nis_max: f64,
    pub nis_diverged: f64,
    pub nis_time_constant: f64,
    pub min_dwell: f64,
    pub fault_confirm_time: f64,
    pub recover_time: f64,
    pub init_duration: f64,
    pub safe_on_divergence: bool,
}

impl Default for ModeParams {
    /// The declared defaults of `ModeManager`.
    fn default() -> Self {
        ModeParams {
            period: 1.0,
            rate_detumbled: 0.00873,
            rate_tumbling: 0.0349,
            rate_safe: 0.15,
            sun_angle_acquired: 0.1745,
            sun_angle_lost: std::f64::consts::FRAC_PI_6,
            sun_axis: [1.0, 0.0, 0.0],
            sigma_converged: 0.00873,
            sigma_diverged: 0.0873,
            nis_max: 3.0,
            nis_diverged: 10.0,
            nis_time_constant: 30.0,
            min_dwell: 10.0,
            fault_confirm_time: 0.0,
            recover_time: 1e30,
            init_duration: 1.0,
            safe_on_divergence: true,
        }
    }
}

/// The inputs of one sample (the FMU's inputs of the same names).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    pub w_meas: Vector3<f64>,
    pub sun_valid: f64,
    pub sun_meas: Vector3<f64>,
    pub p_att: Vector3<f64>,
    pub nis: f64,
    pub nis_dim: i32,
    pub actuator_fault: f64,
    pub recover: f64,
    pub safe_request: f64,
}

impl Default for Inputs {
    /// The declared start values of `ModeManager`.
    fn default() -> Self {
        Inputs {
            w_meas: Vector3::zeros(),
            sun_valid: 0.0,
            sun_meas: Vector3::z(),
            p_att: Vector3::repeat(1.0),
            nis: 0.0,
            nis_dim: 0,
            actuator_fault: 0.0,
            recover: 0.0,
            safe_request: 0.0,
        }
    }
}

impl Inputs {
    /// Refuses inputs the law cannot read, naming the input.
    pub fn check(&self) -> Result<(), String> {
        let vecs = [
            ("w_meas", &self.w_meas),
            ("sun_meas", &self.sun_meas),
            ("p_att", &self.p_att),
        ];
        for (name, v) in vecs {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(format!("input {name} = {:?} is not finite", v.as_slice()));
            }
        }
        let reals = [
            ("sun_valid", self.sun_valid),
            ("nis", self.nis),
            ("actuator_fault", self.actuator_fault),
            ("recover", self.recover),
            ("safe_request", self.safe_request),
        ];
        if let Some((name, x)) = reals.iter().find(|(_, x)| !x.is_finite()) {
            return Err(format!("input {name} = {x} is not finite"));
        }
        if self.p_att.min() < 0.0 {
            return Err(format!(
                "input p_att = {:?} rad2: variances must be >= 0",
                self.p_att.as_slice()
            ));
        }
        if self.nis_dim < 0 || (self.nis_dim > 0 && self.nis < 0.0) {
            return Err(format!(
                "inputs nis = {}, nis_dim = {}: a normalized innovation square >= 0 and a dimension >= 0 are expected",
                self.nis, self.nis_dim
            ));
        }
        Ok(())
    }
}

/// What the law sees at a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Quantities {
    /// |w_meas| (rad/s).
    pub rate: f64,
    pub sun_ok: bool,
    /// Angle between sun_meas and sun_axis (rad); pi when sun_meas has no direction.
    pub sun_angle: f64,
    /// sqrt(max p_att) (rad).
    pub sigma: f64,
    /// The filtered nis/nis_dim; None before the first update (since the start or the entry into DETERMINATION).
    pub nis_avg: Option<f64>,
    /// The actuator fault, confirmed; how long its flag has been up (s).
    pub fault: bool,
    pub fault_held: f64,
    pub recover_input: bool,
    pub recover_cmd: bool,
    pub safe_cmd: bool,
    /// Time in the mode at the sample, before its transition (s).
    pub time_in_mode: f64,
}

/// A mode change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    pub from: Mode,
    pub to: Mode,
    pub reason: Reason,
}

/// The result of one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    pub t: f64,
    pub transition: Option<Transition>,
    pub q: Quantities,
}

/// The outputs the mode selects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Selection {
    pub torque_select: f64,
    pub dipole_select: f64,
    pub controller_enable: f64,
    pub estimator_init: f64,
}

/// What evolves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeState {
    pub mode: Mode,
    /// Time of the entry into the mode (the sample of the transition; the first sample for the initial mode).
    pub t_entry: f64,
    /// Time in the mode at the last sample, after its transition (s).
    pub time_in_mode: f64,
    pub changes: i32,
    pub last_reason: Option<Reason>,
    pub nis_avg: Option<f64>,
    /// Time of the first sample of the current run of the actuator_fault flag.
    pub fault_since: Option<f64>,
    /// The quantities of the last sample (the held diagnostic outputs).
    pub last: Quantities,
}

/// The mode logic: parameters, the filter pole, and the evolving state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeLogic {
    pub p: ModeParams,
    /// exp(-T / nis_time_constant).
    alpha: f64,
    /// sun_axis, normalised.
    axis: [f64; 3],
    pub s: ModeState,
}

/// `lo < hi` for a pair of thresholds; the message names both and the rule.
fn below(lo_name: &str, lo: f64, hi_name: &str, hi: f64, why: &str) -> Result<(), String> {
    if lo < hi {
        Ok(())
    } else {
        Err(format!(
            "parameters {lo_name} = {lo} and {hi_name} = {hi}: need {lo_name} < {hi_name} ({why})"
        ))
    }
}

impl ModeLogic {
    /// Checks the parameters and starts in `initial_mode` at the first sample instant `t0`.
    pub fn new(p: ModeParams, initial_mode: i32, t0: f64) -> Result<Self, String> {
        for (name, x) in [("sample_period", p.period), ("nis_time_constant", p.nis_time_constant)] {
            if !(x > 0.0 && x.is_finite()) {
                return Err(format!("parameter {name} = {x}: must be > 0 and finite"));
            }
        }
        for (name, x) in [
            ("min_dwell", p.min_dwell),
            ("fault_confirm_time", p.fault_confirm_time),
            ("init_duration", p.init_duration),
        ] {
            if !(x >= 0.0 && x.is_finite()) {
                return Err(format!("parameter {name} = {x}: must be >= 0 and finite"));
            }
        }
        below(
            "rate_detumbled",
            p.rate_detumbled,
            "rate_tumbling",
            p.rate_tumbling,
            "the rate hysteresis band",
        )?;
        below(
            "sun_angle_acquired",
            p.sun_angle_acquired,
            "sun_angle_lost",
            p.sun_angle_lost,
            "the sun hysteresis band",
        )?;
        below(
            "sigma_converged",
            p.sigma_converged,
            "sigma_diverged",
            p.sigma_diverged,
            "convergence before divergence",
        )?;
        below(
            "nis_max",
            p.nis_max,
            "nis_diverged",
            p.nis_diverged,
            "convergence before divergence",
        )?;
        let mode = Mode::from_code(initial_mode)
            .ok_or_else(|| format!("parameter initial_mode = {initial_mode}: not one of {:?}", Mode::CODES))?;
        let a = Vector3::from(p.sun_axis);
        if !(a.norm() > 0.0 && a.norm().is_finite()) {
            return Err(format!(
                "parameter sun_axis = {:?}: a non-zero direction is needed",
                p.sun_axis
            ));
        }
        let axis = (a / a.norm()).into();
        let alpha = (-p.period / p.nis_time_constant).exp();
        let s = ModeState {
            mode,
            t_entry: t0,
            time_in_mode: 0.0,
            changes: 0,
            last_reason: None,
            nis_avg: None,
            fault_since: None,
            last: Quantities {
                sun_angle: std::f64::consts::PI,
                ..Quantities::default()
            },
        };
        Ok(ModeLogic { p, alpha, axis, s })
    }

    /// Whether a duration `x` has reached `d` (to a round-off tolerance of 1e-9 T: times are multiples of T).
    fn reached(&self, x: f64, d: f64) -> bool {
        x >= d - 1e-9 * self.p.period
    }

    /// The quantities at sample time t (updates the NIS filter and the fault timer).
    fn measure(&mut self, t: f64, u: &Inputs) -> Quantities {
        let p = &self.p;
        let n = u.sun_meas.norm();
        let sun_angle = if n > 0.0 {
            (u.sun_meas / n).dot(&Vector3::from(self.axis)).clamp(-1.0, 1.0).acos()
        } else {
            std::f64::consts::PI
        };
        if u.nis_dim > 0 {
            let x = u.nis / u.nis_dim as f64;
            self.s.nis_avg = Some(self.s.nis_avg.map_or(x, |a| self.alpha * a + (1.0 - self.alpha) * x));
        }
        let flag = u.actuator_fault >= 0.5;
        self.s.fault_since = if flag {
            Some(self.s.fault_since.unwrap_or(t))
        } else {
            None
        };
        let fault_held = self.s.fault_since.map_or(0.0, |t0| t - t0);
        let recover_input = u.recover >= 0.5;
        Quantities {
            rate: u.w_meas.norm(),
            sun_ok: u.sun_valid >= 0.5 && n > 0.0,
            sun_angle,
            sigma: u.p_att.max().max(0.0).sqrt(),
            nis_avg: self.s.nis_avg,
            fault: flag && self.reached(fault_held, p.fault_confirm_time),
            fault_held,
            recover_input,
            recover_cmd: recover_input || t >= p.recover_time,
            safe_cmd: u.safe_request >= 0.5,
            time_in_mode: t - self.s.t_entry,
        }
    }

    /// The transition of the current mode for the quantities q, in the priority order a–f (at most one).
    fn decide(&self, q: &Quantities) -> Option<(Mode, Reason)> {
        use Mode::*;
        let p = &self.p;
        let dwell = self.reached(q.time_in_mode, p.min_dwell);
        let mode = self.s.mode;
        if mode != Safe && q.fault {
            return Some((Safe, Reason::Fault));
        }
        if mode != Safe && q.safe_cmd {
            return Some((Safe, Reason::SafeRequest));
        }
        let nis_avg = q.nis_avg;
        match mode {
            FinePointing if q.rate > p.rate_safe => Some((Safe, Reason::RateHigh)),
            FinePointing if p.safe_on_divergence && q.sigma > p.sigma_diverged => Some((Safe, Reason::DivergedSigma)),
            FinePointing if p.safe_on_divergence && nis_avg.is_some_and(|a| a > p.nis_diverged) => {
                Some((Safe, Reason::DivergedNis))
            }
            Safe if q.recover_cmd && !q.fault && dwell => Some((
                if q.rate > p.rate_tumbling {
                    Detumble
                } else {
                    SunAcquisition
                },
                Reason::Recover,
            )),
            Detumble if dwell && q.rate < p.rate_detumbled => Some((SunAcquisition, Reason::Detumbled)),
            SunAcquisition | Determination if q.rate > p.rate_tumbling => Some((Detumble, Reason::Tumbling)),
            SunAcquisition if dwell && q.sun_ok && q.sun_angle < p.sun_angle_acquired && q.rate < p.rate_detumbled => {
                Some((Determination, Reason::SunAcquired))
            }
            Determination if q.sun_ok && q.sun_angle > p.sun_angle_lost => Some((SunAcquisition, Reason::SunLost)),
            Determination if dwell && q.sigma < p.sigma_converged && nis_avg.is_some_and(|a| a < p.nis_max) => {
                Some((FinePointing, Reason::Converged))
            }
            _ => None,
        }
    }

    /// One sample at time t with inputs u (checked by [`Inputs::check`]): the quantities, at most one
    /// transition, the new state.
    pub fn sample(&mut self, t: f64, u: &Inputs) -> Outcome {
        let q = self.measure(t, u);
        let transition = self.decide(&q).map(|(to, reason)| {
            let from = self.s.mode;
            self.s.mode = to;
            self.s.t_entry = t;
            self.s.changes = self.s.changes.saturating_add(1);
            self.s.last_reason = Some(reason);
            if to == Mode::Determination {
                self.s.nis_avg = None;
            }
            Transition { from, to, reason }
        });
        self.s.time_in_mode = t - self.s.t_entry;
        self.s.last = Quantities {
            nis_avg: self.s.nis_avg,
            ..q
        };
        Outcome { t, transition, q }
    }

    /// The selection table for the mode and the time in it after the last sample.
    pub fn selection(&self) -> Selection {
        let m = self.s.mode;
        let init = m == Mode::Determination && !self.reached(self.s.time_in_mode, self.p.init_duration);
        Selection {
            torque_select: match m {
                Mode::Detumble => 0.0,
                Mode::FinePointing => 2.0,
                _ => 1.0,
            },
            dipole_select: if m == Mode::Detumble { 1.0 } else { 0.0 },
            controller_enable: if m == Mode::FinePointing { 1.0 } else { 0.0 },
            estimator_init: if init { 1.0 } else { 0.0 },
        }
    }
}

#[cfg(test)]
#[path = "modes_tests.rs"]
mod tests;
