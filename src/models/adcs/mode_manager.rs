//! `ModeManager`: the ADCS mode state machine of `modes.rs` as an FMU, sampled on its own integer schedule
//! (as `BDot`), with the selection outputs that switch the laws of the loop and a log line per mode change.

use serde::{Deserialize, Serialize};

use super::modes::{Inputs, ModeLogic, ModeParams};
use crate::declare_variables;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};
use crate::models::sensors::shared::{last_sample_before, sample_index, MAX_SAMPLES_PER_CALL};

declare_variables! {
    pub struct ModeManagerVars {
        0 => w_meas: Vec3 = [0.0; 3], Input, "rad/s", "Measured body rate (the Gyro's w_meas)";
        3 => sun_valid: Real = 0.0, Input, "", "Sun measurement valid flag (>= 0.5: valid; the SunSensor's valid)";
        4 => sun_meas: Vec3 = [0.0, 0.0, 1.0], Input, "", "Measured sun direction, body axes (the SunSensor's sun_meas; normalised here)";
        7 => p_att: Vec3 = [1.0, 1.0, 1.0], Input, "rad2", "Attitude error covariance diagonal of the estimator (the Mekf's p_att)";
        10 => nis: Real = 0.0, Input, "", "Normalized innovation square of the estimator's last update (the Mekf's nis)";
        11 => nis_dim: Integer = 0, Input, "", "Dimension of that innovation; 0 = no update at this sample (the Mekf's nis_dim)";
        12 => actuator_fault: Real = 0.0, Input, "", "Actuator health flag (>= 0.5: fault; from the plant or a fault detector)";
        13 => recover: Real = 0.0, Input, "", "Ground command: leave SAFE (>= 0.5)";
        14 => safe_request: Real = 0.0, Input, "", "Ground command: enter SAFE (>= 0.5)";
        15 => nis_sum: Real = 0.0, Input, "", "Running sum of the estimator's NIS since its start (the Mekf's nis_sum; read when nis_source = 1)";
        16 => nis_dim_sum: Real = 0.0, Input, "", "Running sum of the innovation dimensions (the Mekf's nis_dim_sum; read when nis_source = 1)";
        20 => mode: Integer = 1, Output, "", "Mode: 0 SAFE, 1 DETUMBLE, 2 SUN_ACQUISITION, 3 DETERMINATION, 4 FINE_POINTING (held between samples)";
        21 => time_in_mode: Real = 0.0, Output, "s", "Time in the mode at the last sample";
        22 => mode_changes: Integer = 0, Output, "", "Number of mode changes since the start";
        23 => torque_select: Real = 1.0, Output, "", "Torque law selected (CommandSwitch's torque_select): 0 none, 1 the safe law, 2 the pointing law";
        24 => dipole_select: Real = 0.0, Output, "", "Dipole law selected (CommandSwitch's dipole_select): 0 none, 1 B-dot";
        25 => estimator_init: Real = 0.0, Output, "", "1 on the samples of DETERMINATION while time_in_mode < init_duration (the estimator re-initialises from the coarse attitude), else 0";
        26 => controller_enable: Real = 0.0, Output, "", "1 in FINE_POINTING, else 0 (EstimateGate's enable)";
        30 => rate: Real = 0.0, Output, "rad/s", "|w_meas| at the last sample";
        31 => sigma_att: Real = 0.0, Output, "rad", "sqrt(max p_att) at the last sample";
        32 => nis_avg: Real = 0.0, Output, "", "Filtered nis/nis_dim at the last sample (0 before the first update since the start or the entry into DETERMINATION)";
        33 => sun_angle: Real = 0.0, Output, "rad", "Angle between sun_meas and sun_axis at the last sample (pi when sun_meas is zero)";
        34 => last_reason: Integer = 0, Output, "", "Reason of the last mode change: 0 none, 1 FAULT, 2 SAFE_REQUEST, 3 RATE_HIGH, 4 DIVERGED_SIGMA, 5 DIVERGED_NIS, 6 RECOVER, 7 DETUMBLED, 8 TUMBLING, 9 SUN_ACQUIRED, 10 SUN_LOST, 11 CONVERGED";
        100 => sample_period: Real = 1.0, Parameter, "s", "Sample period T of the mode logic", Range(1e-6, 1e4);
        101 => rate_detumbled: Real = 0.00873, Parameter, "rad/s", "Rate below which the body counts as detumbled (DETUMBLE -> SUN_ACQUISITION; 0.5 deg/s)", NonNegative;
        102 => rate_tumbling: Real = 0.0349, Parameter, "rad/s", "Rate above which the body counts as tumbling (back to DETUMBLE; 2 deg/s; > rate_detumbled)", NonNegative;
        103 => rate_safe: Real = 0.15, Parameter, "rad/s", "Rate above which FINE_POINTING goes to SAFE", NonNegative;
        104 => sun_angle_acquired: Real = 0.1745, Parameter, "rad", "Sun angle below which the sun counts as acquired (10 deg)", Range(0.0, std::f64::consts::PI);
        105 => sun_angle_lost: Real = std::f64::consts::FRAC_PI_6, Parameter, "rad", "Sun angle above which DETERMINATION returns to SUN_ACQUISITION (pi/6 = 30 deg; > sun_angle_acquired)", Range(0.0, std::f64::consts::PI);
        106 => sun_axis: Vec3 = [1.0, 0.0, 0.0], Parameter, "", "Body axis pointed at the sun in SUN_ACQUISITION (normalised)";
        109 => sigma_converged: Real = 0.00873, Parameter, "rad", "Attitude sigma below which the estimate counts as converged (0.5 deg)", NonNegative;
        110 => sigma_diverged: Real = 0.0873, Parameter, "rad", "Attitude sigma above which FINE_POINTING goes to SAFE (5 deg; > sigma_converged)", NonNegative;
        111 => nis_max: Real = 3.0, Parameter, "", "Filtered NIS per dimension below which the estimator counts as consistent", NonNegative;
        112 => nis_diverged: Real = 10.0, Parameter, "", "Filtered NIS per dimension above which FINE_POINTING goes to SAFE (> nis_max)", NonNegative;
        113 => nis_time_constant: Real = 30.0, Parameter, "s", "Time constant of the first-order filter of nis/nis_dim", Positive;
        114 => min_dwell: Real = 10.0, Parameter, "s", "Minimum time in a mode before a transition that is not a safety one", NonNegative;
        115 => fault_confirm_time: Real = 0.0, Parameter, "s", "Time the actuator_fault flag must be held before it counts (0 = the first sample)", NonNegative;
        116 => recover_time: Real = 1e30, Parameter, "s", "Time from which SAFE recovers without the recover command (1e30 = never)", Limit;
        117 => init_duration: Real = 1.0, Parameter, "s", "Duration of estimator_init = 1 after the entry into DETERMINATION", NonNegative;
        120 => initial_mode: Integer = 1, Parameter, "", "Mode at the start: 0 SAFE, 1 DETUMBLE, 2 SUN_ACQUISITION, 3 DETERMINATION, 4 FINE_POINTING", Choice(super::modes::Mode::CODES);
        121 => safe_on_divergence: Integer = 1, Parameter, "", "1 = FINE_POINTING goes to SAFE when sigma_att > sigma_diverged or nis_avg > nis_diverged; 0 = not", Choice(SWITCH);
        122 => nis_source: Integer = 0, Parameter, "", "0 = nis and nis_dim of the estimator's current sample; 1 = the increments of nis_sum and nis_dim_sum since the last sample (no update is missed whatever the master's order or coupling delay)", Choice(SWITCH);
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct ModeManager {
    law: ModeLogic,
    /// Index of the first sample (the interval of the start time).
    k0: i64,
    /// Index of the next sample to take.
    next: i64,
    /// (nis_sum, nis_dim_sum) at the last sample taken (nis_source = 1).
    seen: (f64, f64),
    /// Mode changes of the last step, for the log.
    #[serde(skip)]
    log: Vec<String>,
}

/// The law's inputs; with nis_source = 1, the NIS and dimension are the running sums' increments since
/// `seen` (the sums at the last sample taken).
fn inputs(v: &ModeManagerVars, seen: (f64, f64)) -> Result<Inputs, String> {
    let (nis, nis_dim) = if v.nis_source == 1 { increments(v, seen)? } else { (v.nis, v.nis_dim) };
    let u = Inputs {
        w_meas: v.w_meas,
        sun_valid: v.sun_valid,
        sun_meas: v.sun_meas,
        p_att: v.p_att,
        nis,
        nis_dim,
        actuator_fault: v.actuator_fault,
        recover: v.recover,
        safe_request: v.safe_request,
    };
    u.check()?;
    Ok(u)
}

fn increments(v: &ModeManagerVars, seen: (f64, f64)) -> Result<(f64, i32), String> {
    let (dn, dd) = (v.nis_sum - seen.0, v.nis_dim_sum - seen.1);
    if !(dn.is_finite() && dd.is_finite()) || dd < 0.0 || dd != dd.round() || dd > f64::from(i32::MAX) || (dd > 0.0 && dn < -1e-9 * v.nis_sum.abs().max(1.0)) {
        return Err(format!(
            "inputs nis_sum = {}, nis_dim_sum = {} after {} and {} at the last sample: running sums that do not decrease (whole dimensions) are expected (are they connected to the Mekf's nis_sum and nis_dim_sum?)",
            v.nis_sum, v.nis_dim_sum, seen.0, seen.1
        ));
    }
    Ok((dn.max(0.0), dd as i32))
}

impl Model for ModeManager {
    type Vars = ModeManagerVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock of the mode logic: at each tick the mode and its selections are computed and held",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["mode", "time_in_mode", "mode_changes", "torque_select", "dipole_select", "estimator_init", "controller_enable", "rate", "sigma_att", "nis_avg", "sun_angle", "last_reason"],
        },
    ];
    fn time_grid(v: &ModeManagerVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["law.s", "next", "seen"];
    const INFO: ModelInfo = ModelInfo {
        name: "ModeManager",
        description: "ADCS mode manager: SAFE, DETUMBLE, SUN_ACQUISITION, DETERMINATION and FINE_POINTING with prioritised transitions, hysteresis bands, a dwell time and fault confirmation; selects the torque and dipole laws, enables the pointing controller and re-initialises the estimator; sampled at its own rate, each mode change logged",
        source: "AOCS modes, safe mode and mode transitions as in [ECSS-E-ST-60-30C]; estimator consistency by the normalized innovation squared of [Bar-Shalom-2001]; thresholds and scheme project choice",
        equations_html: concat!(include_str!("mode_manager.html"), crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 100.0,
        default_step: 0.1,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut ModeManagerVars, exp: &Experiment) -> Result<Self, String> {
        let p = ModeParams {
            period: v.sample_period,
            rate_detumbled: v.rate_detumbled,
            rate_tumbling: v.rate_tumbling,
            rate_safe: v.rate_safe,
            sun_angle_acquired: v.sun_angle_acquired,
            sun_angle_lost: v.sun_angle_lost,
            sun_axis: v.sun_axis.into(),
            sigma_converged: v.sigma_converged,
            sigma_diverged: v.sigma_diverged,
            nis_max: v.nis_max,
            nis_diverged: v.nis_diverged,
            nis_time_constant: v.nis_time_constant,
            min_dwell: v.min_dwell,
            fault_confirm_time: v.fault_confirm_time,
            recover_time: v.recover_time,
            init_duration: v.init_duration,
            safe_on_divergence: v.safe_on_divergence == 1,
        };
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let law = ModeLogic::new(p, v.initial_mode, k0 as f64 * v.sample_period)?;
        Ok(ModeManager { law, k0, next: k0, seen: (v.nis_sum, v.nis_dim_sum), log: Vec::new() })
    }

    fn outputs(&self, v: &mut ModeManagerVars, t: f64) -> ModelResult {
        // a sample due at t and not taken yet is computed from the current input (not latched)
        let mut law = self.law.clone();
        if sample_index(t, self.law.p.period)? >= self.next {
            law.sample(self.next as f64 * self.law.p.period, &inputs(v, self.seen)?);
        }
        let (s, sel) = (&law.s, law.selection());
        v.mode = s.mode.code();
        v.time_in_mode = s.time_in_mode;
        v.mode_changes = s.changes;
        v.last_reason = s.last_reason.map_or(0, |r| r.code());
        (v.torque_select, v.dipole_select) = (sel.torque_select, sel.dipole_select);
        (v.estimator_init, v.controller_enable) = (sel.estimator_init, sel.controller_enable);
        v.rate = s.last.rate;
        v.sigma_att = s.last.sigma;
        v.nis_avg = s.last.nis_avg.unwrap_or(0.0);
        v.sun_angle = s.last.sun_angle;
        Ok(())
    }

    fn step(&mut self, v: &ModeManagerVars, t: f64, h: f64) -> ModelResult {
        let period = self.law.p.period;
        let k_end = last_sample_before(t + h, period)?;
        let n = k_end.checked_sub(self.next).ok_or("sample count overflows")?;
        if n >= MAX_SAMPLES_PER_CALL {
            return Err(format!(
                "a step to t = {} takes {} samples of period {period} s (at most {MAX_SAMPLES_PER_CALL} per step)",
                t + h,
                n + 1
            ));
        }
        if n < 0 {
            return Ok(());
        }
        let mut u = inputs(v, self.seen)?;
        let mut law = self.law.clone();
        let mut lines = vec![];
        for k in self.next..=k_end {
            let o = law.sample(k as f64 * period, &u);
            lines.extend(law.describe(&o));
            if v.nis_source == 1 {
                (u.nis, u.nis_dim) = (0.0, 0); // the increments count once, at the step's first sample
            }
        }
        (self.law, self.next) = (law, k_end + 1);
        if v.nis_source == 1 {
            self.seen = (v.nis_sum, v.nis_dim_sum);
        }
        self.log.extend(lines);
        Ok(())
    }

    fn take_log(&mut self) -> Vec<String> {
        std::mem::take(&mut self.log)
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        let s = &self.law.s;
        if self.next < self.k0 {
            return Err(format!("restored state: next sample index {} before the first {}", self.next, self.k0));
        }
        if s.changes < 0 || s.time_in_mode < 0.0 || s.t_entry < fresh.law.s.t_entry {
            return Err("restored state: mode changes, time in mode or entry time out of range".into());
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "mode_manager_tests.rs"]
mod tests;
