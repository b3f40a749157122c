//! The FMI 3.0 model descriptions against independent references: every committed
//! `modelDescription/fmi3/*.xml` validates against the official FMI 3.0 XSD (shipped inside fmi-rs,
//! validated with libxml2: [`xsd`]) and passes fmi-rs's own FMI 3.0 checks; a clocked model's description
//! says what the standard asks of clocks, read back by fmi-rs's FMI 3.0 reader (not by this crate's writer).

mod xsd;

use std::path::{Path, PathBuf};

use fmi_rs::model_description::fmi3::{Causality, ModelDescription, Variability, VariableType};
use spacecraft_fmus::catalogue::{Catalogue, ClockDescription};
use spacecraft_fmus_package::{check_catalogue, model_description, model_description3};

fn project() -> Catalogue {
    let cat = spacecraft_fmus::export::project_catalogue();
    check_catalogue(&cat).unwrap();
    cat
}

fn committed() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription/fmi3");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    files
}

/// The XSD's and fmi-rs's complaints about one FMI 3.0 description (empty: valid).
fn problems(xml: &str) -> Vec<String> {
    let mut p = xsd::Schema::fmi3_model_description().problems(xml);
    match ModelDescription::from_string(xml) {
        Ok(md) => p.extend(md.validate().into_iter().map(|e| e.message)),
        Err(e) => p.push(format!("fmi-rs cannot read it: {e}")),
    }
    p
}

#[test]
fn every_committed_fmi3_description_is_valid_against_the_official_schema() {
    let files = committed();
    assert!(files.len() >= 30, "only {} files: wrong folder?", files.len());
    let mut bad = vec![];
    for f in &files {
        let p = problems(&std::fs::read_to_string(f).unwrap());
        if !p.is_empty() {
            bad.push(format!("{}: {p:?}", f.display()));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// The validation is not blind: a description the schema forbids (an unknown causality, elements out of
/// the schema's order, a `<Clock>` without its required `intervalVariability`) is refused.
#[test]
fn the_schema_refuses_a_broken_description() {
    let schema = xsd::Schema::fmi3_model_description();
    let good = std::fs::read_to_string(&committed()[0]).unwrap();
    assert_eq!(schema.problems(&good), Vec::<String>::new());
    let refused = |broken: String| {
        assert_ne!(broken, good);
        let p = schema.problems(&broken);
        assert!(!p.is_empty(), "the schema accepts a broken description");
        p
    };
    let p = refused(good.replacen(r#"causality="parameter""#, r#"causality="knob""#, 1));
    assert!(p.iter().any(|m| m.contains("knob")), "{p:?}");
    // <DefaultExperiment> before <LogCategories>
    let (lc, de) = (
        good.find("  <LogCategories>").unwrap(),
        good.find("  <DefaultExperiment ").unwrap(),
    );
    let de_end = de + good[de..].find('\n').unwrap() + 1;
    assert!(lc < de);
    refused(format!(
        "{}{}{}{}",
        &good[..lc],
        &good[de..de_end],
        &good[lc..de],
        &good[de_end..]
    ));
    let clock = r#"<Clock name="c" valueReference="1000200000" causality="input" variability="discrete"/>"#;
    refused(good.replacen("</ModelVariables>", &format!("{clock}</ModelVariables>"), 1));
}

/// The project's catalogue, whose sampled units declare clocks.
fn clocked_catalogue() -> Catalogue {
    let cat = project();
    let n = cat.models.iter().filter(|m| !m.clocks.is_empty()).count();
    assert!(n >= 10, "only {n} clocked models");
    cat
}

/// The project's catalogue with every clock removed (and the GUIDs computed again).
fn unclocked() -> Catalogue {
    let mut cat = project();
    for m in &mut cat.models {
        m.clocks.clear();
        m.guid = spacecraft_fmus::catalogue::guid_of(m);
    }
    cat
}

#[test]
fn a_clocked_description_says_what_the_standard_asks_of_clocks() {
    let cat = clocked_catalogue();
    let plain = unclocked();
    let base = cat.layer.clock_vr_base;
    let mut seen = 0;
    for m in cat.models.iter().filter(|m| !m.clocks.is_empty()) {
        seen += 1;
        let xml = model_description3(&cat, m);
        assert_eq!(problems(&xml), Vec::<String>::new(), "{}", m.name);
        let md = ModelDescription::from_string(&xml).unwrap();
        // clocks need Event Mode (4.4) and a Scheduled Execution interface
        assert!(xml.contains(r#"hasEventMode="true""#), "{}", m.name);
        assert!(
            md.scheduledExecution.is_some() && md.coSimulation.is_some(),
            "{}",
            m.name
        );
        for (i, c) in m.clocks.iter().enumerate() {
            let v = md.variable_by_name(&c.name).unwrap();
            assert_eq!(v.valueReference, base + i as u32);
            assert_eq!(v.causality, Causality::Input);
            assert_eq!(v.variability, Variability::Discrete);
            assert!(matches!(v.variableType, VariableType::Clock { .. }), "{}", c.name);
            // a fixed clock without intervalDecimal: the importer asks the FMU (2.2 clocks)
            let tag = &xml[xml.find(&format!(r#"<Clock name="{}""#, c.name)).unwrap()..];
            let tag = &tag[..tag.find("/>").unwrap()];
            assert!(tag.contains(r#"intervalVariability="fixed""#) && tag.contains(&format!(r#"priority="{i}""#)));
            assert!(
                !tag.contains("intervalDecimal") && !tag.contains("shiftDecimal"),
                "{tag}"
            );
            for o in &c.outputs {
                let v = md.variable_by_name(o).unwrap();
                assert_eq!(v.clocks, vec![base + i as u32], "{o}");
                // clocked variables are discrete or tunable (2.4.7)
                assert_eq!(v.variability, Variability::Discrete, "{o}");
                let out = md
                    .outputs
                    .iter()
                    .find(|u| u.valueReference == v.valueReference)
                    .unwrap();
                assert!(out.dependencies.as_ref().unwrap().contains(&(base + i as u32)), "{o}");
                // its value comes from the ticks: not an initial unknown (2.4.8, as fmpy reads it)
                assert!(
                    !md.initialUnknowns.iter().any(|u| u.valueReference == v.valueReference),
                    "{o}"
                );
            }
        }
        // the outputs no clock lists are as without clocks
        let before = plain.models.iter().find(|p| p.name == m.name).unwrap();
        let md0 = ModelDescription::from_string(&model_description3(&plain, before)).unwrap();
        for v in md0.modelVariables.iter().filter(|v| v.causality == Causality::Output) {
            let now = md.variable_by_name(&v.name).unwrap();
            if now.clocks.is_empty() {
                assert_eq!(now.variability, v.variability, "{}", v.name);
            }
        }
        // FMI 2.0 does not see the clocks: the same description but for the GUID
        assert_eq!(
            model_description(&cat, m).replace(&m.guid, &before.guid),
            model_description(&plain, before),
            "{}",
            m.name
        );
        assert_ne!(m.guid, before.guid, "{}: the GUID must change with the clocks", m.name);
    }
    assert!(seen >= 10);
}

/// A model without clocks has no Clock, no Scheduled Execution and no Event Mode.
#[test]
fn a_model_without_clocks_has_no_clock_element() {
    let cat = project();
    for m in cat.models.iter().filter(|m| m.clocks.is_empty()) {
        let xml = model_description3(&cat, m);
        assert!(
            !xml.contains("<Clock ") && !xml.contains("<ScheduledExecution") && !xml.contains("clocks="),
            "{}",
            m.name
        );
        assert!(xml.contains(r#"hasEventMode="false""#), "{}", m.name);
    }
}

/// The packager refuses clocks that do not fit the model, naming the model and the clock.
#[test]
fn inconsistent_clocks_are_refused() {
    let base = clocked_catalogue();
    type Break = fn(&mut ClockDescription);
    let cases: [(&str, Break); 5] = [
        ("not a fixed Real parameter", |c| c.interval = "theta".into()),
        ("does not declare", |c| c.shift = "no_such_parameter".into()),
        ("which is not an output", |c| c.outputs.push("kp".into())),
        ("clashes with another variable name", |c| c.name = "step".into()),
        ("neither advances the state", |c| {
            c.steps = false;
            c.outputs.clear()
        }),
    ];
    for (want, breakit) in cases {
        let mut cat = base.clone();
        let m = cat.models.iter_mut().find(|m| m.name == "PidController").unwrap();
        breakit(&mut m.clocks[0]);
        let err = check_catalogue(&cat).unwrap_err();
        assert!(err.contains("PidController") && err.contains(want), "{want}: {err}");
    }
    let mut cat = base.clone();
    let m = cat.models.iter_mut().find(|m| m.name == "SampleHold").unwrap();
    let o = m.clocks[1].outputs[0].clone();
    m.clocks[0].outputs.push(o);
    assert!(check_catalogue(&cat).unwrap_err().contains("clocked twice"));
}

/// The documentation page of a clocked model lists its clocks (name, value reference, interval and shift
/// parameters, the outputs its partition computes); a page without clocks has no such section.
#[test]
fn the_documentation_lists_the_clocks() {
    let cat = clocked_catalogue();
    for m in &cat.models {
        let html = spacecraft_fmus_package::documentation_html(&cat, m);
        assert_eq!(html.contains("<h2>Clocks</h2>"), !m.clocks.is_empty(), "{}", m.name);
        for (i, c) in m.clocks.iter().enumerate() {
            let row = format!(
                "<tr><td><code>{}</code></td><td>{}</td><td>{}</td>",
                c.name,
                cat.layer.clock_vr_base + i as u32,
                c.interval
            );
            assert!(html.contains(&row), "{}: {row}", m.name);
            for o in &c.outputs {
                assert!(html.contains(o.as_str()), "{}: {o}", m.name);
            }
        }
    }
}
