//! The rest of the FMI 3.0 functions: FMU states and derivatives (shared with FMI 2.0 through
//! [`Snapshot`] and [`Instance`]), variable dependencies, and every function of a feature these FMUs
//! do not declare. Those exist because the standard's importers (fmpy, FMI Library) resolve every
//! `fmi3*` symbol when they load a binary; each one refuses with `fmi3Error` and a logged reason, as
//! the standard prescribes for a call the model description does not allow.
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::not_unsafe_ptr_arg_deref, clippy::too_many_arguments)]

use std::ffi::{c_char, c_int, c_void};

use super::abi::{out_ptr, slice, slice_mut};
use super::fmi3::{call3, log_without_instance3, mask3, Instance3};
use super::instance::{CallResult, Fail, Log3Fn};
use super::state_calls;
use crate::model::{Causality, Feedthrough, ModelEntry, STATE_VR_BASE};

// ----- FMU state ------------------------------------------------------------------------------------

pub extern "C" fn fmi3GetFMUState(c: Instance3, state: *mut *mut c_void) -> c_int {
    call3(c, "fmi3GetFMUState", mask3::ANY, |inst| state_calls::get(inst, out_ptr(state, "FMUState")?, c as usize))
}

pub extern "C" fn fmi3SetFMUState(c: Instance3, state: *mut c_void) -> c_int {
    // the state carries the time of its last event (Model Exchange), restored with it
    call3(c, "fmi3SetFMUState", mask3::ANY, |inst| state_calls::set(inst, state))
}

pub extern "C" fn fmi3FreeFMUState(c: Instance3, state: *mut *mut c_void) -> c_int {
    call3(c, "fmi3FreeFMUState", mask3::ANY, |_| state_calls::free(out_ptr(state, "FMUState")?))
}

pub extern "C" fn fmi3SerializedFMUStateSize(c: Instance3, state: *mut c_void, size: *mut usize) -> c_int {
    call3(c, "fmi3SerializedFMUStateSize", mask3::ANY, |inst| state_calls::serialized_size(inst, state, out_ptr(size, "size")?))
}

pub extern "C" fn fmi3SerializeFMUState(c: Instance3, state: *mut c_void, buffer: *mut u8, size: usize) -> c_int {
    call3(c, "fmi3SerializeFMUState", mask3::ANY, |inst| {
        state_calls::serialize(inst, state, size, "fmi3SerializedFMUStateSize", || unsafe { slice_mut(buffer, size, "serializedState[]") })
    })
}

pub extern "C" fn fmi3DeserializeFMUState(c: Instance3, buffer: *const u8, size: usize, state: *mut *mut c_void) -> c_int {
    call3(c, "fmi3DeserializeFMUState", mask3::ANY, |inst| {
        let slot = out_ptr(state, "FMUState")?;
        let bytes = unsafe { slice(buffer, size, "serializedState[]")? };
        state_calls::deserialize(inst, bytes, slot, c as usize)
    })
}

// ----- derivatives and dependencies -----------------------------------------------------------------

pub extern "C" fn fmi3GetDirectionalDerivative(
    c: Instance3,
    unknowns: *const u32,
    n_unknowns: usize,
    knowns: *const u32,
    n_knowns: usize,
    seed: *const f64,
    n_seed: usize,
    sensitivity: *mut f64,
    n_sensitivity: usize,
) -> c_int {
    call3(c, "fmi3GetDirectionalDerivative", mask3::DIRECTIONAL_DERIVATIVE, |inst| {
        if n_seed != n_knowns || n_sensitivity != n_unknowns {
            return Err(Fail::error(format!(
                "nSeed = {n_seed} must equal nKnowns = {n_knowns} and nSensitivity = {n_sensitivity} must equal nUnknowns = {n_unknowns} (scalar variables only)"
            )));
        }
        let unknowns = unsafe { slice(unknowns, n_unknowns, "unknowns[]")? };
        let knowns = unsafe { slice(knowns, n_knowns, "knowns[]")? };
        let seed = unsafe { slice(seed, n_seed, "seed[]")? };
        let out = unsafe { slice_mut(sensitivity, n_sensitivity, "sensitivity[]")? };
        let d = inst.directional_derivative(unknowns, knowns, seed)?;
        out.copy_from_slice(&d);
        Ok(())
    })
}

/// Value references of the inputs an output depends on directly (the same list as `<Output
/// dependencies>` in the FMI 3.0 model description).
pub fn output_dependency_vrs(entry: &ModelEntry, output: &str) -> Vec<u32> {
    let inputs = entry.decls.iter().filter(|d| d.causality == Causality::Input);
    match entry.info.feedthrough {
        Feedthrough::None => vec![],
        Feedthrough::AllInputs => inputs.map(|d| d.vr).collect(),
        Feedthrough::Some(list) => {
            let named: Vec<&str> = list.iter().filter(|(o, _)| *o == output).flat_map(|(_, ins)| ins.iter().copied()).collect();
            inputs.filter(|d| named.contains(&d.name)).map(|d| d.vr).collect()
        }
    }
}

/// The knowns an output depends on after initialization (`<Output dependencies>` in the FMI 3.0 model
/// description): the inputs it feeds through from and, for a model with Model Exchange, every
/// continuous state (value references from [`STATE_VR_BASE`]).
pub fn output_dependencies_with_states(entry: &ModelEntry, output: &str) -> Vec<u32> {
    let mut deps = output_dependency_vrs(entry, output);
    deps.extend((0..entry.state_decls().len() as u32).map(|k| STATE_VR_BASE + k));
    deps
}

fn output_dependencies(inst: &super::instance::Instance, vr: u32) -> CallResult<Vec<u32>> {
    match inst.entry.decls.iter().find(|d| d.vr == vr) {
        Some(d) if d.causality == Causality::Output => Ok(output_dependencies_with_states(inst.entry, d.name)),
        Some(d) => Err(Fail::error(format!("{} (value reference {vr}) is not an output: dependencies are declared for outputs only", d.name))),
        None => Err(Fail::error(format!("unknown value reference {vr}"))),
    }
}

pub extern "C" fn fmi3GetNumberOfVariableDependencies(c: Instance3, vr: u32, n: *mut usize) -> c_int {
    call3(c, "fmi3GetNumberOfVariableDependencies", mask3::ANY, |inst| {
        let out = out_ptr(n, "nDependencies")?;
        *out = output_dependencies(inst, vr)?.len();
        Ok(())
    })
}

/// `fmi3Dependent`: no finer dependency kind is declared.
const FMI3_DEPENDENT: c_int = 5;

pub extern "C" fn fmi3GetVariableDependencies(
    c: Instance3,
    dependent: u32,
    element_of_dependent: *mut usize,
    independents: *mut u32,
    element_of_independents: *mut usize,
    kinds: *mut c_int,
    n: usize,
) -> c_int {
    call3(c, "fmi3GetVariableDependencies", mask3::ANY, |inst| {
        let deps = output_dependencies(inst, dependent)?;
        if n != deps.len() {
            return Err(Fail::error(format!("nDependencies = {n}, but the output has {} (see fmi3GetNumberOfVariableDependencies)", deps.len())));
        }
        let e1 = unsafe { slice_mut(element_of_dependent, n, "elementIndicesOfDependent[]")? };
        let ind = unsafe { slice_mut(independents, n, "independents[]")? };
        let e2 = unsafe { slice_mut(element_of_independents, n, "elementIndicesOfIndependents[]")? };
        let k = unsafe { slice_mut(kinds, n, "dependencyKinds[]")? };
        for i in 0..n {
            (e1[i], ind[i], e2[i], k[i]) = (0, deps[i], 0, FMI3_DEPENDENT);
        }
        Ok(())
    })
}

// ----- refused: features and interfaces these FMUs do not declare ------------------------------------

fn refuse(c: Instance3, func: &str, allowed: u16, why: &str) -> c_int {
    call3(c, func, allowed, |_| Err(Fail::error(format!("not supported: {why}"))))
}

pub extern "C" fn fmi3GetAdjointDerivative(c: Instance3, _u: *const u32, _nu: usize, _k: *const u32, _nk: usize, _s: *const f64, _ns: usize, _out: *mut f64, _no: usize) -> c_int {
    refuse(c, "fmi3GetAdjointDerivative", mask3::DIRECTIONAL_DERIVATIVE, "providesAdjointDerivatives = false")
}

pub extern "C" fn fmi3EnterConfigurationMode(c: Instance3) -> c_int {
    refuse(c, "fmi3EnterConfigurationMode", mask3::ANY, "this FMU has no structural parameters")
}

pub extern "C" fn fmi3ExitConfigurationMode(c: Instance3) -> c_int {
    refuse(c, "fmi3ExitConfigurationMode", mask3::ANY, "this FMU has no structural parameters (Configuration Mode is never entered)")
}

/// Model Exchange: from Continuous-Time Mode to Event Mode. Co-Simulation: refused (no Event Mode).
pub extern "C" fn fmi3EnterEventMode(c: Instance3) -> c_int {
    if is_model_exchange(c) {
        return super::fmi3_me::enter_event_mode(c);
    }
    refuse(c, "fmi3EnterEventMode", mask3::ANY, "hasEventMode = false (instantiate with eventModeUsed = false)")
}

/// Whether `c` is a live FMI 3.0 Model Exchange instance (the functions both interfaces share pick their
/// rules by it; anything else goes the Co-Simulation way, which refuses unknown pointers).
fn is_model_exchange(c: Instance3) -> bool {
    super::abi::instance_of(c, true).is_some_and(|inst| inst.model_exchange)
}

pub extern "C" fn fmi3EnterStepMode(c: Instance3) -> c_int {
    refuse(c, "fmi3EnterStepMode", mask3::ANY, "Event Mode is never entered: fmi3ExitInitializationMode leads to Step Mode directly")
}

pub extern "C" fn fmi3GetOutputDerivatives(c: Instance3, _vr: *const u32, _n: usize, _order: *const i32, _v: *mut f64, _nv: usize) -> c_int {
    refuse(c, "fmi3GetOutputDerivatives", mask3::OUTPUT_DERIVATIVES, "maxOutputDerivativeOrder = 0")
}

pub extern "C" fn fmi3EvaluateDiscreteStates(c: Instance3) -> c_int {
    if is_model_exchange(c) {
        return refuse(c, "fmi3EvaluateDiscreteStates", mask3::ANY, "providesEvaluateDiscreteStates = false (fmi3UpdateDiscreteStates evaluates them)");
    }
    refuse(c, "fmi3EvaluateDiscreteStates", mask3::ANY, "this Co-Simulation FMU has no Event Mode")
}

/// Model Exchange: one pass of the event iteration. Co-Simulation: refused (no Event Mode).
pub extern "C" fn fmi3UpdateDiscreteStates(c: Instance3, need: *mut u8, terminate: *mut u8, nominals_changed: *mut u8, values_changed: *mut u8, defined: *mut u8, t: *mut f64) -> c_int {
    if is_model_exchange(c) {
        return super::fmi3_me::update_discrete_states(c, need, terminate, nominals_changed, values_changed, defined, t);
    }
    refuse(c, "fmi3UpdateDiscreteStates", mask3::ANY, "this Co-Simulation FMU has no Event Mode")
}

/// Variables of a type this FMU does not have: a call with values is refused (naming the first value
/// reference); an empty call does nothing.
fn no_such_type(c: Instance3, func: &str, allowed: u16, ty: &str, vr: *const u32, n: usize) -> c_int {
    call3(c, func, allowed, |_| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!("unknown {ty} value reference {v}: this FMU has no variables of type {ty}"))),
        }
    })
}

macro_rules! other_types {
    ($($get:ident, $set:ident, $t:ty, $name:literal;)*) => {$(
        pub extern "C" fn $get(c: Instance3, vr: *const u32, n: usize, _v: *mut $t, _nv: usize) -> c_int {
            no_such_type(c, stringify!($get), mask3::GET, $name, vr, n)
        }
        pub extern "C" fn $set(c: Instance3, vr: *const u32, n: usize, _v: *const $t, _nv: usize) -> c_int {
            no_such_type(c, stringify!($set), mask3::SET, $name, vr, n)
        }
    )*};
}

other_types! {
    fmi3GetFloat32, fmi3SetFloat32, f32, "Float32";
    fmi3GetInt8, fmi3SetInt8, i8, "Int8";
    fmi3GetUInt8, fmi3SetUInt8, u8, "UInt8";
    fmi3GetInt16, fmi3SetInt16, i16, "Int16";
    fmi3GetUInt16, fmi3SetUInt16, u16, "UInt16";
    fmi3GetUInt32, fmi3SetUInt32, u32, "UInt32";
    fmi3GetInt64, fmi3SetInt64, i64, "Int64";
    fmi3GetUInt64, fmi3SetUInt64, u64, "UInt64";
    fmi3GetString, fmi3SetString, *const c_char, "String";
}

pub extern "C" fn fmi3GetBinary(c: Instance3, vr: *const u32, n: usize, _sizes: *mut usize, _v: *mut *const u8, _nv: usize) -> c_int {
    no_such_type(c, "fmi3GetBinary", mask3::GET, "Binary", vr, n)
}

pub extern "C" fn fmi3SetBinary(c: Instance3, vr: *const u32, n: usize, _sizes: *const usize, _v: *const *const u8, _nv: usize) -> c_int {
    no_such_type(c, "fmi3SetBinary", mask3::SET, "Binary", vr, n)
}

pub extern "C" fn fmi3GetClock(c: Instance3, vr: *const u32, n: usize, _v: *mut u8) -> c_int {
    no_such_type(c, "fmi3GetClock", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3SetClock(c: Instance3, vr: *const u32, n: usize, _v: *const u8) -> c_int {
    no_such_type(c, "fmi3SetClock", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3GetIntervalDecimal(c: Instance3, vr: *const u32, n: usize, _i: *mut f64, _q: *mut c_int) -> c_int {
    no_such_type(c, "fmi3GetIntervalDecimal", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3GetIntervalFraction(c: Instance3, vr: *const u32, n: usize, _counters: *mut u64, _r: *mut u64, _q: *mut c_int) -> c_int {
    no_such_type(c, "fmi3GetIntervalFraction", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3GetShiftDecimal(c: Instance3, vr: *const u32, n: usize, _s: *mut f64) -> c_int {
    no_such_type(c, "fmi3GetShiftDecimal", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3GetShiftFraction(c: Instance3, vr: *const u32, n: usize, _counters: *mut u64, _r: *mut u64) -> c_int {
    no_such_type(c, "fmi3GetShiftFraction", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3SetIntervalDecimal(c: Instance3, vr: *const u32, n: usize, _i: *const f64) -> c_int {
    no_such_type(c, "fmi3SetIntervalDecimal", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3SetIntervalFraction(c: Instance3, vr: *const u32, n: usize, _counters: *const u64, _r: *const u64) -> c_int {
    no_such_type(c, "fmi3SetIntervalFraction", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3SetShiftDecimal(c: Instance3, vr: *const u32, n: usize, _s: *const f64) -> c_int {
    no_such_type(c, "fmi3SetShiftDecimal", mask3::ANY, "Clock", vr, n)
}

pub extern "C" fn fmi3SetShiftFraction(c: Instance3, vr: *const u32, n: usize, _counters: *const u64, _r: *const u64) -> c_int {
    no_such_type(c, "fmi3SetShiftFraction", mask3::ANY, "Clock", vr, n)
}

// ----- Model Exchange (in `fmi3_me`) and Scheduled Execution (not provided) ------------------------

pub use super::fmi3_me::{
    fmi3CompletedIntegratorStep, fmi3EnterContinuousTimeMode, fmi3GetContinuousStateDerivatives, fmi3GetContinuousStates, fmi3GetEventIndicators,
    fmi3GetNominalsOfContinuousStates, fmi3GetNumberOfContinuousStates, fmi3GetNumberOfEventIndicators, fmi3InstantiateModelExchange, fmi3SetContinuousStates,
    fmi3SetTime,
};

pub extern "C" fn fmi3InstantiateScheduledExecution(
    _name: *const c_char,
    _token: *const c_char,
    _resources: *const c_char,
    _visible: u8,
    _logging_on: u8,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
    _clock_update: *const c_void,
    _lock: *const c_void,
    _unlock: *const c_void,
) -> Instance3 {
    log_without_instance3(log_message, env, "fmi3InstantiateScheduledExecution", "this FMU provides no Scheduled Execution (no <ScheduledExecution> element)");
    std::ptr::null_mut()
}

pub extern "C" fn fmi3ActivateModelPartition(c: Instance3, _clock: u32, _t: f64) -> c_int {
    refuse(c, "fmi3ActivateModelPartition", mask3::ANY, "Scheduled Execution function; this FMU provides Co-Simulation only")
}
