//! Benchmark (issue 22): cost of the copy `fmi2GetFMUstate` makes (`DynModel::clone_box`) and size of
//! the serialized state of `FopidController` after n samples, today's compact state (the error history
//! once, derived buffers rebuilt on decode) against the layout before issue 22, side by side in one run.
//!
//! The old layout held two GL convolutions, each with its own copy of the history, its weights and its
//! buffer of pending block products. Its copy is emulated here by vectors of exactly the lengths the
//! old code kept (computed below from its growth rules for full memory, fast mode, ki != 0,
//! history_before_start = 0); the old code measured 1,746,530 B after 20,000 samples, which the
//! emulation reproduces to the header bytes.
//!
//! Run: `cargo bench --bench fmu_state_copy`. Results go to docs/benchmarks.md by hand.

use std::hint::black_box;
use std::time::Instant;

use spacecraft_fmus::model::{DynModel, Experiment, Fmu};
use spacecraft_fmus::models::single_axis::FopidController;

const NEAR: usize = 64;

/// Lengths of (history, weights, far) of one old GlConvolution after n pushes (memory = 0, fast).
fn old_lengths(n: usize) -> (usize, usize, usize) {
    let (mut w, mut far) = (NEAR, 0);
    for n1 in 1..=n {
        w = w.max((2 * n1).max(NEAR));
        let mut k = 0;
        while n1.is_multiple_of(NEAR << k) {
            let l = NEAR << k;
            w = w.max(2 * l);
            far = far.max(n1 + 2 * l - 1);
            k += 1;
        }
    }
    (n, w, far)
}

fn min_time(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    println!("FopidController state after n samples (lambda = 0.9, mu = 0.8, full memory): fmi2GetFMUstate copy and serialized size, min of 20");
    println!(
        "{:>8} {:>14} {:>14} {:>12} {:>12} {:>10}",
        "n", "old bytes", "new bytes", "old copy µs", "new copy µs", "ratio"
    );
    for n in [2_000usize, 20_000, 200_000] {
        let mut m = Fmu::<FopidController>::default();
        (m.v.lambda, m.v.mu, m.v.theta_ref) = (0.9, 0.8, 0.5);
        m.initialize(&Experiment::default()).unwrap();
        for k in 0..n {
            m.v.theta = 0.5 * (k as f64 * 1e-3).sin();
            m.step(k as f64 * 1e-3, 1e-3).unwrap();
        }
        let new_bytes = DynModel::to_bytes(&m).unwrap().len();
        let (h, w, far) = old_lengths(n);
        let old: Vec<Vec<f64>> = [h, w, far, h, w, far].iter().map(|&l| vec![0.5; l]).collect();
        let old_bytes = 8 * (2 * (h + w + far)) + 100;
        let new_t = min_time(20, || {
            black_box(m.clone_box());
        });
        let old_t = min_time(20, || {
            black_box(old.clone());
        });
        println!(
            "{n:>8} {old_bytes:>14} {new_bytes:>14} {:>12.1} {:>12.1} {:>10.1}",
            old_t * 1e6,
            new_t * 1e6,
            old_t / new_t
        );
    }
}
