//! FMI 3.0 Co-Simulation functions over an FMI 3.0 Model Exchange unit: the exported C signatures over the
//! shared bodies of [`crate::face`]. What is FMI 3.0's own stays here: the unit's `fmi3…` functions, the
//! numbers of states and event indicators asked at instantiation, the `eventModeUsed` check, step mode and
//! the output arguments of `fmi3DoStep`.

use std::ffi::{c_char, c_void};

use crate::face::{self, call, forward, refuse, Face, Step};
use crate::{instance, me, Config, ERROR, OK};

type Inst = *mut c_void;
type Vr = *const u32;

struct Me3(Inst);

impl Face for Me3 {
    const V3: bool = true;
    fn of(inner: Inst) -> Self {
        Me3(inner)
    }
    fn free(&mut self) {
        if let Some(f) = me!(fmi3FreeInstance, unsafe extern "C" fn(Inst)) {
            unsafe { f(self.0) }
        }
    }
    fn exit_initialization_mode(&mut self) -> i32 {
        call!(fmi3ExitInitializationMode, (Inst), self.0)
    }
    fn reset(&mut self) -> i32 {
        call!(fmi3Reset, (Inst), self.0)
    }
    fn sizes(&mut self, cfg: &mut Config) -> bool {
        let (mut nx, mut nz) = (0usize, 0usize);
        if call!(fmi3GetNumberOfContinuousStates, (Inst, *mut usize), self.0, &mut nx) > 1
            || call!(fmi3GetNumberOfEventIndicators, (Inst, *mut usize), self.0, &mut nz) > 1
        {
            return false;
        }
        (cfg.states, cfg.event_indicators) = (nx, nz);
        true
    }
}

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

type InstantiateMe =
    unsafe extern "C" fn(*const c_char, *const c_char, *const c_char, bool, bool, *mut c_void, *const c_void) -> Inst;

/// Instantiates the unit as Model Exchange (event mode and early return are not offered: `eventModeUsed`
/// must be false; intermediate updates are not made).
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    name: *const c_char,
    token: *const c_char,
    location: *const c_char,
    visible: bool,
    logging_on: bool,
    event_mode_used: bool,
    _early_return: bool,
    _required: Vr,
    _n_required: usize,
    env: *mut c_void,
    log: *const c_void,
    _intermediate: *const c_void,
) -> Inst {
    if event_mode_used {
        return std::ptr::null_mut();
    }
    face::instantiate::<Me3>(location, || match me!(fmi3InstantiateModelExchange, InstantiateMe) {
        Some(f) => f(name, token, location, visible, logging_on, env, log),
        None => std::ptr::null_mut(),
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _n: *const c_char,
    _t: *const c_char,
    _l: *const c_char,
    _v: bool,
    _o: bool,
    _e: *mut c_void,
    _log: *const c_void,
) -> Inst {
    std::ptr::null_mut() // the unit's own library is the Model Exchange one
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _n: *const c_char,
    _t: *const c_char,
    _l: *const c_char,
    _v: bool,
    _o: bool,
    _e: *mut c_void,
    _log: *const c_void,
    _c: *const c_void,
    _lp: *const c_void,
    _up: *const c_void,
) -> Inst {
    std::ptr::null_mut()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(i: Inst) {
    face::free::<Me3>(i)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    i: Inst,
    tol_defined: bool,
    tol: f64,
    start: f64,
    stop_defined: bool,
    stop: f64,
) -> i32 {
    face::setup(i, start, |inner| {
        call!(
            fmi3EnterInitializationMode,
            (Inst, bool, f64, f64, bool, f64),
            inner,
            tol_defined,
            tol,
            start,
            stop_defined,
            stop
        )
    })
}

/// Leaves initialization mode (the unit is then in event mode), runs the initial event iteration and
/// enters continuous-time mode; the wrapper is then in step mode.
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(i: Inst) -> i32 {
    face::exit_initialization_mode::<Me3>(i)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(i: Inst) -> i32 {
    face::reset::<Me3>(i)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(i: Inst) -> i32 {
    if instance(i).is_some() {
        OK
    } else {
        ERROR
    }
}

/// Integrates the unit from t to t + h (inputs held): see the crate documentation. A unit that asks to
/// terminate ends the step with fmi3OK and `terminateSimulation`; `lastSuccessfulTime` is the time reached.
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    i: Inst,
    t: f64,
    h: f64,
    _no_set_prior: bool,
    event_needed: *mut bool,
    terminate: *mut bool,
    early: *mut bool,
    last: *mut f64,
) -> i32 {
    let Some(w) = instance(i) else { return ERROR };
    for p in [event_needed, terminate, early] {
        if !p.is_null() {
            *p = false;
        }
    }
    let r = face::do_step(w, t, h);
    if r != Step::Refused && !last.is_null() {
        *last = w.stepper.t;
    }
    match r {
        Step::Refused => ERROR,
        Step::Reached => OK,
        Step::Terminated => {
            if !terminate.is_null() {
                *terminate = true;
            }
            OK
        }
        Step::Failed(s) => s,
    }
}

type St = *mut c_void;
type S = *const c_char;

forward! {
    fmi3SetDebugLogging(on: bool, n: usize, categories: *const S);
    fmi3Terminate();
    fmi3GetFloat32(vr: Vr, n: usize, v: *mut f32, nv: usize);
    fmi3GetFloat64(vr: Vr, n: usize, v: *mut f64, nv: usize);
    fmi3GetInt8(vr: Vr, n: usize, v: *mut i8, nv: usize);
    fmi3GetUInt8(vr: Vr, n: usize, v: *mut u8, nv: usize);
    fmi3GetInt16(vr: Vr, n: usize, v: *mut i16, nv: usize);
    fmi3GetUInt16(vr: Vr, n: usize, v: *mut u16, nv: usize);
    fmi3GetInt32(vr: Vr, n: usize, v: *mut i32, nv: usize);
    fmi3GetUInt32(vr: Vr, n: usize, v: *mut u32, nv: usize);
    fmi3GetInt64(vr: Vr, n: usize, v: *mut i64, nv: usize);
    fmi3GetUInt64(vr: Vr, n: usize, v: *mut u64, nv: usize);
    fmi3GetBoolean(vr: Vr, n: usize, v: *mut bool, nv: usize);
    fmi3GetString(vr: Vr, n: usize, v: *mut S, nv: usize);
    fmi3GetBinary(vr: Vr, n: usize, sizes: *mut usize, v: *mut *const u8, nv: usize);
    fmi3GetClock(vr: Vr, n: usize, v: *mut bool);
    fmi3SetFloat32(vr: Vr, n: usize, v: *const f32, nv: usize);
    fmi3SetFloat64(vr: Vr, n: usize, v: *const f64, nv: usize);
    fmi3SetInt8(vr: Vr, n: usize, v: *const i8, nv: usize);
    fmi3SetUInt8(vr: Vr, n: usize, v: *const u8, nv: usize);
    fmi3SetInt16(vr: Vr, n: usize, v: *const i16, nv: usize);
    fmi3SetUInt16(vr: Vr, n: usize, v: *const u16, nv: usize);
    fmi3SetInt32(vr: Vr, n: usize, v: *const i32, nv: usize);
    fmi3SetUInt32(vr: Vr, n: usize, v: *const u32, nv: usize);
    fmi3SetInt64(vr: Vr, n: usize, v: *const i64, nv: usize);
    fmi3SetUInt64(vr: Vr, n: usize, v: *const u64, nv: usize);
    fmi3SetBoolean(vr: Vr, n: usize, v: *const bool, nv: usize);
    fmi3SetString(vr: Vr, n: usize, v: *const S, nv: usize);
    fmi3SetBinary(vr: Vr, n: usize, sizes: *const usize, v: *const *const u8, nv: usize);
    fmi3SetClock(vr: Vr, n: usize, v: *const bool);
    fmi3GetNumberOfVariableDependencies(vr: u32, n: *mut usize);
    fmi3GetVariableDependencies(dep: u32, ed: *mut usize, ind: *mut u32, ei: *mut usize, kinds: *mut i32, n: usize);
    fmi3GetDirectionalDerivative(u: Vr, nu: usize, k: Vr, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize);
    fmi3GetAdjointDerivative(u: Vr, nu: usize, k: Vr, nk: usize, s: *const f64, ns: usize, o: *mut f64, no: usize);
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
}

// Model Exchange and Scheduled Execution functions (this face is Co-Simulation), event mode, output
// derivatives, clocks' intervals and FMU states (the stepper's state is not part of one): not offered.
refuse! {
    fmi3EnterEventMode();
    fmi3GetFMUState(s: *mut St);
    fmi3SetFMUState(s: St);
    fmi3FreeFMUState(s: *mut St);
    fmi3SerializedFMUStateSize(s: St, size: *mut usize);
    fmi3SerializeFMUState(s: St, out: *mut u8, size: usize);
    fmi3DeserializeFMUState(data: *const u8, size: usize, s: *mut St);
    fmi3GetIntervalDecimal(vr: Vr, n: usize, v: *mut f64, q: *mut i32);
    fmi3GetIntervalFraction(vr: Vr, n: usize, c: *mut u64, r: *mut u64, q: *mut i32);
    fmi3GetShiftDecimal(vr: Vr, n: usize, v: *mut f64);
    fmi3GetShiftFraction(vr: Vr, n: usize, c: *mut u64, r: *mut u64);
    fmi3SetIntervalDecimal(vr: Vr, n: usize, v: *const f64);
    fmi3SetIntervalFraction(vr: Vr, n: usize, c: *const u64, r: *const u64);
    fmi3SetShiftDecimal(vr: Vr, n: usize, v: *const f64);
    fmi3SetShiftFraction(vr: Vr, n: usize, c: *const u64, r: *const u64);
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(a: *mut bool, b: *mut bool, c: *mut bool, d: *mut bool, e: *mut bool, t: *mut f64);
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(no: bool, a: *mut bool, b: *mut bool);
    fmi3SetTime(t: f64);
    fmi3SetContinuousStates(x: *const f64, n: usize);
    fmi3GetContinuousStateDerivatives(x: *mut f64, n: usize);
    fmi3GetEventIndicators(x: *mut f64, n: usize);
    fmi3GetContinuousStates(x: *mut f64, n: usize);
    fmi3GetNominalsOfContinuousStates(x: *mut f64, n: usize);
    fmi3GetNumberOfEventIndicators(n: *mut usize);
    fmi3GetNumberOfContinuousStates(n: *mut usize);
    fmi3GetOutputDerivatives(vr: Vr, n: usize, o: *const i32, v: *mut f64, nv: usize);
    fmi3ActivateModelPartition(clock: u32, t: f64);
}
