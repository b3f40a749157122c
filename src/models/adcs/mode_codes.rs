//! The codes of the ADCS mode logic (`modes.rs`) and their text: the modes and the reasons of a
//! transition with their names, and the log line of a transition.

use serde::{Deserialize, Serialize};

use super::modes::{ModeLogic, Outcome};

/// An ADCS mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mode {
    Safe = 0,
    Detumble = 1,
    SunAcquisition = 2,
    Determination = 3,
    FinePointing = 4,
}

impl Mode {
    /// The Integer codes (the bound of `initial_mode`).
    pub const CODES: &'static [i32] = &[0, 1, 2, 3, 4];

    pub fn from_code(code: i32) -> Option<Mode> {
        use Mode::*;
        [Safe, Detumble, SunAcquisition, Determination, FinePointing]
            .into_iter()
            .find(|m| m.code() == code)
    }

    pub fn code(self) -> i32 {
        self as i32
    }

    pub fn name(self) -> &'static str {
        match self {
            Mode::Safe => "SAFE",
            Mode::Detumble => "DETUMBLE",
            Mode::SunAcquisition => "SUN_ACQUISITION",
            Mode::Determination => "DETERMINATION",
            Mode::FinePointing => "FINE_POINTING",
        }
    }
}

/// Why a transition fired.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Reason {
    Fault = 1,
    SafeRequest = 2,
    RateHigh = 3,
    DivergedSigma = 4,
    DivergedNis = 5,
    Recover = 6,
    Detumbled = 7,
    Tumbling = 8,
    SunAcquired = 9,
    SunLost = 10,
    Converged = 11,
}

impl Reason {
    pub fn code(self) -> i32 {
        self as i32
    }

    pub fn name(self) -> &'static str {
        use Reason::*;
        match self {
            Fault => "FAULT",
            SafeRequest => "SAFE_REQUEST",
            RateHigh => "RATE_HIGH",
            DivergedSigma => "DIVERGED_SIGMA",
            DivergedNis => "DIVERGED_NIS",
            Recover => "RECOVER",
            Detumbled => "DETUMBLED",
            Tumbling => "TUMBLING",
            SunAcquired => "SUN_ACQUIRED",
            SunLost => "SUN_LOST",
            Converged => "CONVERGED",
        }
    }
}

impl ModeLogic {
    /// The log line of a transition: time, old -> new mode and the condition that fired it.
    pub fn describe(&self, o: &Outcome) -> Option<String> {
        let tr = o.transition?;
        let (p, q) = (&self.p, &o.q);
        let nis = q.nis_avg.map_or("none".to_string(), num);
        let why = match tr.reason {
            Reason::Fault => format!(
                "actuator_fault held {} s >= fault_confirm_time {} s",
                num(q.fault_held),
                num(p.fault_confirm_time)
            ),
            Reason::SafeRequest => "safe_request >= 0.5".to_string(),
            Reason::RateHigh => format!("rate {} rad/s > rate_safe {}", num(q.rate), num(p.rate_safe)),
            Reason::DivergedSigma => format!(
                "sigma_att {} rad > sigma_diverged {}",
                num(q.sigma),
                num(p.sigma_diverged)
            ),
            Reason::DivergedNis => format!("nis_avg {nis} > nis_diverged {}", num(p.nis_diverged)),
            Reason::Recover => format!(
                "{}, rate {} rad/s {} rate_tumbling {}",
                if q.recover_input {
                    "recover >= 0.5".to_string()
                } else {
                    format!("t >= recover_time {}", num(p.recover_time))
                },
                num(q.rate),
                if tr.to == Mode::Detumble { ">" } else { "<=" },
                num(p.rate_tumbling)
            ),
            Reason::Detumbled => format!("rate {} rad/s < rate_detumbled {}", num(q.rate), num(p.rate_detumbled)),
            Reason::Tumbling => format!("rate {} rad/s > rate_tumbling {}", num(q.rate), num(p.rate_tumbling)),
            Reason::SunAcquired => format!(
                "sun_angle {} rad < sun_angle_acquired {}, rate {} rad/s < rate_detumbled {}",
                num(q.sun_angle),
                num(p.sun_angle_acquired),
                num(q.rate),
                num(p.rate_detumbled)
            ),
            Reason::SunLost => format!(
                "sun_angle {} rad > sun_angle_lost {}",
                num(q.sun_angle),
                num(p.sun_angle_lost)
            ),
            Reason::Converged => format!(
                "sigma_att {} rad < sigma_converged {}, nis_avg {nis} < nis_max {}",
                num(q.sigma),
                num(p.sigma_converged),
                num(p.nis_max)
            ),
        };
        Some(format!(
            "t = {} s: {} -> {} ({why}; {})",
            o.t,
            tr.from.name(),
            tr.to.name(),
            tr.reason.name()
        ))
    }
}

/// A number with 4 significant digits, trailing zeros dropped (exponent form outside [1e-4, 1e6)).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 {
        return "0".into();
    }
    if !(1e-4..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let digits = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}
