//! The Model Exchange functions of one unit, typed once per FMI version: the FMI 2.0 and FMI 3.0 tables
//! ([`Fmi2Me`], [`Fmi3Me`]), filled either from a library opened here ([`Table::load`], the Co-Simulation
//! face) or from function pointers a caller already looked up ([`Table::from_slots`], the compiled loop,
//! handed them by Python). [`MeUnit`] (an instance and its table) is the [`Unit`] the stepper drives.

use std::ffi::c_void;
use std::mem::transmute;

use crate::dynlib;
use crate::unit::{Unit, OK};

/// An instance of the unit (`fmi2Component` / `fmi3Instance`).
pub type Comp = *mut c_void;

type SetTime = unsafe extern "C" fn(Comp, f64) -> i32;
type VecIn = unsafe extern "C" fn(Comp, *const f64, usize) -> i32;
type VecOut = unsafe extern "C" fn(Comp, *mut f64, usize) -> i32;
type Plain = unsafe extern "C" fn(Comp) -> i32;
type Completed2 = unsafe extern "C" fn(Comp, i32, *mut i32, *mut i32) -> i32;
type Update2 = unsafe extern "C" fn(Comp, *mut EventInfo2) -> i32;
type Completed3 = unsafe extern "C" fn(Comp, bool, *mut bool, *mut bool) -> i32;
type Update3 = unsafe extern "C" fn(Comp, *mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64) -> i32;

/// `fmi2EventInfo`.
#[repr(C)]
#[derive(Default)]
pub struct EventInfo2 {
    pub new_discrete_states_needed: i32,
    pub terminate_simulation: i32,
    pub nominals_changed: i32,
    pub values_changed: i32,
    pub next_event_time_defined: i32,
    pub next_event_time: f64,
}

/// The order of the functions in [`Table::from_slots`] and [`Table::load`] (FMI 2.0 name, FMI 3.0 name).
pub const ME_FUNCTIONS: [(&str, &str); 9] = [
    ("fmi2SetTime", "fmi3SetTime"),
    ("fmi2SetContinuousStates", "fmi3SetContinuousStates"),
    ("fmi2GetContinuousStates", "fmi3GetContinuousStates"),
    ("fmi2GetDerivatives", "fmi3GetContinuousStateDerivatives"),
    ("fmi2GetEventIndicators", "fmi3GetEventIndicators"),
    ("fmi2CompletedIntegratorStep", "fmi3CompletedIntegratorStep"),
    ("fmi2EnterEventMode", "fmi3EnterEventMode"),
    ("fmi2NewDiscreteStates", "fmi3UpdateDiscreteStates"),
    ("fmi2EnterContinuousTimeMode", "fmi3EnterContinuousTimeMode"),
];

/// An FMI 2.0 unit's Model Exchange functions.
#[derive(Clone, Copy)]
pub struct Fmi2Me {
    pub set_time: SetTime,
    pub set_states: VecIn,
    pub get_states: VecOut,
    pub derivatives: VecOut,
    pub indicators: VecOut,
    pub completed: Completed2,
    pub enter_event_mode: Plain,
    pub new_discrete_states: Update2,
    pub enter_continuous_mode: Plain,
}

/// An FMI 3.0 unit's Model Exchange functions.
#[derive(Clone, Copy)]
pub struct Fmi3Me {
    pub set_time: SetTime,
    pub set_states: VecIn,
    pub get_states: VecOut,
    pub derivatives: VecOut,
    pub indicators: VecOut,
    pub completed: Completed3,
    pub enter_event_mode: Plain,
    pub update_discrete_states: Update3,
    pub enter_continuous_mode: Plain,
}

/// One unit's Model Exchange function table, of its FMI version.
#[derive(Clone, Copy)]
pub enum Table {
    V2(Fmi2Me),
    V3(Fmi3Me),
}

impl Table {
    /// The table from nine function pointers in the order of [`ME_FUNCTIONS`]; None when one is null.
    ///
    /// # Safety
    /// Each non-null pointer must be the function of its place, with the signature of version `v3`.
    pub unsafe fn from_slots(v3: bool, p: [*const c_void; 9]) -> Option<Table> {
        if p.iter().any(|f| f.is_null()) {
            return None;
        }
        Some(if v3 {
            Table::V3(Fmi3Me {
                set_time: transmute::<*const c_void, SetTime>(p[0]),
                set_states: transmute::<*const c_void, VecIn>(p[1]),
                get_states: transmute::<*const c_void, VecOut>(p[2]),
                derivatives: transmute::<*const c_void, VecOut>(p[3]),
                indicators: transmute::<*const c_void, VecOut>(p[4]),
                completed: transmute::<*const c_void, Completed3>(p[5]),
                enter_event_mode: transmute::<*const c_void, Plain>(p[6]),
                update_discrete_states: transmute::<*const c_void, Update3>(p[7]),
                enter_continuous_mode: transmute::<*const c_void, Plain>(p[8]),
            })
        } else {
            Table::V2(Fmi2Me {
                set_time: transmute::<*const c_void, SetTime>(p[0]),
                set_states: transmute::<*const c_void, VecIn>(p[1]),
                get_states: transmute::<*const c_void, VecOut>(p[2]),
                derivatives: transmute::<*const c_void, VecOut>(p[3]),
                indicators: transmute::<*const c_void, VecOut>(p[4]),
                completed: transmute::<*const c_void, Completed2>(p[5]),
                enter_event_mode: transmute::<*const c_void, Plain>(p[6]),
                new_discrete_states: transmute::<*const c_void, Update2>(p[7]),
                enter_continuous_mode: transmute::<*const c_void, Plain>(p[8]),
            })
        })
    }

    /// The table of the library `handle` (from [`dynlib::open`]) by the standard's names; the name of the
    /// first missing function as the error.
    ///
    /// # Safety
    /// `handle` is an open library whose functions of these names have the standard's signatures.
    pub unsafe fn load(handle: *mut c_void, v3: bool) -> Result<Table, String> {
        let mut p = [std::ptr::null(); 9];
        for (slot, (n2, n3)) in p.iter_mut().zip(ME_FUNCTIONS) {
            let name = if v3 { n3 } else { n2 };
            let f = dynlib::symbol(handle, format!("{name}\0").as_bytes());
            if f.is_null() {
                return Err(format!("the unit's library has no {name}"));
            }
            *slot = f as *const c_void;
        }
        Ok(Table::from_slots(v3, p).expect("every function present"))
    }
}

/// An instance of a Model Exchange unit with its function table: what the stepper calls.
#[derive(Clone, Copy)]
pub struct MeUnit {
    pub comp: Comp,
    pub table: Table,
}

// SAFETY (every method): `comp` is an instance of the library the table came from (the constructor's
// contract); the slices give the pointer and the length the functions read or write.
impl Unit for MeUnit {
    fn set_time(&mut self, t: f64) -> i32 {
        match self.table {
            Table::V2(f) => unsafe { (f.set_time)(self.comp, t) },
            Table::V3(f) => unsafe { (f.set_time)(self.comp, t) },
        }
    }
    fn set_states(&mut self, x: &[f64]) -> i32 {
        let f = match self.table {
            Table::V2(f) => f.set_states,
            Table::V3(f) => f.set_states,
        };
        unsafe { f(self.comp, x.as_ptr(), x.len()) }
    }
    fn get_states(&mut self, x: &mut [f64]) -> i32 {
        let f = match self.table {
            Table::V2(f) => f.get_states,
            Table::V3(f) => f.get_states,
        };
        unsafe { f(self.comp, x.as_mut_ptr(), x.len()) }
    }
    fn derivatives(&mut self, dx: &mut [f64]) -> i32 {
        let f = match self.table {
            Table::V2(f) => f.derivatives,
            Table::V3(f) => f.derivatives,
        };
        unsafe { f(self.comp, dx.as_mut_ptr(), dx.len()) }
    }
    fn indicators(&mut self, z: &mut [f64]) -> i32 {
        if z.is_empty() {
            return OK;
        }
        let f = match self.table {
            Table::V2(f) => f.indicators,
            Table::V3(f) => f.indicators,
        };
        unsafe { f(self.comp, z.as_mut_ptr(), z.len()) }
    }
    fn completed(&mut self) -> (i32, bool, bool) {
        match self.table {
            Table::V2(f) => {
                let (mut e, mut t) = (0i32, 0i32);
                let st = unsafe { (f.completed)(self.comp, 1, &mut e, &mut t) };
                (st, e != 0, t != 0)
            }
            Table::V3(f) => {
                let (mut e, mut t) = (false, false);
                let st = unsafe { (f.completed)(self.comp, true, &mut e, &mut t) };
                (st, e, t)
            }
        }
    }
    fn enter_event_mode(&mut self) -> i32 {
        match self.table {
            Table::V2(f) => unsafe { (f.enter_event_mode)(self.comp) },
            Table::V3(f) => unsafe { (f.enter_event_mode)(self.comp) },
        }
    }
    fn update(&mut self) -> (i32, bool, bool, Option<f64>) {
        match self.table {
            Table::V2(f) => {
                let mut e = EventInfo2::default();
                let st = unsafe { (f.new_discrete_states)(self.comp, &mut e) };
                let next = (e.next_event_time_defined != 0).then_some(e.next_event_time);
                (st, e.new_discrete_states_needed != 0, e.terminate_simulation != 0, next)
            }
            Table::V3(f) => {
                let (mut more, mut term, mut nom, mut val, mut def, mut next) =
                    (false, false, false, false, false, 0.0f64);
                let st = unsafe {
                    (f.update_discrete_states)(self.comp, &mut more, &mut term, &mut nom, &mut val, &mut def, &mut next)
                };
                (st, more, term, def.then_some(next))
            }
        }
    }
    fn enter_continuous_mode(&mut self) -> i32 {
        match self.table {
            Table::V2(f) => unsafe { (f.enter_continuous_mode)(self.comp) },
            Table::V3(f) => unsafe { (f.enter_continuous_mode)(self.comp) },
        }
    }
}
