//! A second, independent FMI 2.0 importer: the `fmi-rs` crate's co-simulation driver loads the packaged
//! `fmus/<Model>.fmu` files (unzipped, shared library loaded with its own loader, its own calling sequence)
//! and simulates them. Needs `scripts/build_fmus.sh` first (the test fails with that message otherwise).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use fmi_rs::model_description::fmi2::ModelDescription;
use fmi_rs::sim::fmi2::recorder::Recorder;
use fmi_rs::sim::fmi2::{SimulationSettings, Trajectories, VariableValue};

fn fmu_file(rel: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("fmus").join(rel);
    assert!(p.exists(), "{} missing: run scripts/build_fmus.sh", p.display());
    p
}

/// Simulates `fmu` from 0 to `stop` with output interval `dt` through fmi-rs; returns the time vector
/// and the trajectories of `outputs` (Real variables), by name.
fn simulate(
    fmu: &Path,
    stop: f64,
    dt: f64,
    start: &[(&str, &str)],
    outputs: &[&str],
) -> (Vec<f64>, HashMap<String, Vec<f64>>) {
    let stem = fmu.file_stem().unwrap().to_string_lossy().to_string();
    let dir = std::env::temp_dir().join(format!("scfmu_fmirs_{}_{}", std::process::id(), stem));
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
        start_time: 0.0,
        stop_time: stop,
        logging_on: false,
        set_stop_time: true,
        output_interval: dt,
        log_time_scale: false,
        tolerance: 1e-6,
        set_tolerance: false,
        start_values: start.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
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
    let mut out = HashMap::new();
    for (i, n) in outputs.iter().enumerate() {
        let col = tr
            .trajectory_by_index(i)
            .unwrap()
            .into_iter()
            .map(|v| match v {
                VariableValue::Real(x) => x,
                other => panic!("{n}: not Real: {other:?}"),
            })
            .collect();
        out.insert(n.to_string(), col);
    }
    let _ = std::fs::remove_dir_all(&dir);
    (tr.time, out)
}

#[test]
fn every_packaged_fmu_runs_in_fmi_rs() {
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
        let (t, out) = simulate(&fmu_file(&format!("{name}.fmu")), 0.5, 0.05, start, &outputs);
        assert_eq!(t.len(), 11, "{name}: {t:?}");
        for (n, v) in &out {
            assert!(v.iter().all(|x| x.is_finite()), "{name}.{n} not finite: {v:?}");
        }
    }
}

#[test]
fn attitude_plant_rate_under_constant_torque_matches_closed_form() {
    // Torque about a principal axis from rest: ω × Jω = 0, so ω_x(t) = τ t / J_xx exactly.
    let (t, out) = simulate(
        &fmu_file("AttitudePlant.fmu"),
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
    let loop_fmu = fmu_file("loops/default.fmu");
    let (t_loop, loop_out) = simulate(
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
        fmi_rs::zip::extract_zip_archive(fmu_file(&format!("{model}.fmu")), &dir).unwrap();
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
    // into the controller: q, w (plant), q_ref, w_ref (command); into the plant: torque_cmd; into metrics the rest
    let per_dst: Vec<usize> = (0..4).map(|d| links.iter().filter(|l| l.0 == d).count()).collect();
    assert_eq!(per_dst, [0, 14, 3, 11], "links: {links:?}");
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
