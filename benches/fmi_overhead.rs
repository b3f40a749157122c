//! Cost of one FMI co-simulation cycle through the C ABI (fmi2SetReal of the inputs, fmi2DoStep,
//! fmi2GetReal of the outputs) against the same model work called directly in Rust
//! (field writes, `Fmu::step`, `Fmu::outputs`, field reads).
//!
//! Run: `cargo bench --bench fmi_overhead` (prints a Markdown table for docs/benchmarks.md).

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::Instant;

use common::TestFmu;
use spacecraft_fmus::fmi::fmi2::{fmi2DoStep, fmi2GetReal, fmi2SetReal};
use spacecraft_fmus::model::{Experiment, Fmu};
use spacecraft_fmus::models::attitude::control::PdController;
use spacecraft_fmus::models::attitude::AttitudePlant;

const H: f64 = 0.01;

/// Median over `reps` repetitions of the mean time per iteration of `n` iterations, in ns.
fn time_ns(reps: usize, n: usize, mut f: impl FnMut(usize)) -> f64 {
    let mut samples: Vec<f64> = (0..reps)
        .map(|r| {
            let t = Instant::now();
            for k in 0..n {
                f(r * n + k);
            }
            t.elapsed().as_nanos() as f64 / n as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[reps / 2]
}

struct Case {
    name: &'static str,
    inputs: &'static [&'static str],
    outputs: &'static [&'static str],
}

const PD: Case = Case {
    name: "PdController",
    inputs: &[
        "q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y",
    ],
    outputs: &[
        "torque_cmd_x",
        "torque_cmd_y",
        "torque_cmd_z",
        "k_x",
        "k_y",
        "k_z",
        "k_d_x",
        "k_d_y",
        "k_d_z",
        "torque_cmd_x",
    ],
};

const PLANT: Case = Case {
    name: "AttitudePlant",
    inputs: &[
        "torque_cmd_x",
        "torque_cmd_y",
        "torque_cmd_z",
        "torque_dist_x",
        "torque_dist_y",
        "torque_dist_z",
        "torque_cmd_x",
        "torque_cmd_y",
        "torque_cmd_z",
        "torque_dist_x",
    ],
    outputs: &["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw"],
};

fn input_values(case: &Case, k: usize) -> Vec<f64> {
    let s = 1e-3 * (k % 1000) as f64;
    if case.name == "PdController" {
        let q = [(1.0f64 - s * s).sqrt(), s, 0.0, 0.0];
        vec![q[0], q[1], q[2], q[3], 0.01, -0.02, 0.03, 1.0, 0.0, 0.0]
    } else {
        vec![s, -s, 0.5 * s, 0.0, 0.0, 0.0, s, -s, 0.5 * s, 0.0]
    }
}

fn abi_cycle(case: &Case, reps: usize, n: usize) -> f64 {
    let mut f = TestFmu::new(case.name);
    f.init(&[], &[]);
    let vin: Vec<u32> = case.inputs.iter().map(|x| f.vr(x)).collect();
    let vout: Vec<u32> = case.outputs.iter().map(|x| f.vr(x)).collect();
    let mut out = vec![0.0; vout.len()];
    let mut t = 0.0;
    time_ns(reps, n, |k| {
        let u = input_values(case, k);
        assert_eq!(fmi2SetReal(f.c, vin.as_ptr(), vin.len(), u.as_ptr()), 0);
        assert_eq!(fmi2DoStep(f.c, t, H, 1), 0);
        t += H;
        assert_eq!(fmi2GetReal(f.c, vout.as_ptr(), vout.len(), out.as_mut_ptr()), 0);
        black_box(&out);
    })
}

fn direct_plant(reps: usize, n: usize) -> f64 {
    let mut m = Fmu::<AttitudePlant>::default();
    m.initialize(&Experiment::default()).unwrap();
    let mut t = 0.0;
    time_ns(reps, n, |k| {
        let u = input_values(&PLANT, k);
        let v = &mut m.v;
        (
            v.torque_cmd.x,
            v.torque_cmd.y,
            v.torque_cmd.z,
            v.torque_dist.x,
            v.torque_dist.y,
            v.torque_dist.z,
        ) = (u[6], u[7], u[8], u[9], u[4], u[5]);
        m.step(t, H).unwrap();
        t += H;
        m.outputs(t).unwrap();
        let v = &m.v;
        black_box([v.q.w, v.q.i, v.q.j, v.q.k, v.w.x, v.w.y, v.w.z, v.roll, v.pitch, v.yaw]);
    })
}

fn direct_pd(reps: usize, n: usize) -> f64 {
    let mut m = Fmu::<PdController>::default();
    m.initialize(&Experiment::default()).unwrap();
    let mut t = 0.0;
    time_ns(reps, n, |k| {
        let u = input_values(&PD, k);
        let p = &mut m.v.ports;
        (
            p.q.w, p.q.i, p.q.j, p.q.k, p.w.x, p.w.y, p.w.z, p.q_ref.w, p.q_ref.i, p.q_ref.j,
        ) = (u[0], u[1], u[2], u[3], u[4], u[5], u[6], u[7], u[8], u[9]);
        m.step(t, H).unwrap();
        t += H;
        m.outputs(t).unwrap();
        let v = &m.v;
        black_box([
            v.ports.torque_cmd.x,
            v.ports.torque_cmd.y,
            v.ports.torque_cmd.z,
            v.k.x,
            v.k.y,
            v.k.z,
            v.k_d.x,
            v.k_d.y,
            v.k_d.z,
        ]);
    })
}

fn main() {
    // `cargo test --benches` runs this with --bench absent: keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    let (reps, n) = if quick { (3, 1_000) } else { (15, 100_000) };
    println!("| cycle (10 inputs set, doStep {H} s, 10 outputs read) | C ABI [ns] | direct Rust [ns] | ratio |");
    println!("|---|---|---|---|");
    for (case, direct) in [(&PD, direct_pd as fn(usize, usize) -> f64), (&PLANT, direct_plant)] {
        let a = abi_cycle(case, reps, n);
        let d = direct(reps, n);
        println!("| {} | {a:.0} | {d:.0} | {:.2} |", case.name, a / d);
    }
}
