//! FMI 2.0, the part every FMI 2.0 function shares (Co-Simulation and Model Exchange alike): the C
//! types of `fmi2Functions.h` this layer needs, the room's [`FMI2`] dialect (its names of the shared
//! states, arguments and calls), the state table (`mask`), [`call`] (instance lookup, state check, panic
//! guard, logging), `fmi2Instantiate` and the life-cycle and value functions.
//! Each C function checks its pointers, then runs inside [`call`]; every failure becomes a status plus
//! a logger message naming the function and the reason.
//!
//! Nothing here is exported by itself: [`export_fmus!`](crate::export_fmus) expands, in the crate
//! that builds the shared library (ours or a user's), to `#[no_mangle]` functions with the standard
//! names that call these, and passes its list of models to [`fmi2Instantiate`]. A library that only
//! depends on this crate (an rlib) therefore exports no FMI symbol of its own.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::{c_char, c_int, c_void, CStr};

use crate::fmi::boundary::{self, guarded, instance_of, slice, slice_mut, Request};
use crate::fmi::instance::{CallResult, Fail, Instance, Logger, Reason};
use crate::fmi::types::{Arg, Dialect, FsmState, Status};
use crate::model::{ModelEntry, Value, VarKind};

/// `fmi2Component`.
pub type Component = *mut c_void;

/// `fmi2CallbackLogger`.
pub use crate::fmi::types::PrintfLogFn as LoggerFn;

/// FMI 2.0 in the words of the shared code: what its instances are called and how their failures read.
pub static FMI2: Dialect = Dialect {
    version: "FMI 2.0",
    token_argument: "fmuGUID",
    setup_experiment: "fmi2SetupExperiment",
    set_continuous_states: "fmi2SetContinuousStates",
    argument: |a| match a {
        Arg::States => "x[]",
        Arg::Nominals => "x_nominal[]",
        Arg::Derivatives => "derivatives[]",
    },
    state_name,
};

/// FMI 2.0 name of a state (Co-Simulation section 4.2.4, Model Exchange section 3.2.3).
pub fn state_name(s: FsmState) -> &'static str {
    match s {
        FsmState::Instantiated => "Instantiated",
        FsmState::InitializationMode => "InitializationMode",
        FsmState::StepMode => "StepComplete",
        FsmState::Terminated => "Terminated",
        FsmState::Error => "Error",
        FsmState::Fatal => "Fatal",
        FsmState::EventMode => "EventMode",
        FsmState::ContinuousTimeMode => "ContinuousTimeMode",
        FsmState::Activation => "Activation (not an FMI 2.0 state)",
    }
}

const TYPES_PLATFORM: &CStr = c"default";
const VERSION: &CStr = c"2.0";

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    pub logger: Option<LoggerFn>,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    pub component_environment: *mut c_void,
}

/// Sets of states in which a function may be called (FMI 2.0.4, CS state table; `StepMode` is
/// StepComplete: StepFailed, StepCanceled and StepInProgress are never entered, as `fmi2DoStep` never
/// returns fmi2Discard or fmi2Pending).
pub mod mask {
    use crate::fmi::types::mask_of as m;
    use crate::fmi::types::FsmState::*;
    pub const SET_DEBUG_LOGGING: u16 = m(&[
        Instantiated,
        InitializationMode,
        StepMode,
        Terminated,
        Error,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const FREE_INSTANCE: u16 = SET_DEBUG_LOGGING; // fmi2FreeInstance itself is always honoured (also after fmi2Fatal)
    pub const SETUP_EXPERIMENT: u16 = m(&[Instantiated]);
    pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
    pub const TERMINATE: u16 = m(&[StepMode, EventMode, ContinuousTimeMode]);
    pub const RESET: u16 = FREE_INSTANCE;
    pub const GET: u16 = m(&[
        InitializationMode,
        StepMode,
        Terminated,
        Error,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const SET: u16 = m(&[
        Instantiated,
        InitializationMode,
        StepMode,
        EventMode,
        ContinuousTimeMode,
    ]);
    pub const FMU_STATE: u16 = FREE_INSTANCE;
    pub const DIRECTIONAL_DERIVATIVE: u16 = GET;
    pub const SET_INPUT_DERIVATIVES: u16 = m(&[Instantiated, InitializationMode, StepMode]);
    pub const GET_OUTPUT_DERIVATIVES: u16 = m(&[StepMode, Terminated, Error]);
    pub const DO_STEP: u16 = m(&[StepMode]);
    pub const CANCEL_STEP: u16 = 0; // StepInProgress only, which this FMU never enters
    pub const GET_STATUS: u16 = m(&[StepMode, Terminated]);
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

/// Runs an instance call: state check, panic guard, logging of failures.
#[inline(always)]
pub(crate) fn call(c: Component, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    let Some(inst) = instance_of(c, &FMI2) else {
        return Status::Error as c_int;
    };
    if allowed & inst.run.fsm.bit() == 0 {
        let status = if inst.run.fsm == FsmState::Fatal {
            Status::Fatal
        } else {
            Status::Error
        };
        inst.log_fail(
            func,
            &Fail {
                status,
                reason: Reason::IllegalCall(inst.run.fsm),
            },
        );
        return status as c_int;
    }
    match guarded(|| f(&mut *inst)) {
        Ok(Ok(())) => Status::Ok as c_int,
        Ok(Err(fail)) => {
            inst.log_fail(func, &fail);
            fail.status as c_int
        }
        Err(panic) => {
            inst.run.fsm = FsmState::Fatal;
            inst.log_fail(
                func,
                &Fail {
                    status: Status::Fatal,
                    reason: format!("internal error (panic): {panic}").into(),
                },
            );
            Status::Fatal as c_int
        }
    }
}

// ----- platform ------------------------------------------------------------------------------------

pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    TYPES_PLATFORM.as_ptr()
}

pub extern "C" fn fmi2GetVersion() -> *const c_char {
    VERSION.as_ptr()
}

// ----- life cycle ----------------------------------------------------------------------------------

/// `fmi2Instantiate` for a library holding `models`: the model is the one whose name is the library's
/// file name (`binaries/<platform>/<Model>.<ext>`) if there is one, else the one with the requested GUID.
pub fn fmi2Instantiate(
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    _resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> Component {
    if functions.is_null() {
        return std::ptr::null_mut();
    }
    // SAFETY: non-null pointer to the master's callback struct.
    let functions = unsafe { &*functions };
    boundary::instantiate(Request {
        func: "fmi2Instantiate",
        models,
        instance_name,
        token: fmu_guid,
        logger: functions.logger.map_or(Logger::None, Logger::Printf),
        env: functions.component_environment,
        logging_on: logging_on != 0,
        dialect: &FMI2,
        model_exchange: fmu_type == 0,
        check_arguments: &|| match fmu_type {
            0 | 1 => Ok(()),
            _ => Err(format!(
                "fmuType {fmu_type} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"
            )),
        },
        refuse_model: &|entry| {
            (fmu_type == 0 && !entry.model_exchange()).then(|| {
                format!(
                    "fmuType fmi2ModelExchange requested, but {} supports only Co-Simulation (fmi2CoSimulation = 1)",
                    entry.info.name
                )
            })
        },
    })
}

pub extern "C" fn fmi2FreeInstance(c: Component) {
    boundary::free_instance(c, &FMI2)
}

pub extern "C" fn fmi2SetDebugLogging(
    c: Component,
    logging_on: c_int,
    n: usize,
    categories: *const *const c_char,
) -> c_int {
    call(c, "fmi2SetDebugLogging", mask::SET_DEBUG_LOGGING, |inst| {
        let ptrs = unsafe { slice(categories, n, "categories[]")? };
        let mut names = Vec::with_capacity(n);
        for (i, p) in ptrs.iter().enumerate() {
            if p.is_null() {
                return Err(Fail::error(format!("categories[{i}] is NULL")));
            }
            // SAFETY: non-null C string from the master.
            names.push(unsafe { CStr::from_ptr(*p) }.to_string_lossy().into_owned());
        }
        inst.set_debug_logging(logging_on != 0, &names)
    })
}

pub extern "C" fn fmi2SetupExperiment(
    c: Component,
    tol_defined: c_int,
    tol: f64,
    start: f64,
    stop_defined: c_int,
    stop: f64,
) -> c_int {
    call(c, "fmi2SetupExperiment", mask::SETUP_EXPERIMENT, |inst| {
        inst.trace(|| format!("fmi2SetupExperiment(toleranceDefined={tol_defined}, tolerance={tol}, startTime={start}, stopTimeDefined={stop_defined}, stopTime={stop})"));
        inst.setup_experiment(
            (tol_defined != 0).then_some(tol),
            start,
            (stop_defined != 0).then_some(stop),
        )
    })
}

pub extern "C" fn fmi2EnterInitializationMode(c: Component) -> c_int {
    call(
        c,
        "fmi2EnterInitializationMode",
        mask::ENTER_INITIALIZATION_MODE,
        |inst| inst.enter_initialization_mode(),
    )
}

pub extern "C" fn fmi2ExitInitializationMode(c: Component) -> c_int {
    call(
        c,
        "fmi2ExitInitializationMode",
        mask::EXIT_INITIALIZATION_MODE,
        |inst| inst.exit_initialization_mode(),
    )
}

pub extern "C" fn fmi2Terminate(c: Component) -> c_int {
    call(c, "fmi2Terminate", mask::TERMINATE, |inst| {
        inst.run.fsm = FsmState::Terminated;
        Ok(())
    })
}

pub extern "C" fn fmi2Reset(c: Component) -> c_int {
    call(c, "fmi2Reset", mask::RESET, |inst| {
        inst.reset();
        Ok(())
    })
}

// ----- get / set -----------------------------------------------------------------------------------

fn get_typed<T: Copy>(
    c: Component,
    func: &str,
    kind: VarKind,
    vr: *const u32,
    n: usize,
    value: *mut T,
    conv: impl Fn(Value) -> T,
) -> c_int {
    call(c, func, mask::GET, |inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        let out = unsafe { slice_mut(value, n, "value[]")? };
        inst.get_values(kind, vrs, |i, v| out[i] = conv(v))
    })
}

fn set_typed<T: Copy>(
    c: Component,
    func: &str,
    kind: VarKind,
    vr: *const u32,
    n: usize,
    value: *const T,
    conv: impl Fn(T) -> Value,
) -> c_int {
    call(c, func, mask::SET, |inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        let vals = unsafe { slice(value, n, "value[]")? };
        inst.set_values(kind, vrs, |i| conv(vals[i]))
    })
}

pub extern "C" fn fmi2GetReal(c: Component, vr: *const u32, n: usize, value: *mut f64) -> c_int {
    get_typed(c, "fmi2GetReal", VarKind::Real, vr, n, value, |v| {
        if let Value::Real(x) = v {
            x
        } else {
            f64::NAN
        }
    })
}

pub extern "C" fn fmi2GetInteger(c: Component, vr: *const u32, n: usize, value: *mut c_int) -> c_int {
    get_typed(c, "fmi2GetInteger", VarKind::Integer, vr, n, value, |v| {
        if let Value::Integer(x) = v {
            x
        } else {
            0
        }
    })
}

pub extern "C" fn fmi2GetBoolean(c: Component, vr: *const u32, n: usize, value: *mut c_int) -> c_int {
    get_typed(c, "fmi2GetBoolean", VarKind::Boolean, vr, n, value, |v| {
        matches!(v, Value::Boolean(true)) as c_int
    })
}

pub extern "C" fn fmi2GetString(c: Component, vr: *const u32, n: usize, value: *mut *const c_char) -> c_int {
    call(c, "fmi2GetString", mask::GET, |_inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        unsafe { slice_mut(value, n, "value[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!(
                "unknown String value reference {v} (this FMU has no String variables)"
            ))),
        }
    })
}

pub extern "C" fn fmi2SetReal(c: Component, vr: *const u32, n: usize, value: *const f64) -> c_int {
    set_typed(c, "fmi2SetReal", VarKind::Real, vr, n, value, Value::Real)
}

pub extern "C" fn fmi2SetInteger(c: Component, vr: *const u32, n: usize, value: *const c_int) -> c_int {
    set_typed(c, "fmi2SetInteger", VarKind::Integer, vr, n, value, Value::Integer)
}

pub extern "C" fn fmi2SetBoolean(c: Component, vr: *const u32, n: usize, value: *const c_int) -> c_int {
    set_typed(c, "fmi2SetBoolean", VarKind::Boolean, vr, n, value, |b| {
        Value::Boolean(b != 0)
    })
}

pub extern "C" fn fmi2SetString(c: Component, vr: *const u32, n: usize, value: *const *const c_char) -> c_int {
    call(c, "fmi2SetString", mask::SET, |_inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        unsafe { slice(value, n, "value[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!(
                "unknown String value reference {v} (this FMU has no String variables)"
            ))),
        }
    })
}
