//! FMI 2.0 Co-Simulation only: stepping, the status queries and the input/output derivatives this
//! FMU does not interpolate.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::{c_char, c_int};

use super::common::{call, mask, status_kind, Component};
use crate::fmi::boundary::out_ptr;
use crate::fmi::instance::{CallResult, Fail, Instance};
use crate::fmi::types::FsmState;

pub extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *const f64,
) -> c_int {
    call(c, "fmi2SetRealInputDerivatives", mask::SET_INPUT_DERIVATIVES, |_| {
        Err(Fail::error(
            "not supported: canInterpolateInputs = false, inputs are held constant over a step",
        ))
    })
}

pub extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> c_int {
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
        Err(Fail::discard(format!(
            "status kind {kind} is not available: no asynchronous step is ever pending"
        )))
    })
}

pub extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> c_int {
    status_query(c, "fmi2GetRealStatus", |inst| {
        let out = out_ptr(value, "value")?;
        if kind == status_kind::LAST_SUCCESSFUL_TIME {
            *out = inst.run.time;
            Ok(())
        } else {
            Err(Fail::discard(format!(
                "status kind {kind} has no Real value (only fmi2LastSuccessfulTime)"
            )))
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
            Err(Fail::discard(format!(
                "status kind {kind} has no Boolean value (only fmi2Terminated)"
            )))
        }
    })
}

pub extern "C" fn fmi2GetStringStatus(c: Component, kind: c_int, value: *mut *const c_char) -> c_int {
    status_query(c, "fmi2GetStringStatus", |_| {
        out_ptr(value, "value")?;
        Err(Fail::discard(format!(
            "status kind {kind} is not available: no asynchronous step is ever pending"
        )))
    })
}
