//! The FMI 3.0 `modelDescription.xml` of a model, from the same declarations as the FMI 2.0 one
//! ([`crate::description`]): same variable names, value references, units, bounds and start values,
//! same log categories and default experiment. What differs:
//! - `fmiVersion="3.0"` and `instantiationToken` (the GUID the binary checks);
//! - typed variable elements (`<Float64>`, `<Int32>`, `<Boolean>`) with the attributes on the element;
//! - the independent variable `time` (value reference [`TIME_VR`]), which FMI 3.0 requires;
//! - `<ModelStructure>` lists `<Output>` and `<InitialUnknown>` by value reference, and their
//!   dependencies by value reference too (FMI 2.0: 1-based indices).

use std::io::Cursor;

use quick_xml::events::{BytesDecl, BytesEnd, Event};
use quick_xml::Writer;

use crate::description::{
    bound_str, causality_str, elem, Author, initial_str, initial_unknowns, start_str, variability_str, write_categories_and_experiment, write_unit_definitions, GENERATION_TOOL,
};
use spacecraft_fmus::export::PackageInfo;
use spacecraft_fmus::fmi::fmi3::TIME_VR;
use spacecraft_fmus::fmi::fmi3_more::output_dependency_vrs;
use spacecraft_fmus::model::{Causality, ModelEntry, VarKind};

type W = Writer<Cursor<Vec<u8>>>;

fn empty(w: &mut W, name: &str, attrs: &[(&str, String)]) {
    w.write_event(Event::Empty(elem(name, attrs))).unwrap();
}

fn start(w: &mut W, name: &str, attrs: &[(&str, String)]) {
    w.write_event(Event::Start(elem(name, attrs))).unwrap();
}

fn end(w: &mut W, name: &str) {
    w.write_event(Event::End(BytesEnd::new(name))).unwrap();
}

fn vrs(list: &[u32]) -> String {
    list.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ")
}

/// The complete FMI 3.0 modelDescription.xml of a model whose binary accepts `token`.
pub fn model_description3(entry: &ModelEntry, token: &str, package: &PackageInfo) -> String {
    let info = entry.info;
    let mut w = Writer::new_with_indent(Cursor::new(Vec::new()), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None))).unwrap();
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
    empty(
        &mut w,
        "CoSimulation",
        &[
            ("modelIdentifier", info.name.into()),
            ("needsExecutionTool", "false".into()),
            ("canBeInstantiatedOnlyOncePerProcess", "false".into()),
            ("canGetAndSetFMUState", "true".into()),
            ("canSerializeFMUState", "true".into()),
            ("providesDirectionalDerivatives", "true".into()),
            ("providesAdjointDerivatives", "false".into()),
            ("providesPerElementDependencies", "false".into()),
            ("canHandleVariableCommunicationStepSize", info.variable_step.to_string()),
            ("maxOutputDerivativeOrder", "0".into()),
            ("providesIntermediateUpdate", "false".into()),
            ("mightReturnEarlyFromDoStep", "false".into()),
            ("canReturnEarlyAfterIntermediateUpdate", "false".into()),
            ("hasEventMode", "false".into()),
            ("providesEvaluateDiscreteStates", "false".into()),
        ],
    );
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
        if !d.unit.is_empty() {
            attrs.push(("unit", d.unit.into()));
        }
        let (min, max) = d.bound.min_max();
        if let Some(m) = min {
            attrs.push(("min", bound_str(d.kind, m)));
        }
        if let Some(m) = max {
            attrs.push(("max", bound_str(d.kind, m)));
        }
        if d.has_start() {
            attrs.push(("start", start_str(d.start)));
        }
        let tag = match d.kind {
            VarKind::Real => "Float64",
            VarKind::Integer => "Int32",
            VarKind::Boolean => "Boolean",
        };
        empty(&mut w, tag, &attrs);
    }
    end(&mut w, "ModelVariables");

    start(&mut w, "ModelStructure", &[]);
    for d in entry.decls.iter().filter(|d| d.causality == Causality::Output) {
        // an empty list is meaningful: "depends on no input" (state or time only)
        empty(&mut w, "Output", &[("valueReference", d.vr.to_string()), ("dependencies", vrs(&output_dependency_vrs(entry, d.name)))]);
    }
    // the declared variables only: the continuous states of FMI 2.0 Model Exchange are not published in FMI 3.0 (CS only)
    for (ix, deps) in initial_unknowns(entry).into_iter().filter(|(ix, _)| *ix <= entry.decls.len()) {
        let dep_vrs: Vec<u32> = deps.iter().map(|i| entry.decls[i - 1].vr).collect();
        empty(&mut w, "InitialUnknown", &[("valueReference", entry.decls[ix - 1].vr.to_string()), ("dependencies", vrs(&dep_vrs))]);
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
            assert!(x.contains(&format!(r#"name="{}" valueReference="{}""#, d.name, d.vr)), "{}", d.name);
            assert_ne!(d.vr, TIME_VR);
        }
    }
}
