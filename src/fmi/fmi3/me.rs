//! The FMI 3.0 Model Exchange C functions (FMI 3.0 chapter 3), on the same [`Instance`] and the same
//! Model Exchange methods as FMI 2.0 (`instance/me.rs`): this file adds the FMI 3.0 signatures, the
//! FMI 3.0 Model Exchange state machine and its error rule (`fmi3Error` moves the instance to
//! Terminated, through `call3`).
//!
//! States: Instantiated, Initialization Mode, Event Mode, Continuous-Time Mode, Terminated (and Fatal).
//! `fmi3ExitInitializationMode` leads to Event Mode; `fmi3UpdateDiscreteStates` runs the event
//! iteration (projection, time events), `fmi3EnterContinuousTimeMode` hands over to the importer's
//! solver, `fmi3EnterEventMode` comes back. Which function may be called in which state follows the
//! FMI 3.0 state descriptions (section 2.3 and 3.2): see [`mask3me`].
//!
//! A Model Exchange function called on a Co-Simulation instance is refused (fmi3Error, with a message
//! saying so), as is a Co-Simulation function on a Model Exchange instance.
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int, c_void};

use super::common::{call3, is_model_exchange, mask3, mask3me, refuse, request3, Instance3, Log3Fn};
use crate::fmi::boundary::{self, out_ptr, slice, slice_mut, Request};
use crate::fmi::instance::{CallResult, Fail, Instance, Reason};
use crate::model::ModelEntry;

/// Why a Model Exchange function is refused on an instance that is not a Model Exchange instance.
fn not_me_reason(inst: &Instance) -> String {
    if inst.entry.model_exchange() {
        "Model Exchange function, but this instance was created by fmi3InstantiateCoSimulation".into()
    } else {
        format!(
            "Model Exchange function, but {} provides Co-Simulation only (no <ModelExchange> element)",
            inst.entry.info.name
        )
    }
}

/// `call3` for a Model Exchange function: a Co-Simulation instance is refused as such (before the state
/// check, whose message would not say why), then the state is checked against `allowed`.
#[inline(always)]
fn me3(c: Instance3, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    call3(c, func, mask3::ANY, |inst| {
        if !inst.model_exchange {
            return Err(Fail::error(not_me_reason(inst)));
        }
        if allowed & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(Reason::IllegalCall(inst.run.fsm)));
        }
        f(inst)
    })
}

// ----- instantiation ---------------------------------------------------------------------------------

/// `fmi3InstantiateModelExchange` for a library holding `models`: the model is picked as in
/// `fmi3InstantiateCoSimulation`; a model without Model Exchange gives `NULL` and a log message.
pub fn fmi3InstantiateModelExchange(
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
) -> Instance3 {
    let request = request3(
        "fmi3InstantiateModelExchange",
        models,
        instance_name,
        token,
        logging_on,
        env,
        log_message,
    );
    boundary::instantiate(Request {
        model_exchange: true,
        refuse_model: &|entry| {
            (!entry.model_exchange()).then(|| {
                format!(
                    "{} provides Co-Simulation only (no <ModelExchange> element in its modelDescription.xml): use fmi3InstantiateCoSimulation",
                    entry.info.name
                )
            })
        },
        ..request
    })
}

// ----- mode switches and the event iteration ---------------------------------------------------------

/// `fmi3EnterEventMode` on a Model Exchange instance.
fn enter_event_mode(c: Instance3) -> c_int {
    me3(c, "fmi3EnterEventMode", mask3me::ENTER_EVENT_MODE, |inst| {
        inst.enter_event_mode()
    })
}

/// `fmi3UpdateDiscreteStates` on a Model Exchange instance: one pass of the event iteration.
fn update_discrete_states(
    c: Instance3,
    discrete_states_need_update: *mut u8,
    terminate_simulation: *mut u8,
    nominals_changed: *mut u8,
    values_changed: *mut u8,
    next_event_time_defined: *mut u8,
    next_event_time: *mut f64,
) -> c_int {
    me3(c, "fmi3UpdateDiscreteStates", mask3me::EVENT_MODE, |inst| {
        let need = out_ptr(discrete_states_need_update, "discreteStatesNeedUpdate")?;
        let term = out_ptr(terminate_simulation, "terminateSimulation")?;
        let nominals = out_ptr(nominals_changed, "nominalsOfContinuousStatesChanged")?;
        let values = out_ptr(values_changed, "valuesOfContinuousStatesChanged")?;
        let defined = out_ptr(next_event_time_defined, "nextEventTimeDefined")?;
        let next = out_ptr(next_event_time, "nextEventTime")?;
        let e = inst.new_discrete_states()?;
        inst.trace(|| format!("fmi3UpdateDiscreteStates at t = {}: {e:?}", inst.run.time));
        *need = e.new_discrete_states_needed as u8;
        *term = e.terminate_simulation as u8;
        *nominals = e.nominals_changed as u8;
        *values = e.values_changed as u8;
        *defined = e.next_event_time.is_some() as u8;
        *next = e.next_event_time.unwrap_or(0.0);
        Ok(())
    })
}

pub extern "C" fn fmi3EnterContinuousTimeMode(c: Instance3) -> c_int {
    me3(c, "fmi3EnterContinuousTimeMode", mask3me::EVENT_MODE, |inst| {
        inst.enter_continuous_time_mode()
    })
}

pub extern "C" fn fmi3CompletedIntegratorStep(
    c: Instance3,
    _no_set_prior: u8,
    enter_event_mode: *mut u8,
    terminate_simulation: *mut u8,
) -> c_int {
    me3(
        c,
        "fmi3CompletedIntegratorStep",
        mask3me::CONTINUOUS_TIME_MODE,
        |inst| {
            let enter = out_ptr(enter_event_mode, "enterEventMode")?;
            let term = out_ptr(terminate_simulation, "terminateSimulation")?;
            *enter = inst.completed_integrator_step()? as u8;
            *term = 0;
            Ok(())
        },
    )
}

// ----- time, states, derivatives ---------------------------------------------------------------------

pub extern "C" fn fmi3SetTime(c: Instance3, t: f64) -> c_int {
    me3(c, "fmi3SetTime", mask3me::CONTINUOUS_TIME_MODE, |inst| {
        inst.trace(|| format!("fmi3SetTime({t})"));
        inst.set_time(t)
    })
}

pub extern "C" fn fmi3SetContinuousStates(c: Instance3, x: *const f64, n: usize) -> c_int {
    me3(c, "fmi3SetContinuousStates", mask3me::CONTINUOUS_TIME_MODE, |inst| {
        let x = unsafe { slice(x, n, "continuousStates[]")? };
        inst.set_continuous_states(x)
    })
}

pub extern "C" fn fmi3GetContinuousStates(c: Instance3, x: *mut f64, n: usize) -> c_int {
    me3(c, "fmi3GetContinuousStates", mask3me::GET_ME_VALUES, |inst| {
        let x = unsafe { slice_mut(x, n, "continuousStates[]")? };
        inst.get_continuous_states(x)
    })
}

pub extern "C" fn fmi3GetContinuousStateDerivatives(c: Instance3, dx: *mut f64, n: usize) -> c_int {
    me3(c, "fmi3GetContinuousStateDerivatives", mask3me::GET_ME_VALUES, |inst| {
        let dx = unsafe { slice_mut(dx, n, "derivatives[]")? };
        inst.get_derivatives(dx)
    })
}

pub extern "C" fn fmi3GetNominalsOfContinuousStates(c: Instance3, x: *mut f64, n: usize) -> c_int {
    me3(c, "fmi3GetNominalsOfContinuousStates", mask3me::GET_ME_VALUES, |inst| {
        let x = unsafe { slice_mut(x, n, "nominals[]")? };
        inst.get_nominals(x)
    })
}

pub extern "C" fn fmi3GetEventIndicators(c: Instance3, z: *mut f64, n: usize) -> c_int {
    me3(c, "fmi3GetEventIndicators", mask3me::GET_ME_VALUES, |inst| {
        let z = unsafe { slice_mut(z, n, "eventIndicators[]")? };
        inst.get_event_indicators(z)
    })
}

pub extern "C" fn fmi3GetNumberOfContinuousStates(c: Instance3, n: *mut usize) -> c_int {
    me3(c, "fmi3GetNumberOfContinuousStates", mask3me::NUMBER_OF, |inst| {
        *out_ptr(n, "nContinuousStates")? = inst.n_states();
        Ok(())
    })
}

pub extern "C" fn fmi3GetNumberOfEventIndicators(c: Instance3, n: *mut usize) -> c_int {
    me3(c, "fmi3GetNumberOfEventIndicators", mask3me::NUMBER_OF, |_| {
        *out_ptr(n, "nEventIndicators")? = 0; // no state events: time events only
        Ok(())
    })
}

// ----- functions both interfaces export, with the Model Exchange rules on an ME instance ---------------

/// Model Exchange: from Continuous-Time Mode to Event Mode. Co-Simulation: refused (no Event Mode).
pub extern "C" fn fmi3EnterEventMode(c: Instance3) -> c_int {
    if is_model_exchange(c) {
        return enter_event_mode(c);
    }
    super::clocks::enter_event_mode(c)
}

pub extern "C" fn fmi3EvaluateDiscreteStates(c: Instance3) -> c_int {
    if is_model_exchange(c) {
        return refuse(
            c,
            "fmi3EvaluateDiscreteStates",
            mask3::ANY,
            "providesEvaluateDiscreteStates = false (fmi3UpdateDiscreteStates evaluates them)",
        );
    }
    refuse(
        c,
        "fmi3EvaluateDiscreteStates",
        mask3::ANY,
        "this Co-Simulation FMU has no Event Mode",
    )
}

/// Model Exchange: one pass of the event iteration. Co-Simulation: refused (no Event Mode).
pub extern "C" fn fmi3UpdateDiscreteStates(
    c: Instance3,
    need: *mut u8,
    terminate: *mut u8,
    nominals_changed: *mut u8,
    values_changed: *mut u8,
    defined: *mut u8,
    t: *mut f64,
) -> c_int {
    if is_model_exchange(c) {
        return update_discrete_states(c, need, terminate, nominals_changed, values_changed, defined, t);
    }
    super::clocks::update_discrete_states(c, need, terminate, nominals_changed, values_changed, defined, t)
}
