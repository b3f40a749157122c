//! FMI 2.0 FMU state and directional derivatives, for Co-Simulation and Model Exchange instances alike:
//! each C function checks its pointers and runs the shared body (`state_calls`, `Instance`) inside
//! [`call`].
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::{c_char, c_int, c_void};

use super::common::{call, mask, Component};
use crate::fmi::boundary::{out_ptr, slice, slice_mut};
use crate::fmi::state_calls;

// ----- FMU state -----------------------------------------------------------------------------------

pub extern "C" fn fmi2GetFMUstate(c: Component, state: *mut *mut c_void) -> c_int {
    call(c, "fmi2GetFMUstate", mask::FMU_STATE, |inst| {
        state_calls::get(inst, out_ptr(state, "FMUstate")?, c as usize)
    })
}

pub extern "C" fn fmi2SetFMUstate(c: Component, state: *mut c_void) -> c_int {
    call(c, "fmi2SetFMUstate", mask::FMU_STATE, |inst| {
        state_calls::set(inst, state)
    })
}

pub extern "C" fn fmi2FreeFMUstate(c: Component, state: *mut *mut c_void) -> c_int {
    call(c, "fmi2FreeFMUstate", mask::FMU_STATE, |_inst| {
        state_calls::free(out_ptr(state, "FMUstate")?)
    })
}

pub extern "C" fn fmi2SerializedFMUstateSize(c: Component, state: *mut c_void, size: *mut usize) -> c_int {
    call(c, "fmi2SerializedFMUstateSize", mask::FMU_STATE, |inst| {
        state_calls::serialized_size(inst, state, out_ptr(size, "size")?)
    })
}

pub extern "C" fn fmi2SerializeFMUstate(c: Component, state: *mut c_void, buffer: *mut c_char, size: usize) -> c_int {
    call(c, "fmi2SerializeFMUstate", mask::FMU_STATE, |inst| {
        state_calls::serialize(inst, state, size, "fmi2SerializedFMUstateSize", || unsafe {
            slice_mut(buffer as *mut u8, size, "serializedState[]")
        })
    })
}

pub extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    buffer: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> c_int {
    call(c, "fmi2DeSerializeFMUstate", mask::FMU_STATE, |inst| {
        let slot = out_ptr(state, "FMUstate")?;
        let bytes = unsafe { slice(buffer as *const u8, size, "serializedState[]")? };
        state_calls::deserialize(inst, bytes, slot, c as usize)
    })
}

// ----- derivatives ---------------------------------------------------------------------------------

pub extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    v_unknown: *const u32,
    n_unknown: usize,
    v_known: *const u32,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> c_int {
    call(
        c,
        "fmi2GetDirectionalDerivative",
        mask::DIRECTIONAL_DERIVATIVE,
        |inst| {
            let unknowns = unsafe { slice(v_unknown, n_unknown, "vUnknown_ref[]")? };
            let knowns = unsafe { slice(v_known, n_known, "vKnown_ref[]")? };
            let seed = unsafe { slice(dv_known, n_known, "dvKnown[]")? };
            let out = unsafe { slice_mut(dv_unknown, n_unknown, "dvUnknown[]")? };
            let d = inst.directional_derivative(unknowns, knowns, seed)?;
            out.copy_from_slice(&d);
            Ok(())
        },
    )
}
