//! The clocked FMI 3.0 model descriptions against an independent reader: a clocked model's description
//! says what the standard asks of clocks, read back by fmi-rs's FMI 3.0 reader (not by this crate's
//! writer). The official XSD is checked by fmpy for every FMI 3.0 archive (`tests/test_fmi3.py`, with a
//! broken clock shown refused) and fmi-rs's own checks run on every committed description
//! (`tests/fmi_rs_import.rs`).

use fmi_rs::model_description::fmi3::{Causality, ModelDescription, Variability, VariableType};
use spacecraft_fmus::catalogue::{Catalogue, ClockDescription};
use spacecraft_fmus_package::{check_catalogue, model_description, model_description3};

fn project() -> Catalogue {
    let cat = spacecraft_fmus::export::project_catalogue();
    check_catalogue(&cat).unwrap();
    cat
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
        let md = ModelDescription::from_string(&xml).unwrap();
        let problems: Vec<String> = md.validate().into_iter().map(|e| e.message).collect();
        assert_eq!(problems, Vec::<String>::new(), "{}", m.name);
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
