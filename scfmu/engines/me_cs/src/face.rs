//! The version-neutral bodies of the Co-Simulation entry points. [`crate::fmi2`] and [`crate::fmi3`] are
//! thin C-ABI wrappers: each exports its version's symbols, translates that version's types and arguments
//! (statuses, `fmi2Boolean`/`bool`, the output flags of `fmi3DoStep`) and calls the functions here, which
//! hold the instance handling, the stepper and the rules every version shares. What a body needs from the
//! version's Model Exchange unit beyond its function table (the stepper's [`MeUnit`]) is the trait [`Face`].
//!
//! The macros [`call`], [`forward`] and [`refuse`] write the pass-through and the refused functions of
//! both versions.

use std::ffi::{c_char, c_void};

use scfmu_fmi_stepper::{MeUnit, Stepper, Stop};

use crate::{instance, load, table, Config, Instance, ERROR, MAGIC};

/// One FMI version's Model Exchange unit as the shared entry points use it.
pub trait Face: Sized {
    /// The FMI 3.0 binary folder names ([`load`]).
    const V3: bool;
    /// The unit's instance `inner` (a pointer its own library handed out).
    fn of(inner: *mut c_void) -> Self;
    /// The unit's `FreeInstance` (nothing when its library lacks it).
    fn free(&mut self);
    /// The unit's `ExitInitializationMode`.
    fn exit_initialization_mode(&mut self) -> i32;
    /// The unit's `Reset`.
    fn reset(&mut self) -> i32;
    /// Sets the numbers of states and event indicators from the unit where the version can ask it
    /// (FMI 3.0); false when the unit could not tell. FMI 2.0 keeps the settings' numbers.
    fn sizes(&mut self, _cfg: &mut Config) -> bool {
        true
    }
}

/// Reads the settings at `location`, instantiates the unit with `create` (null: refused) and wraps it;
/// null when any of these fails.
///
/// # Safety
/// `location` is null or a NUL-terminated string.
pub unsafe fn instantiate<U: Face>(location: *const c_char, create: impl FnOnce() -> *mut c_void) -> *mut c_void {
    let Ok(mut cfg) = load(location, U::V3) else {
        return std::ptr::null_mut();
    };
    let Ok(table) = table(U::V3) else {
        return std::ptr::null_mut();
    };
    let inner = create();
    if inner.is_null() {
        return std::ptr::null_mut();
    }
    let mut unit = U::of(inner);
    if !unit.sizes(&mut cfg) {
        unit.free();
        return std::ptr::null_mut();
    }
    let w = Instance {
        magic: MAGIC,
        inner,
        unit: MeUnit { comp: inner, table },
        stepper: stepper(&cfg),
        cfg,
        start_time: 0.0,
        terminated: false,
    };
    Box::into_raw(Box::new(w)) as *mut c_void
}

/// A fresh stepper for the settings `cfg` (the initial event iteration gives the next time event).
fn stepper(cfg: &Config) -> Stepper {
    Stepper::new(cfg.states, cfg.event_indicators, cfg.settings(), None)
}

/// Frees the unit and the wrapper instance `c` (nothing for a pointer this library did not hand out).
///
/// # Safety
/// `c` is null or a pointer handed out by [`instantiate`] and not freed yet.
pub unsafe fn free<U: Face>(c: *mut c_void) {
    if let Some(w) = instance(c) {
        U::of(w.inner).free();
        w.magic = 0;
        drop(Box::from_raw(c as *mut Instance));
    }
}

/// `f` on the unit's instance behind `c`; ERROR when `c` is not an instance of this library.
///
/// # Safety
/// `c` is null or a pointer handed out by [`instantiate`].
pub unsafe fn with_unit(c: *mut c_void, f: impl FnOnce(*mut c_void) -> i32) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    f(w.inner)
}

/// Records the experiment's start time (where the stepper starts) and passes the call on with `f`.
///
/// # Safety
/// `c` is null or a pointer handed out by [`instantiate`].
pub unsafe fn setup(c: *mut c_void, start: f64, f: impl FnOnce(*mut c_void) -> i32) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    w.start_time = start;
    f(w.inner)
}

/// Leaves the unit's initialization mode, runs the initial event iteration and enters continuous-time mode.
///
/// # Safety
/// `c` is null or a pointer handed out by [`instantiate`].
pub unsafe fn exit_initialization_mode<U: Face>(c: *mut c_void) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    let mut unit = U::of(w.inner);
    let st = unit.exit_initialization_mode();
    if st > 1 {
        return st;
    }
    w.stepper.t = w.start_time;
    match w.stepper.event_iteration(&mut w.unit, true) {
        Ok(_) => st,
        Err(Stop::Terminate) => {
            w.terminated = true;
            ERROR
        }
        Err(Stop::Failed(s)) => s,
        Err(Stop::Solver) => ERROR,
    }
}

/// A fresh stepper (same settings) and the unit's `Reset`.
///
/// # Safety
/// `c` is null or a pointer handed out by [`instantiate`].
pub unsafe fn reset<U: Face>(c: *mut c_void) -> i32 {
    let Some(w) = instance(c) else { return ERROR };
    w.stepper = stepper(&w.cfg);
    w.terminated = false;
    U::of(w.inner).reset()
}

/// How a communication step ended; each version turns it into its status and output flags.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// Not integrated: the unit terminated before, or `t`/`h` is not a step (ERROR).
    Refused,
    /// Integrated to t + h.
    Reached,
    /// Integrated until the unit asked to terminate (at the stepper's time).
    Terminated,
    /// The unit failed: the status to return (ERROR or worse).
    Failed(i32),
}

/// Integrates the unit of `w` from `t` to `t + h` with its inputs held (see the crate documentation); the
/// time reached is then `w.stepper.t` (unless refused).
pub fn do_step(w: &mut Instance, t: f64, h: f64) -> Step {
    if w.terminated || h.is_nan() || h <= 0.0 || !t.is_finite() {
        return Step::Refused;
    }
    match w.stepper.step(&mut w.unit, t, t + h) {
        Ok(_) => Step::Reached,
        Err(Stop::Terminate) => {
            w.terminated = true;
            Step::Terminated
        }
        Err(Stop::Failed(s)) => Step::Failed(s.max(ERROR)),
        Err(Stop::Solver) => Step::Failed(ERROR),
    }
}

/// `call!(fmi2SetTime, (*mut c_void, f64), inner, t)`: the unit's function called, or ERROR when its
/// library lacks it.
macro_rules! call {
    ($name:ident, ($($ty:ty),*), $($arg:expr),*) => {
        match $crate::me!($name, unsafe extern "C" fn($($ty),*) -> i32) {
            Some(f) => unsafe { f($($arg),*) },
            None => $crate::ERROR,
        }
    };
}

/// Exported functions passed on unchanged to the unit's function of the same name (ERROR for a pointer
/// this library did not hand out).
macro_rules! forward {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut std::ffi::c_void $(, $arg: $ty)*) -> i32 {
            $crate::face::with_unit(c, |inner| {
                $crate::face::call!($name, (*mut std::ffi::c_void $(, $ty)*), inner $(, $arg)*)
            })
        }
    )* };
}

/// Exported functions this face does not offer: ERROR.
macro_rules! refuse {
    ($($name:ident ( $($arg:ident : $ty:ty),* );)*) => { $(
        #[no_mangle]
        pub unsafe extern "C" fn $name(_c: *mut std::ffi::c_void $(, $arg: $ty)*) -> i32 {
            $(let _ = $arg;)*
            $crate::ERROR
        }
    )* };
}

pub(crate) use {call, forward, refuse};
