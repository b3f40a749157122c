//! The FMI 2.0 Co-Simulation C functions, second half: FMU state, derivatives, stepping and status
//! queries (the first half, with the shared helpers, is `abi.rs`, which re-exports these).
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::{c_char, c_int, c_void};

use super::abi::{call, out_ptr, slice, slice_mut, Component};
use super::instance::{CallResult, Fail, Instance};
use super::state_calls;
use super::{mask, status_kind, FsmState};

// ----- FMU state -----------------------------------------------------------------------------------

pub extern "C" fn fmi2GetFMUstate(c: Component, state: *mut *mut c_void) -> c_int {
    call(c, "fmi2GetFMUstate", mask::FMU_STATE, |inst| state_calls::get(inst, out_ptr(state, "FMUstate")?, c as usize))
}

pub extern "C" fn fmi2SetFMUstate(c: Component, state: *mut c_void) -> c_int {
    call(c, "fmi2SetFMUstate", mask::FMU_STATE, |inst| state_calls::set(inst, state))
}

pub extern "C" fn fmi2FreeFMUstate(c: Component, state: *mut *mut c_void) -> c_int {
    call(c, "fmi2FreeFMUstate", mask::FMU_STATE, |_inst| state_calls::free(out_ptr(state, "FMUstate")?))
}

pub extern "C" fn fmi2SerializedFMUstateSize(c: Component, state: *mut c_void, size: *mut usize) -> c_int {
    call(c, "fmi2SerializedFMUstateSize", mask::FMU_STATE, |inst| state_calls::serialized_size(inst, state, out_ptr(size, "size")?))
}

pub extern "C" fn fmi2SerializeFMUstate(c: Component, state: *mut c_void, buffer: *mut c_char, size: usize) -> c_int {
    call(c, "fmi2SerializeFMUstate", mask::FMU_STATE, |inst| {
        state_calls::serialize(inst, state, size, "fmi2SerializedFMUstateSize", || unsafe { slice_mut(buffer as *mut u8, size, "serializedState[]") })
    })
}

pub extern "C" fn fmi2DeSerializeFMUstate(c: Component, buffer: *const c_char, size: usize, state: *mut *mut c_void) -> c_int {
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
    call(c, "fmi2GetDirectionalDerivative", mask::DIRECTIONAL_DERIVATIVE, |inst| {
        let unknowns = unsafe { slice(v_unknown, n_unknown, "vUnknown_ref[]")? };
        let knowns = unsafe { slice(v_known, n_known, "vKnown_ref[]")? };
        let seed = unsafe { slice(dv_known, n_known, "dvKnown[]")? };
        let out = unsafe { slice_mut(dv_unknown, n_unknown, "dvUnknown[]")? };
        let d = inst.directional_derivative(unknowns, knowns, seed)?;
        out.copy_from_slice(&d);
        Ok(())
    })
}

pub extern "C" fn fmi2SetRealInputDerivatives(c: Component, _vr: *const u32, _n: usize, _order: *const c_int, _value: *const f64) -> c_int {
    call(c, "fmi2SetRealInputDerivatives", mask::SET_INPUT_DERIVATIVES, |_| {
        Err(Fail::error("not supported: canInterpolateInputs = false, inputs are held constant over a step"))
    })
}

pub extern "C" fn fmi2GetRealOutputDerivatives(c: Component, _vr: *const u32, _n: usize, _order: *const c_int, _value: *mut f64) -> c_int {
    call(c, "fmi2GetRealOutputDerivatives", mask::GET_OUTPUT_DERIVATIVES, |_| {
        Err(Fail::error("not supported: maxOutputDerivativeOrder = 0"))
    })
}

// ----- stepping ------------------------------------------------------------------------------------

pub extern "C" fn fmi2DoStep(c: Component, t: f64, h: f64, _no_set_prior: c_int) -> c_int {
    call(c, "fmi2DoStep", mask::DO_STEP, |inst| {
        inst.trace(|| format!("fmi2DoStep(currentCommunicationPoint={t}, communicationStepSize={h})"));
        inst.do_step(t, h)
    })
}

pub extern "C" fn fmi2CancelStep(c: Component) -> c_int {
    // Never allowed: fmi2DoStep is synchronous and never returns fmi2Pending.
    call(c, "fmi2CancelStep", mask::CANCEL_STEP, |_| Ok(()))
}

fn status_query(c: Component, func: &str, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    call(c, func, mask::GET_STATUS, f)
}

pub extern "C" fn fmi2GetStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    status_query(c, "fmi2GetStatus", |_| {
        out_ptr(value, "value")?;
        Err(Fail::discard(format!("status kind {kind} is not available: no asynchronous step is ever pending")))
    })
}

pub extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> c_int {
    status_query(c, "fmi2GetRealStatus", |inst| {
        let out = out_ptr(value, "value")?;
        if kind == status_kind::LAST_SUCCESSFUL_TIME {
            *out = inst.run.time;
            Ok(())
        } else {
            Err(Fail::discard(format!("status kind {kind} has no Real value (only fmi2LastSuccessfulTime)")))
        }
    })
}

pub extern "C" fn fmi2GetIntegerStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    status_query(c, "fmi2GetIntegerStatus", |_| {
        out_ptr(value, "value")?;
        Err(Fail::discard(format!("status kind {kind} has no Integer value")))
    })
}

pub extern "C" fn fmi2GetBooleanStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    status_query(c, "fmi2GetBooleanStatus", |inst| {
        let out = out_ptr(value, "value")?;
        if kind == status_kind::TERMINATED {
            *out = (inst.run.fsm == FsmState::Terminated) as c_int;
            Ok(())
        } else {
            Err(Fail::discard(format!("status kind {kind} has no Boolean value (only fmi2Terminated)")))
        }
    })
}

pub extern "C" fn fmi2GetStringStatus(c: Component, kind: c_int, value: *mut *const c_char) -> c_int {
    status_query(c, "fmi2GetStringStatus", |_| {
        out_ptr(value, "value")?;
        Err(Fail::discard(format!("status kind {kind} is not available: no asynchronous step is ever pending")))
    })
}

