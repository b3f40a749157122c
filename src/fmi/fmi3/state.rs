//! FMI 3.0 FMU states (shared with FMI 2.0 through `state_calls`), directional derivatives and variable
//! dependencies, for Co-Simulation and Model Exchange instances alike.
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_int, c_void};

use super::common::{call3, mask3, Instance3};
use crate::fmi::boundary::{out_ptr, slice, slice_mut};
use crate::fmi::instance::{CallResult, Fail};
use crate::fmi::state_calls;
use crate::model::scalar_list;
use crate::model::{Causality, Feedthrough, ModelEntry, STATE_VR_BASE};

// ----- FMU state ------------------------------------------------------------------------------------

pub extern "C" fn fmi3GetFMUState(c: Instance3, state: *mut *mut c_void) -> c_int {
    call3(c, "fmi3GetFMUState", mask3::ANY, |inst| {
        state_calls::get(inst, out_ptr(state, "FMUState")?, c as usize)
    })
}

pub extern "C" fn fmi3SetFMUState(c: Instance3, state: *mut c_void) -> c_int {
    // the state carries the time of its last event (Model Exchange), restored with it
    call3(c, "fmi3SetFMUState", mask3::ANY, |inst| state_calls::set(inst, state))
}

pub extern "C" fn fmi3FreeFMUState(c: Instance3, state: *mut *mut c_void) -> c_int {
    call3(c, "fmi3FreeFMUState", mask3::ANY, |_| {
        state_calls::free(out_ptr(state, "FMUState")?)
    })
}

pub extern "C" fn fmi3SerializedFMUStateSize(c: Instance3, state: *mut c_void, size: *mut usize) -> c_int {
    call3(c, "fmi3SerializedFMUStateSize", mask3::ANY, |inst| {
        state_calls::serialized_size(inst, state, out_ptr(size, "size")?)
    })
}

pub extern "C" fn fmi3SerializeFMUState(c: Instance3, state: *mut c_void, buffer: *mut u8, size: usize) -> c_int {
    call3(c, "fmi3SerializeFMUState", mask3::ANY, |inst| {
        state_calls::serialize(inst, state, size, "fmi3SerializedFMUStateSize", || unsafe {
            slice_mut(buffer, size, "serializedState[]")
        })
    })
}

pub extern "C" fn fmi3DeserializeFMUState(
    c: Instance3,
    buffer: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> c_int {
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
    call3(
        c,
        "fmi3GetDirectionalDerivative",
        mask3::DIRECTIONAL_DERIVATIVE,
        |inst| {
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
        },
    )
}

/// Value references of the inputs an output depends on directly (the same list as `<Output
/// dependencies>` in the FMI 3.0 model description).
pub fn output_dependency_vrs(entry: &ModelEntry, output: &str) -> Vec<u32> {
    let inputs = entry.decls.iter().filter(|d| d.causality == Causality::Input);
    match entry.info.feedthrough {
        Feedthrough::None => vec![],
        Feedthrough::AllInputs => inputs.map(|d| d.vr).collect(),
        Feedthrough::Some(_) => {
            let named: Vec<&str> = scalar_list(entry)
                .unwrap_or_default()
                .into_iter()
                .filter(|(o, _)| *o == output)
                .flat_map(|(_, ins)| ins)
                .collect();
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

fn output_dependencies(inst: &crate::fmi::instance::Instance, vr: u32) -> CallResult<Vec<u32>> {
    match inst.entry.decls.iter().find(|d| d.vr == vr) {
        Some(d) if d.causality == Causality::Output => Ok(output_dependencies_with_states(inst.entry, d.name)),
        Some(d) => Err(Fail::error(format!(
            "{} (value reference {vr}) is not an output: dependencies are declared for outputs only",
            d.name
        ))),
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
            return Err(Fail::error(format!(
                "nDependencies = {n}, but the output has {} (see fmi3GetNumberOfVariableDependencies)",
                deps.len()
            )));
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
