//! The FMI 2.0 Model Exchange C functions (chapter 3), on the same instances, checks and logging as
//! the Co-Simulation ones (`common.rs`). Each one refuses a Co-Simulation instance with a message.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::c_int;

use super::common::{call, mask, Component};
use crate::fmi::boundary::{out_ptr, slice, slice_mut};
use crate::fmi::instance::{CallResult, Fail, Instance, Reason};
use crate::fmi::types::FsmState;

/// `fmi2GetDerivatives` (FMI 2.0 ME state table): event, continuous-time, terminated and error state,
/// not initialization mode (the Reference FMUs use the same masks).
const GET_DERIVATIVES: u16 = mask::GET_ME_VALUES & !FsmState::InitializationMode.bit();
/// `fmi2GetNominalsOfContinuousStates`: also in the instantiated state (before the parameters are
/// set, for the solver's setup), not in initialization mode.
const GET_NOMINALS: u16 = (mask::GET_ME_VALUES | FsmState::Instantiated.bit()) & !FsmState::InitializationMode.bit();

/// `fmi2EventInfo`.
#[repr(C)]
pub struct EventInfo2 {
    pub new_discrete_states_needed: c_int,
    pub terminate_simulation: c_int,
    pub nominals_of_continuous_states_changed: c_int,
    pub values_of_continuous_states_changed: c_int,
    pub next_event_time_defined: c_int,
    pub next_event_time: f64,
}

/// `call` for a Model Exchange function: a Co-Simulation instance is refused as such (before the
/// state check, whose message would not say why).
#[inline(always)]
fn me_call(c: Component, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    call(c, func, mask::SET_DEBUG_LOGGING, |inst| {
        if !inst.model_exchange {
            return Err(Fail::error("this instance was instantiated for Co-Simulation (fmuType fmi2CoSimulation); Model Exchange functions are not available"));
        }
        if allowed & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(Reason::IllegalCall(inst.run.fsm)));
        }
        f(inst)
    })
}

pub extern "C" fn fmi2EnterEventMode(c: Component) -> c_int {
    me_call(c, "fmi2EnterEventMode", mask::ENTER_EVENT_MODE, |inst| {
        inst.enter_event_mode()
    })
}

pub extern "C" fn fmi2NewDiscreteStates(c: Component, info: *mut EventInfo2) -> c_int {
    me_call(c, "fmi2NewDiscreteStates", mask::NEW_DISCRETE_STATES, |inst| {
        let out = out_ptr(info, "fmi2EventInfo")?;
        let e = inst.new_discrete_states()?;
        inst.trace(|| format!("fmi2NewDiscreteStates at t = {}: {e:?}", inst.run.time));
        *out = EventInfo2 {
            new_discrete_states_needed: e.new_discrete_states_needed as c_int,
            terminate_simulation: e.terminate_simulation as c_int,
            nominals_of_continuous_states_changed: e.nominals_changed as c_int,
            values_of_continuous_states_changed: e.values_changed as c_int,
            next_event_time_defined: e.next_event_time.is_some() as c_int,
            next_event_time: e.next_event_time.unwrap_or(0.0),
        };
        Ok(())
    })
}

pub extern "C" fn fmi2EnterContinuousTimeMode(c: Component) -> c_int {
    me_call(
        c,
        "fmi2EnterContinuousTimeMode",
        mask::ENTER_CONTINUOUS_TIME_MODE,
        |inst| inst.enter_continuous_time_mode(),
    )
}

pub extern "C" fn fmi2CompletedIntegratorStep(
    c: Component,
    _no_set_prior: c_int,
    enter_event_mode: *mut c_int,
    terminate: *mut c_int,
) -> c_int {
    me_call(
        c,
        "fmi2CompletedIntegratorStep",
        mask::COMPLETED_INTEGRATOR_STEP,
        |inst| {
            let enter = out_ptr(enter_event_mode, "enterEventMode")?;
            let term = out_ptr(terminate, "terminateSimulation")?;
            *enter = inst.completed_integrator_step()? as c_int;
            *term = 0;
            Ok(())
        },
    )
}

pub extern "C" fn fmi2SetTime(c: Component, t: f64) -> c_int {
    me_call(c, "fmi2SetTime", mask::SET_TIME, |inst| inst.set_time(t))
}

pub extern "C" fn fmi2SetContinuousStates(c: Component, x: *const f64, nx: usize) -> c_int {
    me_call(c, "fmi2SetContinuousStates", mask::SET_CONTINUOUS_STATES, |inst| {
        let x = unsafe { slice(x, nx, "x[]")? };
        inst.set_continuous_states(x)
    })
}

pub extern "C" fn fmi2GetDerivatives(c: Component, dx: *mut f64, nx: usize) -> c_int {
    me_call(c, "fmi2GetDerivatives", GET_DERIVATIVES, |inst| {
        let dx = unsafe { slice_mut(dx, nx, "derivatives[]")? };
        inst.get_derivatives(dx)
    })
}

pub extern "C" fn fmi2GetEventIndicators(c: Component, z: *mut f64, ni: usize) -> c_int {
    me_call(c, "fmi2GetEventIndicators", mask::GET_ME_VALUES, |inst| {
        let z = unsafe { slice_mut(z, ni, "eventIndicators[]")? };
        inst.get_event_indicators(z)
    })
}

pub extern "C" fn fmi2GetContinuousStates(c: Component, x: *mut f64, nx: usize) -> c_int {
    me_call(c, "fmi2GetContinuousStates", mask::GET_ME_VALUES, |inst| {
        let x = unsafe { slice_mut(x, nx, "x[]")? };
        inst.get_continuous_states(x)
    })
}

pub extern "C" fn fmi2GetNominalsOfContinuousStates(c: Component, x: *mut f64, nx: usize) -> c_int {
    me_call(c, "fmi2GetNominalsOfContinuousStates", GET_NOMINALS, |inst| {
        let x = unsafe { slice_mut(x, nx, "x_nominal[]")? };
        inst.get_nominals(x)
    })
}
