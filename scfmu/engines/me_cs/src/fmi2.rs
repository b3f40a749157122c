//! FMI 2.0 Co-Simulation functions over an FMI 2.0 Model Exchange unit: the exported C signatures over the
//! shared bodies of [`crate::face`]. What is FMI 2.0's own stays here: the unit's `fmi2…` functions
//! (`fmi2EventInfo`, `fmi2Boolean` as an int), the `fmuType` check and fmi2Discard for a unit that terminates.

use std::ffi::{c_char, c_void};

use crate::face::{self, call, forward, refuse, Face, Step};
use crate::{instance, me, DISCARD, ERROR, OK};

type Comp = *mut c_void;

struct Me2(Comp);

impl Face for Me2 {
    const V3: bool = false;
    fn of(inner: Comp) -> Self {
        Me2(inner)
    }
    fn free(&mut self) {
        if let Some(f) = me!(fmi2FreeInstance, unsafe extern "C" fn(Comp)) {
            unsafe { f(self.0) }
        }
    }
    fn exit_initialization_mode(&mut self) -> i32 {
        call!(fmi2ExitInitializationMode, (Comp), self.0)
    }
    fn reset(&mut self) -> i32 {
        call!(fmi2Reset, (Comp), self.0)
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
    face::instantiate::<Me2>(location, || match me!(fmi2Instantiate, Instantiate) {
        Some(f) => f(name, 0, guid, location, functions, visible, logging_on),
        None => std::ptr::null_mut(),
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: Comp) {
    face::free::<Me2>(c)
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
    face::setup(c, start, |inner| {
        call!(
            fmi2SetupExperiment,
            (Comp, i32, f64, f64, i32, f64),
            inner,
            tol_defined,
            tol,
            start,
            stop_defined,
            stop
        )
    })
}

/// Leaves initialization mode, runs the initial event iteration and enters continuous-time mode.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Comp) -> i32 {
    face::exit_initialization_mode::<Me2>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: Comp) -> i32 {
    face::reset::<Me2>(c)
}

/// Integrates the unit from t to t + h (inputs held): see the crate documentation. A unit that asks to
/// terminate ends the step with fmi2Discard.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(c: Comp, t: f64, h: f64, _no_set_prior: i32) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    match face::do_step(w, t, h) {
        Step::Refused => ERROR,
        Step::Reached => OK,
        Step::Terminated => DISCARD,
        Step::Failed(s) => s,
    }
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

// The stepper's state is not part of an FMU state, and the Co-Simulation extras are not offered.
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
