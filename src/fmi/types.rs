//! The C-level vocabulary both FMI versions share: the status codes, the two logger callback types,
//! the states of the state machine (one enum for FMI 2.0 and 3.0, Co-Simulation and Model Exchange)
//! with their bit masks, and the log categories every model description declares. Nothing here calls
//! anything: every other file of the FMI layer may use it.

use std::ffi::{c_char, c_int, c_void};

/// `fmi2Status`.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
    Pending = 5,
}

/// `fmi2CallbackLogger`: a C-variadic function; we always pass a fully formatted message.
pub type LoggerFn = unsafe extern "C" fn(
    env: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// `fmi3LogMessageCallback`: not variadic, the message is plain text (not a printf format).
pub type Log3Fn =
    unsafe extern "C" fn(env: *mut c_void, status: c_int, category: *const c_char, message: *const c_char);

/// Log categories declared in every modelDescription and accepted by `fmi2SetDebugLogging`.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusWarning", "Warnings (always forwarded to the logger)"),
    ("logStatusError", "Errors (always forwarded to the logger)"),
    ("logStatusFatal", "Fatal errors (always forwarded to the logger)"),
    ("logCalls", "Every FMI function call with its arguments (debug logging)"),
    (
        "logEvents",
        "Events of a model's law, e.g. a mode change, one line each (debug logging)",
    ),
    ("logAll", "All of the above"),
];

/// States of the FMI 2.0 Co-Simulation state machine (section 4.2.4). `StepInProgress` and
/// `StepCanceled` cannot be reached: `fmi2DoStep` never returns `fmi2Pending`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FsmState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
    Fatal,
    /// Model Exchange (FMI 2.0 section 3.2.3): event mode (after initialization and at events).
    EventMode,
    /// Model Exchange: continuous-time mode (the importer's solver integrates).
    ContinuousTimeMode,
}

impl FsmState {
    pub const fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

/// The set of states (as bits) in which a function may be called: the masks of `fmi2::common::mask`,
/// `fmi3::common::mask3` and `fmi3::common::mask3me`.
pub const fn mask_of(states: &[FsmState]) -> u16 {
    let mut bits = 0;
    let mut i = 0;
    while i < states.len() {
        bits |= states[i].bit();
        i += 1;
    }
    bits
}
