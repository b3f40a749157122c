//! Generates `modelDescription.xml` and `documentation/index.html` from a model's declarations, as the
//! runtime exports them (the packaging tool reads them from a built library's catalogue; the project's
//! own pages and tests read the registry directly). The runtime never renders XML.
//!
//! XML is written with quick-xml. (fmi-schema's FMI 2 types were the first choice, but their `<Real>`
//! has no `unit` attribute and an empty `dependencies=""` list, which says "no direct feed-through",
//! cannot be written; masters such as OMSimulator would then see algebraic loops that do not exist.)

use std::io::Cursor;

use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use quick_xml::Writer;

use spacecraft_fmus::export::PackageInfo;
use spacecraft_fmus::fmi::LOG_CATEGORIES;
use spacecraft_fmus::model::{
    Bound, Causality, Feedthrough, Initial, ModelEntry, ModelInfo, Start, VarDecl, VarKind, Variability,
    DERIVATIVE_VR_BASE, RESERVED_VR_START, STATE_VR_BASE,
};
use spacecraft_fmus::units;

use crate::structure::input_index;
pub use crate::structure::{derivative_dependencies, initial_unknowns, output_dependencies, state_indices};

pub const GENERATION_TOOL: &str = concat!("spacecraft_fmus fmu-package ", env!("CARGO_PKG_VERSION"));

pub(crate) fn causality_str(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::CalculatedParameter => "calculatedParameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
    }
}

pub(crate) fn variability_str(v: Variability) -> &'static str {
    match v {
        Variability::Constant => "constant",
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

pub(crate) fn initial_str(i: Initial) -> &'static str {
    match i {
        Initial::Exact => "exact",
        Initial::Approx => "approx",
        Initial::Calculated => "calculated",
    }
}

/// xs:double text of a finite value ("1e30", "0.01", "1.0").
pub fn fmt_real(v: f64) -> String {
    assert!(v.is_finite(), "non-finite value cannot go into modelDescription");
    format!("{v:?}")
}

pub(crate) fn start_str(s: Start) -> String {
    match s {
        Start::Real(v) => fmt_real(v),
        Start::Integer(v) => v.to_string(),
        Start::Boolean(v) => v.to_string(),
    }
}

pub(crate) fn bound_str(kind: VarKind, v: f64) -> String {
    if kind == VarKind::Integer {
        (v as i32).to_string()
    } else {
        fmt_real(v)
    }
}

fn join(ix: &[usize]) -> String {
    ix.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" ")
}

/// Checks of a declaration table that the type system cannot make: unique names and value
/// references, known units, feed-through names that are outputs and inputs.
pub fn check_declarations(entry: &ModelEntry) -> Result<(), String> {
    let name = entry.info.name;
    for (i, a) in entry.decls.iter().enumerate() {
        for b in &entry.decls[i + 1..] {
            if a.name == b.name {
                return Err(format!("{name}: duplicate variable name {}", a.name));
            }
            // Unique across kinds too: the generated slot/value dispatch matches on the number only.
            if a.vr == b.vr {
                return Err(format!(
                    "{name}: {} and {} share value reference {}",
                    a.name, b.name, a.vr
                ));
            }
        }
        if a.vr == spacecraft_fmus::fmi::fmi3::TIME_VR {
            return Err(format!(
                "{name}: {} uses value reference {}, reserved for time in FMI 3.0",
                a.name, a.vr
            ));
        }
        if !a.unit.is_empty() && units::lookup(a.unit).is_none() {
            return Err(format!("{name}: variable {} uses undefined unit {}", a.name, a.unit));
        }
        if !a.unit.is_empty() && a.kind != VarKind::Real {
            return Err(format!("{name}: only Real variables carry units ({})", a.name));
        }
        if a.description.is_empty() {
            return Err(format!("{name}: variable {} has no description", a.name));
        }
        if let Start::Real(v) = a.start {
            if !v.is_finite() {
                return Err(format!("{name}: start of {} is not finite", a.name));
            }
        }
        if a.causality == Causality::Parameter {
            let ok = match a.start {
                Start::Real(v) => a.bound.check_real(a.name, v),
                Start::Integer(v) => a.bound.check_integer(a.name, v),
                Start::Boolean(_) => Ok(()),
            };
            ok.map_err(|e| format!("{name}: start value outside the declared bound: {e}"))?;
        } else if a.bound != Bound::Any {
            return Err(format!("{name}: {} has a bound but is not a parameter", a.name));
        }
    }
    for d in entry.decls {
        if d.vr >= RESERVED_VR_START && d.vr != spacecraft_fmus::fmi::fmi3::TIME_VR {
            return Err(format!("{name}: {} uses value reference {}, reserved for the layer's Model Exchange variables (>= {RESERVED_VR_START})", d.name, d.vr));
        }
    }
    let states = entry.state_decls();
    for (i, x) in states.iter().enumerate() {
        let der = format!("der({})", x.name);
        if entry.decl(x.name).is_some()
            || entry.decl(&der).is_some()
            || states[i + 1..].iter().any(|y| y.name == x.name)
        {
            return Err(format!(
                "{name}: continuous state {} clashes with another variable name",
                x.name
            ));
        }
        if !x.unit.is_empty() && units::lookup(x.unit).is_none() {
            return Err(format!(
                "{name}: continuous state {} uses undefined unit {}",
                x.name, x.unit
            ));
        }
        if x.description.is_empty() {
            return Err(format!("{name}: continuous state {} has no description", x.name));
        }
        for d in x.starts_from {
            if input_index(entry, d).is_none() {
                return Err(format!(
                    "{name}: the start of continuous state {} is taken from {d}, which is not an input (inputs: {})",
                    x.name,
                    crate::names::of_causality(entry, Causality::Input)
                ));
            }
        }
        for d in x.depends.unwrap_or(&[]) {
            let input = entry.decl(d).is_some_and(|v| v.causality == Causality::Input);
            if !input && !states.iter().any(|y| y.name == *d) {
                return Err(format!("{name}: the derivative of continuous state {} depends on {d}, which is neither an input nor a continuous state (valid: {})", x.name, crate::names::inputs_and_states(entry)));
            }
        }
    }
    if states.len() > (DERIVATIVE_VR_BASE - STATE_VR_BASE) as usize {
        return Err(format!(
            "{name}: {} continuous states are more than the layer can number",
            states.len()
        ));
    }
    if let Feedthrough::Some(list) = entry.info.feedthrough {
        for (o, ins) in list {
            match entry.decl(o) {
                Some(d) if d.causality == Causality::Output => {}
                _ => {
                    let valid = crate::names::of_causality(entry, Causality::Output);
                    return Err(format!(
                        "{name}: feedthrough output {o} is not an output (outputs: {valid})"
                    ));
                }
            }
            for i in *ins {
                match entry.decl(i) {
                    Some(d) if d.causality == Causality::Input => {}
                    _ => {
                        let valid = crate::names::of_causality(entry, Causality::Input);
                        return Err(format!(
                            "{name}: feedthrough input {i} is not an input (inputs: {valid})"
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

pub(crate) fn elem<'a>(name: &'a str, attrs: &[(&'a str, String)]) -> BytesStart<'a> {
    let mut e = BytesStart::new(name);
    for (k, v) in attrs {
        e.push_attribute((*k, v.as_str()));
    }
    e
}

pub(crate) type W = Writer<Cursor<Vec<u8>>>;

/// `<name attrs/>`.
pub(crate) fn empty(w: &mut W, name: &str, attrs: &[(&str, String)]) {
    w.write_event(Event::Empty(elem(name, attrs))).unwrap();
}

/// `<name attrs>`.
pub(crate) fn start(w: &mut W, name: &str, attrs: &[(&str, String)]) {
    w.write_event(Event::Start(elem(name, attrs))).unwrap();
}

/// `</name>`.
pub(crate) fn end(w: &mut W, name: &str) {
    w.write_event(Event::End(BytesEnd::new(name))).unwrap();
}

/// The value attributes of a declared variable's type element (`<Real>`, `<Float64>`, …), in the
/// order both FMI versions write them: unit, min, max, start.
pub(crate) fn value_attrs(d: &VarDecl) -> Vec<(&'static str, String)> {
    let mut t: Vec<(&str, String)> = vec![];
    if !d.unit.is_empty() {
        t.push(("unit", d.unit.into()));
    }
    let (min, max) = d.bound.min_max();
    if let Some(m) = min {
        t.push(("min", bound_str(d.kind, m)));
    }
    if let Some(m) = max {
        t.push(("max", bound_str(d.kind, m)));
    }
    if d.has_start() {
        t.push(("start", start_str(d.start)));
    }
    t
}

/// `<UnitDefinitions>` of the units a model uses, in table order (deterministic); nothing when it uses
/// none. The same element in FMI 2.0 and 3.0.
/// `<LogCategories>` and `<DefaultExperiment>`, the same in FMI 2.0 and 3.0.
pub(crate) fn write_categories_and_experiment(w: &mut Writer<Cursor<Vec<u8>>>, info: &ModelInfo) {
    w.write_event(Event::Start(elem("LogCategories", &[]))).unwrap();
    for (name, desc) in LOG_CATEGORIES {
        w.write_event(Event::Empty(elem(
            "Category",
            &[("name", (*name).into()), ("description", (*desc).into())],
        )))
        .unwrap();
    }
    w.write_event(Event::End(BytesEnd::new("LogCategories"))).unwrap();
    let experiment = [
        ("startTime", "0.0".into()),
        ("stopTime", fmt_real(info.default_stop_time)),
        ("tolerance", "1e-8".into()),
        ("stepSize", fmt_real(info.default_step)),
    ];
    w.write_event(Event::Empty(elem("DefaultExperiment", &experiment)))
        .unwrap();
}

pub(crate) fn write_unit_definitions(w: &mut W, entry: &ModelEntry) {
    let used: Vec<_> = units::UNITS
        .iter()
        .filter(|(n, _, _)| {
            entry.decls.iter().any(|d| d.unit == *n) || entry.state_decls().iter().any(|x| x.unit == *n)
        })
        .collect();
    if !used.is_empty() {
        start(w, "UnitDefinitions", &[]);
        for (name, b, display) in used {
            start(w, "Unit", &[("name", (*name).into())]);
            let mut attrs: Vec<(&str, String)> = vec![];
            for (k, v) in [("kg", b.kg), ("m", b.m), ("s", b.s), ("A", b.a), ("rad", b.rad)] {
                if v != 0 {
                    attrs.push((k, v.to_string()));
                }
            }
            if b.factor != 1.0 {
                attrs.push(("factor", fmt_real(b.factor)));
            }
            empty(w, "BaseUnit", &attrs);
            for (dn, f) in display.iter() {
                empty(w, "DisplayUnit", &[("name", (*dn).into()), ("factor", fmt_real(*f))]);
            }
            end(w, "Unit");
        }
        end(w, "UnitDefinitions");
    }
}

/// Writes the complete model description with the given GUID.
fn write_xml(entry: &ModelEntry, guid: &str, package: &PackageInfo) -> String {
    let info = entry.info;
    let mut w = Writer::new_with_indent(Cursor::new(Vec::new()), b' ', 2);

    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))
        .unwrap();
    start(
        &mut w,
        "fmiModelDescription",
        &[
            ("fmiVersion", "2.0".into()),
            ("modelName", info.name.into()),
            ("guid", guid.into()),
            ("description", info.description.into()),
            ("author", package.author()),
            ("version", package.version.clone()),
            ("license", package.license.clone()),
            ("generationTool", GENERATION_TOOL.into()),
            ("variableNamingConvention", "flat".into()),
            ("numberOfEventIndicators", "0".into()),
        ],
    );
    if entry.model_exchange() {
        empty(
            &mut w,
            "ModelExchange",
            &[
                ("modelIdentifier", info.name.into()),
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
        &mut w,
        "CoSimulation",
        &[
            ("modelIdentifier", info.name.into()),
            ("needsExecutionTool", "false".into()),
            ("canHandleVariableCommunicationStepSize", info.variable_step.to_string()),
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

    write_unit_definitions(&mut w, entry);
    write_categories_and_experiment(&mut w, info);

    start(&mut w, "ModelVariables", &[]);
    for (i, d) in entry.decls.iter().enumerate() {
        w.write_event(Event::Comment(BytesText::new(&format!(" index {} ", i + 1))))
            .unwrap();
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
        start(&mut w, "ScalarVariable", &attrs);
        let t = value_attrs(d);
        let tag = match d.kind {
            VarKind::Real => "Real",
            VarKind::Integer => "Integer",
            VarKind::Boolean => "Boolean",
        };
        empty(&mut w, tag, &t);
        end(&mut w, "ScalarVariable");
    }
    let n_decl = entry.decls.len();
    let states = entry.state_decls();
    for (k, x) in states.iter().enumerate() {
        w.write_event(Event::Comment(BytesText::new(&format!(
            " index {}: continuous state {} ",
            n_decl + k + 1,
            k + 1
        ))))
        .unwrap();
        let attrs: Vec<(&str, String)> = vec![
            ("name", x.name.into()),
            ("valueReference", (STATE_VR_BASE + k as u32).to_string()),
            ("description", x.description.into()),
            ("causality", "local".into()),
            ("variability", "continuous".into()),
            ("initial", "calculated".into()),
        ];
        start(&mut w, "ScalarVariable", &attrs);
        let t: Vec<(&str, String)> = if x.unit.is_empty() {
            vec![]
        } else {
            vec![("unit", x.unit.into())]
        };
        empty(&mut w, "Real", &t);
        end(&mut w, "ScalarVariable");
    }
    for (k, x) in states.iter().enumerate() {
        w.write_event(Event::Comment(BytesText::new(&format!(
            " index {}: derivative of state {} ",
            n_decl + states.len() + k + 1,
            k + 1
        ))))
        .unwrap();
        let attrs: Vec<(&str, String)> = vec![
            ("name", format!("der({})", x.name)),
            ("valueReference", (DERIVATIVE_VR_BASE + k as u32).to_string()),
            ("description", format!("Time derivative of {}", x.name)),
            ("causality", "local".into()),
            ("variability", "continuous".into()),
            ("initial", "calculated".into()),
        ];
        start(&mut w, "ScalarVariable", &attrs);
        empty(&mut w, "Real", &[("derivative", (n_decl + k + 1).to_string())]);
        end(&mut w, "ScalarVariable");
    }
    end(&mut w, "ModelVariables");

    start(&mut w, "ModelStructure", &[]);
    let outputs: Vec<(usize, &VarDecl)> = entry
        .decls
        .iter()
        .enumerate()
        .filter(|(_, d)| d.causality == Causality::Output)
        .map(|(i, d)| (i + 1, d))
        .collect();
    if !outputs.is_empty() {
        start(&mut w, "Outputs", &[]);
        for (ix, d) in &outputs {
            // An empty list is meaningful: "depends on no input" (state or time only).
            let mut deps = output_dependencies(entry, d);
            // with Model Exchange the states are variables too: an output may depend on any of them
            deps.extend(state_indices(entry));
            empty(
                &mut w,
                "Unknown",
                &[("index", ix.to_string()), ("dependencies", join(&deps))],
            );
        }
        end(&mut w, "Outputs");
    }
    if !states.is_empty() {
        start(&mut w, "Derivatives", &[]);
        for (k, deps) in derivative_dependencies(entry) {
            empty(
                &mut w,
                "Unknown",
                &[
                    ("index", (n_decl + states.len() + k + 1).to_string()),
                    ("dependencies", join(&deps)),
                ],
            );
        }
        end(&mut w, "Derivatives");
    }
    let initial_unknowns = initial_unknowns(entry);
    if !initial_unknowns.is_empty() {
        start(&mut w, "InitialUnknowns", &[]);
        for (ix, deps) in initial_unknowns {
            // Always written: a missing attribute would mean "depends on every known" (inputs included).
            empty(
                &mut w,
                "Unknown",
                &[("index", ix.to_string()), ("dependencies", join(&deps))],
            );
        }
        end(&mut w, "InitialUnknowns");
    }
    end(&mut w, "ModelStructure");
    end(&mut w, "fmiModelDescription");

    let mut s = String::from_utf8(w.into_inner().into_inner()).expect("quick-xml writes UTF-8");
    s.push('\n');
    s
}

/// The complete modelDescription.xml of a model whose binary accepts `guid`, exported by `package`.
pub fn model_description(entry: &ModelEntry, guid: &str, package: &PackageInfo) -> String {
    write_xml(entry, guid, package)
}

/// `author`, `version` and `license` of the project's own models (the metadata of `src/cdylib`, whose
/// catalogue says the same; `fmu-package --check` compares the two outputs).
pub fn project_package() -> PackageInfo {
    PackageInfo {
        name: "spacecraft_fmus_cdylib".into(),
        version: "0.1.0".into(),
        authors: "spacecraft_fmus contributors".into(),
        license: "BSD-2-Clause".into(),
    }
}

/// Cargo's colon-separated authors as one `author` attribute (the package name when there are none).
pub(crate) trait Author {
    fn author(&self) -> String;
}

impl Author for PackageInfo {
    fn author(&self) -> String {
        if self.authors.trim().is_empty() {
            format!("{} authors", self.name)
        } else {
            self.authors.split(':').collect::<Vec<_>>().join(", ")
        }
    }
}

pub(crate) fn bound_text(b: Bound) -> String {
    match b {
        Bound::Any => String::new(),
        Bound::Positive => "> 0".into(),
        Bound::NonNegative => ">= 0".into(),
        Bound::Limit => ">= 0 (1e30 = no limit)".into(),
        Bound::Range(lo, hi) => format!("[{lo}, {hi}]"),
        Bound::Choice(codes) => format!("one of {codes:?}"),
    }
}

pub(crate) fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// documentation/index.html: purpose, source, equations, variable tables.
/// The variable tables of a model's documentation (HTML page and Markdown model pages), in order.
pub(crate) const VARIABLE_SECTIONS: [(&str, Causality); 5] = [
    ("Parameters", Causality::Parameter),
    ("Inputs", Causality::Input),
    ("Outputs", Causality::Output),
    ("Calculated parameters", Causality::CalculatedParameter),
    ("Local variables", Causality::Local),
];

/// Which FMI interfaces a model offers, in one sentence (model pages and documentation/index.html).
pub fn interfaces_text(entry: &ModelEntry) -> String {
    match entry.states {
        Some([]) => "FMI 2.0 and FMI 3.0 Model Exchange (a static law: no continuous state) and Co-Simulation.".into(),
        Some(states) => format!(
            "FMI 2.0 and FMI 3.0 Model Exchange ({} continuous states: {}) and Co-Simulation.",
            states.len(),
            states.iter().map(|x| x.name).collect::<Vec<_>>().join(", ")
        ),
        None if !entry.info.variable_step => "FMI 2.0 and FMI 3.0 Co-Simulation only: a sampled law (its behaviour is defined at its sample times, not as a continuous right-hand side).".into(),
        None => "FMI 2.0 and FMI 3.0 Co-Simulation only: its internal state evolves in discrete steps (not as a continuous right-hand side).".into(),
    }
}

pub fn documentation_html(entry: &ModelEntry, guid: &str) -> String {
    let info = entry.info;
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    h.push_str(&format!("<title>{}</title>\n", info.name));
    h.push_str("<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:left;vertical-align:top}pre{background:#f4f4f4;padding:0.5em;overflow-x:auto}code{background:#f4f4f4}</style>\n</head>\n<body>\n");
    h.push_str(&format!(
        "<h1>{}</h1>\n<p>{}</p>\n",
        info.name,
        html_escape(info.description)
    ));
    h.push_str(&format!("<p><b>Source:</b> {}</p>\n", html_escape(info.source)));
    h.push_str(&format!(
        "<p><b>GUID:</b> <code>{}</code> &middot; <b>Generated by:</b> {}</p>\n",
        guid, GENERATION_TOOL
    ));
    h.push_str(&format!(
        "<p><b>Interfaces:</b> {}</p>\n",
        html_escape(&interfaces_text(entry))
    ));
    h.push_str("<h2>Equations</h2>\n");
    h.push_str(info.equations_html);
    h.push_str("\n<h2>Conventions</h2>\n<ul><li>SI units on every port; degrees only where the name ends in <code>_deg</code>.</li>");
    h.push_str("<li>Quaternions are scalar-first Hamilton quaternions (q_w, q_x, q_y, q_z) of the body frame relative to the reference frame; A(q) maps reference components into body components.</li>");
    h.push_str(
        "<li>Parameters are read at fmi2ExitInitializationMode; invalid values give fmi2Error with a log message.</li>",
    );
    h.push_str("<li>\"No limit\" is encoded as 1e30.</li></ul>\n");
    for (title, caus) in VARIABLE_SECTIONS {
        let rows: Vec<&VarDecl> = entry.decls.iter().filter(|d| d.causality == caus).collect();
        if rows.is_empty() {
            continue;
        }
        h.push_str(&format!("<h2>{title}</h2>\n<table>\n<tr><th>name</th><th>vr</th><th>type</th><th>variability</th><th>start</th><th>unit</th><th>admissible</th><th>meaning</th></tr>\n"));
        for d in rows {
            let start = if d.has_start() {
                start_str(d.start)
            } else {
                String::new()
            };
            h.push_str(&format!(
                "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                d.name,
                d.vr,
                d.kind,
                variability_str(d.variability),
                start,
                html_escape(d.unit),
                html_escape(&bound_text(d.bound)),
                html_escape(d.description)
            ));
        }
        h.push_str("</table>\n");
    }
    let cited = crate::references::cited_in(entry.texts());
    if !cited.is_empty() {
        h.push_str("<h2>References</h2>\n<ul>\n");
        for r in cited {
            h.push_str(&format!(
                "<li><b>[{}]</b> {}</li>\n",
                r.key,
                html_escape(&crate::references::citation(r))
            ));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_model_has_consistent_declarations() {
        for e in spacecraft_fmus::registry::ALL {
            check_declarations(e).unwrap();
        }
    }

    #[test]
    fn the_fmi3_time_value_reference_is_reserved() {
        let e = spacecraft_fmus::registry::find("PdController").unwrap();
        let mut decls = e.decls.to_vec();
        decls[0].vr = spacecraft_fmus::fmi::fmi3::TIME_VR;
        let bad = ModelEntry {
            decls: Box::leak(decls.into_boxed_slice()),
            ..*e
        };
        assert!(check_declarations(&bad)
            .unwrap_err()
            .contains("reserved for time in FMI 3.0"));
    }

    #[test]
    fn real_formatting_is_xs_double() {
        assert_eq!(fmt_real(1e30), "1e30");
        assert_eq!(fmt_real(0.01), "0.01");
        assert_eq!(fmt_real(1.0), "1.0");
        assert_eq!(fmt_real(-2000.0), "-2000.0");
    }
}
