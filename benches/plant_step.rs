//! Benchmark (issue 3, item 4): cost of one `fmi2DoStep` of `AttitudePlant` with reaction wheels,
//! magnetorquers and the full disturbance generator at a 0.1 s communication step (default internal
//! RK4 step 0.01 s → 10 internal steps), through the exported C ABI, versus the direct Rust
//! `Fmu::step` of the same configuration. Plain `std::time::Instant` loops, no harness.
//!
//! Run: `cargo bench --bench plant_step` (release profile). Results go to docs/benchmarks.md by hand.

use std::ffi::c_int;
use std::hint::black_box;
use std::time::Instant;

use spacecraft_fmus::fmi::fmi2::*;
use spacecraft_fmus::model::{Experiment, Fmu, SlotMut, Variables};
use spacecraft_fmus::models::attitude::plant::AttitudePlantVars;
use spacecraft_fmus::models::attitude::AttitudePlant;
use spacecraft_fmus::registry;

const DT: f64 = 0.1;

mod shared;
use shared::{INTS, REALS};

fn vr(name: &str) -> u32 {
    registry::find("AttitudePlant")
        .unwrap()
        .decl(name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .vr
}

fn cmd(k: usize) -> [f64; 3] {
    let t = k as f64 * DT;
    [0.03 * (0.3 * t).sin(), 0.03 * (0.2 * t).cos(), -0.02]
}

/// Mean time per call of `f` over `n` calls after a warm-up; the step index keeps counting (an FMU
/// checks that time advances consistently).
fn time_block(start: &mut usize, n: usize, f: &mut impl FnMut(usize)) -> f64 {
    let t0 = Instant::now();
    for k in *start..*start + n {
        f(k);
    }
    *start += n;
    t0.elapsed().as_secs_f64() / n as f64
}

/// Interleaves the measurements (ROUNDS rounds of BLOCK calls each) and reports the minimum and the
/// median of the per-round means: the machine is shared, so the minimum is the least disturbed value.
const ROUNDS: usize = 15;
const BLOCK: usize = 4000;

/// Declaration index of a variable (what the FMI layer maps a value reference to).
fn index(name: &str) -> usize {
    AttitudePlantVars::DECLS.iter().position(|d| d.name == name).unwrap()
}

fn direct_model() -> Fmu<AttitudePlant> {
    let mut m = Fmu::<AttitudePlant>::default();
    for (n, v) in REALS {
        if let Some(SlotMut::Real(x)) = m.v.slot(index(n)) {
            *x = *v;
        }
    }
    for (n, v) in INTS {
        if let Some(SlotMut::Integer(x)) = m.v.slot(index(n)) {
            *x = *v;
        }
    }
    m.initialize(&Experiment::default()).unwrap();
    m
}

fn abi_instance() -> *mut std::ffi::c_void {
    let c = shared::instantiate("AttitudePlant");
    let (rv, rx): (Vec<u32>, Vec<f64>) = REALS.iter().map(|(n, v)| (vr(n), *v)).unzip();
    assert_eq!(fmi2SetReal(c, rv.as_ptr(), rv.len(), rx.as_ptr()), 0);
    let (iv, ix): (Vec<u32>, Vec<c_int>) = INTS.iter().map(|(n, v)| (vr(n), *v)).unzip();
    assert_eq!(fmi2SetInteger(c, iv.as_ptr(), iv.len(), ix.as_ptr()), 0);
    assert_eq!(fmi2ExitInitializationMode(c), 0);
    c
}

fn main() {
    println!("AttitudePlant, wheels + magnetorquers + gravity gradient + const/sin/noise disturbances,");
    println!("communication step {DT} s, RK4 internal step 0.01 s (10 internal steps); {ROUNDS} interleaved rounds of {BLOCK} steps\n");
    let in_vr = [vr("torque_cmd_x"), vr("torque_cmd_y"), vr("torque_cmd_z")];
    let in_ix = [index("torque_cmd_x"), index("torque_cmd_y"), index("torque_cmd_z")];
    let out_names = [
        "q_w",
        "q_x",
        "q_y",
        "q_z",
        "w_x",
        "w_y",
        "w_z",
        "torque_applied_x",
        "torque_applied_y",
        "torque_applied_z",
        "h_wheel_x",
        "h_wheel_y",
        "h_wheel_z",
    ];
    let out_vr: Vec<u32> = out_names.iter().map(|n| vr(n)).collect();
    let out_ix: Vec<usize> = out_names.iter().map(|n| index(n)).collect();
    let mut buf = vec![0.0; out_vr.len()];
    let mut buf2 = vec![0.0; out_vr.len()];

    // 1. direct Rust: inputs written into the variable block, Model::do_step
    let mut m = direct_model();
    let mut direct = |k: usize| {
        let c = cmd(k);
        for (i, x) in in_ix.iter().zip(&c) {
            if let Some(SlotMut::Real(s)) = m.v.slot(*i) {
                *s = *x;
            }
        }
        m.step(k as f64 * DT, DT).unwrap();
    };
    // 2. through the C ABI: fmi2SetReal(3 inputs) + fmi2DoStep
    let c = abi_instance();
    let mut abi = |k: usize| {
        let u = cmd(k);
        assert_eq!(fmi2SetReal(c, in_vr.as_ptr(), 3, u.as_ptr()), 0);
        assert_eq!(fmi2DoStep(c, k as f64 * DT, DT, 1), 0);
    };
    // 3. a master's full cycle: set inputs, step, read 13 outputs
    let mut m2 = direct_model();
    let mut direct_cycle = |k: usize| {
        let u = cmd(k);
        for (i, x) in in_ix.iter().zip(&u) {
            if let Some(SlotMut::Real(s)) = m2.v.slot(*i) {
                *s = *x;
            }
        }
        m2.step(k as f64 * DT, DT).unwrap();
        m2.outputs((k + 1) as f64 * DT).unwrap();
        for (b, i) in buf.iter_mut().zip(&out_ix) {
            if let Some(spacecraft_fmus::model::Value::Real(x)) = m2.v.value(*i) {
                *b = x;
            }
        }
        black_box(&buf);
    };
    let c2 = abi_instance();
    let mut abi_cycle = |k: usize| {
        let u = cmd(k);
        assert_eq!(fmi2SetReal(c2, in_vr.as_ptr(), 3, u.as_ptr()), 0);
        assert_eq!(fmi2DoStep(c2, k as f64 * DT, DT, 1), 0);
        assert_eq!(fmi2GetReal(c2, out_vr.as_ptr(), out_vr.len(), buf2.as_mut_ptr()), 0);
        black_box(&buf2);
    };

    let mut idx = [0usize; 4];
    let mut res: [Vec<f64>; 4] = Default::default();
    // warm-up round, not recorded
    time_block(&mut idx[0], BLOCK / 4, &mut direct);
    time_block(&mut idx[1], BLOCK / 4, &mut abi);
    time_block(&mut idx[2], BLOCK / 4, &mut direct_cycle);
    time_block(&mut idx[3], BLOCK / 4, &mut abi_cycle);
    for _ in 0..ROUNDS {
        res[0].push(time_block(&mut idx[0], BLOCK, &mut direct));
        res[1].push(time_block(&mut idx[1], BLOCK, &mut abi));
        res[2].push(time_block(&mut idx[2], BLOCK, &mut direct_cycle));
        res[3].push(time_block(&mut idx[3], BLOCK, &mut abi_cycle));
    }
    let labels = [
        "direct Rust Fmu::step (+ 3 inputs written)",
        "C ABI fmi2SetReal(3) + fmi2DoStep",
        "direct Rust cycle: 3 inputs + do_step + update_outputs + 13 reads",
        "C ABI cycle: fmi2SetReal(3) + fmi2DoStep + fmi2GetReal(13)",
    ];
    let mut mins = [0.0; 4];
    println!("{:<68} {:>10} {:>10}", "", "min µs", "median µs");
    for (i, r) in res.iter_mut().enumerate() {
        r.sort_by(f64::total_cmp);
        mins[i] = r[0];
        println!("{:<68} {:>10.3} {:>10.3}", labels[i], r[0] * 1e6, r[r.len() / 2] * 1e6);
    }
    println!("\nratio C ABI / direct (min), step only:  {:.3}", mins[1] / mins[0]);
    println!("ratio C ABI / direct (min), full cycle: {:.3}", mins[3] / mins[2]);
    println!(
        "C ABI overhead per step (min): {:.3} µs (step only), {:.3} µs (cycle)",
        (mins[1] - mins[0]) * 1e6,
        (mins[3] - mins[2]) * 1e6
    );
    fmi2FreeInstance(c);
    fmi2FreeInstance(c2);
}
