//! fmi-rs 0.3.4 as the importer of the clocked FMI 3.0 units (issue 48): its own unzip, its own loader of the
//! shared library (`fmi_rs::fmi3::native::NativeLibrary`) and its own binding of the FMI 3.0 functions.
//!
//! * fmi-rs's Co-Simulation driver (`fmi_rs::sim::fmi3::cs::simulate`, the one `tests/tools/fmusim_rs.rs`
//!   wraps): without event mode it runs a clocked unit sampled inside `fmi3DoStep` (the FMU's lenient
//!   mode) and the outputs equal the FMI 2.0 FMU's; with `event_mode_used` it sets no clock (the driver has
//!   no clock handling), which the unit refuses: the run fails.
//! * fmi-rs's instance API (`fmi_rs::fmi3::Instance`: `fmi3SetClock`, `fmi3GetIntervalDecimal`,
//!   `fmi3GetShiftDecimal`, `fmi3UpdateDiscreteStates`, `fmi3EnterStepMode`, `fmi3DoStep`,
//!   `fmi3EnterEventMode`) drives the gyro's and the star tracker's clocks at their ticks: every output read at
//!   every communication point has the same bits as the unit's FMI 2.0 FMU stepped by fmi-rs's FMU2 binding
//!   (the sampled run, no clocks).
//! * Scheduled Execution: fmi-rs 0.3.4 loads `fmi3InstantiateScheduledExecution` but its `Implementation`
//!   offers Model Exchange and Co-Simulation instances only, so it cannot create one (docs/tools.md).
//!
//! Needs `scripts/build_fmus.sh` first (the test fails with that message otherwise).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use fmi_rs::fmi3::log::Logger;
use fmi_rs::fmi3::native::NativeLibrary;
use fmi_rs::fmi3::types::{fmi3IntervalQualifier, fmi3Status};
use fmi_rs::fmi3::Implementation;
use fmi_rs::model_description::fmi3::{Causality, ModelDescription, VariableType};

/// `<FMU folder>/<rel>.fmu`: `SCFMU_FMU_DIR` when set (as for the Python tests), else the checkout's `fmus/`.
fn fmu(rel: &str) -> PathBuf {
    let root = std::env::var_os("SCFMU_FMU_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("fmus"));
    let p = root.join(format!("{rel}.fmu"));
    assert!(p.exists(), "{} missing: run scripts/build_fmus.sh", p.display());
    p
}

fn unzip(rel: &str, tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("scfmu_fmirs_clk_{}_{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(fmu(rel), &dir).expect("unzip");
    dir
}

/// fmi-rs's logger, keeping the FMU's messages.
#[derive(Default)]
struct Keep(Mutex<Vec<String>>);
impl Logger for Keep {
    fn log_call(&self, _: fmi3Status, _: &str) {}
    fn log_message(&self, _: fmi3Status, _: &str, message: &str) {
        self.0.lock().unwrap().push(message.to_string());
    }
}

/// The inputs at time t (s): a slow rotation about a fixed axis, as rate (gyro) and quaternion (star tracker).
fn inputs(model: &str, t: f64) -> Vec<(&'static str, f64)> {
    const AXIS: [f64; 3] = [0.48, -0.6, 0.64];
    let a = 0.05 * t + 0.3 * (0.7 * t).sin();
    match model {
        "Gyro" => vec![
            ("w_x", 0.01 * t.sin()),
            ("w_y", 0.01 * (2.0 * t).sin()),
            ("w_z", 0.01 * (3.0 * t).sin()),
        ],
        _ => vec![
            ("q_w", (a / 2.0).cos()),
            ("q_x", (a / 2.0).sin() * AXIS[0]),
            ("q_y", (a / 2.0).sin() * AXIS[1]),
            ("q_z", (a / 2.0).sin() * AXIS[2]),
        ],
    }
}

fn ok(s: fmi3Status, what: &str, log: &Keep) {
    assert!(
        matches!(s, fmi3Status::Ok),
        "{what}: {s:?}; log: {:?}",
        log.0.lock().unwrap()
    );
}

/// The unit's Float64 outputs (name, value reference), in description order.
fn outputs(md: &ModelDescription) -> Vec<(String, u32)> {
    md.modelVariables
        .iter()
        .filter(|v| v.causality == Causality::Output && matches!(v.variableType, VariableType::Float64 { .. }))
        .map(|v| (v.name.clone(), v.valueReference))
        .collect()
}

fn vr(md: &ModelDescription, name: &str) -> u32 {
    md.modelVariables
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no {name}"))
        .valueReference
}

/// The sampled run: the FMI 2.0 FMU through fmi-rs's FMU2 binding; at t = k h set the inputs, read the
/// outputs, step.
fn sampled(model: &str, h: f64, n: usize, outs: &[(String, u32)]) -> Vec<Vec<f64>> {
    use fmi_rs::fmi2::log::DefaultLogger;
    use fmi_rs::fmi2::types::fmi2Status;
    use fmi_rs::fmi2::{CS, FMU2};
    let dir = unzip(model, &format!("{model}2"));
    let md = fmi_rs::model_description::fmi2::ModelDescription::from_path(&dir.join("modelDescription.xml")).unwrap();
    let f = FMU2::<CS>::new(
        &dir,
        model,
        model,
        &md.guid,
        false,
        false,
        false,
        Arc::new(DefaultLogger::default()),
        false,
    )
    .unwrap();
    let ok2 = |s: fmi2Status, w: &str| assert!(matches!(s, fmi2Status::Ok), "{w}: {s:?}");
    let vr2 = |name: &str| {
        md.modelVariables
            .iter()
            .find(|v| v.name == name)
            .unwrap()
            .valueReference
    };
    ok2(f.setupExperiment(None, 0.0, None), "setupExperiment");
    ok2(f.enterInitializationMode(), "enterInitializationMode");
    ok2(f.exitInitializationMode(), "exitInitializationMode");
    let mut rows = vec![];
    for k in 0..n {
        let t = k as f64 * h;
        for (name, x) in inputs(model, t) {
            ok2(f.setReal(&[vr2(name)], &[x]), "setReal");
        }
        let mut row = vec![0.0; outs.len()];
        for (j, (name, _)) in outs.iter().enumerate() {
            ok2(f.getReal(&[vr2(name)], &mut row[j..j + 1]), "getReal");
        }
        rows.push(row);
        ok2(f.doStep(t, h, 1), "doStep");
    }
    f.terminate();
    let _ = std::fs::remove_dir_all(&dir);
    rows
}

fn due(t: f64, interval: f64, shift: f64) -> bool {
    let k = ((t - shift) / interval).round();
    k >= 0.0 && (t - (shift + k * interval)).abs() <= 1e-9 * t.abs().max(1.0)
}

/// fmi-rs's instance API drives every clock of `model` (Co-Simulation, eventModeUsed = true) over `n` steps
/// of `h`; the outputs equal the sampled FMI 2.0 run's bit for bit. `timing`: the intervals and shifts the
/// unit documents.
fn clocked_equals_sampled(model: &str, h: f64, n: usize, timing: &[(f64, f64)]) {
    let dir = unzip(&format!("fmi3/{model}"), &format!("{model}3"));
    let md = ModelDescription::from_path(&dir.join("modelDescription.xml")).unwrap();
    let clocks: Vec<u32> = md
        .modelVariables
        .iter()
        .filter(|v| matches!(v.variableType, VariableType::Clock { .. }))
        .map(|v| v.valueReference)
        .collect();
    assert_eq!(clocks.len(), timing.len(), "{model}: clocks {clocks:?}");
    let outs = outputs(&md);
    let lib = NativeLibrary::load(dir.join(format!("binaries/x86_64-linux/{model}.so"))).expect("load");
    let log = Arc::new(Keep::default());
    let f = lib
        .instantiateCoSimulation(
            model,
            &md.instantiationToken,
            None,
            false,
            true,
            true,
            false,
            &[],
            log.clone(),
        )
        .unwrap_or_else(|e| {
            panic!(
                "{model}: fmi3InstantiateCoSimulation: {e:?}; {:?}",
                log.0.lock().unwrap()
            )
        });
    ok(
        f.enterInitializationMode(None, 0.0, None),
        "fmi3EnterInitializationMode",
        &log,
    );
    let (mut iv, mut sh) = (vec![0.0; clocks.len()], vec![0.0; clocks.len()]);
    let mut q = vec![fmi3IntervalQualifier::IntervalNotYetKnown; clocks.len()];
    ok(
        f.getIntervalDecimal(&clocks, &mut iv, &mut q),
        "fmi3GetIntervalDecimal",
        &log,
    );
    ok(f.getShiftDecimal(&clocks, &mut sh), "fmi3GetShiftDecimal", &log);
    let got: Vec<(f64, f64)> = iv.iter().copied().zip(sh.iter().copied()).collect();
    assert_eq!(got, timing, "{model}: interval and shift of each clock");
    assert!(
        q.iter().all(|q| *q == fmi3IntervalQualifier::IntervalChanged),
        "{model}: {q:?}"
    );
    ok(f.exitInitializationMode(), "fmi3ExitInitializationMode", &log);
    let mut rows = vec![];
    for k in 0..n {
        let t = k as f64 * h;
        for (name, x) in inputs(model, t) {
            ok(f.setFloat64(&[vr(&md, name)], &[x]), "fmi3SetFloat64", &log);
        }
        let active: Vec<u32> = clocks
            .iter()
            .zip(timing)
            .filter(|(_, &(i, s))| due(t, i, s))
            .map(|(c, _)| *c)
            .collect();
        if !active.is_empty() {
            ok(f.setClock(&active, &vec![true; active.len()]), "fmi3SetClock", &log);
        }
        let (mut need, mut term, mut nom, mut val, mut next) = (true, true, true, true, None);
        ok(
            f.updateDiscreteStates(&mut need, &mut term, &mut nom, &mut val, &mut next),
            "fmi3UpdateDiscreteStates",
            &log,
        );
        assert!(
            !need && !term && next.is_some_and(|x| x > t),
            "{model} at {t}: {need} {term} {next:?}"
        );
        let mut row = vec![0.0; outs.len()];
        let refs: Vec<u32> = outs.iter().map(|o| o.1).collect();
        ok(f.getFloat64(&refs, &mut row), "fmi3GetFloat64", &log);
        rows.push(row);
        ok(f.enterStepMode(), "fmi3EnterStepMode", &log);
        let (mut ev, mut te, mut er, mut last) = (false, false, false, 0.0);
        ok(
            f.doStep(t, h, true, &mut ev, &mut te, &mut er, &mut last),
            "fmi3DoStep",
            &log,
        );
        ok(f.enterEventMode(), "fmi3EnterEventMode", &log);
    }
    ok(f.terminate(), "fmi3Terminate", &log);
    drop(f);
    let reference = sampled(model, h, n, &outs);
    for (j, (name, _)) in outs.iter().enumerate() {
        let a: Vec<u64> = rows.iter().map(|r| r[j].to_bits()).collect();
        let b: Vec<u64> = reference.iter().map(|r| r[j].to_bits()).collect();
        assert_eq!(
            a, b,
            "{model}.{name}: fmi-rs's clocked run differs from the sampled FMI 2.0 run"
        );
    }
    assert!(
        outs.iter()
            .enumerate()
            .any(|(j, _)| rows.iter().any(|r| r[j] != rows[0][j])),
        "{model}: every output constant"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fmi_rs_drives_the_gyro_clock_and_equals_the_sampled_run() {
    clocked_equals_sampled("Gyro", 0.01, 300, &[(0.01, 0.0)]);
}

#[test]
fn fmi_rs_drives_the_star_tracker_sample_and_delivery_clocks_and_equals_the_sampled_run() {
    clocked_equals_sampled("StarTracker", 0.1, 60, &[(0.2, 0.0), (0.2, 0.1)]);
}

/// fmi-rs's own Co-Simulation driver on a clocked unit: without event mode it runs (the unit samples inside
/// fmi3DoStep); with event mode it never sets a clock and the run fails.
#[test]
fn fmi_rs_simulate_runs_a_clocked_unit_without_event_mode_and_fails_with_it() {
    use fmi_rs::fmi3::LibraryKind;
    use fmi_rs::sim::fmi3::{cs, recorder::Recorder, SimulationSettings, Trajectories};
    let run = |event_mode_used: bool| {
        let dir = unzip("fmi3/Gyro", &format!("sim{event_mode_used}"));
        let md = Arc::new(ModelDescription::from_path(&dir.join("modelDescription.xml")).unwrap());
        let outs: Vec<usize> = md
            .modelVariables
            .iter()
            .enumerate()
            .filter(|(_, v)| v.causality == Causality::Output)
            .map(|(i, _)| i)
            .collect();
        #[allow(clippy::arc_with_non_send_sync)]
        let recorder = Arc::new(Recorder::new(Trajectories::new(md.clone(), outs)));
        let settings = SimulationSettings {
            unzipdir: dir.clone(),
            model_description: md,
            library_kind: LibraryKind::Native,
            enable_dae: false,
            start_time: 0.0,
            stop_time: 1.0,
            visible: false,
            logging_on: false,
            set_stop_time: true,
            output_interval: 0.01,
            log_time_scale: false,
            tolerance: 1e-6,
            set_tolerance: false,
            start_values: vec![],
            log_fmi_calls: false,
            intermediate_update: false,
            input_file: None,
            early_return_allowed: false,
            event_mode_used,
            log_file: None,
            initial_fmu_state_file: None,
            final_fmu_state_file: None,
        };
        let r = cs::simulate(&settings, None, recorder.clone()).map_err(|e| e.to_string());
        drop(settings);
        let _ = std::fs::remove_dir_all(&dir);
        r.map(|_| Arc::try_unwrap(recorder).ok().unwrap().into_trajectories().rows.len())
    };
    assert_eq!(run(false), Ok(101), "without event mode: 101 rows (0 to 1 s, 0.01 s)");
    let e = run(true).expect_err("with event mode and no clock set, the clocked unit must refuse to step");
    eprintln!("fmi-rs cs::simulate with event_mode_used on Gyro: {e}");
}
