//! The clock declarations of the sampled models (`Model::CLOCKS`): exactly the ten sampled units are
//! clocked, every clock names an existing Real parameter as interval (and shift), and every clocked
//! output name stands for outputs of the model.

use crate::model::{clocked_outputs, Causality, ClockDecl, ModelEntry, VarKind};
use crate::registry::ALL;

const CLOCKED: [&str; 10] = [
    "PidController",
    "FopidController",
    "SampleHold",
    "Gyro",
    "Magnetometer",
    "StarTracker",
    "SunSensor",
    "Mekf",
    "BDot",
    "ModeManager",
];

fn real_parameter(e: &ModelEntry, name: &str) -> Result<(), String> {
    match e.decls.iter().find(|d| d.name == name) {
        Some(d) if d.causality == Causality::Parameter && d.kind == VarKind::Real => Ok(()),
        Some(d) => Err(format!(
            "{}: {name} is {:?} {:?}, not a Real parameter",
            e.info.name, d.causality, d.kind
        )),
        None => Err(format!("{}: no variable {name}", e.info.name)),
    }
}

/// Scalar outputs the name stands for: the output of that exact name, or the components of a vector
/// stem (`name_x`, `_y`, `_z` of a Vec3, `name_w` … `_z` of a quaternion; counted here by hand,
/// independently of the layer's `names`).
fn outputs_named(e: &ModelEntry, name: &str) -> usize {
    let out = |n: &str| e.decls.iter().any(|d| d.name == n && d.causality == Causality::Output);
    if out(name) {
        return 1;
    }
    ["w", "x", "y", "z"]
        .iter()
        .filter(|c| out(&format!("{name}_{c}")))
        .count()
}

fn check_clock(e: &ModelEntry, c: &ClockDecl) -> Result<(), String> {
    real_parameter(e, c.interval)?;
    if !c.shift.is_empty() {
        real_parameter(e, c.shift)?;
    }
    let mut want = 0;
    for n in c.outputs {
        let k = outputs_named(e, n);
        if k == 0 {
            return Err(format!("{}.{}: {n} is no output", e.info.name, c.name));
        }
        want += k;
    }
    let got = clocked_outputs(e, c).len();
    if got != want {
        return Err(format!(
            "{}.{}: {got} clocked scalars, {want} named",
            e.info.name, c.name
        ));
    }
    Ok(())
}

#[test]
fn the_sampled_models_declare_valid_clocks() {
    let clocked: Vec<&str> = ALL
        .iter()
        .filter(|e| !e.clocks.is_empty())
        .map(|e| e.info.name)
        .collect();
    let mut want = CLOCKED.to_vec();
    want.sort_unstable();
    let mut got = clocked.clone();
    got.sort_unstable();
    assert_eq!(got, want);
    for e in ALL.iter().filter(|e| !e.clocks.is_empty()) {
        assert_eq!(e.clocks[0].name, "sample_clock", "{}", e.info.name);
        assert!(
            e.clocks.iter().any(|c| c.steps),
            "{}: no clock advances the state",
            e.info.name
        );
        for c in e.clocks {
            check_clock(e, c).unwrap();
        }
        // a clocked output is listed by one clock only
        let all: Vec<String> = e.clocks.iter().flat_map(|c| clocked_outputs(e, c)).collect();
        let mut unique = all.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), all.len(), "{}: an output is clocked twice", e.info.name);
    }
}

#[test]
fn a_wrong_clock_declaration_is_caught() {
    let e = ALL.iter().find(|e| e.info.name == "StarTracker").unwrap();
    let mut c = e.clocks[1];
    c.outputs = &["q_mea"];
    assert!(check_clock(e, &c).unwrap_err().contains("q_mea is no output"));
    c.outputs = &["q_meas"];
    c.shift = "seed";
    assert!(check_clock(e, &c).unwrap_err().contains("not a Real parameter"));
    c.shift = "latency";
    check_clock(e, &c).unwrap();
}
