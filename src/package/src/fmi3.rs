//! The FMI 3.0 `modelDescription.xml` of a model, from the same catalogue entry as the FMI 2.0 one
//! ([`crate::fmi2`]): same variable names, value references, units, bounds and start values, same log
//! categories and default experiment. What differs:
//! - `fmiVersion="3.0"` and `instantiationToken` (the GUID the binary checks);
//! - typed variable elements (`<Float64>`, `<Int32>`, `<Boolean>`) with the attributes on the element;
//! - the independent variable `time` (at the layer's value reference, [`LayerInfo::time_vr`]), which
//!   FMI 3.0 requires;
//! - `<ModelStructure>` lists `<Output>`, `<ContinuousStateDerivative>` and `<InitialUnknown>` by value
//!   reference, and their dependencies by value reference too (FMI 2.0: 1-based indices). The lists
//!   are the FMI 2.0 ones ([`crate::structure`]) with each index translated to its value reference, so
//!   the two descriptions cannot disagree;
//! - Model Exchange (`<ModelExchange>`, for the models that have it): the continuous states and their
//!   derivatives are `<Float64>` variables at the same value references as in FMI 2.0
//!   (`state_vr_base + k`, `derivative_vr_base + k`), `derivative` names the state's value reference;
//! - clocks (sampled models that declare them, [`crate::clocks`]): `hasEventMode="true"`, a
//!   `<ScheduledExecution>` element, one `<Clock>` per clock and the clocked outputs marked as such.

use spacecraft_fmus::catalogue::{Catalogue, Causality, LayerInfo, ModelDescription, VarKind};

use crate::clocks::{clock_of, clock_vr, write_clocks};
use crate::structure::{derivative_dependencies, initial_unknowns, output_dependencies, state_indices};
use crate::xml::{
    empty, end, join, local_attrs, model_description_document, start, value_attrs, variable_attrs, Version, W,
};

/// Value reference of the variable at 1-based FMI 2.0 ScalarVariable index `ix`: the declared variables,
/// then the continuous states, then their derivatives (the order of the FMI 2.0 description).
fn vr_of_index(m: &ModelDescription, layer: &LayerInfo, ix: usize) -> u32 {
    let (n, ns) = (m.variables.len(), m.state_decls().len());
    assert!(
        ix >= 1 && ix <= n + 2 * ns,
        "{}: ScalarVariable index {ix} out of range",
        m.name
    );
    if ix <= n {
        m.variables[ix - 1].vr
    } else if ix <= n + ns {
        layer.state_vr_base + (ix - n - 1) as u32
    } else {
        layer.derivative_vr_base + (ix - n - ns - 1) as u32
    }
}

fn vrs_of(m: &ModelDescription, layer: &LayerInfo, ix: &[usize]) -> String {
    join(&ix.iter().map(|i| vr_of_index(m, layer, *i)).collect::<Vec<_>>())
}

/// The complete FMI 3.0 modelDescription.xml of model `m` of the catalogue `cat`.
pub fn model_description3(cat: &Catalogue, m: &ModelDescription) -> String {
    let v = Version {
        fmi_version: "3.0",
        token: "instantiationToken",
        extra: &[],
        interfaces: write_interfaces,
        variables: write_variables,
        structure: write_structure,
    };
    model_description_document(cat, m, &v)
}

/// `<ModelExchange>` (models with continuous states), `<CoSimulation>`, and `<ScheduledExecution>` for a
/// model with clocks.
fn write_interfaces(w: &mut W, m: &ModelDescription) {
    // the attributes both interface elements have, in the order of the standard's schema
    let shared = || -> Vec<(&str, String)> {
        vec![
            ("modelIdentifier", m.name.clone()),
            ("needsExecutionTool", "false".into()),
            ("canBeInstantiatedOnlyOncePerProcess", "false".into()),
            ("canGetAndSetFMUState", "true".into()),
            ("canSerializeFMUState", "true".into()),
            ("providesDirectionalDerivatives", "true".into()),
            ("providesAdjointDerivatives", "false".into()),
            ("providesPerElementDependencies", "false".into()),
        ]
    };
    if m.model_exchange() {
        let mut me = shared();
        me.extend([
            // the plants project the attitude back onto its manifold in the step event it requests
            ("needsCompletedIntegratorStep", "true".into()),
            ("providesEvaluateDiscreteStates", "false".into()),
        ]);
        empty(w, "ModelExchange", &me);
    }
    let mut cs = shared();
    cs.extend([
        ("canHandleVariableCommunicationStepSize", m.variable_step.to_string()),
        ("maxOutputDerivativeOrder", "0".into()),
        ("providesIntermediateUpdate", "false".into()),
        ("mightReturnEarlyFromDoStep", "false".into()),
        ("canReturnEarlyAfterIntermediateUpdate", "false".into()),
        // a model with clocks must have Event Mode (FMI 3.0 section 4.4)
        ("hasEventMode", (!m.clocks.is_empty()).to_string()),
        ("providesEvaluateDiscreteStates", "false".into()),
    ]);
    empty(w, "CoSimulation", &cs);
    if !m.clocks.is_empty() {
        // the common capability flags are the only attributes of <ScheduledExecution>
        empty(w, "ScheduledExecution", &shared());
    }
}

/// `time`, the declared variables, (Model Exchange) the continuous states and their derivatives, then the
/// clocks.
fn write_variables(w: &mut W, m: &ModelDescription, layer: &LayerInfo) {
    empty(
        w,
        "Float64",
        &[
            ("name", "time".into()),
            ("valueReference", layer.time_vr.to_string()),
            ("description", "Simulation time (the independent variable)".into()),
            ("causality", "independent".into()),
            ("variability", "continuous".into()),
        ],
    );
    for d in &m.variables {
        let mut attrs = variable_attrs(d);
        if let Some(i) = clock_of(m, &d.name) {
            // a clocked variable is discrete, and names its clock (after variability, as in the schema)
            let v = attrs
                .iter()
                .position(|(k, _)| *k == "variability")
                .expect("every variable has one");
            attrs[v].1 = "discrete".into();
            attrs.insert(v + 1, ("clocks", clock_vr(layer, i).to_string()));
        }
        attrs.extend(value_attrs(d));
        let tag = match d.kind {
            VarKind::Real => "Float64",
            VarKind::Integer => "Int32",
            VarKind::Boolean => "Boolean",
        };
        empty(w, tag, &attrs);
    }
    let states = m.state_decls();
    for (k, x) in states.iter().enumerate() {
        let mut attrs = local_attrs(x.name.clone(), layer.state_vr_base + k as u32, x.description.clone());
        if !x.unit.is_empty() {
            attrs.push(("unit", x.unit.clone()));
        }
        empty(w, "Float64", &attrs);
    }
    for (k, x) in states.iter().enumerate() {
        let description = format!("Time derivative of {}", x.name);
        let mut attrs = local_attrs(
            format!("der({})", x.name),
            layer.derivative_vr_base + k as u32,
            description,
        );
        attrs.push(("derivative", (layer.state_vr_base + k as u32).to_string()));
        empty(w, "Float64", &attrs);
    }
    write_clocks(w, m, layer);
}

/// `<ModelStructure>`: outputs, state derivatives and initial unknowns, by value reference.
fn write_structure(w: &mut W, m: &ModelDescription, layer: &LayerInfo) {
    start(w, "ModelStructure", &[]);
    for (i, d) in m
        .variables
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Output)
    {
        // an empty list is meaningful: "depends on no input" (state or time only); with Model Exchange
        // the states are variables too, and an output may depend on any of them (as in FMI 2.0)
        let mut deps = output_dependencies(m, d);
        deps.extend(state_indices(m));
        debug_assert_eq!(vr_of_index(m, layer, i + 1), d.vr);
        let mut vrs = vrs_of(m, layer, &deps);
        if let Some(k) = clock_of(m, &d.name) {
            // a clocked output depends on its clock too (the standard asks for it to be listed)
            vrs = format!("{vrs} {}", clock_vr(layer, k)).trim_start().to_string();
        }
        let attrs = [("valueReference", d.vr.to_string()), ("dependencies", vrs)];
        empty(w, "Output", &attrs);
    }
    // every state's derivative, in state order (the order of fmi3GetContinuousStates and friends)
    for (k, deps) in derivative_dependencies(m) {
        let attrs = [
            ("valueReference", (layer.derivative_vr_base + k as u32).to_string()),
            ("dependencies", vrs_of(m, layer, &deps)),
        ];
        empty(w, "ContinuousStateDerivative", &attrs);
    }
    // outputs and calculated parameters, then the states and derivatives (initial = "calculated"); a
    // clocked output is not one (its value comes from its clock's ticks)
    for (ix, deps) in initial_unknowns(m) {
        if ix <= m.variables.len() && clock_of(m, &m.variables[ix - 1].name).is_some() {
            continue;
        }
        let attrs = [
            ("valueReference", vr_of_index(m, layer, ix).to_string()),
            ("dependencies", vrs_of(m, layer, &deps)),
        ];
        empty(w, "InitialUnknown", &attrs);
    }
    end(w, "ModelStructure");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_is_the_independent_variable_and_dependencies_are_value_references() {
        let cat = crate::tests_support::project();
        let time_vr = cat.layer.time_vr;
        let m = cat.models.iter().find(|m| m.name == "PdController").unwrap();
        let x = model_description3(&cat, m);
        assert!(x.contains(r#"fmiVersion="3.0""#) && x.contains(&format!(r#"instantiationToken="{}""#, m.guid)));
        assert!(x.contains(&format!(r#"<Float64 name="time" valueReference="{time_vr}""#)));
        assert_eq!(x.matches(r#"causality="independent""#).count(), 1);
        assert!(!x.contains("ScalarVariable") && !x.contains("index="));
        for d in &m.variables {
            assert!(
                x.contains(&format!(r#"name="{}" valueReference="{}""#, d.name, d.vr)),
                "{}",
                d.name
            );
            assert_ne!(d.vr, time_vr);
        }
    }

    /// Model Exchange in FMI 3.0 follows the declarations: a `<ModelExchange>` element, a Float64 per state
    /// and per derivative (whose `derivative` is the state's value reference) and a
    /// `<ContinuousStateDerivative>` per state exactly for the models that declare states; none otherwise.
    #[test]
    fn model_exchange_elements_follow_the_declared_states() {
        let cat = crate::tests_support::project();
        for m in &cat.models {
            let x = model_description3(&cat, m);
            let n = m.state_decls().len();
            assert_eq!(x.contains("<ModelExchange "), m.model_exchange(), "{}", m.name);
            assert_eq!(x.matches("<ContinuousStateDerivative ").count(), n, "{}", m.name);
            for (k, s) in m.state_decls().iter().enumerate() {
                let (svr, dvr) = (
                    cat.layer.state_vr_base + k as u32,
                    cat.layer.derivative_vr_base + k as u32,
                );
                assert!(
                    x.contains(&format!(r#"name="{}" valueReference="{svr}""#, s.name)),
                    "{}",
                    s.name
                );
                assert!(
                    x.contains(&format!(r#"name="der({})" valueReference="{dvr}""#, s.name)),
                    "{}",
                    s.name
                );
                assert!(x.contains(&format!(r#"derivative="{svr}"/>"#)), "{}", s.name);
                assert!(
                    x.contains(&format!(r#"<InitialUnknown valueReference="{svr}""#))
                        && x.contains(&format!(r#"<InitialUnknown valueReference="{dvr}""#))
                );
            }
            // the schema's order of the ModelStructure elements
            let (o, c, i) = (
                x.rfind("<Output "),
                x.find("<ContinuousStateDerivative "),
                x.find("<InitialUnknown "),
            );
            if let (Some(o), Some(c)) = (o, c) {
                assert!(o < c, "{}", m.name);
            }
            if let (Some(c), Some(i)) = (c, i) {
                assert!(c < i, "{}", m.name);
            }
        }
    }
}
