//! The FMI 2.0 `modelDescription.xml` of a model, from its catalogue entry: header, interface
//! elements (Model Exchange where the model declares continuous states, always Co-Simulation), units,
//! the layer's log categories, the default experiment, `<ModelVariables>` (the declared variables,
//! then each continuous state and its derivative at the layer's value references) and
//! `<ModelStructure>` (dependency lists from [`crate::structure`], as 1-based indices).

use spacecraft_fmus::catalogue::{Catalogue, Causality, LayerInfo, ModelDescription, VarKind};

use crate::structure::{derivative_dependencies, initial_unknowns, output_dependencies, state_indices};
use crate::xml::{
    comment, empty, end, join, local_attrs, model_description_document, start, value_attrs, variable_attrs, Version, W,
};

/// The complete FMI 2.0 modelDescription.xml of model `m` of the catalogue `cat`.
pub fn model_description(cat: &Catalogue, m: &ModelDescription) -> String {
    let v = Version {
        fmi_version: "2.0",
        token: "guid",
        extra: &[("numberOfEventIndicators", "0")],
        interfaces: write_interfaces,
        variables: write_variables,
        structure: write_structure,
    };
    model_description_document(cat, m, &v)
}

/// `<ModelExchange>` (models with continuous states) and `<CoSimulation>`.
fn write_interfaces(w: &mut W, m: &ModelDescription) {
    if m.model_exchange() {
        empty(
            w,
            "ModelExchange",
            &[
                ("modelIdentifier", m.name.clone()),
                ("needsExecutionTool", "false".into()),
                ("completedIntegratorStepNotNeeded", "false".into()),
                ("canBeInstantiatedOnlyOncePerProcess", "false".into()),
                ("canNotUseMemoryManagementFunctions", "true".into()),
                ("canGetAndSetFMUstate", "true".into()),
                ("canSerializeFMUstate", "true".into()),
                ("providesDirectionalDerivative", "true".into()),
            ],
        );
    }
    empty(
        w,
        "CoSimulation",
        &[
            ("modelIdentifier", m.name.clone()),
            ("needsExecutionTool", "false".into()),
            ("canHandleVariableCommunicationStepSize", m.variable_step.to_string()),
            ("canInterpolateInputs", "false".into()),
            ("maxOutputDerivativeOrder", "0".into()),
            ("canRunAsynchronuously", "false".into()),
            ("canBeInstantiatedOnlyOncePerProcess", "false".into()),
            ("canNotUseMemoryManagementFunctions", "true".into()),
            ("canGetAndSetFMUstate", "true".into()),
            ("canSerializeFMUstate", "true".into()),
            ("providesDirectionalDerivative", "true".into()),
        ],
    );
}

/// One `<ScalarVariable>` per declared variable, then per continuous state, then per derivative.
fn write_variables(w: &mut W, m: &ModelDescription, layer: &LayerInfo) {
    for (i, d) in m.variables.iter().enumerate() {
        comment(w, &format!(" index {} ", i + 1));
        start(w, "ScalarVariable", &variable_attrs(d));
        let tag = match d.kind {
            VarKind::Real => "Real",
            VarKind::Integer => "Integer",
            VarKind::Boolean => "Boolean",
        };
        empty(w, tag, &value_attrs(d));
        end(w, "ScalarVariable");
    }
    let n_decl = m.variables.len();
    let states = m.state_decls();
    for (k, x) in states.iter().enumerate() {
        comment(w, &format!(" index {}: continuous state {} ", n_decl + k + 1, k + 1));
        let attrs = local_attrs(x.name.clone(), layer.state_vr_base + k as u32, x.description.clone());
        start(w, "ScalarVariable", &attrs);
        let t: Vec<(&str, String)> = if x.unit.is_empty() {
            vec![]
        } else {
            vec![("unit", x.unit.clone())]
        };
        empty(w, "Real", &t);
        end(w, "ScalarVariable");
    }
    for (k, x) in states.iter().enumerate() {
        let ix = n_decl + states.len() + k + 1;
        comment(w, &format!(" index {ix}: derivative of state {} ", k + 1));
        let vr = layer.derivative_vr_base + k as u32;
        let attrs = local_attrs(format!("der({})", x.name), vr, format!("Time derivative of {}", x.name));
        start(w, "ScalarVariable", &attrs);
        empty(w, "Real", &[("derivative", (n_decl + k + 1).to_string())]);
        end(w, "ScalarVariable");
    }
}

/// `<ModelStructure>`: outputs, derivatives and initial unknowns with their dependencies.
fn write_structure(w: &mut W, m: &ModelDescription, _layer: &LayerInfo) {
    start(w, "ModelStructure", &[]);
    let outputs: Vec<_> = m
        .variables
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Output)
        .collect();
    if !outputs.is_empty() {
        start(w, "Outputs", &[]);
        for (i, d) in outputs {
            // An empty list is meaningful: "depends on no input" (state or time only).
            let mut deps = output_dependencies(m, d);
            // with Model Exchange the states are variables too: an output may depend on any of them
            deps.extend(state_indices(m));
            let attrs = [("index", (i + 1).to_string()), ("dependencies", join(&deps))];
            empty(w, "Unknown", &attrs);
        }
        end(w, "Outputs");
    }
    let (n_decl, n_states) = (m.variables.len(), m.state_decls().len());
    if n_states > 0 {
        start(w, "Derivatives", &[]);
        for (k, deps) in derivative_dependencies(m) {
            let attrs = [
                ("index", (n_decl + n_states + k + 1).to_string()),
                ("dependencies", join(&deps)),
            ];
            empty(w, "Unknown", &attrs);
        }
        end(w, "Derivatives");
    }
    let initial_unknowns = initial_unknowns(m);
    if !initial_unknowns.is_empty() {
        start(w, "InitialUnknowns", &[]);
        for (ix, deps) in initial_unknowns {
            // Always written: a missing attribute would mean "depends on every known" (inputs included).
            empty(
                w,
                "Unknown",
                &[("index", ix.to_string()), ("dependencies", join(&deps))],
            );
        }
        end(w, "InitialUnknowns");
    }
    end(w, "ModelStructure");
}
