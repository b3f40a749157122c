//! FMI 3.0 value access for both interfaces: `fmi3Get/SetFloat64`, `Int32` and `Boolean` over the
//! shared instance, the independent variable `time`, and the Model Exchange rules for setting values in
//! Event and Continuous-Time Mode (continuous states by value reference, discrete variables refused in
//! Continuous-Time Mode).
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::c_int;

use super::common::{call3, mask3, Instance3, TIME_VR};
use crate::fmi::boundary::{slice, slice_mut};
use crate::fmi::instance::{CallResult, Fail, Instance, LayerVar};
use crate::fmi::types::FsmState;
use crate::model::{Causality, Value, VarKind, Variability};

// ----- get / set ------------------------------------------------------------------------------------

fn scalar_count(n_vr: usize, n_values: usize) -> CallResult {
    if n_vr != n_values {
        return Err(Fail::error(format!(
            "nValues = {n_values} differs from nValueReferences = {n_vr} (every variable of this FMU is a scalar)"
        )));
    }
    Ok(())
}

fn get3<T: Copy>(
    c: Instance3,
    func: &str,
    kind: VarKind,
    vr: *const u32,
    n: usize,
    value: *mut T,
    nv: usize,
    conv: impl Fn(Value) -> T,
) -> c_int {
    call3(c, func, mask3::GET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let out = unsafe { slice_mut(value, n, "values[]")? };
        inst.get_values(kind, vrs, |i, v| out[i] = conv(v))
    })
}

fn set3<T: Copy>(
    c: Instance3,
    func: &str,
    kind: VarKind,
    vr: *const u32,
    n: usize,
    value: *const T,
    nv: usize,
    conv: impl Fn(T) -> Value,
) -> c_int {
    call3(c, func, mask3::SET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let vals = unsafe { slice(value, n, "values[]")? };
        if vrs.contains(&TIME_VR) {
            return Err(Fail::error(time_not_settable(inst)));
        }
        refuse_discrete_in_continuous_time(inst, kind_name3(kind), vrs)?;
        inst.set_values(kind, vrs, |i| conv(vals[i]))
    })
}

pub extern "C" fn fmi3GetFloat64(c: Instance3, vr: *const u32, n: usize, value: *mut f64, nv: usize) -> c_int {
    call3(c, "fmi3GetFloat64", mask3::GET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let out = unsafe { slice_mut(value, n, "values[]")? };
        let real = |v| if let Value::Real(x) = v { x } else { f64::NAN };
        if !vrs.contains(&TIME_VR) {
            return inst.get_values(VarKind::Real, vrs, |i, v| out[i] = real(v));
        }
        // time among the declared variables: read the others, then fill in the FMU time
        let others: Vec<usize> = (0..n).filter(|i| vrs[*i] != TIME_VR).collect();
        let other_vrs: Vec<u32> = others.iter().map(|i| vrs[*i]).collect();
        inst.get_values(VarKind::Real, &other_vrs, |j, v| out[others[j]] = real(v))?;
        for (o, v) in out.iter_mut().zip(vrs) {
            if *v == TIME_VR {
                *o = inst.run.time;
            }
        }
        Ok(())
    })
}

fn time_not_settable(inst: &Instance) -> String {
    let how = if inst.model_exchange {
        "it is set with fmi3SetTime"
    } else {
        "it advances with fmi3DoStep"
    };
    format!("value reference {TIME_VR} is time, the independent variable: it cannot be set ({how})")
}

fn kind_name3(kind: VarKind) -> &'static str {
    match kind {
        VarKind::Real => "Float64",
        VarKind::Integer => "Int32",
        VarKind::Boolean => "Boolean",
    }
}

pub extern "C" fn fmi3SetFloat64(c: Instance3, vr: *const u32, n: usize, value: *const f64, nv: usize) -> c_int {
    call3(c, "fmi3SetFloat64", mask3::SET, |inst| {
        scalar_count(n, nv)?;
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let vals = unsafe { slice(value, n, "values[]")? };
        if vrs.contains(&TIME_VR) {
            return Err(Fail::error(time_not_settable(inst)));
        }
        if inst.model_exchange && matches!(inst.run.fsm, FsmState::EventMode | FsmState::ContinuousTimeMode) {
            // continuous states can be set by value reference; in Continuous-Time Mode only they and continuous inputs
            return set_float64_me(inst, vrs, vals);
        }
        inst.set_values(VarKind::Real, vrs, |i| Value::Real(vals[i]))
    })
}

pub extern "C" fn fmi3GetInt32(c: Instance3, vr: *const u32, n: usize, value: *mut i32, nv: usize) -> c_int {
    get3(c, "fmi3GetInt32", VarKind::Integer, vr, n, value, nv, |v| {
        if let Value::Integer(x) = v {
            x
        } else {
            0
        }
    })
}

pub extern "C" fn fmi3SetInt32(c: Instance3, vr: *const u32, n: usize, value: *const i32, nv: usize) -> c_int {
    set3(c, "fmi3SetInt32", VarKind::Integer, vr, n, value, nv, Value::Integer)
}

/// `fmi3Boolean` is a C `bool` (one byte): written as 0 or 1, read as "non-zero is true".
pub extern "C" fn fmi3GetBoolean(c: Instance3, vr: *const u32, n: usize, value: *mut u8, nv: usize) -> c_int {
    get3(c, "fmi3GetBoolean", VarKind::Boolean, vr, n, value, nv, |v| {
        matches!(v, Value::Boolean(true)) as u8
    })
}

pub extern "C" fn fmi3SetBoolean(c: Instance3, vr: *const u32, n: usize, value: *const u8, nv: usize) -> c_int {
    set3(c, "fmi3SetBoolean", VarKind::Boolean, vr, n, value, nv, |b| {
        Value::Boolean(b != 0)
    })
}

// ----- fmi3SetFloat64 on a Model Exchange instance ----------------------------------------------------

/// `fmi3SetFloat64` on a Model Exchange instance in Event or Continuous-Time Mode: continuous states may
/// be set by value reference (FMI 3.0 section 3.2.1); in Continuous-Time Mode only continuous inputs
/// and states may be set. Every value is checked before any is written.
fn set_float64_me(inst: &mut Instance, vrs: &[u32], vals: &[f64]) -> CallResult {
    let continuous_time = inst.run.fsm == FsmState::ContinuousTimeMode;
    let mut states: Option<Vec<f64>> = None;
    let mut others: Vec<usize> = Vec::with_capacity(vrs.len());
    for (i, vr) in vrs.iter().enumerate() {
        match inst.layer_var(*vr) {
            Some(LayerVar::State(k)) => {
                let name = inst.entry.state_decls()[k].name;
                if !vals[i].is_finite() {
                    return Err(Fail::error(format!(
                        "value {} for continuous state {name} is not finite",
                        vals[i]
                    )));
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
                return Err(Fail::error(format!(
                    "der({}) is a state derivative and cannot be set",
                    inst.entry.state_decls()[k].name
                )));
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
fn refuse_discrete_in_continuous_time(inst: &Instance, ty: &str, vrs: &[u32]) -> CallResult {
    if inst.run.fsm == FsmState::ContinuousTimeMode && !vrs.is_empty() {
        return Err(Fail::error(format!(
            "{ty} variables are discrete: they cannot be set in Continuous-Time Mode (call fmi3EnterEventMode first)"
        )));
    }
    Ok(())
}
