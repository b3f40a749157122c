//! The codes of the ADCS mode logic (`modes.rs`) and their text: the modes and the reasons of a
//! transition with their names (the log line of a transition: `mode_log.rs`).

use serde::{Deserialize, Serialize};

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
