//! The FMI 3.0 Co-Simulation C functions, on top of the same [`Instance`] as FMI 2.0: value access,
//! stepping, initialization and FMU states are shared; this file adds the FMI 3.0 signatures, its state
//! machine (a mask table like [`super::mask`]), the independent variable `time`, and its error rule:
//! a function that returns `fmi3Error` puts the instance into Terminated (FMI 3.0, section 2.3.1).
//!
//! States are mapped onto [`FsmState`]: Instantiated, InitializationMode, Step Mode
//! (`StepComplete`), Terminated and Fatal. Configuration, Event, Intermediate Update and
//! Reconfiguration Mode are never entered (no structural parameters, `hasEventMode = false`, no
//! intermediate update). `fmi3Boolean` arguments are read as bytes (any non-zero byte is true), so a
//! master passing a value other than 0 or 1 cannot cause undefined behaviour.
//!
//! The functions of other interfaces and of features these FMUs do not declare (clocks, other
//! variable types, adjoint derivatives, ...) are in [`super::fmi3_more`].
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref, clippy::too_many_arguments)]

use std::ffi::{c_char, c_int, c_void, CStr};

use super::abi::{find_model, free_instance, guarded, instance_of, register, slice, slice_mut, out_ptr};
use super::instance::{CallResult, Fail, Instance, Log3Fn, Logger};
use super::{FsmState, Status};
use crate::model::{ModelEntry, Value, VarKind};

pub type Instance3 = *mut c_void;

/// Value reference of the independent variable `time` in every FMI 3.0 model description. Declared
/// variables may not use it (a `VarIndex` would need 2^31 slots anyway). `i32::MAX` rather than
/// `u32::MAX`, which some importers use as "no value reference".
pub const TIME_VR: u32 = i32::MAX as u32;

const VERSION: &CStr = c"3.0";

/// Sets of states in which an FMI 3.0 Co-Simulation function may be called.
pub mod mask3 {
    use super::FsmState::*;
    use crate::fmi::mask_of as m;
    // Event Mode and Continuous-Time Mode are reached by Model Exchange instances only (`fmi3_me`).
    /// Every state but Fatal (the super state "FMU State Settable" plus Terminated).
    pub const ANY: u16 = m(&[Instantiated, InitializationMode, StepComplete, Terminated, EventMode, ContinuousTimeMode]);
    pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
    pub const TERMINATE: u16 = m(&[StepComplete, EventMode, ContinuousTimeMode]);
    pub const GET: u16 = m(&[InitializationMode, StepComplete, Terminated, EventMode, ContinuousTimeMode]);
    pub const SET: u16 = m(&[Instantiated, InitializationMode, StepComplete, EventMode, ContinuousTimeMode]);
    pub const DIRECTIONAL_DERIVATIVE: u16 = m(&[InitializationMode, StepComplete, Terminated, EventMode, ContinuousTimeMode]);
    pub const DO_STEP: u16 = m(&[StepComplete]);
    pub const OUTPUT_DERIVATIVES: u16 = m(&[StepComplete, Terminated]);
}

/// Runs an FMI 3.0 call on an instance: state check, panic guard, logging; `fmi3Error` moves the
/// instance to Terminated, a panic to Fatal.
pub(super) fn call3(c: Instance3, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    let Some(inst) = instance_of(c, true) else {
        return Status::Error as c_int;
    };
    if inst.run.fsm == FsmState::Error {
        // FMI 2.0's error state (a step or output failure inside the shared Instance code, or an FMU
        // state serialized by an FMI 2.0 instance) is FMI 3.0's Terminated
        inst.run.fsm = FsmState::Terminated;
    }
    let result = if allowed & inst.run.fsm.bit() == 0 {
        let status = if inst.run.fsm == FsmState::Fatal { Status::Fatal } else { Status::Error };
        Err(Fail { status, reason: format!("not allowed in state {} (illegal call sequence)", state_name(inst.run.fsm)) })
    } else {
        match guarded(|| f(&mut *inst)) {
            Ok(r) => r,
            Err(panic) => Err(Fail { status: Status::Fatal, reason: format!("internal error (panic): {panic}") }),
        }
    };
    match result {
        Ok(()) => Status::Ok as c_int,
        Err(fail) => {
            match fail.status {
                Status::Fatal => inst.run.fsm = FsmState::Fatal,
                Status::Error => inst.run.fsm = FsmState::Terminated,
                _ => {}
            }
            let reason = fail.reason.replace("fmi2SetupExperiment", "fmi3EnterInitializationMode").replace("fmi2SetContinuousStates", "fmi3SetContinuousStates");
            inst.log_fail(func, &Fail { status: fail.status, reason });
            fail.status as c_int
        }
    }
}

/// FMI 3.0 name of a state.
pub fn state_name(s: FsmState) -> &'static str {
    match s {
        FsmState::Instantiated => "Instantiated",
        FsmState::InitializationMode => "Initialization Mode",
        FsmState::StepComplete | FsmState::StepFailed | FsmState::StepCanceled => "Step Mode",
        FsmState::Terminated | FsmState::Error => "Terminated",
        FsmState::Fatal => "Fatal",
        FsmState::EventMode => "Event Mode",
        FsmState::ContinuousTimeMode => "Continuous-Time Mode",
    }
}

pub(super) fn log_without_instance3(logger: Option<Log3Fn>, env: *mut c_void, func: &str, message: &str) {
    if let Some(logger) = logger {
        let text = std::ffi::CString::new(format!("{func}: {message}").replace('\0', "")).unwrap_or_default();
        // SAFETY: master-provided callback with valid NUL-terminated strings.
        unsafe { logger(env, Status::Error as c_int, c"logStatusError".as_ptr(), text.as_ptr()) };
    }
}

/// Reads a C string argument that must be non-null (and, for names, non-empty).
fn c_str<'a>(p: *const c_char, what: &str) -> Result<&'a CStr, String> {
    if p.is_null() {
        return Err(format!("{what} is NULL"));
    }
    // SAFETY: non-null C string from the master.
    Ok(unsafe { CStr::from_ptr(p) })
}

// ----- version, instantiation, life cycle ---------------------------------------------------------

pub extern "C" fn fmi3GetVersion() -> *const c_char {
    VERSION.as_ptr()
}

/// `fmi3InstantiateCoSimulation` for a library holding `models`: the model is picked by the library's
/// file name and the instantiation token (the GUID), as in `fmi2Instantiate`.
pub fn fmi3InstantiateCoSimulation(
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    event_mode_used: u8,
    early_return_allowed: u8,
    required_intermediate: *const u32,
    n_required_intermediate: usize,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
    _intermediate_update: *const c_void,
) -> Instance3 {
    let _ = early_return_allowed; // allowed, never used: fmi3DoStep always completes the whole step
    let result = guarded(|| -> Result<Instance3, String> {
        let name = c_str(instance_name, "instanceName")?;
        if name.to_bytes().is_empty() {
            return Err("instanceName is empty".into());
        }
        if event_mode_used != 0 {
            return Err("eventModeUsed = true, but this FMU has no Event Mode (hasEventMode = false)".into());
        }
        if n_required_intermediate > 0 {
            let vrs = unsafe { slice(required_intermediate, n_required_intermediate, "requiredIntermediateVariables[]") }.map_err(|f| f.reason)?;
            return Err(format!("requiredIntermediateVariables {vrs:?}: this FMU provides no intermediate update (providesIntermediateUpdate = false)"));
        }
        let requested = c_str(token, "instantiationToken")?.to_string_lossy();
        let entry = find_model(models, &requested).map_err(|e| e.replace("fmuGUID", "instantiationToken"))?;
        let mut inst = Box::new(Instance::new(name.to_owned(), entry, log_message.map_or(Logger::None, Logger::Fmi3), env, logging_on != 0));
        inst.fmi3 = true;
        inst.trace(|| format!("fmi3InstantiateCoSimulation: {} instance of {}", inst.name.to_string_lossy(), entry.info.name));
        Ok(register(inst))
    });
    match result {
        Ok(Ok(p)) => p,
        Ok(Err(msg)) => {
            log_without_instance3(log_message, env, "fmi3InstantiateCoSimulation", &msg);
            std::ptr::null_mut()
        }
        Err(panic) => {
            log_without_instance3(log_message, env, "fmi3InstantiateCoSimulation", &format!("internal error (panic): {panic}"));
            std::ptr::null_mut()
        }
    }
}

pub extern "C" fn fmi3FreeInstance(c: Instance3) {
    free_instance(c, true)
}

pub extern "C" fn fmi3SetDebugLogging(c: Instance3, logging_on: u8, n: usize, categories: *const *const c_char) -> c_int {
    call3(c, "fmi3SetDebugLogging", mask3::ANY, |inst| {
        let ptrs = unsafe { slice(categories, n, "categories[]")? };
        let mut names = Vec::with_capacity(n);
        for (i, p) in ptrs.iter().enumerate() {
            names.push(c_str(*p, &format!("categories[{i}]")).map_err(Fail::error)?.to_string_lossy().into_owned());
        }
        inst.set_debug_logging(logging_on != 0, &names)
    })
}

pub extern "C" fn fmi3EnterInitializationMode(c: Instance3, tol_defined: u8, tol: f64, start: f64, stop_defined: u8, stop: f64) -> c_int {
    call3(c, "fmi3EnterInitializationMode", mask3::ENTER_INITIALIZATION_MODE, |inst| {
        inst.trace(|| format!("fmi3EnterInitializationMode(toleranceDefined={tol_defined}, tolerance={tol}, startTime={start}, stopTimeDefined={stop_defined}, stopTime={stop})"));
        let setup = inst.setup_experiment((tol_defined != 0).then_some(tol), start, (stop_defined != 0).then_some(stop));
        if let Err(f) = &setup {
            if f.status > Status::Warning {
                return setup;
            }
        }
        inst.enter_initialization_mode()?;
        setup // Ok, or the tolerance warning
    })
}

pub extern "C" fn fmi3ExitInitializationMode(c: Instance3) -> c_int {
    call3(c, "fmi3ExitInitializationMode", mask3::EXIT_INITIALIZATION_MODE, |inst| inst.exit_initialization_mode())
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

// ----- get / set ------------------------------------------------------------------------------------

fn scalar_count(n_vr: usize, n_values: usize) -> CallResult {
    if n_vr != n_values {
        return Err(Fail::error(format!("nValues = {n_values} differs from nValueReferences = {n_vr} (every variable of this FMU is a scalar)")));
    }
    Ok(())
}

fn get3<T: Copy>(c: Instance3, func: &str, kind: VarKind, vr: *const u32, n: usize, value: *mut T, nv: usize, conv: impl Fn(Value) -> T) -> c_int {
    call3(c, func, mask3::GET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let out = unsafe { slice_mut(value, n, "values[]")? };
        inst.get_values(kind, vrs, |i, v| out[i] = conv(v))
    })
}

fn set3<T: Copy>(c: Instance3, func: &str, kind: VarKind, vr: *const u32, n: usize, value: *const T, nv: usize, conv: impl Fn(T) -> Value) -> c_int {
    call3(c, func, mask3::SET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let vals = unsafe { slice(value, n, "values[]")? };
        if vrs.contains(&TIME_VR) {
            return Err(Fail::error(time_not_settable(inst)));
        }
        super::fmi3_me::refuse_discrete_in_continuous_time(inst, kind_name3(kind), vrs)?;
        inst.set_values(kind, vrs, |i| conv(vals[i]))
    })
}

pub extern "C" fn fmi3GetFloat64(c: Instance3, vr: *const u32, n: usize, value: *mut f64, nv: usize) -> c_int {
    call3(c, "fmi3GetFloat64", mask3::GET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let out = unsafe { slice_mut(value, n, "values[]")? };
        let real = |v| if let Value::Real(x) = v { x } else { f64::NAN };
        if !vrs.contains(&TIME_VR) {
            return inst.get_values(VarKind::Real, vrs, |i, v| out[i] = real(v));
        }
        // time among the declared variables: read the others, then fill in the FMU time
        let others: Vec<usize> = (0..n).filter(|i| vrs[*i] != TIME_VR).collect();
        let other_vrs: Vec<u32> = others.iter().map(|i| vrs[*i]).collect();
        inst.get_values(VarKind::Real, &other_vrs, |j, v| out[others[j]] = real(v))?;
        for (o, v) in out.iter_mut().zip(vrs) {
            if *v == TIME_VR {
                *o = inst.run.time;
            }
        }
        Ok(())
    })
}

fn time_not_settable(inst: &Instance) -> String {
    let how = if inst.model_exchange { "it is set with fmi3SetTime" } else { "it advances with fmi3DoStep" };
    format!("value reference {TIME_VR} is time, the independent variable: it cannot be set ({how})")
}

fn kind_name3(kind: VarKind) -> &'static str {
    match kind {
        VarKind::Real => "Float64",
        VarKind::Integer => "Int32",
        VarKind::Boolean => "Boolean",
    }
}

pub extern "C" fn fmi3SetFloat64(c: Instance3, vr: *const u32, n: usize, value: *const f64, nv: usize) -> c_int {
    call3(c, "fmi3SetFloat64", mask3::SET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let vals = unsafe { slice(value, n, "values[]")? };
        if vrs.contains(&TIME_VR) {
            return Err(Fail::error(time_not_settable(inst)));
        }
        if inst.model_exchange && matches!(inst.run.fsm, FsmState::EventMode | FsmState::ContinuousTimeMode) {
            // continuous states can be set by value reference; in Continuous-Time Mode only they and continuous inputs
            return super::fmi3_me::set_float64_me(inst, vrs, vals);
        }
        inst.set_values(VarKind::Real, vrs, |i| Value::Real(vals[i]))
    })
}

pub extern "C" fn fmi3GetInt32(c: Instance3, vr: *const u32, n: usize, value: *mut i32, nv: usize) -> c_int {
    get3(c, "fmi3GetInt32", VarKind::Integer, vr, n, value, nv, |v| if let Value::Integer(x) = v { x } else { 0 })
}

pub extern "C" fn fmi3SetInt32(c: Instance3, vr: *const u32, n: usize, value: *const i32, nv: usize) -> c_int {
    set3(c, "fmi3SetInt32", VarKind::Integer, vr, n, value, nv, Value::Integer)
}

/// `fmi3Boolean` is a C `bool` (one byte): written as 0 or 1, read as "non-zero is true".
pub extern "C" fn fmi3GetBoolean(c: Instance3, vr: *const u32, n: usize, value: *mut u8, nv: usize) -> c_int {
    get3(c, "fmi3GetBoolean", VarKind::Boolean, vr, n, value, nv, |v| matches!(v, Value::Boolean(true)) as u8)
}

pub extern "C" fn fmi3SetBoolean(c: Instance3, vr: *const u32, n: usize, value: *const u8, nv: usize) -> c_int {
    set3(c, "fmi3SetBoolean", VarKind::Boolean, vr, n, value, nv, |b| Value::Boolean(b != 0))
}

// ----- stepping -------------------------------------------------------------------------------------

pub extern "C" fn fmi3DoStep(
    c: Instance3,
    t: f64,
    h: f64,
    _no_set_prior: u8,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> c_int {
    call3(c, "fmi3DoStep", mask3::ANY, |inst| {
        super::fmi3_me::require_co_simulation(inst)?;
        if mask3::DO_STEP & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(format!("not allowed in state {} (illegal call sequence)", state_name(inst.run.fsm))));
        }
        inst.trace(|| format!("fmi3DoStep(currentCommunicationPoint={t}, communicationStepSize={h})"));
        let ev = out_ptr(event_handling_needed, "eventHandlingNeeded")?;
        let term = out_ptr(terminate_simulation, "terminateSimulation")?;
        let early = out_ptr(early_return, "earlyReturn")?;
        let last = out_ptr(last_successful_time, "lastSuccessfulTime")?;
        (*ev, *term, *early) = (0, 0, 0);
        let r = inst.do_step(t, h);
        *last = inst.run.time;
        r
    })
}
