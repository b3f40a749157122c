//! The value functions (Real / Float64, Integer / Int32, Boolean getters and setters) and `doStep` of one
//! unit, typed once per FMI version: what a master calls besides the Model Exchange functions of
//! [`crate::fmi`]. Filled from function pointers the caller looked up ([`Values::from_slots`]); a function
//! the caller did not give is absent, and calling it returns Error (3).

use std::ffi::c_void;

use crate::fmi::Comp;
use crate::unit::ERROR;

type Get2<T> = unsafe extern "C" fn(Comp, *const u32, usize, *mut T) -> i32;
type Set2<T> = unsafe extern "C" fn(Comp, *const u32, usize, *const T) -> i32;
type Get3<T> = unsafe extern "C" fn(Comp, *const u32, usize, *mut T, usize) -> i32;
type Set3<T> = unsafe extern "C" fn(Comp, *const u32, usize, *const T, usize) -> i32;
type DoStep2 = unsafe extern "C" fn(Comp, f64, f64, i32) -> i32;
type DoStep3 = unsafe extern "C" fn(Comp, f64, f64, bool, *mut bool, *mut bool, *mut bool, *mut f64) -> i32;

/// The order of the functions in [`Values::from_slots`] (FMI 2.0 name, FMI 3.0 name).
pub const VALUE_FUNCTIONS: [(&str, &str); 7] = [
    ("fmi2GetReal", "fmi3GetFloat64"),
    ("fmi2SetReal", "fmi3SetFloat64"),
    ("fmi2GetInteger", "fmi3GetInt32"),
    ("fmi2SetInteger", "fmi3SetInt32"),
    ("fmi2GetBoolean", "fmi3GetBoolean"),
    ("fmi2SetBoolean", "fmi3SetBoolean"),
    ("fmi2DoStep", "fmi3DoStep"),
];

#[derive(Clone, Copy)]
enum Table {
    V2 {
        get_real: Option<Get2<f64>>,
        set_real: Option<Set2<f64>>,
        get_int: Option<Get2<i32>>,
        set_int: Option<Set2<i32>>,
        get_bool: Option<Get2<i32>>, // fmi2Boolean is an int
        set_bool: Option<Set2<i32>>,
        do_step: Option<DoStep2>,
    },
    V3 {
        get_real: Option<Get3<f64>>,
        set_real: Option<Set3<f64>>,
        get_int: Option<Get3<i32>>,
        set_int: Option<Set3<i32>>,
        get_bool: Option<Get3<bool>>,
        set_bool: Option<Set3<bool>>,
        do_step: Option<DoStep3>,
    },
}

/// An instance with its value functions and `doStep`.
pub struct Values {
    pub comp: Comp,
    table: Table,
    scratch: Vec<bool>,
}

/// `p` as the function type `F`, None when null.
///
/// # Safety
/// A non-null `p` is a function of type `F`.
unsafe fn typed<F: Copy>(p: *const c_void) -> Option<F> {
    (!p.is_null()).then(|| std::mem::transmute_copy::<*const c_void, F>(&p))
}

impl Values {
    /// The table from seven function pointers in the order of [`VALUE_FUNCTIONS`] (null: not given).
    ///
    /// # Safety
    /// Each non-null pointer is the function of its place, with the signature of version `v3`, and `comp`
    /// an instance of that library.
    pub unsafe fn from_slots(comp: Comp, v3: bool, p: [*const c_void; 7]) -> Values {
        let table = if v3 {
            Table::V3 {
                get_real: typed(p[0]),
                set_real: typed(p[1]),
                get_int: typed(p[2]),
                set_int: typed(p[3]),
                get_bool: typed(p[4]),
                set_bool: typed(p[5]),
                do_step: typed(p[6]),
            }
        } else {
            Table::V2 {
                get_real: typed(p[0]),
                set_real: typed(p[1]),
                get_int: typed(p[2]),
                set_int: typed(p[3]),
                get_bool: typed(p[4]),
                set_bool: typed(p[5]),
                do_step: typed(p[6]),
            }
        };
        Values {
            comp,
            table,
            scratch: Vec::new(),
        }
    }

    /// Gets (or, with `set`, sets) `n` Real / Float64 values of the references `vr` from (into) `buf`.
    ///
    /// # Safety
    /// `vr` and `buf` point to `n` elements each.
    pub unsafe fn reals(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut f64) -> i32 {
        match (self.table, set) {
            (Table::V2 { get_real: Some(f), .. }, false) => f(self.comp, vr, n, buf),
            (Table::V2 { set_real: Some(f), .. }, true) => f(self.comp, vr, n, buf),
            (Table::V3 { get_real: Some(f), .. }, false) => f(self.comp, vr, n, buf, n),
            (Table::V3 { set_real: Some(f), .. }, true) => f(self.comp, vr, n, buf, n),
            _ => ERROR,
        }
    }

    /// Integer / Int32 values, as [`Values::reals`].
    ///
    /// # Safety
    /// `vr` and `buf` point to `n` elements each.
    pub unsafe fn ints(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut i32) -> i32 {
        match (self.table, set) {
            (Table::V2 { get_int: Some(f), .. }, false) => f(self.comp, vr, n, buf),
            (Table::V2 { set_int: Some(f), .. }, true) => f(self.comp, vr, n, buf),
            (Table::V3 { get_int: Some(f), .. }, false) => f(self.comp, vr, n, buf, n),
            (Table::V3 { set_int: Some(f), .. }, true) => f(self.comp, vr, n, buf, n),
            _ => ERROR,
        }
    }

    /// Boolean values as ints 0/1 in `buf` (FMI 3.0's one-byte `fmi3Boolean` converted at the call).
    ///
    /// # Safety
    /// `vr` and `buf` point to `n` elements each.
    pub unsafe fn bools(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut i32) -> i32 {
        let (get3, set3) = match (self.table, set) {
            (Table::V2 { get_bool: Some(f), .. }, false) => return f(self.comp, vr, n, buf),
            (Table::V2 { set_bool: Some(f), .. }, true) => return f(self.comp, vr, n, buf),
            (Table::V3 { get_bool, set_bool, .. }, _) => (get_bool, set_bool),
            _ => return ERROR,
        };
        self.scratch.resize(n, false);
        let vals = std::slice::from_raw_parts_mut(buf, n);
        if set {
            let Some(f) = set3 else { return ERROR };
            for (s, v) in self.scratch.iter_mut().zip(vals.iter()) {
                *s = *v != 0;
            }
            f(self.comp, vr, n, self.scratch.as_ptr(), n)
        } else {
            let Some(f) = get3 else { return ERROR };
            let st = f(self.comp, vr, n, self.scratch.as_mut_ptr(), n);
            for (v, s) in vals.iter_mut().zip(self.scratch.iter()) {
                *v = *s as i32;
            }
            st
        }
    }

    /// `doStep(t, h)` (no set of prior state): (status, the unit asked to terminate: FMI 3.0's flag).
    pub fn do_step(&mut self, t: f64, h: f64) -> (i32, bool) {
        match self.table {
            // SAFETY: the constructor's contract
            Table::V2 { do_step: Some(f), .. } => (unsafe { f(self.comp, t, h, 1) }, false),
            Table::V3 { do_step: Some(f), .. } => {
                let (mut ev, mut term, mut early, mut last) = (false, false, false, 0.0f64);
                let st = unsafe { f(self.comp, t, h, true, &mut ev, &mut term, &mut early, &mut last) };
                (st, term)
            }
            _ => (ERROR, false),
        }
    }
}
