//! Unit tests of `mekf.rs`: an independent simulation of the filter's consistency, a mis-set filter that
//! fails it, restore mid-run, direction-only updates and bad input.

use super::*;
use crate::math::attitude::quat_from_euler321;
use crate::math::random::normal;
use crate::model::{DynModel, Fmu};

/// Truth and sensors of a closed-form rotation with a constant bias, simulated here from the
/// definitions (independent of the Gyro/StarTracker FMUs): ω(t) = ω₀ + a sin(t), q from RK-free
/// exponential steps of a fine grid; gyro = ω + b + N/√T n; star tracker every 20 samples.
struct Truth {
    q: Quaternion<f64>,
    b: Vector3<f64>,
}

fn rate(t: f64) -> Vector3<f64> {
    Vector3::new(0.01 + 0.005 * (0.2 * t).sin(), -0.02, 0.015 * (0.3 * t).cos())
}

/// One sample of a test run: (err δθ, P_att diag, bias err, nis, dim).
type Sample = (Vector3<f64>, Vector3<f64>, Vector3<f64>, f64, i32);

/// Runs the filter with a communication step h = T; returns one [`Sample`] per sample.
fn run(f: &mut Fmu<Mekf>, n: usize, seed: i64, arw: f64, sc: f64, b: Vector3<f64>) -> Vec<Sample> {
    run_with(f, n, seed, arw, sc, b, |_, _, _| {})
}

/// [`run`] with `hook(sample, filter, true attitude)` called before each sample's outputs (after the
/// sensors' inputs are set): a test changes further inputs there.
fn run_with(f: &mut Fmu<Mekf>, n: usize, seed: i64, arw: f64, sc: f64, b: Vector3<f64>, mut hook: impl FnMut(usize, &mut Fmu<Mekf>, &Quaternion<f64>)) -> Vec<Sample> {
    f.initialize(&Experiment::default()).unwrap();
    let tp = f.v.sample_period;
    let mut tr = Truth { q: quat_from_euler321(0.3, -0.2, 1.0), b };
    let mut out = vec![];
    let mut qm = tr.q;
    for i in 0..n {
        let t = i as f64 * tp;
        f.v.w_meas = rate(t) + tr.b + Vector3::from_fn(|j, _| (arw / tp).sqrt() * normal(seed, i as i64, j as u64));
        if i % 20 == 0 {
            let nse = Vector3::from_fn(|j, _| sc * normal(seed, i as i64, 3 + j as u64));
            qm = tr.q * quat_exp(&nse);
        }
        f.v.q_meas = qm;
        hook(i, f, &tr.q);
        f.outputs(t).unwrap();
        let e = quat_log(&(f.v.q_est.conjugate() * tr.q));
        out.push((e, f.v.p_att, f.v.bias_est - tr.b, f.v.nis, f.v.nis_dim));
        f.step(t, tp).unwrap();
        // truth over [t, t+T]: 50 exponential sub-steps of the true rate (midpoint)
        for j in 0..50 {
            let s = t + (j as f64 + 0.5) * tp / 50.0;
            tr.q *= quat_exp(&(rate(s) * (tp / 50.0)));
        }
    }
    out
}

fn filter(sc: f64) -> Fmu<Mekf> {
    let mut f = Fmu::<Mekf>::default();
    f.v.sample_period = 0.1;
    f.v.arw_psd = Vector3::repeat(1e-8);
    f.v.rrw_psd = Vector3::repeat(1e-14);
    (f.v.st_noise_cross, f.v.st_noise_about) = (sc, sc);
    f.v.sigma_bias_init = 1e-3;
    f
}

/// Consistency on the independent simulation: the time-averaged NEES of the attitude (3 dof) and the
/// NIS lie in their chi-square bands, the bias converges within 3 sigma.
#[test]
fn consistent_on_an_independent_simulation() {
    let (arw, sc) = (1e-8, 1e-4);
    let b = Vector3::new(2e-4, -5e-4, 1e-4);
    let mut nees = vec![];
    let (mut nis, mut dof) = (0.0, 0);
    for seed in 1..=10 {
        let mut f = filter(sc);
        let out = run(&mut f, 3000, seed, arw, sc, b);
        for (e, p, _, ni, dim) in out.iter().skip(500) {
            nees.push((0..3).map(|i| e[i] * e[i] / p[i]).sum::<f64>());
            nis += ni;
            dof += dim;
        }
        let (_, _, be, _, _) = out.last().unwrap();
        let pb = f.v.p_bias;
        for i in 0..3 {
            assert!(be[i].abs() < 3.0 * pb[i].sqrt(), "seed {seed}: bias error {be} vs sigma {}", pb.map(f64::sqrt));
        }
    }
    // mean NEES per dof ≈ 1 (diagonal approximation of the 3x3 NEES; samples strongly correlated: loose band)
    let m = nees.iter().sum::<f64>() / nees.len() as f64 / 3.0;
    assert!((m - 1.0).abs() < 0.15, "mean NEES/dof {m}");
    let r = nis / dof as f64;
    println!("independent simulation, 10 runs: attitude NEES per dof {m:.4}, NIS per dof {r:.4} over {dof} dof");
    // dof ≈ 10 runs × 125 updates × 3 = 3750: the 95 % band of chi2(dof)/dof is about 1 ± 0.045
    assert!((r - 1.0).abs() < 0.06, "NIS/dof {r} over {dof}");
}

#[test]
fn a_mis_set_filter_is_inconsistent() {
    let (arw, sc) = (1e-8, 1e-4);
    let mut f = filter(sc * 10.0);
    let out = run(&mut f, 2000, 3, arw, sc, Vector3::zeros());
    let (nis, dof) = out.iter().skip(300).fold((0.0, 0), |(a, d), o| (a + o.3, d + o.4));
    println!("star-tracker noise x10: NIS per dof {:.4}", nis / dof as f64);
    assert!(nis / (dof as f64) < 0.2, "{}", nis / dof as f64);
}

#[test]
fn state_restore_mid_run_is_bit_identical_and_seeded_runs_repeat() {
    let mut a = filter(1e-4);
    let full = run(&mut a, 400, 7, 1e-8, 1e-4, Vector3::new(1e-4, 0.0, 0.0));
    let mut b = filter(1e-4);
    let again = run(&mut b, 400, 7, 1e-8, 1e-4, Vector3::new(1e-4, 0.0, 0.0));
    assert_eq!(full.iter().map(|o| o.0).collect::<Vec<_>>(), again.iter().map(|o| o.0).collect::<Vec<_>>());
    // snapshot after 200 steps of a fresh run, continue 50 steps, restore, repeat the 50 steps
    let mut c = filter(1e-4);
    c.initialize(&Experiment::default()).unwrap();
    let steps = |c: &mut Fmu<Mekf>, from: usize, to: usize| {
        let mut o = vec![];
        for i in from..to {
            let t = i as f64 * 0.1;
            c.v.w_meas = rate(t) + Vector3::from_fn(|j, _| 1e-4 * normal(1, i as i64, j as u64));
            c.v.q_meas = quat_exp(&(rate(0.0) * t + Vector3::from_fn(|j, _| 1e-4 * normal(1, (i / 20) as i64, 3 + j as u64))));
            c.outputs(t).unwrap();
            o.push((c.v.q_est, c.v.p_att, c.v.nis));
            c.step(t, 0.1).unwrap();
        }
        o
    };
    steps(&mut c, 0, 200);
    let bytes = DynModel::to_bytes(&c).unwrap();
    let first = steps(&mut c, 200, 250);
    let mut d = filter(1e-4);
    d.initialize(&Experiment::default()).unwrap();
    d.load_bytes(&bytes).unwrap();
    DynModel::validate(&mut d, &Experiment::default()).unwrap();
    assert_eq!(steps(&mut d, 200, 250), first);
}

#[test]
fn vector_updates_observe_the_attitude() {
    // two perfect directions (sun, field) only: the attitude error collapses to about the noise
    let mut f = Fmu::<Mekf>::default();
    (f.v.use_star_tracker, f.v.use_sun, f.v.use_mag) = (0, 1, 1);
    (f.v.sun_noise, f.v.mag_noise) = (1e-3, 1e-3);
    f.v.sigma_att_init = 0.05;
    f.initialize(&Experiment::default()).unwrap();
    let q = quat_exp(&Vector3::new(0.02, -0.03, 0.01));
    let (s, m) = (Vector3::new(1.0, 0.2, 0.1).normalize(), Vector3::new(0.1, -1.0, 0.5).normalize());
    let a = attitude_matrix(&q);
    let tp = f.v.sample_period;
    for i in 0..200 {
        let t = i as f64 * tp;
        let nse = |c: u64| Vector3::from_fn(|j, _| 1e-3 * normal(5, i, c + j as u64));
        (f.v.sun_ref, f.v.b_ref) = (s, m * 3e-5);
        f.v.sun_meas = (a * s + nse(0)).normalize();
        f.v.b_meas = (a * m + nse(3)) * 3e-5;
        f.outputs(t).unwrap();
        assert_eq!(f.v.nis_dim, 4);
        f.step(t, tp).unwrap();
    }
    let e = quat_log(&(f.v.q_est.conjugate() * q));
    assert!(e.norm() < 5.0 * f.v.p_att.sum().sqrt() && f.v.p_att.max() < 1e-6, "{e} {}", f.v.p_att);
}

#[test]
fn bad_inputs_and_parameters_are_named() {
    let mut f = Fmu::<Mekf>::default();
    f.v.arw_psd = Vector3::new(1e-9, 0.0, 1e-9);
    assert!(f.initialize(&Experiment::default()).unwrap_err().contains("arw_psd"));
    f.v.arw_psd = Vector3::repeat(1e-9);
    f.v.st_noise_cross = 0.0;
    assert!(f.initialize(&Experiment::default()).unwrap_err().contains("st_noise_cross"));
    f.v.st_noise_cross = 1e-5;
    f.initialize(&Experiment::default()).unwrap();
    f.v.w_meas = Vector3::new(f64::NAN, 0.0, 0.0);
    assert!(f.outputs(0.0).unwrap_err().contains("w_meas is not finite"));
    f.v.w_meas = Vector3::zeros();
    f.v.q_meas = Quaternion::new(0.0, 0.0, 0.0, 0.0);
    assert!(f.outputs(0.0).unwrap_err().contains("q_meas has norm 0"));
    f.v.q_meas = Quaternion::new(1.0, 0.0, 0.0, 0.0);
    f.v.use_sun = 1;
    f.initialize(&Experiment::default()).unwrap();
    f.v.sun_meas = Vector3::zeros();
    assert!(f.outputs(0.0).unwrap_err().contains("sun_meas has norm 0"));
    let e = f.step(0.0, 1e5).unwrap_err();
    assert!(e.contains("samples of period") || e.contains("sun_meas"), "{e}");
}

/// Constant body rate of the latency tests [rad/s]: |ω| = 0.0985 rad/s.
const W_LAT: Vector3<f64> = Vector3::new(0.05, -0.03, 0.08);

/// The true attitude of the latency tests: q(t) = q₀ ⊗ exp(ω t / 2), closed form.
fn q_true(t: f64) -> Quaternion<f64> {
    quat_from_euler321(0.3, -0.2, 1.0) * quat_exp(&(W_LAT * t))
}

/// A noise-free gyro and a noise-free star tracker sampled every 10 filter samples (T = 0.01 s) and
/// delivered `lag` samples later (invalid before its first delivery); the filter compensates
/// `st_latency` and starts 0.027 rad off (init_from_star_tracker = 0). Returns the attitude error [rad]
/// of every sample and the filter.
fn delayed_run(lag: i64, st_latency: f64, n: i64) -> (Vec<f64>, Fmu<Mekf>) {
    let mut f = Fmu::<Mekf>::default();
    (f.v.sample_period, f.v.st_latency, f.v.init_from_star_tracker) = (0.01, st_latency, 0);
    (f.v.st_noise_cross, f.v.st_noise_about, f.v.sigma_att_init) = (1e-5, 1e-5, 0.05);
    f.v.q_init = q_true(0.0) * quat_exp(&Vector3::new(0.01, -0.02, 0.015));
    f.initialize(&Experiment::default()).unwrap();
    let mut err = vec![];
    for i in 0..n {
        let t = i as f64 * 0.01;
        let j = (i - lag).div_euclid(10) * 10; // the sample delivered now, measured at sample j
        f.v.st_valid = if i >= lag { 1.0 } else { 0.0 };
        f.v.q_meas = q_true(j as f64 * 0.01);
        f.v.w_meas = W_LAT;
        f.outputs(t).unwrap();
        err.push(quat_log(&(f.v.q_est.conjugate() * q_true(t))).norm());
        f.step(t, 0.01).unwrap();
    }
    (err, f)
}

/// Latency compensation against the closed form: with st_latency = the star tracker's 0.1 s the error
/// of noise-free data goes to round-off; with st_latency = 0 on the same data the estimate lags the
/// truth by exactly |ω| τ (the filter settles on q(t − τ) propagated with the exact rate, q(t) ⊗
/// exp(−ω τ / 2)); a compensation of the wrong delay (0.05 s) lags by |ω| × 0.05 s.
#[test]
fn star_tracker_latency_is_compensated_against_the_closed_form() {
    let tau = 0.1;
    let last = |e: &[f64]| e[e.len() - 2000..].iter().cloned().fold(0.0, f64::max);
    let (comp, f) = delayed_run(10, tau, 6000);
    println!("latency 0.1 s: max error over the last 20 s {:.3e} rad compensated", last(&comp));
    assert!(last(&comp) < 1e-6, "compensated: {:.3e} rad", last(&comp));
    assert!(f.v.bias_est.norm() < 1e-6 && f.v.nis_dim == 0, "{}", f.v.bias_est);
    let lag = W_LAT.norm() * tau;
    let (raw, _) = delayed_run(10, 0.0, 6000);
    let (half, _) = delayed_run(10, 0.05, 6000);
    println!("uncompensated {:.6e} rad, |w| tau = {lag:.6e} rad; half-compensated {:.6e} rad", last(&raw), last(&half));
    assert!((last(&raw) - lag).abs() < 1e-3 * lag, "uncompensated {} vs |w| tau {lag}", last(&raw));
    assert!((last(&half) - lag / 2.0).abs() < 1e-3 * lag, "half {} vs {}", last(&half), lag / 2.0);
}

/// The delayed update's NIS describes the delayed innovation: on a noisy star tracker with 0.1 s latency
/// the time-averaged NIS per degree of freedom is in its chi-square band.
#[test]
fn delayed_updates_are_consistent_and_restore_with_their_history() {
    let mut f = filter(1e-4);
    f.v.st_latency = 0.3; // 3 samples of 0.1 s
    f.initialize(&Experiment::default()).unwrap();
    let drive = |f: &mut Fmu<Mekf>, from: i64, to: i64| {
        let mut o = vec![];
        for i in from..to {
            let t = i as f64 * 0.1;
            f.v.w_meas = W_LAT + Vector3::from_fn(|j, _| (1e-8f64 / 0.1).sqrt() * normal(9, i, j as u64));
            let m = (i - 3).div_euclid(5) * 5; // every 0.5 s, 0.3 s late
            f.v.st_valid = if i >= 3 { 1.0 } else { 0.0 };
            f.v.q_meas = q_true(m as f64 * 0.1) * quat_exp(&Vector3::from_fn(|j, _| 1e-4 * normal(9, m, 3 + j as u64)));
            f.outputs(t).unwrap();
            o.push((f.v.q_est, f.v.p_att, f.v.nis, f.v.nis_dim, quat_log(&(f.v.q_est.conjugate() * q_true(t)))));
            f.step(t, 0.1).unwrap();
        }
        o
    };
    let head = drive(&mut f, 0, 3000);
    let bytes = DynModel::to_bytes(&f).unwrap();
    let tail = drive(&mut f, 3000, 3100);
    let mut g = filter(1e-4);
    g.v.st_latency = 0.3;
    g.initialize(&Experiment::default()).unwrap();
    g.load_bytes(&bytes).unwrap();
    DynModel::validate(&mut g, &Experiment::default()).unwrap();
    assert_eq!(drive(&mut g, 3000, 3100), tail);
    // a re-initialization (fmi2Reset) clears the history: the run repeats from its start
    g.initialize(&Experiment::default()).unwrap();
    assert_eq!(drive(&mut g, 0, 100), head[..100]);
    let (nis, dof) = head.iter().skip(500).fold((0.0, 0), |(a, d), o| (a + o.2, d + o.3));
    let nees = head.iter().skip(500).map(|o| (0..3).map(|i| o.4[i] * o.4[i] / o.1[i]).sum::<f64>()).sum::<f64>() / (3.0 * 2500.0);
    println!("0.3 s latency compensated: NIS per dof {:.4} over {dof} dof, attitude NEES per dof {nees:.4}", nis / dof as f64);
    // 500 updates x 3 dof: the 95 % band of chi2(1500)/1500 is 1 ± 0.072
    assert!((nis / dof as f64 - 1.0).abs() < 0.072 && dof == 1500, "NIS/dof {} over {dof}", nis / dof as f64);
    assert!((nees - 1.0).abs() < 0.25, "NEES/dof {nees}");
}

#[test]
fn a_latency_off_the_sample_grid_or_too_long_is_refused() {
    let mut f = Fmu::<Mekf>::default();
    f.v.st_latency = 0.105; // 10.5 samples of 0.01 s
    let e = f.initialize(&Experiment::default()).unwrap_err();
    assert!(e.contains("st_latency = 0.105") && e.contains("whole number"), "{e}");
    (f.v.st_latency, f.v.sample_period) = (2.0, 1e-3); // 2000 samples
    let e = f.initialize(&Experiment::default()).unwrap_err();
    assert!(e.contains("st_latency = 2") && e.contains("at most 1000"), "{e}");
    f.v.st_latency = -0.1;
    assert!(f.initialize(&Experiment::default()).unwrap_err().contains("st_latency"));
    (f.v.st_latency, f.v.sample_period) = (0.3, 0.1); // summed decimals: 0.3 / 0.1 = 2.9999999999999996
    f.initialize(&Experiment::default()).unwrap();
}

#[path = "mekf_coarse_tests.rs"]
mod coarse;
