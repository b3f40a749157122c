//! Benchmark (issue 10): per-step cost of the fractional PI^λD^μ law against the length of its
//! Grünwald–Letnikov history, direct O(n) sums versus the exact block-FFT evaluation, with the
//! SingleAxisPlant Euler step (the rest of the closed loop) for scale. Plain `Instant` loops.
//!
//! Run: `cargo bench --bench fractional`. Results go to docs/benchmarks.md by hand.

use std::hint::black_box;
use std::time::Instant;

use spacecraft_fmus::model::{Experiment, Fmu};
use spacecraft_fmus::models::single_axis::shared::laws::{FopidLaw, FopidParams, PidLaw};
use spacecraft_fmus::models::single_axis::SingleAxisPlant;

const H: f64 = 0.001;

fn params() -> FopidParams {
    FopidParams {
        kp: 2.0,
        ki: 0.5,
        kd: 8.0,
        lambda: 0.9,
        mu: 0.8,
        h: H,
        memory: 0,
        history_before_start: false,
    }
}

fn err(k: usize) -> f64 {
    0.5 * (-(k as f64) * 2e-4).exp() * (1.0 + 0.1 * (k as f64 * 0.01).sin())
}

/// Runs the law to `upto` samples and returns the mean seconds per step (output + push) over the
/// window [from, upto).
fn window(fast: bool, from: usize, upto: usize) -> f64 {
    let mut law = FopidLaw::with_evaluation(params(), fast).unwrap();
    for k in 0..from {
        black_box(law.output(err(k)));
        law.push(err(k));
    }
    let t0 = Instant::now();
    for k in from..upto {
        black_box(law.output(err(k)));
        law.push(err(k));
    }
    t0.elapsed().as_secs_f64() / (upto - from) as f64
}

fn run_fopid(fast: bool, n: usize) -> f64 {
    let mut law = FopidLaw::with_evaluation(params(), fast).unwrap();
    let t0 = Instant::now();
    for k in 0..n {
        black_box(law.output(err(k)));
        law.push(err(k));
    }
    t0.elapsed().as_secs_f64()
}

fn run_pid(n: usize) -> f64 {
    let mut law = PidLaw::new(params()).unwrap();
    let t0 = Instant::now();
    for k in 0..n {
        black_box(law.output(err(k)));
        law.push(err(k));
    }
    t0.elapsed().as_secs_f64()
}

fn run_plant(n: usize) -> f64 {
    let mut p = Fmu::<SingleAxisPlant>::default();
    p.initialize(&Experiment::default()).unwrap();
    let t0 = Instant::now();
    for k in 0..n {
        p.step(k as f64 * H, H).unwrap();
        p.outputs((k + 1) as f64 * H).unwrap();
    }
    black_box(&p);
    t0.elapsed().as_secs_f64()
}

fn min_of<F: FnMut() -> f64>(reps: usize, mut f: F) -> f64 {
    (0..reps).map(|_| f()).fold(f64::INFINITY, f64::min)
}

fn main() {
    println!(
        "per-step cost of FOPID (output + push, λ = 0.9, μ = 0.8, full memory) in the window [n, n + 2048), min of 3"
    );
    println!("{:>8} {:>12} {:>12} {:>8}", "n", "direct µs", "fast µs", "ratio");
    for n in [1_000usize, 2_000, 5_000, 10_000, 20_000, 50_000, 100_000] {
        let d = min_of(3, || window(false, n, n + 2048));
        let f = min_of(3, || window(true, n, n + 2048));
        println!("{n:>8} {:>12.3} {:>12.3} {:>8.1}", d * 1e6, f * 1e6, d / f);
    }
    println!();
    println!("whole runs at h = 1 ms (seconds, min of 3)");
    println!(
        "{:>8} {:>12} {:>12} {:>12} {:>12} {:>10}",
        "steps", "FOPID direct", "FOPID fast", "PID", "plant", "direct/fast"
    );
    for n in [20_000usize, 100_000] {
        let d = min_of(3, || run_fopid(false, n));
        let f = min_of(3, || run_fopid(true, n));
        let p = min_of(3, || run_pid(n));
        let pl = min_of(3, || run_plant(n));
        println!("{n:>8} {d:>12.4} {f:>12.4} {p:>12.5} {pl:>12.5} {:>10.1}", d / f);
    }
}
