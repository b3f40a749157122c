//! The FMI 2.0 Co-Simulation C functions, written once for every model. Each one: checks pointers,
//! finds the instance among the live ones, checks the state machine, runs the call inside
//! `catch_unwind`, and turns every failure into a status plus a logger message naming the function
//! and the reason.
//!
//! Nothing here is exported by itself: [`export_fmus!`](crate::export_fmus) expands, in the crate
//! that builds the shared library (ours or a user's), to `#[no_mangle]` functions with the standard
//! names that call these, and passes its list of models to [`fmi2Instantiate`]. A library that only
//! depends on this crate (an rlib) therefore exports no FMI symbol of its own.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::cell::{Cell, RefCell};
use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::MutexGuard;

use super::instance::{CallResult, Fail, Instance, Logger};
use super::state::Snapshot;
use super::{mask, BuildAddrHasher, CallbackFunctions, FsmState, LiveSet, Status};
use crate::model::guid::guid;
use crate::model::{ModelEntry, Value, VarKind};

pub use super::abi_me::*;
pub use super::abi_more::*;

pub(crate) type Component = *mut c_void;

const TYPES_PLATFORM: &CStr = c"default";
const VERSION: &CStr = c"2.0";

// ----- live instances ----------------------------------------------------------------------------

fn live_instances() -> MutexGuard<'static, HashSet<usize, BuildAddrHasher>> {
    static LIVE: LiveSet = LiveSet::new();
    LIVE.lock()
}

/// The instance behind a component pointer, if it is one of ours and not freed. A null, foreign or
/// freed pointer gives None (and the call returns fmi2Error: there is no logger to tell).
fn instance<'a>(c: Component) -> Option<&'a mut Instance> {
    instance_of(c, false)
}

/// The instance behind a pointer if it is live and was created through the FMI version asked for
/// (`fmi3`: by `fmi3InstantiateCoSimulation`); an FMI 2.0 instance is foreign to the FMI 3.0
/// functions and the other way round.
pub(super) fn instance_of<'a>(c: Component, fmi3: bool) -> Option<&'a mut Instance> {
    if c.is_null() || !live_instances().contains(&(c as usize)) {
        return None;
    }
    // SAFETY: the address is registered by fmi2Instantiate / fmi3InstantiateCoSimulation and removed
    // by fmi2FreeInstance / fmi3FreeInstance.
    let inst = unsafe { &mut *(c as *mut Instance) };
    (inst.fmi3 == fmi3).then_some(inst)
}

/// Registers a new instance (installing the panic hook with the first one).
pub(super) fn register(inst: Box<Instance>) -> Component {
    let p = Box::into_raw(inst) as Component;
    let mut live = live_instances();
    if live.is_empty() {
        install_panic_hook();
    }
    live.insert(p as usize);
    p
}

// ----- panics ------------------------------------------------------------------------------------

thread_local! {
    static IN_FFI: Cell<bool> = const { Cell::new(false) };
    static PANIC_MESSAGE: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Panics inside an FMI call are reported through the logger, not printed: the hook records the
/// message and location; outside FMI calls (Rust tests) a one-line report goes to stderr. The
/// hook is installed while at least one instance lives (changed only under the live-instance lock)
/// and removed with the last one, so an unloaded library leaves no hook behind.
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        if IN_FFI.with(Cell::get) {
            let loc = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            PANIC_MESSAGE.with(|m| *m.borrow_mut() = Some(format!("{msg}{loc}")));
        } else {
            let msg = info.payload().downcast_ref::<&str>().copied().or_else(|| info.payload().downcast_ref::<String>().map(String::as_str));
            eprintln!("panic: {}{}", msg.unwrap_or("unknown panic"), info.location().map(|l| format!(" at {l}")).unwrap_or_default());
        }
    }));
}

pub(super) fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    let was = IN_FFI.with(|x| x.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    IN_FFI.with(|x| x.set(was));
    r.map_err(|_| PANIC_MESSAGE.with(|m| m.borrow_mut().take()).unwrap_or_else(|| "unknown panic".into()))
}

/// Runs an instance call: state check, panic guard, logging of failures.
pub(crate) fn call(c: Component, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    let Some(inst) = instance(c) else {
        return Status::Error as c_int;
    };
    if allowed & inst.run.fsm.bit() == 0 {
        let status = if inst.run.fsm == FsmState::Fatal { Status::Fatal } else { Status::Error };
        inst.log_fail(func, &Fail { status, reason: format!("not allowed in state {:?} (illegal call sequence)", inst.run.fsm) });
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
            inst.log_fail(func, &Fail { status: Status::Fatal, reason: format!("internal error (panic): {panic}") });
            Status::Fatal as c_int
        }
    }
}

// ----- pointer helpers ---------------------------------------------------------------------------

/// Borrows a C array; `n == 0` needs no pointer. Null with n > 0 is an error naming the argument.
pub(super) unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> CallResult<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL but its length is {n}")));
    }
    if n > (isize::MAX as usize) / std::mem::size_of::<T>().max(1) {
        return Err(Fail::error(format!("length {n} of {what} is impossible")));
    }
    // SAFETY: non-null, length checked against the address space; the master owns n elements.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

pub(super) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> CallResult<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL but its length is {n}")));
    }
    if n > (isize::MAX as usize) / std::mem::size_of::<T>().max(1) {
        return Err(Fail::error(format!("length {n} of {what} is impossible")));
    }
    // SAFETY: as in `slice`.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

pub(super) fn out_ptr<'a, T>(p: *mut T, what: &str) -> CallResult<&'a mut T> {
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL")));
    }
    // SAFETY: non-null pointer to storage the master provides for the result.
    Ok(unsafe { &mut *p })
}

// ----- model lookup for fmi2Instantiate ------------------------------------------------------------

pub(super) fn find_model(all: &'static [ModelEntry], requested: &str) -> Result<&'static ModelEntry, String> {
    if let Some(expected) = super::library_path::own_library_stem().and_then(|stem| all.iter().find(|e| e.info.name == stem)) {
        let want = guid(expected);
        return if requested == want.as_str() {
            Ok(expected)
        } else {
            Err(format!("fmuGUID {requested} does not match {}'s GUID {want} (modelDescription.xml and binary are from different builds)", expected.info.name))
        };
    }
    all.iter().find(|e| guid(e).as_str() == requested).ok_or_else(|| format!("fmuGUID {requested} matches no model in this binary"))
}

fn log_without_instance(functions: &CallbackFunctions, name: &CStr, message: &str) {
    if let Some(logger) = functions.logger {
        let text = CString::new(format!("fmi2Instantiate: {message}").replace('%', "%%").replace('\0', "")).unwrap_or_default();
        // SAFETY: master-provided callback with valid NUL-terminated strings.
        unsafe { logger(functions.component_environment, name.as_ptr(), Status::Error as c_int, c"logStatusError".as_ptr(), text.as_ptr()) };
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
    let result = guarded(|| -> Result<Component, String> {
        if instance_name.is_null() {
            return Err("instanceName is NULL".into());
        }
        // SAFETY: non-null C string from the master.
        let name = unsafe { CStr::from_ptr(instance_name) };
        if name.to_bytes().is_empty() {
            return Err("instanceName is empty".into());
        }
        if fmu_type != 0 && fmu_type != 1 {
            return Err(format!("fmuType {fmu_type} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"));
        }
        if fmu_guid.is_null() {
            return Err("fmuGUID is NULL".into());
        }
        // SAFETY: non-null C string from the master.
        let requested = unsafe { CStr::from_ptr(fmu_guid) }.to_string_lossy();
        let entry = find_model(models, &requested)?;
        if fmu_type == 0 && !entry.model_exchange() {
            return Err(format!("fmuType fmi2ModelExchange requested, but {} supports only Co-Simulation (fmi2CoSimulation = 1)", entry.info.name));
        }
        let mut inst = Box::new(Instance::new(name.to_owned(), entry, functions.logger.map_or(Logger::None, Logger::Fmi2), functions.component_environment, logging_on != 0));
        inst.model_exchange = fmu_type == 0;
        inst.trace(|| format!("fmi2Instantiate: {} instance of {}", inst.name.to_string_lossy(), entry.info.name));
        Ok(register(inst))
    });
    let name = if instance_name.is_null() { c"?" } else { unsafe { CStr::from_ptr(instance_name) } };
    match result {
        Ok(Ok(p)) => p,
        Ok(Err(msg)) => {
            log_without_instance(functions, name, &msg);
            std::ptr::null_mut()
        }
        Err(panic) => {
            log_without_instance(functions, name, &format!("internal error (panic): {panic}"));
            std::ptr::null_mut()
        }
    }
}

pub extern "C" fn fmi2FreeInstance(c: Component) {
    free_instance(c, false)
}

/// Frees an instance of the given FMI version (and its FMU states); anything else is ignored.
pub(super) fn free_instance(c: Component, fmi3: bool) {
    if instance_of(c, fmi3).is_none() || !live_instances().remove(&(c as usize)) {
        return; // null, not ours or of the other FMI version: nothing to free, nothing to log to
    }
    let _ = guarded(|| {
        Snapshot::free_all_of(c as usize);
        // SAFETY: it was registered (so it is a leaked Box<Instance>) and is now unregistered.
        drop(unsafe { Box::from_raw(c as *mut Instance) });
    });
    let mut live = live_instances();
    if live.is_empty() {
        // the last instance: give the set's memory back and remove the panic hook (not while the
        // calling thread unwinds: take_hook panics then, which would abort inside extern "C")
        live.shrink_to_fit();
        if !std::thread::panicking() {
            drop(std::panic::take_hook());
        }
    }
}

pub extern "C" fn fmi2SetDebugLogging(c: Component, logging_on: c_int, n: usize, categories: *const *const c_char) -> c_int {
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

pub extern "C" fn fmi2SetupExperiment(c: Component, tol_defined: c_int, tol: f64, start: f64, stop_defined: c_int, stop: f64) -> c_int {
    call(c, "fmi2SetupExperiment", mask::SETUP_EXPERIMENT, |inst| {
        inst.trace(|| format!("fmi2SetupExperiment(toleranceDefined={tol_defined}, tolerance={tol}, startTime={start}, stopTimeDefined={stop_defined}, stopTime={stop})"));
        inst.setup_experiment((tol_defined != 0).then_some(tol), start, (stop_defined != 0).then_some(stop))
    })
}

pub extern "C" fn fmi2EnterInitializationMode(c: Component) -> c_int {
    call(c, "fmi2EnterInitializationMode", mask::ENTER_INITIALIZATION_MODE, |inst| inst.enter_initialization_mode())
}

pub extern "C" fn fmi2ExitInitializationMode(c: Component) -> c_int {
    call(c, "fmi2ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE, |inst| inst.exit_initialization_mode())
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

fn set_typed<T: Copy>(c: Component, func: &str, kind: VarKind, vr: *const u32, n: usize, value: *const T, conv: impl Fn(T) -> Value) -> c_int {
    call(c, func, mask::SET, |inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        let vals = unsafe { slice(value, n, "value[]")? };
        inst.set_values(kind, vrs, |i| conv(vals[i]))
    })
}

pub extern "C" fn fmi2GetReal(c: Component, vr: *const u32, n: usize, value: *mut f64) -> c_int {
    get_typed(c, "fmi2GetReal", VarKind::Real, vr, n, value, |v| if let Value::Real(x) = v { x } else { f64::NAN })
}

pub extern "C" fn fmi2GetInteger(c: Component, vr: *const u32, n: usize, value: *mut c_int) -> c_int {
    get_typed(c, "fmi2GetInteger", VarKind::Integer, vr, n, value, |v| if let Value::Integer(x) = v { x } else { 0 })
}

pub extern "C" fn fmi2GetBoolean(c: Component, vr: *const u32, n: usize, value: *mut c_int) -> c_int {
    get_typed(c, "fmi2GetBoolean", VarKind::Boolean, vr, n, value, |v| matches!(v, Value::Boolean(true)) as c_int)
}

pub extern "C" fn fmi2GetString(c: Component, vr: *const u32, n: usize, value: *mut *const c_char) -> c_int {
    call(c, "fmi2GetString", mask::GET, |_inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        unsafe { slice_mut(value, n, "value[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!("unknown String value reference {v} (this FMU has no String variables)"))),
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
    set_typed(c, "fmi2SetBoolean", VarKind::Boolean, vr, n, value, |b| Value::Boolean(b != 0))
}

pub extern "C" fn fmi2SetString(c: Component, vr: *const u32, n: usize, value: *const *const c_char) -> c_int {
    call(c, "fmi2SetString", mask::SET, |_inst| {
        let vrs = unsafe { slice(vr, n, "vr[]")? };
        unsafe { slice(value, n, "value[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!("unknown String value reference {v} (this FMU has no String variables)"))),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::LoggerFn;
    use std::sync::Mutex as StdMutex;

    type Log = StdMutex<Vec<(c_int, String)>>;

    unsafe extern "C" fn record(env: *mut c_void, _n: *const c_char, status: c_int, _c: *const c_char, msg: *const c_char) {
        let log = unsafe { &*(env as *const Log) };
        log.lock().unwrap().push((status, unsafe { CStr::from_ptr(msg) }.to_string_lossy().into_owned()));
    }

    /// A panic inside a call becomes fmi2Fatal with a logged message, and the instance refuses
    /// everything afterwards except fmi2FreeInstance.
    #[test]
    fn panic_is_caught_logged_and_fatal() {
        let log: Box<Log> = Box::new(StdMutex::new(vec![]));
        // SAFETY: non-variadic callee with the fixed arguments of fmi2CallbackLogger (see tests/common).
        let logger: LoggerFn = unsafe { std::mem::transmute(record as unsafe extern "C" fn(_, _, _, _, _)) };
        let cb = CallbackFunctions {
            logger: Some(logger),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &*log as *const Log as *mut c_void,
        };
        let entry = crate::registry::find("AttitudeMetrics").unwrap();
        let g = CString::new(guid(entry).as_str()).unwrap();
        let c = fmi2Instantiate(crate::registry::ALL, c"p".as_ptr(), 1, g.as_ptr(), std::ptr::null(), &cb, 0, 0);
        assert!(!c.is_null());
        let st = call(c, "fmi2Probe", mask::SETUP_EXPERIMENT, |_| panic!("deliberate test panic"));
        assert_eq!(st, Status::Fatal as c_int);
        let (status, msg) = log.lock().unwrap().last().cloned().unwrap();
        assert_eq!(status, Status::Fatal as c_int);
        assert!(msg.contains("fmi2Probe") && msg.contains("deliberate test panic"), "{msg}");
        assert_eq!(fmi2EnterInitializationMode(c), Status::Fatal as c_int);
        fmi2FreeInstance(c);
    }
}
