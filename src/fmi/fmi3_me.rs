//! The FMI 3.0 Model Exchange C functions (FMI 3.0 chapter 3), on the same [`Instance`] and the same
//! Model Exchange methods as FMI 2.0 (`instance_me.rs`): this file adds the FMI 3.0 signatures, the
//! FMI 3.0 Model Exchange state machine and its error rule (`fmi3Error` moves the instance to
//! Terminated, through [`call3`]).
//!
//! States: Instantiated, Initialization Mode, Event Mode, Continuous-Time Mode, Terminated (and Fatal).
//! `fmi3ExitInitializationMode` leads to Event Mode; `fmi3UpdateDiscreteStates` runs the event
//! iteration (projection, time events), `fmi3EnterContinuousTimeMode` hands over to the importer's
//! solver, `fmi3EnterEventMode` comes back. Which function may be called in which state follows the
//! FMI 3.0 state descriptions (section 2.3 and 3.2): see [`mask3me`].
//!
//! A Model Exchange function called on a Co-Simulation instance is refused (fmi3Error, with a message
//! saying so), as is a Co-Simulation function on a Model Exchange instance.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref, clippy::too_many_arguments)]

use std::ffi::{c_char, c_int, c_void, CStr};

use super::abi::{find_model, guarded, out_ptr, register, slice, slice_mut};
use super::fmi3::{call3, log_without_instance3, mask3, state_name, Instance3};
use super::instance::{CallResult, Fail, Instance, Log3Fn, Logger};
use super::instance_me::LayerVar;
use super::FsmState;
use crate::model::{Causality, ModelEntry, Value, VarKind, Variability};

/// Sets of states in which an FMI 3.0 Model Exchange function may be called.
pub mod mask3me {
    use super::FsmState::*;
    use crate::fmi::mask_of as m;
    /// `fmi3EnterEventMode`: from Continuous-Time Mode (FMI 3.0 section 3.2.1).
    pub const ENTER_EVENT_MODE: u16 = m(&[ContinuousTimeMode]);
    /// `fmi3UpdateDiscreteStates`, `fmi3EnterContinuousTimeMode`: Event Mode only.
    pub const EVENT_MODE: u16 = m(&[EventMode]);
    /// `fmi3SetTime`, `fmi3SetContinuousStates`, `fmi3CompletedIntegratorStep`: Continuous-Time Mode only.
    pub const CONTINUOUS_TIME_MODE: u16 = m(&[ContinuousTimeMode]);
    /// `fmi3GetContinuousStates`, `fmi3GetContinuousStateDerivatives`, `fmi3GetEventIndicators`,
    /// `fmi3GetNominalsOfContinuousStates`.
    pub const GET_ME_VALUES: u16 = m(&[InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
    /// `fmi3GetNumberOfContinuousStates`, `fmi3GetNumberOfEventIndicators`: any state but Fatal.
    pub const NUMBER_OF: u16 = m(&[Instantiated, InitializationMode, EventMode, ContinuousTimeMode, Terminated]);
}

/// Why a Model Exchange function is refused on an instance that is not a Model Exchange instance.
fn not_me_reason(inst: &Instance) -> String {
    if inst.entry.model_exchange() {
        "Model Exchange function, but this instance was created by fmi3InstantiateCoSimulation".into()
    } else {
        format!("Model Exchange function, but {} provides Co-Simulation only (no <ModelExchange> element)", inst.entry.info.name)
    }
}

/// `call3` for a Model Exchange function: a Co-Simulation instance is refused as such (before the state
/// check, whose message would not say why), then the state is checked against `allowed`.
pub(super) fn me3(c: Instance3, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    call3(c, func, mask3::ANY, |inst| {
        if !inst.model_exchange {
            return Err(Fail::error(not_me_reason(inst)));
        }
        if allowed & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(format!("not allowed in state {} (illegal call sequence)", state_name(inst.run.fsm))));
        }
        f(inst)
    })
}

/// Refuses a Co-Simulation function on a Model Exchange instance (used inside the CS functions).
pub(super) fn require_co_simulation(inst: &Instance) -> CallResult {
    if inst.model_exchange {
        return Err(Fail::error("Co-Simulation function, but this instance was created by fmi3InstantiateModelExchange"));
    }
    Ok(())
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
    const FUNC: &str = "fmi3InstantiateModelExchange";
    let result = guarded(|| -> Result<Instance3, String> {
        if instance_name.is_null() {
            return Err("instanceName is NULL".into());
        }
        // SAFETY: non-null C string from the master.
        let name = unsafe { CStr::from_ptr(instance_name) };
        if name.to_bytes().is_empty() {
            return Err("instanceName is empty".into());
        }
        if token.is_null() {
            return Err("instantiationToken is NULL".into());
        }
        // SAFETY: non-null C string from the master.
        let requested = unsafe { CStr::from_ptr(token) }.to_string_lossy();
        let entry = find_model(models, &requested).map_err(|e| e.replace("fmuGUID", "instantiationToken"))?;
        if !entry.model_exchange() {
            return Err(format!(
                "{} provides Co-Simulation only (no <ModelExchange> element in its modelDescription.xml): use fmi3InstantiateCoSimulation",
                entry.info.name
            ));
        }
        let mut inst = Box::new(Instance::new(name.to_owned(), entry, log_message.map_or(Logger::None, Logger::Fmi3), env, logging_on != 0));
        inst.fmi3 = true;
        inst.model_exchange = true;
        inst.trace(|| format!("{FUNC}: {} instance of {}", inst.name.to_string_lossy(), entry.info.name));
        Ok(register(inst))
    });
    match result {
        Ok(Ok(p)) => p,
        Ok(Err(msg)) => {
            log_without_instance3(log_message, env, FUNC, &msg);
            std::ptr::null_mut()
        }
        Err(panic) => {
            log_without_instance3(log_message, env, FUNC, &format!("internal error (panic): {panic}"));
            std::ptr::null_mut()
        }
    }
}

// ----- mode switches and the event iteration ---------------------------------------------------------

/// `fmi3EnterEventMode` on a Model Exchange instance.
pub(super) fn enter_event_mode(c: Instance3) -> c_int {
    me3(c, "fmi3EnterEventMode", mask3me::ENTER_EVENT_MODE, |inst| inst.enter_event_mode())
}

/// `fmi3UpdateDiscreteStates` on a Model Exchange instance: one pass of the event iteration.
pub(super) fn update_discrete_states(
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
    me3(c, "fmi3EnterContinuousTimeMode", mask3me::EVENT_MODE, |inst| inst.enter_continuous_time_mode())
}

pub extern "C" fn fmi3CompletedIntegratorStep(c: Instance3, _no_set_prior: u8, enter_event_mode: *mut u8, terminate_simulation: *mut u8) -> c_int {
    me3(c, "fmi3CompletedIntegratorStep", mask3me::CONTINUOUS_TIME_MODE, |inst| {
        let enter = out_ptr(enter_event_mode, "enterEventMode")?;
        let term = out_ptr(terminate_simulation, "terminateSimulation")?;
        *enter = inst.completed_integrator_step()? as u8;
        *term = 0;
        Ok(())
    })
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
        inst.set_continuous_states(x).map_err(rename_x("continuousStates[]"))
    })
}

pub extern "C" fn fmi3GetContinuousStates(c: Instance3, x: *mut f64, n: usize) -> c_int {
    me3(c, "fmi3GetContinuousStates", mask3me::GET_ME_VALUES, |inst| {
        let x = unsafe { slice_mut(x, n, "continuousStates[]")? };
        inst.get_continuous_states(x).map_err(rename_x("continuousStates[]"))
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
        inst.get_nominals(x).map_err(rename_x("nominals[]"))
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

/// The shared Model Exchange methods name the FMI 2.0 arguments (`x[]`, `x_nominal[]`): give the FMI 3.0 names.
fn rename_x(name: &'static str) -> impl Fn(Fail) -> Fail {
    move |f| Fail { status: f.status, reason: f.reason.replace("x_nominal[]", name).replace("x[", &name[..name.len() - 1]) }
}

// ----- fmi3SetFloat64 on a Model Exchange instance ----------------------------------------------------

/// `fmi3SetFloat64` on a Model Exchange instance in Event or Continuous-Time Mode: continuous states may
/// be set by value reference (FMI 3.0 section 3.2.1); in Continuous-Time Mode only continuous inputs
/// and states may be set. Every value is checked before any is written.
pub(super) fn set_float64_me(inst: &mut Instance, vrs: &[u32], vals: &[f64]) -> CallResult {
    let continuous_time = inst.run.fsm == FsmState::ContinuousTimeMode;
    let mut states: Option<Vec<f64>> = None;
    let mut others: Vec<usize> = Vec::with_capacity(vrs.len());
    for (i, vr) in vrs.iter().enumerate() {
        match inst.layer_var(*vr) {
            Some(LayerVar::State(k)) => {
                let name = inst.entry.state_decls()[k].name;
                if !vals[i].is_finite() {
                    return Err(Fail::error(format!("value {} for continuous state {name} is not finite", vals[i])));
                }
                let x = match states.as_mut() {
                    Some(x) => x,
                    None => {
                        let mut x = vec![0.0; inst.n_states()];
                        inst.model.get_states(&mut x).map_err(Fail::error)?;
                        states.insert(x)
                    }
                };
                x[k] = vals[i];
            }
            Some(LayerVar::Derivative(k)) => {
                return Err(Fail::error(format!("der({}) is a state derivative and cannot be set", inst.entry.state_decls()[k].name)));
            }
            None => {
                if continuous_time {
                    if let Some(d) = inst.entry.decls.iter().find(|d| d.vr == *vr && d.kind == VarKind::Real) {
                        if !(d.causality == Causality::Input && d.variability == Variability::Continuous) {
                            return Err(Fail::error(format!(
                                "{} cannot be set in Continuous-Time Mode: only continuous inputs and continuous states can (FMI 3.0 section 3.2.1)",
                                d.name
                            )));
                        }
                    }
                }
                others.push(i);
            }
        }
    }
    let other_vrs: Vec<u32> = others.iter().map(|i| vrs[*i]).collect();
    inst.set_values(VarKind::Real, &other_vrs, |j| Value::Real(vals[others[j]]))?;
    if let Some(x) = states {
        inst.set_continuous_states(&x)?;
    }
    Ok(())
}

/// In Continuous-Time Mode only continuous Float64 inputs can be set: `fmi3SetInt32` and
/// `fmi3SetBoolean` (discrete variables) are refused there.
pub(super) fn refuse_discrete_in_continuous_time(inst: &Instance, ty: &str, vrs: &[u32]) -> CallResult {
    if inst.run.fsm == FsmState::ContinuousTimeMode && !vrs.is_empty() {
        return Err(Fail::error(format!(
            "{ty} variables are discrete: they cannot be set in Continuous-Time Mode (call fmi3EnterEventMode first)"
        )));
    }
    Ok(())
}

