//! Tests of the coarse re-initialisation (`mekf_coarse.rs`, inputs `q_coarse`, `init_request`): the
//! re-initialisation sample against the definition (attitude, covariance σ² I exactly, bias kept),
//! convergence and chi-square consistency after a coarse attitude 5° off the truth on the independent
//! simulation of `mekf_tests.rs`, bit-identity with the request low, the restarted latency history and
//! bad inputs.

use super::*;

/// The re-initialisation sample of the tests: between two star-tracker samples (every 20 samples).
const K_RE: usize = 1010;

/// A coarse attitude 5° off the truth q about a seeded random axis: q ⊗ exp(δ/2), |δ| = 5°. Per axis the
/// error has the variance (5°)²/3 = (0.0504 rad)², the default sigma_att_coarse (0.05 rad) to 1 %.
fn coarse_of(q: &Quaternion<f64>, seed: i64) -> Quaternion<f64> {
    let axis = Vector3::from_fn(|j, _| normal(seed, -1, j as u64)).normalize();
    q * quat_exp(&(axis * 5f64.to_radians()))
}

/// Requests a re-initialisation from `coarse_of(truth)` at sample K_RE only.
fn request_at_k_re(seed: i64) -> impl FnMut(usize, &mut Fmu<Mekf>, &Quaternion<f64>) {
    move |i, f, q| {
        f.v.init_request = if i == K_RE { 1.0 } else { 0.0 };
        if i == K_RE {
            f.v.q_coarse = coarse_of(q, seed);
        }
    }
}

#[test]
fn the_reinitialization_sample_has_the_coarse_attitude_and_covariance() {
    let (arw, sc, b) = (1e-8, 1e-4, Vector3::new(2e-4, -5e-4, 1e-4));
    let mut twin = filter(sc);
    run(&mut twin, K_RE + 1, 4, arw, sc, b);
    let mut f = filter(sc);
    let sigma = 0.03;
    f.v.sigma_att_coarse = sigma;
    let (mut qc, mut qt) = (Quaternion::identity(), Quaternion::identity());
    let out = run_with(&mut f, K_RE + 1, 4, arw, sc, b, |i, f, q| {
        if i == K_RE {
            (qc, qt) = (coarse_of(q, 4), *q);
            // not of unit norm and on the other hemisphere: the filter normalises and flips it
            (f.v.q_coarse, f.v.init_request) = (-qc * 2.0, 0.7);
        }
    });
    // the covariance of the sample is the definition's, exactly: σ² I, no attitude-bias correlation
    assert_eq!(f.v.p_att, Vector3::repeat(sigma * sigma));
    let p = f.model().s.p;
    assert_eq!(p.fixed_view::<3, 3>(0, 3).into_owned(), Matrix3::zeros());
    assert_eq!(p.fixed_view::<3, 3>(3, 0).into_owned(), Matrix3::zeros());
    assert_eq!(out.last().unwrap().4, 0, "no measurement at the re-initialisation sample");
    // the attitude is the coarse one (normalised, on the estimate's hemisphere), 5° off the truth
    let qn = qc.normalize(); // the simulated truth is of unit norm only to its accumulated round-off
    assert!((f.v.q_est.coords - qn.coords).amax() < 1e-15, "{:?} vs {:?}", f.v.q_est, qn);
    let e = quat_log(&(f.v.q_est.conjugate() * qt)).norm();
    assert!((e - 5f64.to_radians()).abs() < 1e-12, "{e}");
    // the bias estimate and its covariance are kept: those of the same run without the request
    assert_eq!((f.v.bias_est, f.v.p_bias), (twin.v.bias_est, twin.v.p_bias));
    println!("re-initialisation sample: p_att = {:?} (sigma_att_coarse^2 = {:e}), attitude error {:.6} deg", f.v.p_att.as_slice(), sigma * sigma, e.to_degrees());
}

/// Ten seeded runs of the independent simulation re-initialised at 101 s from a coarse attitude 5° off
/// the truth about a random axis (default sigma_att_coarse 0.05 rad): the first star-tracker update brings
/// the error back to the star tracker's level, and from the re-initialisation to the end (2000 samples
/// per run) the NEES and the NIS per degree of freedom lie in their bands. `coarse_sigma` is the filter's
/// sigma_att_coarse; returns (NEES per dof, NIS per dof, dof, largest error 2 s after the re-initialisation).
fn after_reinitialization(coarse_sigma: f64) -> (f64, f64, i32, f64) {
    let (arw, sc, b) = (1e-8, 1e-4, Vector3::new(2e-4, -5e-4, 1e-4));
    let (mut nees, mut n, mut nis, mut dof, mut worst) = (0.0, 0, 0.0, 0, 0.0f64);
    for seed in 1..=10 {
        let mut f = filter(sc);
        f.v.sigma_att_coarse = coarse_sigma;
        let out = run_with(&mut f, 3010, seed, arw, sc, b, request_at_k_re(seed));
        assert!((out[K_RE].0.norm() - 5f64.to_radians()).abs() < 1e-12, "seed {seed}: {}", out[K_RE].0.norm());
        for (e, p, _, ni, dim) in &out[K_RE..] {
            nees += (0..3).map(|i| e[i] * e[i] / p[i]).sum::<f64>();
            (n, nis, dof) = (n + 3, nis + ni, dof + dim);
        }
        worst = worst.max(out[K_RE + 20].0.norm());
    }
    (nees / n as f64, nis / dof as f64, dof, worst)
}

#[test]
fn converges_and_stays_consistent_after_a_5_degree_coarse_attitude() {
    let (nees, nis, dof, worst) = after_reinitialization(0.05);
    println!("after a 5 deg coarse re-initialisation, 10 runs: NEES per dof {nees:.4}, NIS per dof {nis:.4} over {dof} dof, error 2 s later <= {worst:.3e} rad");
    // 100 star-tracker updates x 3 dof x 10 runs: the 95 % band of chi2(3000)/3000 is 1 +- 0.051
    assert_eq!(dof, 3000);
    assert!((nis - 1.0).abs() < 0.051, "NIS/dof {nis}");
    assert!((nees - 1.0).abs() < 0.15, "NEES/dof {nees}");
    assert!(worst < 1e-3, "error after the first updates {worst} rad");
}

#[test]
fn an_overconfident_coarse_sigma_is_inconsistent() {
    // sigma_att_coarse 1e-3 rad claims 50x less than the 5 deg error: the first update's NIS alone is ~2500 per dof
    let (nees, nis, dof, _) = after_reinitialization(1e-3);
    println!("sigma_att_coarse = 1e-3 rad against 5 deg: NEES per dof {nees:.2}, NIS per dof {nis:.2} over {dof} dof");
    assert!(nis > 1.5 && nees > 1.5, "NIS/dof {nis}, NEES/dof {nees}");
}

#[test]
fn with_the_request_low_q_coarse_is_not_read_and_the_filter_is_unchanged() {
    let bits = |o: &[Sample]| -> Vec<u64> {
        o.iter().flat_map(|(e, p, be, ni, d)| e.iter().chain(p.iter()).chain(be.iter()).copied().chain([*ni, *d as f64]).map(f64::to_bits).collect::<Vec<_>>()).collect()
    };
    for latency in [0.0, 0.3] {
        let mut a = filter(1e-4);
        a.v.st_latency = latency;
        let ra = run(&mut a, 1500, 6, 1e-8, 1e-4, Vector3::new(1e-4, 0.0, -2e-4));
        let mut b = filter(1e-4);
        (b.v.st_latency, b.v.sigma_att_coarse) = (latency, 0.2);
        let rb = run_with(&mut b, 1500, 6, 1e-8, 1e-4, Vector3::new(1e-4, 0.0, -2e-4), |i, f, _| {
            // a quaternion that would be refused if it were read, and a request just below the threshold
            f.v.q_coarse = if i % 2 == 0 { Quaternion::new(0.0, 0.0, 0.0, 0.0) } else { Quaternion::new(f64::NAN, 1.0, 0.0, 0.0) };
            f.v.init_request = 0.49;
        });
        assert_eq!(bits(&ra), bits(&rb), "st_latency {latency}");
        assert_eq!(a.v.q_est.coords.map(f64::to_bits), b.v.q_est.coords.map(f64::to_bits));
    }
}

/// With st_latency = 0.1 s (10 samples of 0.01 s) and a noise-free star tracker delivered 0.1 s late, a
/// re-initialisation at sample 300 restarts the kept history: the quaternion arriving at that sample
/// (measured before it) is not used, the one measured at the re-initialisation sample (arriving 10
/// samples later) updates the coarse estimate of that sample, and the error returns to round-off.
#[test]
fn a_reinitialization_restarts_the_latency_history() {
    let mut f = Fmu::<Mekf>::default();
    (f.v.sample_period, f.v.st_latency, f.v.init_from_star_tracker) = (0.01, 0.1, 0);
    (f.v.st_noise_cross, f.v.st_noise_about) = (1e-5, 1e-5);
    f.v.q_init = q_true(0.0);
    f.initialize(&Experiment::default()).unwrap();
    let (mut dims, mut err) = (vec![], vec![]);
    for i in 0..600i64 {
        let t = i as f64 * 0.01;
        let j = (i - 10).div_euclid(10) * 10; // delivered now, measured at sample j
        (f.v.st_valid, f.v.q_meas, f.v.w_meas) = (if i >= 10 { 1.0 } else { 0.0 }, q_true(j as f64 * 0.01), W_LAT);
        f.v.init_request = if i == 300 { 1.0 } else { 0.0 };
        f.v.q_coarse = coarse_of(&q_true(t), 3);
        f.outputs(t).unwrap();
        dims.push(f.v.nis_dim);
        err.push(quat_log(&(f.v.q_est.conjugate() * q_true(t))).norm());
        f.step(t, 0.01).unwrap();
        if i == 300 {
            assert_eq!(f.model().s.hist.len(), 1, "the history restarts at the re-initialisation sample");
        }
    }
    assert_eq!((dims[290], dims[300], dims[310]), (3, 0, 3), "{:?}", &dims[290..=310]);
    assert!((err[300] - 5f64.to_radians()).abs() < 1e-12 && err[309] > 0.08, "{} {}", err[300], err[309]);
    let tail = err[400..].iter().cloned().fold(0.0, f64::max);
    println!("latency 0.1 s, re-initialised 5 deg off at 3 s: error {:.3e} rad at 3.09 s, {:.3e} rad at 3.1 s, at most {tail:.3e} rad after 4 s", err[309], err[310]);
    assert!(tail < 1e-6, "{tail}");
}

#[test]
fn a_zero_or_non_finite_coarse_attitude_is_refused_by_name() {
    let mut f = Fmu::<Mekf>::default();
    f.initialize(&Experiment::default()).unwrap();
    (f.v.init_request, f.v.q_coarse) = (1.0, Quaternion::new(0.0, 0.0, 0.0, 0.0));
    let e = f.outputs(0.0).unwrap_err();
    assert!(e.contains("input q_coarse has norm 0"), "{e}");
    f.v.q_coarse = Quaternion::new(1.0, f64::INFINITY, 0.0, 0.0);
    let e = f.outputs(0.0).unwrap_err();
    assert!(e.contains("input q_coarse is not finite"), "{e}");
    (f.v.init_request, f.v.q_coarse) = (f64::NAN, Quaternion::identity());
    assert!(f.outputs(0.0).unwrap_err().contains("input init_request = NaN"));
    // the same zero quaternion is not read with the request low
    (f.v.init_request, f.v.q_coarse) = (0.0, Quaternion::new(0.0, 0.0, 0.0, 0.0));
    f.outputs(0.0).unwrap();
    f.v.sigma_att_coarse = 0.0;
    assert!(f.initialize(&Experiment::default()).unwrap_err().contains("sigma_att_coarse"));
}
