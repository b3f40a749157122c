//! FMI 3.0, the part every FMI 3.0 function shares, on top of the same [`Instance`] as FMI 2.0 (value
//! access, stepping, initialization and FMU states are shared): the state tables of Co-Simulation
//! ([`mask3`]) and Model Exchange ([`mask3me`]), the independent variable `time`, [`call3`] with FMI
//! 3.0's error rule (a function that returns `fmi3Error` puts the instance into Terminated, FMI 3.0
//! section 2.3.1), and the life-cycle functions of both interfaces.
//!
//! The shared states are FMI 3.0's own: Instantiated, Initialization Mode, Step Mode, Event Mode and
//! Continuous-Time Mode (Model Exchange instances only), Terminated and Fatal; the shared Error state is
//! Terminated here. [`FMI3`] names them, and the arguments and calls the shared failures mention.
//! Configuration, Intermediate Update and Reconfiguration Mode are never entered (no structural
//! parameters, no intermediate update), nor is Event Mode by a Co-Simulation instance
//! (`hasEventMode = false`). `fmi3Boolean` arguments are read as bytes (any non-zero byte is true), so
//! a master passing a value other than 0 or 1 cannot cause undefined behaviour.
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int, c_void, CStr};

use crate::fmi::boundary::{self, c_str, guarded, instance_of, slice, Request};
use crate::fmi::instance::{CallResult, Fail, Instance, Logger, Reason};
use crate::fmi::types::{Arg, Dialect, FsmState, Status};
use crate::model::ModelEntry;

/// `fmi3Instance`.
pub type Instance3 = *mut c_void;

/// `fmi3LogMessageCallback`.
pub use crate::fmi::types::TextLogFn as Log3Fn;

/// FMI 3.0 in the words of the shared code: what its instances are called and how their failures read.
pub static FMI3: Dialect = Dialect {
    version: "FMI 3.0",
    token_argument: "instantiationToken",
    setup_experiment: "fmi3EnterInitializationMode",
    set_continuous_states: "fmi3SetContinuousStates",
    argument: |a| match a {
        Arg::States => "continuousStates[]",
        Arg::Nominals => "nominals[]",
        Arg::Derivatives => "derivatives[]",
    },
    state_name,
};

/// Value reference of the independent variable `time` in every FMI 3.0 model description. Declared
/// variables may not use it (a `VarIndex` would need 2^31 slots anyway). `i32::MAX` rather than
/// `u32::MAX`, which some importers use as "no value reference".
pub const TIME_VR: u32 = i32::MAX as u32;

const VERSION: &CStr = c"3.0";

/// Sets of states in which an FMI 3.0 Co-Simulation function may be called.
pub mod mask3 {
    use crate::fmi::types::mask_of as m;
    use crate::fmi::types::FsmState::*;
    // Event Mode: Model Exchange and clocked Co-Simulation; Continuous-Time Mode: Model Exchange only;
    // Activation (Clock Activation Mode): Scheduled Execution only.
    /// Every state but Fatal (the super state "FMU State Settable" plus Terminated).
    pub const ANY: u16 = m(&[
        Instantiated,
        InitializationMode,
        StepMode,
        Terminated,
        EventMode,
        ContinuousTimeMode,
        Activation,
    ]);
    pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
    pub const TERMINATE: u16 = m(&[StepMode, EventMode, ContinuousTimeMode, Activation]);
    pub const GET: u16 = m(&[
        InitializationMode,
        StepMode,
        Terminated,
        EventMode,
        ContinuousTimeMode,
        Activation,
    ]);
    pub const SET: u16 = m(&[
        Instantiated,
        InitializationMode,
        StepMode,
        EventMode,
        ContinuousTimeMode,
        Activation,
    ]);
    /// Clock Activation Mode included: the Scheduled Execution API allows it there.
    pub const DIRECTIONAL_DERIVATIVE: u16 = m(&[
        InitializationMode,
        StepMode,
        Terminated,
        EventMode,
        ContinuousTimeMode,
        Activation,
    ]);
    pub const DO_STEP: u16 = m(&[StepMode]);
    pub const OUTPUT_DERIVATIVES: u16 = m(&[StepMode, Terminated]);
}

/// Sets of states in which an FMI 3.0 Model Exchange function may be called.
pub mod mask3me {
    use crate::fmi::types::mask_of as m;
    use crate::fmi::types::FsmState::*;
    /// `fmi3EnterEventMode`: from Continuous-Time Mode (FMI 3.0 section 3.2.1).
    pub const ENTER_EVENT_MODE: u16 = m(&[ContinuousTimeMode]);
    /// `fmi3UpdateDiscreteStates`, `fmi3EnterContinuousTimeMode`: Event Mode only.
    pub const EVENT_MODE: u16 = m(&[EventMode]);
    /// `fmi3SetTime`, `fmi3SetContinuousStates`, `fmi3CompletedIntegratorStep`: Continuous-Time Mode only.
    pub const CONTINUOUS_TIME_MODE: u16 = m(&[ContinuousTimeMode]);
    /// `fmi3GetContinuousStates`, `fmi3GetContinuousStateDerivatives`, `fmi3GetEventIndicators`,
    /// `fmi3GetNominalsOfContinuousStates`.
    pub const GET_ME_VALUES: u16 = m(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
    /// `fmi3GetNumberOfContinuousStates`, `fmi3GetNumberOfEventIndicators`: any state but Fatal.
    pub const NUMBER_OF: u16 = m(&[
        Instantiated,
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        Terminated,
    ]);
}

/// Runs an FMI 3.0 call on an instance: state check, panic guard, logging; `fmi3Error` moves the
/// instance to Terminated, a panic to Fatal.
#[inline(always)]
pub fn call3(c: Instance3, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    let Some(inst) = instance_of(c, &FMI3) else {
        return Status::Error as c_int;
    };
    if inst.run.fsm == FsmState::Error {
        // the shared Error state (a step or output failure inside the shared Instance code) is
        // FMI 3.0's Terminated
        inst.run.fsm = FsmState::Terminated;
    }
    if allowed & inst.run.fsm.bit() != 0 {
        // the path of every successful call: nothing else on it (the failures are out of line)
        return match guarded(|| f(&mut *inst)) {
            Ok(Ok(())) => Status::Ok as c_int,
            Ok(Err(fail)) => failed3(inst, func, fail),
            Err(panic) => failed3(
                inst,
                func,
                Fail {
                    status: Status::Fatal,
                    reason: format!("internal error (panic): {panic}").into(),
                },
            ),
        };
    }
    let status = if inst.run.fsm == FsmState::Fatal {
        Status::Fatal
    } else {
        Status::Error
    };
    let reason = Reason::IllegalCall(inst.run.fsm);
    failed3(inst, func, Fail { status, reason })
}

/// A failed FMI 3.0 call: `fmi3Error` moves the instance to Terminated, `fmi3Fatal` to Fatal; the reason is
/// logged in FMI 3.0 terms (the instance's dialect is [`FMI3`]); returns the status.
#[cold]
#[inline(never)]
fn failed3(inst: &mut Instance, func: &str, fail: Fail) -> c_int {
    match fail.status {
        Status::Fatal => inst.run.fsm = FsmState::Fatal,
        Status::Error => inst.run.fsm = FsmState::Terminated,
        _ => {}
    }
    inst.log_fail(func, &fail);
    fail.status as c_int
}

/// FMI 3.0 name of a state.
pub fn state_name(s: FsmState) -> &'static str {
    match s {
        FsmState::Instantiated => "Instantiated",
        FsmState::InitializationMode => "Initialization Mode",
        FsmState::StepMode => "Step Mode",
        FsmState::Terminated | FsmState::Error => "Terminated",
        FsmState::Fatal => "Fatal",
        FsmState::EventMode => "Event Mode",
        FsmState::ContinuousTimeMode => "Continuous-Time Mode",
        FsmState::Activation => "Clock Activation Mode",
    }
}

/// An error message through the master's FMI 3.0 logger when there is no instance to log with.
pub fn log_without_instance3(logger: Option<Log3Fn>, env: *mut c_void, func: &str, message: &str) {
    boundary::log_without_instance(
        logger.map_or(Logger::None, Logger::Text),
        env,
        std::ptr::null(),
        func,
        message,
    );
}

/// A call of a function whose feature this FMU does not provide: refused with the reason.
pub fn refuse(c: Instance3, func: &str, allowed: u16, why: &str) -> c_int {
    call3(c, func, allowed, |_| Err(Fail::error(format!("not supported: {why}"))))
}

/// Whether `c` is a live FMI 3.0 Model Exchange instance (the functions both interfaces share pick their
/// rules by it; anything else goes the Co-Simulation way, which refuses unknown pointers).
pub fn is_model_exchange(c: Instance3) -> bool {
    instance_of(c, &FMI3).is_some_and(|inst| inst.model_exchange)
}

/// Refuses a Co-Simulation function on a Model Exchange instance (used inside the CS functions).
pub fn require_co_simulation(inst: &Instance) -> CallResult {
    if inst.model_exchange {
        return Err(Fail::error(
            "Co-Simulation function, but this instance was created by fmi3InstantiateModelExchange",
        ));
    }
    Ok(())
}

// ----- version, life cycle ---------------------------------------------------------------------------

pub extern "C" fn fmi3GetVersion() -> *const c_char {
    VERSION.as_ptr()
}

pub extern "C" fn fmi3FreeInstance(c: Instance3) {
    boundary::free_instance(c, &FMI3)
}

pub extern "C" fn fmi3SetDebugLogging(
    c: Instance3,
    logging_on: u8,
    n: usize,
    categories: *const *const c_char,
) -> c_int {
    call3(c, "fmi3SetDebugLogging", mask3::ANY, |inst| {
        let ptrs = unsafe { slice(categories, n, "categories[]")? };
        let mut names = Vec::with_capacity(n);
        for (i, p) in ptrs.iter().enumerate() {
            names.push(
                c_str(*p, &format!("categories[{i}]"))
                    .map_err(Fail::error)?
                    .to_string_lossy()
                    .into_owned(),
            );
        }
        inst.set_debug_logging(logging_on != 0, &names)
    })
}

pub extern "C" fn fmi3EnterInitializationMode(
    c: Instance3,
    tol_defined: u8,
    tol: f64,
    start: f64,
    stop_defined: u8,
    stop: f64,
) -> c_int {
    call3(
        c,
        "fmi3EnterInitializationMode",
        mask3::ENTER_INITIALIZATION_MODE,
        |inst| {
            inst.trace(|| format!("fmi3EnterInitializationMode(toleranceDefined={tol_defined}, tolerance={tol}, startTime={start}, stopTimeDefined={stop_defined}, stopTime={stop})"));
            let setup = inst.setup_experiment(
                (tol_defined != 0).then_some(tol),
                start,
                (stop_defined != 0).then_some(stop),
            );
            if let Err(f) = &setup {
                if f.status > Status::Warning {
                    return setup;
                }
            }
            inst.enter_initialization_mode()?;
            setup // Ok, or the tolerance warning
        },
    )
}

pub extern "C" fn fmi3ExitInitializationMode(c: Instance3) -> c_int {
    call3(
        c,
        "fmi3ExitInitializationMode",
        mask3::EXIT_INITIALIZATION_MODE,
        |inst| inst.exit_initialization_mode(),
    )
}

pub extern "C" fn fmi3Terminate(c: Instance3) -> c_int {
    call3(c, "fmi3Terminate", mask3::TERMINATE, |inst| {
        inst.run.fsm = FsmState::Terminated;
        Ok(())
    })
}

pub extern "C" fn fmi3Reset(c: Instance3) -> c_int {
    call3(c, "fmi3Reset", mask3::ANY, |inst| {
        inst.reset();
        Ok(())
    })
}

/// The request both FMI 3.0 instantiate functions start from: a Co-Simulation instance with the FMI
/// 3.0 logger, no further argument checks and every model accepted; `fmi3InstantiateCoSimulation` adds
/// its argument checks, `fmi3InstantiateModelExchange` the interface and its refusal.
pub fn request3(
    func: &'static str,
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    token: *const c_char,
    logging_on: u8,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
) -> Request<'static> {
    Request {
        func,
        models,
        instance_name,
        token,
        logger: log_message.map_or(Logger::None, Logger::Text),
        env,
        logging_on: logging_on != 0,
        dialect: &FMI3,
        model_exchange: false,
        check_arguments: &|| Ok(()),
        refuse_model: &|_| None,
    }
}
