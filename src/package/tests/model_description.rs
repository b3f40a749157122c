//! The committed modelDescription/ files are exactly what the declarations generate, and every
//! generated description passes fmi-rs's FMI 2.0 validation and parses with fmi-schema.

use std::path::Path;
use std::str::FromStr;

use spacecraft_fmus::catalogue::{Catalogue, Causality};
use spacecraft_fmus_package::{
    check_catalogue, model_description, stale_model_descriptions, stale_model_descriptions3,
};

/// The project's catalogue, as `src/cdylib` exports it (built in this process).
fn project() -> Catalogue {
    let cat = spacecraft_fmus::export::project_catalogue();
    check_catalogue(&cat).unwrap();
    cat
}

#[test]
fn committed_model_descriptions_are_not_stale() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription");
    let stale = stale_model_descriptions(&project(), &dir);
    assert!(
        stale.is_empty(),
        "stale modelDescription/ for {stale:?}: run scripts/build_fmus.sh and commit"
    );
}

#[test]
fn committed_fmi3_model_descriptions_are_not_stale() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription/fmi3");
    let stale = stale_model_descriptions3(&project(), &dir);
    assert!(
        stale.is_empty(),
        "stale modelDescription/fmi3/ for {stale:?}: run scripts/build_fmus.sh and commit"
    );
}

#[test]
fn fmi_rs_validation_finds_no_problem() {
    let cat = project();
    for e in &cat.models {
        let xml = model_description(&cat, e);
        let md = fmi_rs::model_description::fmi2::ModelDescription::from_string(&xml)
            .unwrap_or_else(|err| panic!("{}: fmi-rs cannot read the description: {err}", e.name));
        let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
        assert!(problems.is_empty(), "{}: {problems:?}", e.name);
    }
}

#[test]
fn fmi_schema_reads_every_variable_back() {
    let cat = project();
    for e in &cat.models {
        let xml = model_description(&cat, e);
        let md =
            fmi_schema::fmi2::Fmi2ModelDescription::from_str(&xml).unwrap_or_else(|err| panic!("{}: {err}", e.name));
        assert_eq!(md.model_name, e.name);
        // the declared variables, then (Model Exchange) each continuous state and its derivative
        let states = e.state_decls();
        assert_eq!(md.num_variables(), e.variables.len() + 2 * states.len());
        assert_eq!(md.model_exchange.is_some(), e.model_exchange(), "{}", e.name);
        let extra = &md.model_variables.variables[e.variables.len()..];
        for (k, x) in states.iter().enumerate() {
            assert_eq!(
                (extra[k].name.as_str(), extra[k].value_reference),
                (x.name.as_str(), cat.layer.state_vr_base + k as u32)
            );
            let der = &extra[states.len() + k];
            assert_eq!(
                (der.name.as_str(), der.value_reference),
                (
                    format!("der({})", x.name).as_str(),
                    cat.layer.derivative_vr_base + k as u32
                )
            );
        }
        let cs = md.co_simulation.as_ref().expect("CoSimulation element");
        assert_eq!(cs.model_identifier, e.name);
        assert_eq!(cs.can_get_and_set_fmu_state, Some(true));
        assert_eq!(cs.can_serialize_fmu_state, Some(true));
        for (sv, d) in md.model_variables.variables.iter().zip(&e.variables) {
            assert_eq!((sv.name.as_str(), sv.value_reference), (d.name.as_str(), d.vr));
        }
    }
}

/// Within a family (one family of the catalogue), a parameter name keeps one value reference in
/// every FMU that declares it (calculated parameters included), so a master or a scenario can address
/// it by reference across the family.
#[test]
fn every_parameter_keeps_one_value_reference_within_a_family() {
    use std::collections::BTreeMap;
    let cat = project();
    let mut groups: BTreeMap<&str, Vec<&spacecraft_fmus::catalogue::ModelDescription>> = BTreeMap::new();
    for f in &cat.families {
        let members = f
            .models
            .iter()
            .map(|n| cat.models.iter().find(|m| &m.name == n).unwrap());
        groups.entry(&f.slug).or_default().extend(members);
    }
    let mut problems = vec![];
    let mut shared = 0;
    for (family, fmus) in &groups {
        let mut seen: BTreeMap<&str, (u32, &str)> = BTreeMap::new();
        for e in fmus {
            for d in e
                .variables
                .iter()
                .filter(|d| matches!(d.causality, Causality::Parameter | Causality::CalculatedParameter))
            {
                match seen.get(d.name.as_str()) {
                    Some((vr, first)) if *vr != d.vr => problems.push(format!(
                        "{family}: {} is {} in {first} but {} in {}",
                        d.name, vr, d.vr, e.name
                    )),
                    Some(_) => shared += 1,
                    None => {
                        seen.insert(&d.name, (d.vr, &e.name));
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
