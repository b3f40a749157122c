//! FMI 2.0 Co-Simulation functions over an FMI 2.0 Model Exchange unit.

use std::ffi::{c_char, c_void};

use crate::{instance, load, me, Instance, Solver, Unit, DISCARD, ERROR, MAGIC, OK};

type Comp = *mut c_void;

#[repr(C)]
#[derive(Default)]
struct EventInfo {
    new_discrete_states_needed: i32,
    terminate_simulation: i32,
    nominals_changed: i32,
    values_changed: i32,
    next_event_time_defined: i32,
    next_event_time: f64,
}

struct Me2(Comp);

macro_rules! call {
    ($name:ident, ($($ty:ty),*), $($arg:expr),*) => {
        match me!($name, unsafe extern "C" fn($($ty),*) -> i32) {
            Some(f) => unsafe { f($($arg),*) },
            None => ERROR,
        }
    };
}

impl Unit for Me2 {
    fn set_time(&mut self, t: f64) -> i32 {
        call!(fmi2SetTime, (Comp, f64), self.0, t)
    }
    fn set_states(&mut self, x: &[f64]) -> i32 {
        call!(
            fmi2SetContinuousStates,
            (Comp, *const f64, usize),
            self.0,
            x.as_ptr(),
            x.len()
        )
    }
    fn get_states(&mut self, x: &mut [f64]) -> i32 {
        call!(
            fmi2GetContinuousStates,
            (Comp, *mut f64, usize),
            self.0,
            x.as_mut_ptr(),
            x.len()
        )
    }
    fn derivatives(&mut self, dx: &mut [f64]) -> i32 {
        call!(
            fmi2GetDerivatives,
            (Comp, *mut f64, usize),
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
            fmi2GetEventIndicators,
            (Comp, *mut f64, usize),
            self.0,
            z.as_mut_ptr(),
            z.len()
        )
    }
    fn completed(&mut self) -> (i32, bool, bool) {
        let (mut enter, mut term) = (0i32, 0i32);
        let st = call!(
            fmi2CompletedIntegratorStep,
            (Comp, i32, *mut i32, *mut i32),
            self.0,
            1,
            &mut enter,
            &mut term
        );
        (st, enter != 0, term != 0)
    }
    fn enter_event_mode(&mut self) -> i32 {
        call!(fmi2EnterEventMode, (Comp), self.0)
    }
    fn update(&mut self) -> (i32, bool, bool, Option<f64>) {
        let mut e = EventInfo::default();
        let st = call!(fmi2NewDiscreteStates, (Comp, *mut EventInfo), self.0, &mut e);
        let next = (e.next_event_time_defined != 0).then_some(e.next_event_time);
        (st, e.new_discrete_states_needed != 0, e.terminate_simulation != 0, next)
    }
    fn enter_continuous_mode(&mut self) -> i32 {
        call!(fmi2EnterContinuousTimeMode, (Comp), self.0)
    }
}

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

type Instantiate =
    unsafe extern "C" fn(*const c_char, i32, *const c_char, *const c_char, *const c_void, i32, i32) -> Comp;

/// `fmuType` must be fmi2CoSimulation (1); the unit is instantiated as fmi2ModelExchange (0).
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    name: *const c_char,
    fmu_type: i32,
    guid: *const c_char,
    location: *const c_char,
    functions: *const c_void,
    visible: i32,
    logging_on: i32,
) -> Comp {
    if fmu_type != 1 {
        return std::ptr::null_mut();
    }
    let Ok(cfg) = load(location, false) else {
        return std::ptr::null_mut();
    };
    let Some(f) = me!(fmi2Instantiate, Instantiate) else {
        return std::ptr::null_mut();
    };
    let inner = f(name, 0, guid, location, functions, visible, logging_on);
    if inner.is_null() {
        return std::ptr::null_mut();
    }
    let w = Instance {
        magic: MAGIC,
        inner,
        solver: Solver::new(cfg),
        start_time: 0.0,
        terminated: false,
    };
    Box::into_raw(Box::new(w)) as Comp
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: Comp) {
    if let Some(w) = instance(c) {
        if let Some(f) = me!(fmi2FreeInstance, unsafe extern "C" fn(Comp)) {
            f(w.inner);
        }
        w.magic = 0;
        drop(Box::from_raw(c as *mut Instance));
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Comp,
    tol_defined: i32,
    tol: f64,
    start: f64,
    stop_defined: i32,
    stop: f64,
) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    w.start_time = start;
    call!(
        fmi2SetupExperiment,
        (Comp, i32, f64, f64, i32, f64),
        w.inner,
        tol_defined,
        tol,
        start,
        stop_defined,
        stop
    )
}

/// Leaves initialization mode, runs the initial event iteration and enters continuous-time mode.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Comp) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    let st = call!(fmi2ExitInitializationMode, (Comp), w.inner);
    if st > 1 {
        return st;
    }
    w.solver.t = w.start_time;
    match w.solver.event_iteration(&mut Me2(w.inner), true) {
        Ok(false) => st,
        Ok(true) => {
            w.terminated = true;
            ERROR
        }
        Err((s, _)) => s,
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: Comp) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    let cfg = w.solver.cfg.clone();
    w.solver = Solver::new(cfg);
    w.terminated = false;
    call!(fmi2Reset, (Comp), w.inner)
}

/// Integrates the unit from t to t + h (inputs held): see the crate documentation.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(c: Comp, t: f64, h: f64, _no_set_prior: i32) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    if w.terminated || h.is_nan() || h <= 0.0 || !t.is_finite() {
        return ERROR;
    }
    w.solver.t = t;
    match w.solver.advance(&mut Me2(w.inner), t + h) {
        Ok(false) => OK,
        Ok(true) => {
            w.terminated = true;
            DISCARD
        }
        Err((s, _)) => s.max(ERROR),
    }
}

macro_rules! forward {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: Comp $(, $arg: $ty)*) -> i32 {
            let Some(w) = instance(c) else { return ERROR };
            call!($name, (Comp $(, $ty)*), w.inner $(, $arg)*)
        }
    )* };
}

macro_rules! refuse {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(_c: Comp $(, $arg: $ty)*) -> i32 {
            $(let _ = $arg;)*
            ERROR
        }
    )* };
}

forward! {
    fmi2SetDebugLogging(on: i32, n: usize, categories: *const *const c_char);
    fmi2EnterInitializationMode();
    fmi2Terminate();
    fmi2GetReal(vr: *const u32, n: usize, v: *mut f64);
    fmi2GetInteger(vr: *const u32, n: usize, v: *mut i32);
    fmi2GetBoolean(vr: *const u32, n: usize, v: *mut i32);
    fmi2GetString(vr: *const u32, n: usize, v: *mut *const c_char);
    fmi2SetReal(vr: *const u32, n: usize, v: *const f64);
    fmi2SetInteger(vr: *const u32, n: usize, v: *const i32);
    fmi2SetBoolean(vr: *const u32, n: usize, v: *const i32);
    fmi2SetString(vr: *const u32, n: usize, v: *const *const c_char);
    fmi2GetDirectionalDerivative(u: *const u32, nu: usize, k: *const u32, nk: usize, dv: *const f64, df: *mut f64);
}

// The solver's state is not part of an FMU state, and the Co-Simulation extras are not offered.
refuse! {
    fmi2GetFMUstate(s: *mut *mut c_void);
    fmi2SetFMUstate(s: *mut c_void);
    fmi2FreeFMUstate(s: *mut *mut c_void);
    fmi2SerializedFMUstateSize(s: *mut c_void, size: *mut usize);
    fmi2SerializeFMUstate(s: *mut c_void, out: *mut c_char, size: usize);
    fmi2DeSerializeFMUstate(data: *const c_char, size: usize, s: *mut *mut c_void);
    fmi2SetRealInputDerivatives(vr: *const u32, n: usize, order: *const i32, v: *const f64);
    fmi2GetRealOutputDerivatives(vr: *const u32, n: usize, order: *const i32, v: *mut f64);
    fmi2CancelStep();
    fmi2GetStatus(kind: i32, v: *mut i32);
    fmi2GetRealStatus(kind: i32, v: *mut f64);
    fmi2GetIntegerStatus(kind: i32, v: *mut i32);
    fmi2GetBooleanStatus(kind: i32, v: *mut i32);
    fmi2GetStringStatus(kind: i32, v: *mut *const c_char);
}
