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
