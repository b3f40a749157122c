//! The C-level vocabulary both interfaces share: the status codes, the two shapes of logger callback,
//! the states of the one state machine every instance runs (Co-Simulation and Model Exchange alike)
//! with their bit masks, the log categories every model description declares, and [`Dialect`]: how the
//! room that created an instance names things. Nothing here calls anything: every other file of the
//! FMI layer may use it.

use std::ffi::{c_char, c_int, c_void};

/// The status a C function returns (the same codes in both versions; `Pending` is never returned).
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

/// A logger that takes the instance name and a printf format: a C-variadic function; we always pass a
/// fully formatted message (with '%' escaped).
pub type PrintfLogFn = unsafe extern "C" fn(
    env: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// A logger that takes plain text and no instance name: not variadic, the message is not a format.
pub type TextLogFn =
    unsafe extern "C" fn(env: *mut c_void, status: c_int, category: *const c_char, message: *const c_char);

/// Log categories declared in every modelDescription and accepted by the debug-logging call.
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

/// Where an instance is in its life. These are the states both standards share; each room says which
/// of its functions may be called in which of them (its masks) and names them in its own words.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FsmState {
    /// Created; the experiment and the parameters may be set.
    Instantiated,
    /// Parameters and start values are being set; outputs may be read.
    InitializationMode,
    /// Co-Simulation, between two steps: the instance steps on the master's request.
    StepMode,
    /// Stopped normally; values may still be read.
    Terminated,
    /// A call failed so that the instance cannot go on (a failed step, a non-finite output); a room
    /// whose standard has no such state treats it as Terminated.
    Error,
    /// A panic was caught: only freeing the instance is honoured.
    Fatal,
    /// Model Exchange: after initialization and at events, where discrete states are updated.
    EventMode,
    /// Model Exchange: the importer's solver integrates the continuous states.
    ContinuousTimeMode,
    /// A clocked model whose partitions the importer activates one at a time (between activations
    /// inputs may be set and outputs read).
    Activation,
}

impl FsmState {
    pub const fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

/// The set of states (as bits) in which a function may be called: the masks the rooms declare.
pub const fn mask_of(states: &[FsmState]) -> u16 {
    let mut bits = 0;
    let mut i = 0;
    while i < states.len() {
        bits |= states[i].bit();
        i += 1;
    }
    bits
}

/// The arrays of the Model Exchange calls whose names differ between the interfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arg {
    /// the continuous states
    States,
    /// their nominal values
    Nominals,
    /// the state derivatives
    Derivatives,
}

/// The interface an instance serves, as the room that created it describes it: the one value through
/// which the shared code knows the interface. Each room has one static `Dialect`; an instance holds a
/// reference to it, the handle lookup compares it, an FMU state records its `version`, and every
/// failure the shared code reports is worded with its names (`fail::Reason::render`).
pub struct Dialect {
    /// The interface's name in messages (the standard and its version), also recorded in a serialized FMU state.
    pub version: &'static str,
    /// The instantiate argument that carries the model's GUID.
    pub token_argument: &'static str,
    /// The call that sets start time, stop time and tolerance.
    pub setup_experiment: &'static str,
    /// The Model Exchange call that sets the continuous states.
    pub set_continuous_states: &'static str,
    /// The name of an array argument of the Model Exchange calls (with its `[]`).
    pub argument: fn(Arg) -> &'static str,
    /// The standard's name of a state.
    pub state_name: fn(FsmState) -> &'static str,
}
