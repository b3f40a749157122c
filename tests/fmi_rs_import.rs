//! Two independent importers in one file, for every FMI version: the `fmi-rs` crate's Co-Simulation driver
//! loads the packaged `fmus/<Model>.fmu` (FMI 2.0) and `fmus/fmi3/<Model>.fmu` (FMI 3.0) files (unzipped,
//! shared library loaded with its own loader, its own calling sequence) and simulates them; each behaviour
//! runs for both versions (`VERSIONS`). FMI 2.0 only: a Gauss–Seidel master on fmi-rs's FMU2 bindings against
//! the loop FMU. FMI 3.0 only: fmi-rs validates every committed FMI 3.0 description and drives a Model
//! Exchange instance through its `FMU3` API (instantiate, initialize, event iteration, time, states,
//! derivatives). Needs `scripts/build_fmus.sh` first (the test fails with that message otherwise).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use fmi_rs::fmi3::LibraryKind;
use fmi_rs::model_description::fmi2::ModelDescription;
use fmi_rs::model_description::fmi3::ModelDescription as ModelDescription3;

/// The FMI version of the packaged FMUs a case drives.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fmi {
    V2,
    V3,
}
const VERSIONS: [Fmi; 2] = [Fmi::V2, Fmi::V3];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// `fmus/<rel>.fmu` (FMI 2.0) or `fmus/fmi3/<rel>.fmu` (FMI 3.0).
fn fmu_file(v: Fmi, rel: &str) -> PathBuf {
    let dir = if v == Fmi::V2 {
        root().join("fmus")
    } else {
        root().join("fmus/fmi3")
    };
    let p = dir.join(format!("{rel}.fmu"));
    assert!(p.exists(), "{} missing: run scripts/build_fmus.sh", p.display());
    p
}

/// Reads the description of version module `$m` from `$dir` and makes fmi-rs's recorder of `$outputs`:
/// (description, recorder).
macro_rules! recorder {
    ($m:ident, $dir:expr, $stem:expr, $outputs:expr) => {{
        let md = Arc::new(
            fmi_rs::model_description::$m::ModelDescription::from_path(&$dir.join("modelDescription.xml"))
                .expect("modelDescription"),
        );
        let indices: Vec<usize> = $outputs
            .iter()
            .map(|n| {
                md.modelVariables
                    .iter()
                    .position(|v| v.name == *n)
                    .unwrap_or_else(|| panic!("{}: no variable {n}", $stem))
            })
            .collect();
        let tr = fmi_rs::sim::$m::Trajectories::new(md.clone(), indices);
        (md, Arc::new(fmi_rs::sim::$m::recorder::Recorder::new(tr)))
    }};
}

/// Simulates `fmu` (of version `v`) from 0 to `stop` with output interval `dt` through fmi-rs's own
/// Co-Simulation driver; returns the time vector and the trajectories of `outputs` (Real / Float64
/// variables), by name.
fn simulate(
    v: Fmi,
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
    let dir = std::env::temp_dir().join(format!("scfmu_fmirs_{}_{stem}_{v:?}_{call}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(fmu, &dir).expect("unzip");
    let start_values = start.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    let mut out: HashMap<String, Vec<f64>> = outputs.iter().map(|n| (n.to_string(), vec![])).collect();
    let time = match v {
        Fmi::V2 => {
            use fmi_rs::sim::fmi2::{SimulationSettings, VariableValue};
            let (md, recorder) = recorder!(fmi2, dir, stem, outputs);
            let settings = SimulationSettings {
                unzipdir: dir.clone(),
                model_description: md,
                start_time: 0.0,
                stop_time: stop,
                logging_on: false,
                set_stop_time: true,
                output_interval: dt,
                log_time_scale: false,
                tolerance: 1e-6,
                set_tolerance: false,
                start_values,
                log_fmi_calls: false,
                input_file: None,
                early_return_allowed: false,
                event_mode_used: false,
                log_file: None,
                initial_fmu_state_file: None,
                final_fmu_state_file: None,
            };
            fmi_rs::sim::fmi2::cs::simulate(&settings, None, recorder.clone())
                .unwrap_or_else(|e| panic!("{stem}: fmi-rs simulation failed: {e}"));
            drop(settings);
            let tr = Arc::try_unwrap(recorder)
                .expect("recorder still shared")
                .into_trajectories();
            for (i, n) in outputs.iter().enumerate() {
                for x in tr.trajectory_by_index(i).unwrap() {
                    match x {
                        VariableValue::Real(x) => out.get_mut(*n).unwrap().push(x),
                        other => panic!("{n}: not Real: {other:?}"),
                    }
                }
            }
            tr.time
        }
        Fmi::V3 => {
            use fmi_rs::sim::fmi3::{SimulationSettings, VariableValue};
            let (md, recorder) = recorder!(fmi3, dir, stem, outputs);
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
                start_values,
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
            for row in &tr.rows {
                for (i, n) in outputs.iter().enumerate() {
                    match &row[i] {
                        VariableValue::Float64(v) => out.get_mut(*n).unwrap().push(v[0]),
                        other => panic!("{n}: not Float64: {other:?}"),
                    }
                }
            }
            tr.time
        }
    };
    let _ = std::fs::remove_dir_all(&dir);
    (time, out)
}

#[test]
fn every_packaged_fmu_runs_in_fmi_rs() {
    for v in VERSIONS {
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
            // sampled controllers (PID, FOPID) require the communication step to equal their `step` parameter
            let start: &[(&str, &str)] = if e.decl("step").is_some() {
                &[("step", "0.05")]
            } else {
                &[]
            };
            let (t, out) = simulate(v, &fmu_file(v, name), 0.5, 0.05, start, &outputs);
            assert_eq!(t.len(), 11, "{v:?} {name}: {t:?}");
            for (n, x) in &out {
                assert_eq!(x.len(), 11, "{v:?} {name}.{n}");
                assert!(x.iter().all(|x| x.is_finite()), "{v:?} {name}.{n} not finite: {x:?}");
            }
        }
    }
}

#[test]
fn attitude_plant_rate_under_constant_torque_matches_closed_form() {
    // Torque about a principal axis from rest: ω × Jω = 0, so ω_x(t) = τ t / J_xx exactly.
    for v in VERSIONS {
        let (t, out) = simulate(
            v,
            &fmu_file(v, "AttitudePlant"),
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
                "{v:?} t = {tk}: w_x {} != {want}",
                out["w_x"][k]
            );
            assert_eq!((out["w_y"][k], out["w_z"][k]), (0.0, 0.0));
        }
    }
}

// ----- FMI 2.0 only ----------------------------------------------------------------------------------

/// A fixed-step Gauss–Seidel master written here on fmi-rs's FMU2 bindings: at each communication point
/// the instances, in order, get their inputs from the outputs of the same name of the other instances,
/// then every instance steps. Runs the default slew (command → PD → plant → metrics) with the parameter
/// values the loop FMU carries, and compares it with the loop FMU (fmpy's compiled container, a different
/// implementation of the same scheme) simulated by fmi-rs's own driver: same scheme, same order, so the
/// expected difference is zero.
#[test]
fn closed_loop_in_a_fmi_rs_master_equals_the_loop_fmu() {
    use fmi_rs::fmi2::log::DefaultLogger;
    use fmi_rs::fmi2::types::fmi2Status;
    use fmi_rs::fmi2::{CS, FMU2};
    use fmi_rs::model_description::fmi2::{Causality, VariableType};
    use fmi_rs::sim::fmi2::{parse_variable_value, set_variable_value};

    let (dt, n) = (0.01, 300usize);
    let loop_fmu = fmu_file(Fmi::V2, "loops/default");
    let (t_loop, loop_out) = simulate(
        Fmi::V2,
        &loop_fmu,
        n as f64 * dt,
        dt,
        &[],
        &["metrics.alpha_deg", "plant.w_x", "controller.torque_cmd_y"],
    );

    // parameter values of the scenario, as carried by the loop FMU ("instance.parameter" start values)
    let ldir = std::env::temp_dir().join(format!("scfmu_fmirs_{}_loopmd", std::process::id()));
    fmi_rs::zip::extract_zip_archive(&loop_fmu, &ldir).unwrap();
    let lmd = ModelDescription::from_path(&ldir.join("modelDescription.xml")).unwrap();
    let _ = std::fs::remove_dir_all(&ldir);
    let start_of = |v: &VariableType| match v {
        VariableType::Real { start, .. }
        | VariableType::Integer { start, .. }
        | VariableType::Boolean { start, .. } => start.clone(),
        _ => None,
    };

    let instances = [
        ("command", "AttitudeCommand"),
        ("controller", "PdController"),
        ("plant", "AttitudePlant"),
        ("metrics", "AttitudeMetrics"),
    ];
    let ok = |s: fmi2Status, what: &str| assert!(matches!(s, fmi2Status::Ok), "{what}: {s:?}");
    let mut fmus = vec![];
    for (inst, model) in instances {
        let dir = std::env::temp_dir().join(format!("scfmu_fmirs_{}_{inst}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        fmi_rs::zip::extract_zip_archive(fmu_file(Fmi::V2, model), &dir).unwrap();
        let md = ModelDescription::from_path(&dir.join("modelDescription.xml")).unwrap();
        let fmu = FMU2::<CS>::new(
            &dir,
            model,
            inst,
            &md.guid,
            false,
            false,
            false,
            Arc::new(DefaultLogger::default()),
            false,
        )
        .unwrap();
        ok(fmu.setupExperiment(None, 0.0, None), "setupExperiment");
        ok(fmu.enterInitializationMode(), "enterInitializationMode");
        for v in lmd
            .modelVariables
            .iter()
            .filter(|v| v.causality == Causality::Parameter)
        {
            if let Some(p) = v.name.strip_prefix(&format!("{inst}.")) {
                let nv = md.modelVariables.iter().find(|x| x.name == p).unwrap();
                let value = parse_variable_value(&nv.variableType, &start_of(&v.variableType).unwrap()).unwrap();
                set_variable_value(&fmu, nv.valueReference, &value).unwrap();
            }
        }
        ok(fmu.exitInitializationMode(), "exitInitializationMode");
        fmus.push((inst, md, fmu, dir));
    }
    // wiring by port name: (dst, input vr, src, output vr), grouped by destination in instance order
    let mut links = vec![];
    for (d, (_, dmd, _, _)) in fmus.iter().enumerate() {
        for inp in dmd.modelVariables.iter().filter(|v| v.causality == Causality::Input) {
            let src: Vec<(usize, u32)> = fmus
                .iter()
                .enumerate()
                .filter(|(s, _)| *s != d)
                .filter_map(|(s, (_, smd, _, _))| {
                    smd.modelVariables
                        .iter()
                        .find(|v| v.causality == Causality::Output && v.name == inp.name)
                        .map(|v| (s, v.valueReference))
                })
                .collect();
            assert!(src.len() <= 1, "{} has several sources", inp.name);
            if let Some(&(s, vr)) = src.first() {
                links.push((d, inp.valueReference, s, vr));
            }
        }
    }
    // into the controller: q, w (plant), q_ref, w_ref, w_ref_dot (command); into the plant: torque_cmd; into
    // metrics the rest
    let per_dst: Vec<usize> = (0..4).map(|d| links.iter().filter(|l| l.0 == d).count()).collect();
    assert_eq!(per_dst, [0, 17, 3, 11], "links: {links:?}");
    let vr_of = |i: usize, name: &str| {
        fmus[i]
            .1
            .modelVariables
            .iter()
            .find(|v| v.name == name)
            .unwrap()
            .valueReference
    };
    let (alpha, wx, tqy) = (vr_of(3, "alpha_deg"), vr_of(2, "w_x"), vr_of(1, "torque_cmd_y"));
    let mut rec = vec![];
    for k in 0..=n {
        let t = k as f64 * dt;
        for &(d, dvr, s, svr) in &links {
            let mut x = [0.0];
            ok(fmus[s].2.getReal(&[svr], &mut x), "getReal");
            ok(fmus[d].2.setReal(&[dvr], &x), "setReal");
        }
        let get = |i: usize, vr: u32| {
            let mut x = [0.0];
            ok(fmus[i].2.getReal(&[vr], &mut x), "getReal");
            x[0]
        };
        rec.push((t, get(3, alpha), get(2, wx), get(1, tqy)));
        if k < n {
            for (_, _, f, _) in &fmus {
                ok(f.doStep(t, dt, 1), "doStep");
            }
        }
    }
    for (_, _, f, dir) in &fmus {
        f.terminate();
        let _ = std::fs::remove_dir_all(dir);
    }
    assert_eq!(t_loop.len(), n + 1);
    for (k, &(t, a, w, tq)) in rec.iter().enumerate() {
        assert!((t_loop[k] - t).abs() < 1e-12);
        assert_eq!(
            (a, w, tq),
            (
                loop_out["metrics.alpha_deg"][k],
                loop_out["plant.w_x"][k],
                loop_out["controller.torque_cmd_y"][k]
            ),
            "t = {t}"
        );
    }
    assert!(
        rec[n].1 < 0.5 * rec[0].1,
        "the slew reduces the eigenaxis error: {} -> {}",
        rec[0].1,
        rec[n].1
    );
}

// ----- FMI 3.0 only ----------------------------------------------------------------------------------

#[test]
fn fmi_rs_validates_every_committed_fmi3_description() {
    for e in spacecraft_fmus::registry::ALL {
        let path = root()
            .join("modelDescription/fmi3")
            .join(format!("{}.xml", e.info.name));
        let md = ModelDescription3::from_path(&path)
            .unwrap_or_else(|err| panic!("{}: fmi-rs cannot read {}: {err}", e.info.name, path.display()));
        let problems: Vec<String> = md.validate().into_iter().map(|p| format!("{p:?}")).collect();
        assert!(problems.is_empty(), "{}: {problems:?}", e.info.name);
        // declared variables, time, for Model Exchange each continuous state and its derivative, and
        // each clock of a sampled unit
        let nx = e.state_decls().len();
        assert_eq!(
            md.modelVariables.len(),
            e.decls.len() + 1 + 2 * nx + e.clocks.len(),
            "{}: declared variables + time + states + derivatives + clocks",
            e.info.name
        );
        assert_eq!(md.modelExchange.is_some(), e.model_exchange(), "{}", e.info.name);
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
    fmi_rs::zip::extract_zip_archive(fmu_file(Fmi::V3, "AttitudePlant"), &dir).expect("unzip");
    let md = ModelDescription3::from_path(&dir.join("modelDescription.xml")).expect("modelDescription");
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
