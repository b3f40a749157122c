//! An fmusim-compatible command line over the `fmi-rs` crate's simulator (a port of the Modelica
//! Reference-FMUs' fmusim: its own FMU loader, calling sequence, input interpolation and CSV writer), for
//! `scfmu verify --importer fmusim` where the Reference-FMUs' fmusim is not installed (tests only: built
//! with `cargo build --release --example fmusim_rs`, pointed at by SCFMU_FMUSIM).
//!
//! fmusim_rs [--interface-type cs] [--start-time T0] [--stop-time T1] [--output-interval H]
//!           [--input-file IN.csv] [--start-value NAME VALUE]... --output-file OUT.csv MODEL.fmu
//! Co-Simulation only; records every output variable; FMI 2.0 or 3.0 from the modelDescription.

use std::path::{Path, PathBuf};
use std::sync::Arc;

fn fail(msg: String) -> ! {
    eprintln!("fmusim_rs: {msg}");
    std::process::exit(1)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut t0, mut t1, mut h) = (0.0f64, None::<f64>, None::<f64>);
    let (mut input, mut output, mut fmu) = (None::<PathBuf>, None::<PathBuf>, None::<PathBuf>);
    let mut starts: Vec<(String, String)> = vec![];
    let mut i = 0;
    while i < args.len() {
        let next = |i: usize| {
            args.get(i + 1)
                .cloned()
                .unwrap_or_else(|| fail(format!("{} needs a value", args[i])))
        };
        let num = |s: String| s.parse::<f64>().unwrap_or_else(|_| fail(format!("not a number: {s}")));
        match args[i].as_str() {
            "--interface-type" => {
                if next(i) != "cs" {
                    fail("only --interface-type cs".into());
                }
                i += 1;
            }
            "--start-time" => {
                t0 = num(next(i));
                i += 1;
            }
            "--stop-time" => {
                t1 = Some(num(next(i)));
                i += 1;
            }
            "--output-interval" => {
                h = Some(num(next(i)));
                i += 1;
            }
            "--input-file" => {
                input = Some(next(i).into());
                i += 1;
            }
            "--start-value" => {
                starts.push((next(i), next(i + 1)));
                i += 2;
            }
            "--output-file" => {
                output = Some(next(i).into());
                i += 1;
            }
            a if a.starts_with("--") => fail(format!("unknown option {a}")),
            a => fmu = Some(a.into()),
        }
        i += 1;
    }
    let fmu = fmu.unwrap_or_else(|| fail("no FMU given".into()));
    let output = output.unwrap_or_else(|| fail("no --output-file".into()));
    let dir = std::env::temp_dir().join(format!("fmusim_rs_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    fmi_rs::zip::extract_zip_archive(&fmu, &dir).unwrap_or_else(|e| fail(format!("unzip {}: {e}", fmu.display())));
    let xml = std::fs::read_to_string(dir.join("modelDescription.xml"))
        .unwrap_or_else(|e| fail(format!("modelDescription.xml: {e}")));
    let r = if xml.contains("fmiVersion=\"3.") {
        run3(&dir, t0, t1, h, input.as_deref(), &output, starts)
    } else {
        run2(&dir, t0, t1, h, input.as_deref(), &output, starts)
    };
    let _ = std::fs::remove_dir_all(&dir);
    if let Err(e) = r {
        fail(e);
    }
}

fn run2(
    dir: &Path,
    t0: f64,
    t1: Option<f64>,
    h: Option<f64>,
    input: Option<&Path>,
    output: &Path,
    starts: Vec<(String, String)>,
) -> Result<(), String> {
    use fmi_rs::model_description::fmi2::{Causality, ModelDescription};
    use fmi_rs::sim::fmi2::{cs, csv, input::StaticInput, recorder::Recorder, SimulationSettings, Trajectories};
    let md = Arc::new(ModelDescription::from_path(&dir.join("modelDescription.xml")).map_err(|e| format!("{e:?}"))?);
    let de = md.defaultExperiment.as_ref();
    let stop = t1
        .or(de.and_then(|d| d.stopTime.as_deref().and_then(|s| s.parse().ok())))
        .unwrap_or(1.0);
    let dt = h
        .or(de.and_then(|d| d.stepSize.as_deref().and_then(|s| s.parse().ok())))
        .unwrap_or((stop - t0) / 500.0);
    let outs: Vec<usize> = md
        .modelVariables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| i)
        .collect();
    let inp = match input {
        Some(p) => {
            let f = std::fs::File::open(p).map_err(|e| format!("{}: {e}", p.display()))?;
            Some(Arc::new(StaticInput::new(
                csv::read_csv(f, md.clone()).map_err(|e| format!("{e}"))?,
                1e-10,
            )))
        }
        None => None,
    };
    #[allow(clippy::arc_with_non_send_sync)] // fmi-rs's simulate() takes the recorder as an Arc; one thread
    let recorder = Arc::new(Recorder::new(Trajectories::new(md.clone(), outs)));
    let settings = SimulationSettings {
        unzipdir: dir.to_path_buf(),
        model_description: md,
        start_time: t0,
        stop_time: stop,
        logging_on: false,
        set_stop_time: true,
        output_interval: dt,
        log_time_scale: false,
        tolerance: 1e-10,
        set_tolerance: false,
        start_values: starts,
        log_fmi_calls: false,
        input_file: None,
        early_return_allowed: false,
        event_mode_used: false,
        log_file: None,
        initial_fmu_state_file: None,
        final_fmu_state_file: None,
    };
    cs::simulate(&settings, inp, recorder.clone()).map_err(|e| format!("simulation failed: {e}"))?;
    drop(settings);
    let tr = Arc::try_unwrap(recorder)
        .map_err(|_| "recorder still shared".to_string())?
        .into_trajectories();
    csv::write_csv(&tr, output).map_err(|e| format!("{}: {e}", output.display()))
}

fn run3(
    dir: &Path,
    t0: f64,
    t1: Option<f64>,
    h: Option<f64>,
    input: Option<&Path>,
    output: &Path,
    starts: Vec<(String, String)>,
) -> Result<(), String> {
    use fmi_rs::fmi3::LibraryKind;
    use fmi_rs::model_description::fmi3::{Causality, ModelDescription};
    use fmi_rs::sim::fmi3::{cs, csv, input::StaticInput, recorder::Recorder, SimulationSettings, Trajectories};
    let md = Arc::new(ModelDescription::from_path(&dir.join("modelDescription.xml")).map_err(|e| format!("{e:?}"))?);
    let de = md.defaultExperiment.as_ref();
    let stop = t1
        .or(de.and_then(|d| d.stopTime.as_deref().and_then(|s| s.parse().ok())))
        .unwrap_or(1.0);
    let dt = h
        .or(de.and_then(|d| d.stepSize.as_deref().and_then(|s| s.parse().ok())))
        .unwrap_or((stop - t0) / 500.0);
    let outs: Vec<usize> = md
        .modelVariables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| i)
        .collect();
    let inp = match input {
        Some(p) => {
            let f = std::fs::File::open(p).map_err(|e| format!("{}: {e}", p.display()))?;
            Some(Arc::new(StaticInput::new(
                csv::read_csv(f, md.clone()).map_err(|e| format!("{e}"))?,
                1e-10,
            )))
        }
        None => None,
    };
    #[allow(clippy::arc_with_non_send_sync)] // fmi-rs's simulate() takes the recorder as an Arc; one thread
    let recorder = Arc::new(Recorder::new(Trajectories::new(md.clone(), outs)));
    let settings = SimulationSettings {
        unzipdir: dir.to_path_buf(),
        model_description: md,
        library_kind: LibraryKind::Native,
        enable_dae: false,
        start_time: t0,
        stop_time: stop,
        visible: false,
        logging_on: false,
        set_stop_time: true,
        output_interval: dt,
        log_time_scale: false,
        tolerance: 1e-10,
        set_tolerance: false,
        start_values: starts,
        log_fmi_calls: false,
        intermediate_update: false,
        input_file: None,
        early_return_allowed: false,
        event_mode_used: false,
        log_file: None,
        initial_fmu_state_file: None,
        final_fmu_state_file: None,
    };
    cs::simulate(&settings, inp, recorder.clone()).map_err(|e| format!("simulation failed: {e}"))?;
    drop(settings);
    let tr = Arc::try_unwrap(recorder)
        .map_err(|_| "recorder still shared".to_string())?
        .into_trajectories();
    csv::write_csv(&tr, output).map_err(|e| format!("{}: {e}", output.display()))
}
