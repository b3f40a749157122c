//! FMI 3.0 Co-Simulation functions over an FMI 3.0 Model Exchange unit.

use std::ffi::{c_char, c_void};

use crate::{instance, load, me, Instance, Solver, Unit, ERROR, MAGIC, OK};

type Inst = *mut c_void;
type Vr = *const u32;

struct Me3(Inst);

macro_rules! call {
    ($name:ident, ($($ty:ty),*), $($arg:expr),*) => {
        match me!($name, unsafe extern "C" fn($($ty),*) -> i32) {
            Some(f) => unsafe { f($($arg),*) },
            None => ERROR,
        }
    };
}

impl Unit for Me3 {
    fn set_time(&mut self, t: f64) -> i32 {
        call!(fmi3SetTime, (Inst, f64), self.0, t)
    }
    fn set_states(&mut self, x: &[f64]) -> i32 {
        call!(
            fmi3SetContinuousStates,
            (Inst, *const f64, usize),
            self.0,
            x.as_ptr(),
            x.len()
        )
    }
    fn get_states(&mut self, x: &mut [f64]) -> i32 {
        call!(
            fmi3GetContinuousStates,
            (Inst, *mut f64, usize),
            self.0,
            x.as_mut_ptr(),
            x.len()
        )
    }
    fn derivatives(&mut self, dx: &mut [f64]) -> i32 {
        call!(
            fmi3GetContinuousStateDerivatives,
            (Inst, *mut f64, usize),
            self.0,
            dx.as_mut_ptr(),
            dx.len()
        )
    }
    fn indicators(&mut self, z: &mut [f64]) -> i32 {
        if z.is_empty() {
            return OK;
        }
        call!(
            fmi3GetEventIndicators,
            (Inst, *mut f64, usize),
            self.0,
            z.as_mut_ptr(),
            z.len()
        )
    }
    fn completed(&mut self) -> (i32, bool, bool) {
        let (mut enter, mut term) = (false, false);
        let st = call!(
            fmi3CompletedIntegratorStep,
            (Inst, bool, *mut bool, *mut bool),
            self.0,
            true,
            &mut enter,
            &mut term
        );
        (st, enter, term)
    }
    fn enter_event_mode(&mut self) -> i32 {
        call!(fmi3EnterEventMode, (Inst), self.0)
    }
    fn update(&mut self) -> (i32, bool, bool, Option<f64>) {
        let (mut more, mut term, mut nom, mut val, mut def, mut next) = (false, false, false, false, false, 0.0f64);
        let st = call!(
            fmi3UpdateDiscreteStates,
            (Inst, *mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64),
            self.0,
            &mut more,
            &mut term,
            &mut nom,
            &mut val,
            &mut def,
            &mut next
        );
        (st, more, term, def.then_some(next))
    }
    fn enter_continuous_mode(&mut self) -> i32 {
        call!(fmi3EnterContinuousTimeMode, (Inst), self.0)
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
    let Ok(mut cfg) = load(location, true) else {
        return std::ptr::null_mut();
    };
    let Some(f) = me!(fmi3InstantiateModelExchange, InstantiateMe) else {
        return std::ptr::null_mut();
    };
    let inner = f(name, token, location, visible, logging_on, env, log);
    if inner.is_null() {
        return std::ptr::null_mut();
    }
    let (mut nx, mut nz) = (0usize, 0usize);
    if call!(fmi3GetNumberOfContinuousStates, (Inst, *mut usize), inner, &mut nx) > 1
        || call!(fmi3GetNumberOfEventIndicators, (Inst, *mut usize), inner, &mut nz) > 1
    {
        if let Some(free) = me!(fmi3FreeInstance, unsafe extern "C" fn(Inst)) {
            free(inner);
        }
        return std::ptr::null_mut();
    }
    (cfg.states, cfg.event_indicators) = (nx, nz);
    let w = Instance {
        magic: MAGIC,
        inner,
        solver: Solver::new(cfg),
        start_time: 0.0,
        terminated: false,
    };
    Box::into_raw(Box::new(w)) as Inst
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
    if let Some(w) = instance(i) {
        if let Some(f) = me!(fmi3FreeInstance, unsafe extern "C" fn(Inst)) {
            f(w.inner);
        }
        w.magic = 0;
        drop(Box::from_raw(i as *mut Instance));
    }
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
    let Some(w) = instance(i) else { return ERROR };
    w.start_time = start;
    call!(
        fmi3EnterInitializationMode,
        (Inst, bool, f64, f64, bool, f64),
        w.inner,
        tol_defined,
        tol,
        start,
        stop_defined,
        stop
    )
}

/// Leaves initialization mode (the unit is then in event mode), runs the initial event iteration and
/// enters continuous-time mode; the wrapper is then in step mode.
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(i: Inst) -> i32 {
    let Some(w) = instance(i) else { return ERROR };
    let st = call!(fmi3ExitInitializationMode, (Inst), w.inner);
    if st > 1 {
        return st;
    }
    w.solver.t = w.start_time;
    match w.solver.event_iteration(&mut Me3(w.inner), true) {
        Ok(false) => st,
        Ok(true) => {
            w.terminated = true;
            ERROR
        }
        Err((s, _)) => s,
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(i: Inst) -> i32 {
    let Some(w) = instance(i) else { return ERROR };
    let cfg = w.solver.cfg.clone();
    w.solver = Solver::new(cfg);
    w.terminated = false;
    call!(fmi3Reset, (Inst), w.inner)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(i: Inst) -> i32 {
    if instance(i).is_some() {
        OK
    } else {
        ERROR
    }
}

/// Integrates the unit from t to t + h (inputs held): see the crate documentation.
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
    if w.terminated || h.is_nan() || h <= 0.0 || !t.is_finite() {
        return ERROR;
    }
    w.solver.t = t;
    let r = w.solver.advance(&mut Me3(w.inner), t + h);
    if !last.is_null() {
        *last = w.solver.t;
    }
    match r {
        Ok(false) => OK,
        Ok(true) => {
            w.terminated = true;
            if !terminate.is_null() {
                *terminate = true;
            }
            OK
        }
        Err((s, _)) => s.max(ERROR),
    }
}

macro_rules! forward {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(i: Inst $(, $arg: $ty)*) -> i32 {
            let Some(w) = instance(i) else { return ERROR };
            call!($name, (Inst $(, $ty)*), w.inner $(, $arg)*)
        }
    )* };
}

macro_rules! refuse {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(_i: Inst $(, $arg: $ty)*) -> i32 {
            $(let _ = $arg;)*
            ERROR
        }
    )* };
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
// derivatives, clocks' intervals and FMU states (the solver's state is not part of one): not offered.
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
