//! The FMI 2.0 and 3.0 Co-Simulation layer, written once for every model: C types, the exported C ABI
//! (`abi` for FMI 2.0, `fmi3` and `fmi3_more` for FMI 3.0), the per-instance state machine, logging and value access (`instance`), and FMU state
//! snapshots and their byte format (`state`). Models never see anything in here.

pub mod abi;
mod abi_me;
mod abi_more;
pub mod fmi3;
pub mod fmi3_me;
pub mod fmi3_more;
#[cfg(test)]
mod fmi3_tests;
pub mod instance;
pub mod instance_me;
mod jacobian;
mod library_path;
pub mod state;
mod state_calls;

use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void};
use std::hash::{BuildHasher, Hasher};
use std::sync::{Mutex, MutexGuard};

/// Hasher for addresses: one multiply (Fibonacci hashing). SipHash's DoS resistance is not needed
/// for pointers we allocated ourselves, and this set is consulted on every FMI call.
#[derive(Default)]
pub struct AddrHasher(u64);

impl Hasher for AddrHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn write_usize(&mut self, n: usize) {
        self.0 = (n as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    }
}

#[derive(Clone, Copy, Default)]
pub struct BuildAddrHasher;

impl BuildHasher for BuildAddrHasher {
    type Hasher = AddrHasher;
    fn build_hasher(&self) -> AddrHasher {
        AddrHasher(0)
    }
}

/// Addresses handed to the master (instances, FMU states): a foreign or freed pointer is recognised
/// before it is dereferenced.
pub struct LiveSet(Mutex<HashSet<usize, BuildAddrHasher>>);

impl LiveSet {
    pub const fn new() -> Self {
        LiveSet(Mutex::new(HashSet::with_hasher(BuildAddrHasher)))
    }
    pub fn lock(&self) -> MutexGuard<'_, HashSet<usize, BuildAddrHasher>> {
        self.0.lock().unwrap_or_else(|p| p.into_inner())
    }
}

impl Default for LiveSet {
    fn default() -> Self {
        Self::new()
    }
}

/// Log categories declared in every modelDescription and accepted by `fmi2SetDebugLogging`.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusWarning", "Warnings (always forwarded to the logger)"),
    ("logStatusError", "Errors (always forwarded to the logger)"),
    ("logStatusFatal", "Fatal errors (always forwarded to the logger)"),
    ("logCalls", "Every FMI function call with its arguments (debug logging)"),
    ("logAll", "All of the above"),
];

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
pub type LoggerFn =
    unsafe extern "C" fn(env: *mut c_void, instance_name: *const c_char, status: c_int, category: *const c_char, message: *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    pub logger: Option<LoggerFn>,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    pub component_environment: *mut c_void,
}

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

/// The set of states (as bits) in which a function may be called: the masks of `mask`, `fmi3::mask3`
/// and `fmi3_me::mask3me`.
pub const fn mask_of(states: &[FsmState]) -> u16 {
    let mut bits = 0;
    let mut i = 0;
    while i < states.len() {
        bits |= states[i].bit();
        i += 1;
    }
    bits
}

/// Sets of states in which a function may be called (FMI 2.0.4, CS state table).
pub mod mask {
    use super::FsmState::*;
    use crate::fmi::mask_of as m;
    pub const SET_DEBUG_LOGGING: u16 =
        m(&[Instantiated, InitializationMode, StepComplete, StepFailed, StepCanceled, Terminated, Error, EventMode, ContinuousTimeMode]);
    pub const FREE_INSTANCE: u16 = SET_DEBUG_LOGGING; // fmi2FreeInstance itself is always honoured (also after fmi2Fatal)
    pub const SETUP_EXPERIMENT: u16 = m(&[Instantiated]);
    pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
    pub const TERMINATE: u16 = m(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
    pub const RESET: u16 = FREE_INSTANCE;
    pub const GET: u16 = m(&[InitializationMode, StepComplete, StepFailed, StepCanceled, Terminated, Error, EventMode, ContinuousTimeMode]);
    pub const SET: u16 = m(&[Instantiated, InitializationMode, StepComplete, EventMode, ContinuousTimeMode]);
    pub const FMU_STATE: u16 = FREE_INSTANCE;
    pub const DIRECTIONAL_DERIVATIVE: u16 = GET;
    pub const SET_INPUT_DERIVATIVES: u16 = m(&[Instantiated, InitializationMode, StepComplete]);
    pub const GET_OUTPUT_DERIVATIVES: u16 = m(&[StepComplete, StepFailed, StepCanceled, Terminated, Error]);
    pub const DO_STEP: u16 = m(&[StepComplete]);
    pub const CANCEL_STEP: u16 = 0; // StepInProgress only, which this FMU never enters
    pub const GET_STATUS: u16 = m(&[StepComplete, StepFailed, Terminated]);
    // Model Exchange (FMI 2.0.4, ME state table)
    pub const SET_TIME: u16 = m(&[EventMode, ContinuousTimeMode]);
    pub const SET_CONTINUOUS_STATES: u16 = m(&[ContinuousTimeMode]);
    pub const GET_ME_VALUES: u16 = m(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated, Error]);
    pub const ENTER_EVENT_MODE: u16 = m(&[EventMode, ContinuousTimeMode]);
    pub const NEW_DISCRETE_STATES: u16 = m(&[EventMode]);
    pub const ENTER_CONTINUOUS_TIME_MODE: u16 = m(&[EventMode]);
    pub const COMPLETED_INTEGRATOR_STEP: u16 = m(&[ContinuousTimeMode]);
}

/// `fmi2StatusKind` (all four listed; only the last two have values here).
#[allow(dead_code)]
pub mod status_kind {
    pub const DO_STEP_STATUS: i32 = 0;
    pub const PENDING_STATUS: i32 = 1;
    pub const LAST_SUCCESSFUL_TIME: i32 = 2;
    pub const TERMINATED: i32 = 3;
}
