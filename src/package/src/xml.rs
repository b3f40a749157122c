//! XML helpers both model-description writers use ([`crate::fmi2`], [`crate::fmi3`]): quick-xml events,
//! the text form of values and enumerations, the attributes of a variable's type element, and the
//! elements that are the same in FMI 2.0 and 3.0 (the root element's attributes, `<UnitDefinitions>`,
//! `<LogCategories>`, `<DefaultExperiment>`), and the document's outline both follow
//! ([`model_description_document`], given a [`Version`]).
//!
//! XML is written with quick-xml. (fmi-schema's FMI 2 types were the first choice, but their `<Real>`
//! has no `unit` attribute and an empty `dependencies=""` list, which says "no direct feed-through",
//! cannot be written; masters such as OMSimulator would then see algebraic loops that do not exist.)

use std::io::Cursor;

use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use quick_xml::Writer;

use spacecraft_fmus::catalogue::{
    Catalogue, Causality, Initial, LayerInfo, ModelDescription, PackageInfo, Start, VarKind, Variability,
    VariableDescription,
};
use spacecraft_fmus::units;

pub const GENERATION_TOOL: &str = concat!("spacecraft_fmus fmu-package ", env!("CARGO_PKG_VERSION"));

pub(crate) type W = Writer<Cursor<Vec<u8>>>;

/// A writer with the XML declaration written, indenting by two spaces.
pub(crate) fn document() -> W {
    let mut w = Writer::new_with_indent(Cursor::new(Vec::new()), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))
        .unwrap();
    w
}

/// The document as text, with a final newline.
pub(crate) fn finish(w: W) -> String {
    let mut s = String::from_utf8(w.into_inner().into_inner()).expect("quick-xml writes UTF-8");
    s.push('\n');
    s
}

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

/// Space-separated list of numbers (indices or value references).
pub(crate) fn join<T: ToString>(ix: &[T]) -> String {
    ix.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" ")
}

pub(crate) fn elem<'a>(name: &'a str, attrs: &[(&'a str, String)]) -> BytesStart<'a> {
    let mut e = BytesStart::new(name);
    for (k, v) in attrs {
        e.push_attribute((*k, v.as_str()));
    }
    e
}

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

/// `<!--text-->`.
pub(crate) fn comment(w: &mut W, text: &str) {
    w.write_event(Event::Comment(BytesText::new(text))).unwrap();
}

/// The value attributes of a declared variable's type element (`<Real>`, `<Float64>`, …), in the
/// order both FMI versions write them: unit, min, max, start.
pub(crate) fn value_attrs(d: &VariableDescription) -> Vec<(&'static str, String)> {
    let mut t: Vec<(&str, String)> = vec![];
    if !d.unit.is_empty() {
        t.push(("unit", d.unit.clone()));
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

/// The attributes every variable element starts with, in both versions: name, valueReference,
/// description, causality, variability and (where it has one) initial.
pub(crate) fn variable_attrs(d: &VariableDescription) -> Vec<(&'static str, String)> {
    let mut attrs: Vec<(&str, String)> = vec![
        ("name", d.name.clone()),
        ("valueReference", d.vr.to_string()),
        ("description", d.description.clone()),
        ("causality", causality_str(d.causality).into()),
        ("variability", variability_str(d.variability).into()),
    ];
    if let Some(init) = d.initial() {
        attrs.push(("initial", initial_str(init).into()));
    }
    attrs
}

/// What the FMI 2.0 and 3.0 descriptions differ in, for [`model_description_document`].
pub(crate) struct Version {
    /// `fmiVersion`.
    pub fmi_version: &'static str,
    /// The attribute that carries the model's GUID: `guid` (2.0), `instantiationToken` (3.0).
    pub token: &'static str,
    /// Root attributes after the shared ones (FMI 2.0: `numberOfEventIndicators`).
    pub extra: &'static [(&'static str, &'static str)],
    /// `<ModelExchange>` / `<CoSimulation>`.
    pub interfaces: fn(&mut W, &ModelDescription),
    /// The contents of `<ModelVariables>`.
    pub variables: fn(&mut W, &ModelDescription, &LayerInfo),
    /// `<ModelStructure>`.
    pub structure: fn(&mut W, &ModelDescription, &LayerInfo),
}

/// The complete modelDescription.xml of model `m` of the catalogue `cat` in FMI version `v`: the root
/// element with the attributes both versions share (model name, GUID, description, author, version,
/// license, generation tool, naming convention), the interfaces, `<UnitDefinitions>`, `<LogCategories>`,
/// `<DefaultExperiment>`, `<ModelVariables>` and `<ModelStructure>`, in the order both schemas prescribe.
pub(crate) fn model_description_document(cat: &Catalogue, m: &ModelDescription, v: &Version) -> String {
    let mut w = document();
    let mut attrs: Vec<(&str, String)> = vec![
        ("fmiVersion", v.fmi_version.into()),
        ("modelName", m.name.clone()),
        (v.token, m.guid.clone()),
        ("description", m.description.clone()),
        ("author", author(&cat.package)),
        ("version", cat.package.version.clone()),
        ("license", cat.package.license.clone()),
        ("generationTool", GENERATION_TOOL.into()),
        ("variableNamingConvention", "flat".into()),
    ];
    attrs.extend(v.extra.iter().map(|(k, x)| (*k, x.to_string())));
    start(&mut w, "fmiModelDescription", &attrs);
    (v.interfaces)(&mut w, m);
    write_unit_definitions(&mut w, m);
    write_categories_and_experiment(&mut w, m, &cat.layer);
    start(&mut w, "ModelVariables", &[]);
    (v.variables)(&mut w, m, &cat.layer);
    end(&mut w, "ModelVariables");
    (v.structure)(&mut w, m, &cat.layer);
    end(&mut w, "fmiModelDescription");
    finish(w)
}

/// The attributes of a continuous state's or a derivative's variable element (both versions): a local,
/// continuous, calculated variable.
pub(crate) fn local_attrs(name: String, vr: u32, description: String) -> Vec<(&'static str, String)> {
    vec![
        ("name", name),
        ("valueReference", vr.to_string()),
        ("description", description),
        ("causality", "local".into()),
        ("variability", "continuous".into()),
        ("initial", "calculated".into()),
    ]
}

/// `<LogCategories>` (the layer's, from the catalogue) and `<DefaultExperiment>`, the same in FMI 2.0 and 3.0.
fn write_categories_and_experiment(w: &mut W, m: &ModelDescription, layer: &LayerInfo) {
    start(w, "LogCategories", &[]);
    for (name, desc) in &layer.log_categories {
        empty(w, "Category", &[("name", name.clone()), ("description", desc.clone())]);
    }
    end(w, "LogCategories");
    let experiment = [
        ("startTime", "0.0".into()),
        ("stopTime", fmt_real(m.default_stop_time)),
        ("tolerance", "1e-8".into()),
        ("stepSize", fmt_real(m.default_step)),
    ];
    empty(w, "DefaultExperiment", &experiment);
}

/// `<UnitDefinitions>` of the units a model uses, in table order (deterministic); nothing when it uses
/// none. The same element in FMI 2.0 and 3.0.
fn write_unit_definitions(w: &mut W, m: &ModelDescription) {
    let used: Vec<_> = units::UNITS
        .iter()
        .filter(|(n, _, _)| m.variables.iter().any(|d| d.unit == *n) || m.state_decls().iter().any(|x| x.unit == *n))
        .collect();
    if used.is_empty() {
        return;
    }
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

/// Cargo's colon-separated authors as one `author` attribute (the package name when there are none).
pub(crate) fn author(p: &PackageInfo) -> String {
    if p.authors.trim().is_empty() {
        format!("{} authors", p.name)
    } else {
        p.authors.split(':').collect::<Vec<_>>().join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_formatting_is_xs_double() {
        assert_eq!(fmt_real(1e30), "1e30");
        assert_eq!(fmt_real(0.01), "0.01");
        assert_eq!(fmt_real(1.0), "1.0");
        assert_eq!(fmt_real(-2000.0), "-2000.0");
    }
}
