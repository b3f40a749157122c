//! The FMI 3.0 `modelDescription.xml` of a model, from the same declarations as the FMI 2.0 one
//! ([`crate::description`]): same variable names, value references, units, bounds and start values,
//! same log categories and default experiment. What differs:
//! - `fmiVersion="3.0"` and `instantiationToken` (the GUID the binary checks);
//! - typed variable elements (`<Float64>`, `<Int32>`, `<Boolean>`) with the attributes on the element;
//! - the independent variable `time` (value reference [`TIME_VR`]), which FMI 3.0 requires;
//! - `<ModelStructure>` lists `<Output>`, `<ContinuousStateDerivative>` and `<InitialUnknown>` by value
//!   reference, and their dependencies by value reference too (FMI 2.0: 1-based indices). The lists
//!   are the FMI 2.0 ones ([`output_dependencies`], [`derivative_dependencies`], [`initial_unknowns`],
//!   [`state_indices`]) with each index translated to its value reference, so the two descriptions
//!   cannot disagree;
//! - Model Exchange (`<ModelExchange>`, for the models that have it): the continuous states and their
//!   derivatives are `<Float64>` variables at the same value references as in FMI 2.0
//!   (`STATE_VR_BASE + k`, `DERIVATIVE_VR_BASE + k`), `derivative` names the state's value reference.

use std::io::Cursor;

use quick_xml::events::{BytesDecl, Event};
use quick_xml::Writer;

use crate::description::{
    causality_str, derivative_dependencies, empty, end, initial_str, initial_unknowns, output_dependencies, start,
    state_indices, value_attrs, variability_str, write_categories_and_experiment, write_unit_definitions, Author,
    GENERATION_TOOL,
};
use spacecraft_fmus::export::PackageInfo;
use spacecraft_fmus::fmi::fmi3::TIME_VR;
use spacecraft_fmus::model::{Causality, ModelEntry, VarKind, DERIVATIVE_VR_BASE, STATE_VR_BASE};

fn vrs(list: &[u32]) -> String {
    list.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ")
}

/// Value reference of the variable at 1-based FMI 2.0 ScalarVariable index `ix`: the declared variables,
/// then the continuous states, then their derivatives (the order of the FMI 2.0 description).
fn vr_of_index(entry: &ModelEntry, ix: usize) -> u32 {
    let (n, ns) = (entry.decls.len(), entry.state_decls().len());
    assert!(
        ix >= 1 && ix <= n + 2 * ns,
        "{}: ScalarVariable index {ix} out of range",
        entry.info.name
    );
    if ix <= n {
        entry.decls[ix - 1].vr
    } else if ix <= n + ns {
        STATE_VR_BASE + (ix - n - 1) as u32
    } else {
        DERIVATIVE_VR_BASE + (ix - n - ns - 1) as u32
    }
}

fn vrs_of(entry: &ModelEntry, ix: &[usize]) -> String {
    vrs(&ix.iter().map(|i| vr_of_index(entry, *i)).collect::<Vec<_>>())
}

/// The complete FMI 3.0 modelDescription.xml of a model whose binary accepts `token`.
pub fn model_description3(entry: &ModelEntry, token: &str, package: &PackageInfo) -> String {
    let info = entry.info;
    let mut w = Writer::new_with_indent(Cursor::new(Vec::new()), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))
        .unwrap();
    start(
        &mut w,
        "fmiModelDescription",
        &[
            ("fmiVersion", "3.0".into()),
            ("modelName", info.name.into()),
            ("instantiationToken", token.into()),
            ("description", info.description.into()),
            ("author", package.author()),
            ("version", package.version.clone()),
            ("license", package.license.clone()),
            ("generationTool", GENERATION_TOOL.into()),
            ("variableNamingConvention", "flat".into()),
        ],
    );
    // the attributes both interface elements have, in the order of the standard's schema
    let shared = || -> Vec<(&str, String)> {
        vec![
            ("modelIdentifier", info.name.into()),
            ("needsExecutionTool", "false".into()),
            ("canBeInstantiatedOnlyOncePerProcess", "false".into()),
            ("canGetAndSetFMUState", "true".into()),
            ("canSerializeFMUState", "true".into()),
            ("providesDirectionalDerivatives", "true".into()),
            ("providesAdjointDerivatives", "false".into()),
            ("providesPerElementDependencies", "false".into()),
        ]
    };
    if entry.model_exchange() {
        let mut me = shared();
        me.extend([
            // the plants project the attitude back onto its manifold in the step event it requests
            ("needsCompletedIntegratorStep", "true".into()),
            ("providesEvaluateDiscreteStates", "false".into()),
        ]);
        empty(&mut w, "ModelExchange", &me);
    }
    let mut cs = shared();
    cs.extend([
        ("canHandleVariableCommunicationStepSize", info.variable_step.to_string()),
        ("maxOutputDerivativeOrder", "0".into()),
        ("providesIntermediateUpdate", "false".into()),
        ("mightReturnEarlyFromDoStep", "false".into()),
        ("canReturnEarlyAfterIntermediateUpdate", "false".into()),
        ("hasEventMode", "false".into()),
        ("providesEvaluateDiscreteStates", "false".into()),
    ]);
    empty(&mut w, "CoSimulation", &cs);
    write_unit_definitions(&mut w, entry);
    write_categories_and_experiment(&mut w, info);

    start(&mut w, "ModelVariables", &[]);
    empty(
        &mut w,
        "Float64",
        &[
            ("name", "time".into()),
            ("valueReference", TIME_VR.to_string()),
            ("description", "Simulation time (the independent variable)".into()),
            ("causality", "independent".into()),
            ("variability", "continuous".into()),
        ],
    );
    for d in entry.decls {
        let mut attrs: Vec<(&str, String)> = vec![
            ("name", d.name.into()),
            ("valueReference", d.vr.to_string()),
            ("description", d.description.into()),
            ("causality", causality_str(d.causality).into()),
            ("variability", variability_str(d.variability).into()),
        ];
        if let Some(init) = d.initial() {
            attrs.push(("initial", initial_str(init).into()));
        }
        attrs.extend(value_attrs(d));
        let tag = match d.kind {
            VarKind::Real => "Float64",
            VarKind::Integer => "Int32",
            VarKind::Boolean => "Boolean",
        };
        empty(&mut w, tag, &attrs);
    }
    // Model Exchange: the continuous states, then their derivatives (as in FMI 2.0)
    let states = entry.state_decls();
    for (k, x) in states.iter().enumerate() {
        let mut attrs: Vec<(&str, String)> = vec![
            ("name", x.name.into()),
            ("valueReference", (STATE_VR_BASE + k as u32).to_string()),
            ("description", x.description.into()),
            ("causality", "local".into()),
            ("variability", "continuous".into()),
            ("initial", "calculated".into()),
        ];
        if !x.unit.is_empty() {
            attrs.push(("unit", x.unit.into()));
        }
        empty(&mut w, "Float64", &attrs);
    }
    for (k, x) in states.iter().enumerate() {
        empty(
            &mut w,
            "Float64",
            &[
                ("name", format!("der({})", x.name)),
                ("valueReference", (DERIVATIVE_VR_BASE + k as u32).to_string()),
                ("description", format!("Time derivative of {}", x.name)),
                ("causality", "local".into()),
                ("variability", "continuous".into()),
                ("initial", "calculated".into()),
                ("derivative", (STATE_VR_BASE + k as u32).to_string()),
            ],
        );
    }
    end(&mut w, "ModelVariables");

    start(&mut w, "ModelStructure", &[]);
    for (i, d) in entry
        .decls
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Output)
    {
        // an empty list is meaningful: "depends on no input" (state or time only); with Model Exchange
        // the states are variables too, and an output may depend on any of them (as in FMI 2.0)
        let mut deps = output_dependencies(entry, d);
        deps.extend(state_indices(entry));
        debug_assert_eq!(vr_of_index(entry, i + 1), d.vr);
        empty(
            &mut w,
            "Output",
            &[
                ("valueReference", d.vr.to_string()),
                ("dependencies", vrs_of(entry, &deps)),
            ],
        );
    }
    // every state's derivative, in state order (the order of fmi3GetContinuousStates and friends)
    for (k, deps) in derivative_dependencies(entry) {
        empty(
            &mut w,
            "ContinuousStateDerivative",
            &[
                ("valueReference", (DERIVATIVE_VR_BASE + k as u32).to_string()),
                ("dependencies", vrs_of(entry, &deps)),
            ],
        );
    }
    // outputs and calculated parameters, then the states and derivatives (initial = "calculated")
    for (ix, deps) in initial_unknowns(entry) {
        empty(
            &mut w,
            "InitialUnknown",
            &[
                ("valueReference", vr_of_index(entry, ix).to_string()),
                ("dependencies", vrs_of(entry, &deps)),
            ],
        );
    }
    end(&mut w, "ModelStructure");
    end(&mut w, "fmiModelDescription");

    let mut s = String::from_utf8(w.into_inner().into_inner()).expect("quick-xml writes UTF-8");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_is_the_independent_variable_and_dependencies_are_value_references() {
        let e = spacecraft_fmus::registry::find("PdController").unwrap();
        let x = model_description3(e, "{token}", &crate::description::project_package());
        assert!(x.contains(r#"fmiVersion="3.0""#) && x.contains(r#"instantiationToken="{token}""#));
        assert!(x.contains(&format!(r#"<Float64 name="time" valueReference="{TIME_VR}""#)));
        assert_eq!(x.matches(r#"causality="independent""#).count(), 1);
        assert!(!x.contains("ScalarVariable") && !x.contains("index="));
        for d in e.decls {
            assert!(
                x.contains(&format!(r#"name="{}" valueReference="{}""#, d.name, d.vr)),
                "{}",
                d.name
            );
            assert_ne!(d.vr, TIME_VR);
        }
    }

    /// Model Exchange in FMI 3.0 follows the declarations: a `<ModelExchange>` element, a Float64 per state
    /// and per derivative (whose `derivative` is the state's value reference) and a
    /// `<ContinuousStateDerivative>` per state exactly for the models that declare states; none otherwise.
    #[test]
    fn model_exchange_elements_follow_the_declared_states() {
        for e in spacecraft_fmus::registry::ALL {
            let x = model_description3(e, "{token}", &crate::description::project_package());
            let n = e.state_decls().len();
            assert_eq!(x.contains("<ModelExchange "), e.model_exchange(), "{}", e.info.name);
            assert_eq!(x.matches("<ContinuousStateDerivative ").count(), n, "{}", e.info.name);
            for (k, s) in e.state_decls().iter().enumerate() {
                let (svr, dvr) = (STATE_VR_BASE + k as u32, DERIVATIVE_VR_BASE + k as u32);
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
                assert!(o < c, "{}", e.info.name);
            }
            if let (Some(c), Some(i)) = (c, i) {
                assert!(c < i, "{}", e.info.name);
            }
        }
    }
}
