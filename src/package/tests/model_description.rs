//! The committed modelDescription/ files are exactly what the declarations generate, and every
//! generated description passes fmi-rs's FMI 2.0 validation and parses with fmi-schema.

use std::path::Path;
use std::str::FromStr;

use spacecraft_fmus::registry;
use spacecraft_fmus_package::description::model_description;
use spacecraft_fmus_package::{stale_model_descriptions, stale_model_descriptions3, Unit};

fn xml(e: &spacecraft_fmus::model::ModelEntry) -> String {
    let u = Unit::registered(e);
    model_description(e, u.guid, u.package)
}

#[test]
fn committed_model_descriptions_are_not_stale() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription");
    let units: Vec<Unit> = registry::ALL.iter().map(Unit::registered).collect();
    let stale = stale_model_descriptions(&units, &dir);
    assert!(
        stale.is_empty(),
        "stale modelDescription/ for {stale:?}: run scripts/build_fmus.sh and commit"
    );
}

#[test]
fn committed_fmi3_model_descriptions_are_not_stale() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription/fmi3");
    let units: Vec<Unit> = registry::ALL.iter().map(Unit::registered).collect();
    let stale = stale_model_descriptions3(&units, &dir);
    assert!(
        stale.is_empty(),
        "stale modelDescription/fmi3/ for {stale:?}: run scripts/build_fmus.sh and commit"
    );
}

#[test]
fn fmi_rs_validation_finds_no_problem() {
    for e in registry::ALL {
        let xml = xml(e);
        let md = fmi_rs::model_description::fmi2::ModelDescription::from_string(&xml)
            .unwrap_or_else(|err| panic!("{}: fmi-rs cannot read the description: {err}", e.info.name));
        let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
        assert!(problems.is_empty(), "{}: {problems:?}", e.info.name);
    }
}

#[test]
fn fmi_schema_reads_every_variable_back() {
    for e in registry::ALL {
        let xml = xml(e);
        let md = fmi_schema::fmi2::Fmi2ModelDescription::from_str(&xml)
            .unwrap_or_else(|err| panic!("{}: {err}", e.info.name));
        assert_eq!(md.model_name, e.info.name);
        // the declared variables, then (Model Exchange) each continuous state and its derivative
        let states = e.state_decls();
        assert_eq!(md.num_variables(), e.decls.len() + 2 * states.len());
        assert_eq!(md.model_exchange.is_some(), e.model_exchange(), "{}", e.info.name);
        let extra = &md.model_variables.variables[e.decls.len()..];
        for (k, x) in states.iter().enumerate() {
            assert_eq!(
                (extra[k].name.as_str(), extra[k].value_reference),
                (x.name, spacecraft_fmus::model::STATE_VR_BASE + k as u32)
            );
            let der = &extra[states.len() + k];
            assert_eq!(
                (der.name.as_str(), der.value_reference),
                (
                    format!("der({})", x.name).as_str(),
                    spacecraft_fmus::model::DERIVATIVE_VR_BASE + k as u32
                )
            );
        }
        let cs = md.co_simulation.as_ref().expect("CoSimulation element");
        assert_eq!(cs.model_identifier, e.info.name);
        assert_eq!(cs.can_get_and_set_fmu_state, Some(true));
        assert_eq!(cs.can_serialize_fmu_state, Some(true));
        for (sv, d) in md.model_variables.variables.iter().zip(e.decls) {
            assert_eq!((sv.name.as_str(), sv.value_reference), (d.name, d.vr));
        }
    }
}

/// Within a family (one `registry::FAMILIES` entry), a parameter name keeps one value reference in
/// every FMU that declares it (calculated parameters included), so a master or a scenario can address
/// it by reference across the family.
#[test]
fn every_parameter_keeps_one_value_reference_within_a_family() {
    use spacecraft_fmus::model::Causality;
    use std::collections::BTreeMap;
    let mut groups: BTreeMap<&str, Vec<&spacecraft_fmus::model::ModelEntry>> = BTreeMap::new();
    for f in registry::FAMILIES {
        groups.entry(f.slug).or_default().extend(f.fmus.iter());
    }
    let mut problems = vec![];
    let mut shared = 0;
    for (family, fmus) in &groups {
        let mut seen: BTreeMap<&str, (u32, &str)> = BTreeMap::new();
        for e in fmus {
            for d in e
                .decls
                .iter()
                .filter(|d| matches!(d.causality, Causality::Parameter | Causality::CalculatedParameter))
            {
                match seen.get(d.name) {
                    Some((vr, first)) if *vr != d.vr => problems.push(format!(
                        "{family}: {} is {} in {first} but {} in {}",
                        d.name, vr, d.vr, e.info.name
                    )),
                    Some(_) => shared += 1,
                    None => {
                        seen.insert(d.name, (d.vr, e.info.name));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{problems:#?}");
    assert!(
        shared > 20,
        "only {shared} parameters shared within families: the check sees too little"
    );
}
