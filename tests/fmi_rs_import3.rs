//! An independent FMI 3.0 importer: the `fmi-rs` crate validates every committed FMI 3.0 model
//! description, loads the packaged `fmus/fmi3/<Model>.fmu` files with its own loader and simulates them
//! with its own Co-Simulation driver (its own calling sequence), and drives an FMI 3.0 Model Exchange
//! instance through its `FMU3` API (instantiate, initialize, event iteration, time, states,
//! derivatives). Needs `scripts/build_fmus.sh` first.

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
fn simulate3(
    fmu: &Path,
    stop: f64,
    dt: f64,
    start: &[(&str, &str)],
    outputs: &[&str],
) -> (Vec<f64>, HashMap<String, Vec<f64>>) {
    let stem = fmu.file_stem().unwrap().to_string_lossy().to_string();
    // one directory per call: tests run in parallel and two of them simulate the same model
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("scfmu_fmirs3_{}_{}_{call}", std::process::id(), stem));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(fmu, &dir).expect("unzip");
    let md = Arc::new(ModelDescription::from_path(&dir.join("modelDescription.xml")).expect("modelDescription"));
    let indices: Vec<usize> = outputs
        .iter()
        .map(|n| {
            md.modelVariables
                .iter()
                .position(|v| v.name == *n)
                .unwrap_or_else(|| panic!("{stem}: no variable {n}"))
        })
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
    fmi_rs::sim::fmi3::cs::simulate(&settings, None, recorder.clone())
        .unwrap_or_else(|e| panic!("{stem}: fmi-rs FMI 3.0 simulation failed: {e}"));
    drop(settings);
    let tr = Arc::try_unwrap(recorder)
        .expect("recorder still shared")
        .into_trajectories();
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
        let path = root()
            .join("modelDescription/fmi3")
            .join(format!("{}.xml", e.info.name));
        let md = ModelDescription::from_path(&path)
            .unwrap_or_else(|err| panic!("{}: fmi-rs cannot read {}: {err}", e.info.name, path.display()));
        let problems: Vec<String> = md.validate().into_iter().map(|p| format!("{p:?}")).collect();
        assert!(problems.is_empty(), "{}: {problems:?}", e.info.name);
        // declared variables, time, and for Model Exchange each continuous state and its derivative
        let nx = e.state_decls().len();
        assert_eq!(
            md.modelVariables.len(),
            e.decls.len() + 1 + 2 * nx,
            "{}: declared variables + time + states + derivatives",
            e.info.name
        );
        assert_eq!(md.modelExchange.is_some(), e.model_exchange(), "{}", e.info.name);
    }
}

#[test]
fn every_fmi3_fmu_runs_in_fmi_rs() {
    for e in spacecraft_fmus::registry::ALL {
        let name = e.info.name;
        let outputs: Vec<&str> = e
            .decls
            .iter()
            .filter(|d| {
                d.causality == spacecraft_fmus::model::Causality::Output
                    && d.kind == spacecraft_fmus::model::VarKind::Real
            })
            .map(|d| d.name)
            .collect();
        let start: &[(&str, &str)] = if e.decl("step").is_some() {
            &[("step", "0.05")]
        } else {
            &[]
        };
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
    let (t, out) = simulate3(
        &fmu3_file("AttitudePlant"),
        2.0,
        0.1,
        &[("torque_cmd_x", "2.5")],
        &["w_x", "w_y", "w_z"],
    );
    assert_eq!(t.len(), 21);
    for (k, tk) in t.iter().enumerate() {
        let want = 2.5 * tk / 1000.0;
        assert!(
            (out["w_x"][k] - want).abs() < 1e-12,
            "t = {tk}: w_x {} != {want}",
            out["w_x"][k]
        );
        assert_eq!((out["w_y"][k], out["w_z"][k]), (0.0, 0.0));
    }
}

/// fmi-rs as an FMI 3.0 Model Exchange importer: AttitudePlant instantiated as Model Exchange, initialized
/// from rest under a constant torque about its principal axis z, then a state set by the importer at a
/// later time. The derivatives must follow the rigid body by hand: q̇ = ½ q ⊗ (0, ω), ω̇ = J⁻¹ (τ − ω × Jω)
/// with ω × Jω = 0 about a principal axis, so ω̇_z = τ/I_z.
#[test]
fn fmi_rs_drives_an_fmi3_model_exchange_instance_and_the_derivatives_follow_the_closed_form() {
    use fmi_rs::fmi3::log::DefaultLogger;
    use fmi_rs::fmi3::native::NativeLibrary;
    use fmi_rs::fmi3::types::fmi3Status;
    use fmi_rs::fmi3::{Implementation, FMU3};

    let dir = std::env::temp_dir().join(format!("scfmu_fmirs3_me_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(&fmu3_file("AttitudePlant"), &dir).expect("unzip");
    let md = ModelDescription::from_path(&dir.join("modelDescription.xml")).expect("modelDescription");
    let me = md.modelExchange.as_ref().expect("<ModelExchange>");
    assert!(me.needsCompletedIntegratorStep);
    let vr = |name: &str| {
        md.modelVariables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("no {name}"))
            .valueReference
    };
    let lib = NativeLibrary::load(dir.join("binaries/x86_64-linux/AttitudePlant.so")).expect("load");
    let implementation: Box<dyn Implementation> = Box::new(lib);
    let fmu = FMU3::instantiateModelExchange(
        implementation,
        None,
        "me",
        &md.instantiationToken,
        false,
        false,
        Arc::new(DefaultLogger::default()),
        false,
    )
    .expect("fmi3InstantiateModelExchange");
    let ok = |s: fmi3Status, what: &str| assert!(matches!(s, fmi3Status::Ok), "{what}: {s:?}");

    let mut n = 0usize;
    ok(
        fmu.getNumberOfContinuousStates(&mut n),
        "fmi3GetNumberOfContinuousStates",
    );
    assert_eq!(n, 18);
    let mut nz = 99usize;
    ok(
        fmu.getNumberOfEventIndicators(&mut nz),
        "fmi3GetNumberOfEventIndicators",
    );
    assert_eq!(nz, 0);
    let (tau, iz) = (0.2, 700.0);
    ok(
        fmu.enterInitializationMode(None, 0.0, None),
        "fmi3EnterInitializationMode",
    );
    ok(fmu.setFloat64(&[vr("torque_cmd_z")], &[tau]), "fmi3SetFloat64");
    ok(fmu.exitInitializationMode(), "fmi3ExitInitializationMode");
    let (mut need, mut term, mut nom, mut val, mut next) = (true, false, false, false, None);
    ok(
        fmu.updateDiscreteStates(&mut need, &mut term, &mut nom, &mut val, &mut next),
        "fmi3UpdateDiscreteStates",
    );
    assert!(!need && !term);
    ok(fmu.enterContinuousTimeMode(), "fmi3EnterContinuousTimeMode");

    // the state vector in <ContinuousStateDerivative> order: the states named in the description
    let state_vrs: Vec<u32> = md
        .modelVariables
        .iter()
        .filter(|v| v.name.starts_with("der("))
        .map(|v| v.valueReference - 100_000)
        .collect();
    let names: Vec<String> = state_vrs
        .iter()
        .map(|s| {
            md.modelVariables
                .iter()
                .find(|v| v.valueReference == *s)
                .unwrap()
                .name
                .clone()
        })
        .collect();
    let k = |name: &str| {
        names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no state {name}"))
    };
    let mut x = vec![0.0; n];
    ok(fmu.getContinuousStates(&mut x), "fmi3GetContinuousStates");
    let mut dx = vec![f64::NAN; n];
    ok(
        fmu.getContinuousStateDerivatives(&mut dx),
        "fmi3GetContinuousStateDerivatives",
    );
    assert!(
        (dx[k("state_w_z")] - tau / iz).abs() < 1e-15,
        "dw_z/dt = {} at rest",
        dx[k("state_w_z")]
    );
    assert_eq!((dx[k("state_w_x")], dx[k("state_w_y")]), (0.0, 0.0));

    // the closed-form state at t = 3 s: w_z = tau/I_z t, q = (cos θ/2, 0, 0, sin θ/2) with θ = ½ (tau/I_z) t²
    let t = 3.0;
    let (wz, theta) = (tau / iz * t, 0.5 * tau / iz * t * t);
    ok(fmu.setTime(t), "fmi3SetTime");
    x[k("state_w_z")] = wz;
    // kinematics = 0: the first four attitude states are q_w, q_x, q_y, q_z
    x[k("state_att_1")] = (theta / 2.0).cos();
    x[k("state_att_4")] = (theta / 2.0).sin();
    ok(fmu.setContinuousStates(&x), "fmi3SetContinuousStates");
    ok(
        fmu.getContinuousStateDerivatives(&mut dx),
        "fmi3GetContinuousStateDerivatives",
    );
    assert!((dx[k("state_w_z")] - tau / iz).abs() < 1e-15);
    // q̇ = ½ q ⊗ (0, 0, 0, w_z): q̇_w = -½ q_z w_z, q̇_z = ½ q_w w_z
    assert!(
        (dx[k("state_att_1")] + 0.5 * (theta / 2.0).sin() * wz).abs() < 1e-15,
        "{}",
        dx[k("state_att_1")]
    );
    assert!(
        (dx[k("state_att_4")] - 0.5 * (theta / 2.0).cos() * wz).abs() < 1e-15,
        "{}",
        dx[k("state_att_4")]
    );
    // the same through fmi3GetFloat64 by value reference, and the outputs follow the states
    let mut v = [0.0; 4];
    ok(
        fmu.getFloat64(&[vr("der(state_w_z)"), vr("w_z"), vr("q_w"), vr("q_z")], &mut v),
        "fmi3GetFloat64",
    );
    assert!((v[0] - tau / iz).abs() < 1e-15 && (v[1] - wz).abs() < 1e-15);
    assert!((v[2] - (theta / 2.0).cos()).abs() < 1e-15 && (v[3] - (theta / 2.0).sin()).abs() < 1e-15);
    let (mut enter, mut stop) = (true, true);
    ok(
        fmu.completedIntegratorStep(true, &mut enter, &mut stop),
        "fmi3CompletedIntegratorStep",
    );
    assert!(!enter && !stop, "a unit quaternion needs no projection");
    // a Co-Simulation call on the Model Exchange instance is refused
    let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
    assert!(matches!(
        fmu.doStep(t, 0.1, true, &mut a, &mut b, &mut c, &mut last),
        fmi3Status::Error
    ));
    drop(fmu);
    let _ = std::fs::remove_dir_all(&dir);
}
