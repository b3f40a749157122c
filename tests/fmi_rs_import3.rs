//! An independent FMI 3.0 importer: the `fmi-rs` crate validates every committed FMI 3.0 model
//! description, loads the packaged `fmus/fmi3/<Model>.fmu` files with its own loader and simulates them
//! with its own Co-Simulation driver (its own calling sequence). Needs `scripts/build_fmus.sh` first.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use fmi_rs::fmi3::LibraryKind;
use fmi_rs::model_description::fmi3::ModelDescription;
use fmi_rs::sim::fmi3::recorder::Recorder;
use fmi_rs::sim::fmi3::{SimulationSettings, Trajectories, VariableValue};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

fn fmu3_file(model: &str) -> PathBuf {
    let p = root().join("fmus/fmi3").join(format!("{model}.fmu"));
    assert!(p.exists(), "{} missing: run scripts/build_fmus.sh", p.display());
    p
}

/// Simulates an FMI 3.0 FMU from 0 to `stop` with output interval `dt` through fmi-rs; returns the time
/// vector and the trajectories of `outputs` (Float64 variables), by name.
fn simulate3(fmu: &Path, stop: f64, dt: f64, start: &[(&str, &str)], outputs: &[&str]) -> (Vec<f64>, HashMap<String, Vec<f64>>) {
    let stem = fmu.file_stem().unwrap().to_string_lossy().to_string();
    let dir = std::env::temp_dir().join(format!("scfmu_fmirs3_{}_{}", std::process::id(), stem));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(fmu, &dir).expect("unzip");
    let md = Arc::new(ModelDescription::from_path(&dir.join("modelDescription.xml")).expect("modelDescription"));
    let indices: Vec<usize> = outputs
        .iter()
        .map(|n| md.modelVariables.iter().position(|v| v.name == *n).unwrap_or_else(|| panic!("{stem}: no variable {n}")))
        .collect();
    let recorder = Arc::new(Recorder::new(Trajectories::new(md.clone(), indices)));
    let settings = SimulationSettings {
        unzipdir: dir.clone(),
        model_description: md,
        library_kind: LibraryKind::Native,
        enable_dae: false,
        start_time: 0.0,
        stop_time: stop,
        visible: false,
        logging_on: false,
        set_stop_time: true,
        output_interval: dt,
        log_time_scale: false,
        tolerance: 1e-6,
        set_tolerance: false,
        start_values: start.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
        log_fmi_calls: false,
        intermediate_update: false,
        input_file: None,
        early_return_allowed: false,
        event_mode_used: false,
        log_file: None,
        initial_fmu_state_file: None,
        final_fmu_state_file: None,
    };
    fmi_rs::sim::fmi3::cs::simulate(&settings, None, recorder.clone()).unwrap_or_else(|e| panic!("{stem}: fmi-rs FMI 3.0 simulation failed: {e}"));
    drop(settings);
    let tr = Arc::try_unwrap(recorder).expect("recorder still shared").into_trajectories();
    let mut out: HashMap<String, Vec<f64>> = outputs.iter().map(|n| (n.to_string(), vec![])).collect();
    for row in &tr.rows {
        for (i, n) in outputs.iter().enumerate() {
            match &row[i] {
                VariableValue::Float64(v) => out.get_mut(*n).unwrap().push(v[0]),
                other => panic!("{n}: not Float64: {other:?}"),
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    (tr.time, out)
}

#[test]
fn fmi_rs_validates_every_committed_fmi3_description() {
    for e in spacecraft_fmus::registry::ALL {
        let path = root().join("modelDescription/fmi3").join(format!("{}.xml", e.info.name));
        let md = ModelDescription::from_path(&path).unwrap_or_else(|err| panic!("{}: fmi-rs cannot read {}: {err}", e.info.name, path.display()));
        let problems: Vec<String> = md.validate().into_iter().map(|p| format!("{p:?}")).collect();
        assert!(problems.is_empty(), "{}: {problems:?}", e.info.name);
        assert_eq!(md.modelVariables.len(), e.decls.len() + 1, "{}: declared variables + time", e.info.name);
    }
}

#[test]
fn every_fmi3_fmu_runs_in_fmi_rs() {
    for e in spacecraft_fmus::registry::ALL {
        let name = e.info.name;
        let outputs: Vec<&str> = e
            .decls
            .iter()
            .filter(|d| d.causality == spacecraft_fmus::model::Causality::Output && d.kind == spacecraft_fmus::model::VarKind::Real)
            .map(|d| d.name)
            .collect();
        let start: &[(&str, &str)] = if e.decl("step").is_some() { &[("step", "0.05")] } else { &[] };
        let (t, out) = simulate3(&fmu3_file(name), 0.5, 0.05, start, &outputs);
        assert_eq!(t.len(), 11, "{name}: {t:?}");
        for (n, v) in &out {
            assert_eq!(v.len(), 11, "{name}.{n}");
            assert!(v.iter().all(|x| x.is_finite()), "{name}.{n} not finite: {v:?}");
        }
    }
}

#[test]
fn fmi3_attitude_plant_rate_under_constant_torque_matches_closed_form() {
    // Torque about a principal axis from rest: ω × Jω = 0, so ω_x(t) = τ t / J_xx exactly.
    let (t, out) = simulate3(&fmu3_file("AttitudePlant"), 2.0, 0.1, &[("torque_cmd_x", "2.5")], &["w_x", "w_y", "w_z"]);
    assert_eq!(t.len(), 21);
    for (k, tk) in t.iter().enumerate() {
        let want = 2.5 * tk / 1000.0;
        assert!((out["w_x"][k] - want).abs() < 1e-12, "t = {tk}: w_x {} != {want}", out["w_x"][k]);
        assert_eq!((out["w_y"][k], out["w_z"][k]), (0.0, 0.0));
    }
}
