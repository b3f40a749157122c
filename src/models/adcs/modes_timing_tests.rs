//! Unit tests of the mode logic over time: the dwell, the fault confirmation, the NIS filter against its
//! closed form, no chatter inside the bands, the selection table, the parameter rules and the log line
//! (helpers in `modes_tests.rs`).

use super::*;

#[test]
fn the_dwell_holds_progress_but_not_safety() {
    // after DETUMBLE -> SUN_ACQUISITION at t = 10, the sun is acquired at once but waits until t = 20;
    // a fault at t = 12 in a fresh run ends SUN_ACQUISITION two samples after its entry
    let p = ModeParams::default();
    let mut l = logic(Detumble, p.clone());
    let got = run(&mut l, 40, |_| sun(at_rate(0.001), 0.0));
    assert_eq!(
        got,
        [
            (10.0, Detumble, SunAcquisition, Reason::Detumbled),
            (20.0, SunAcquisition, Determination, Reason::SunAcquired)
        ]
    );
    let mut l = logic(Detumble, p.clone());
    let got = run(&mut l, 40, |t| Inputs {
        actuator_fault: if t >= 12.0 { 1.0 } else { 0.0 },
        ..sun(at_rate(0.001), 0.0)
    });
    assert_eq!(
        got,
        [
            (10.0, Detumble, SunAcquisition, Reason::Detumbled),
            (12.0, SunAcquisition, Safe, Reason::Fault)
        ]
    );
    let mut l = logic(Detumble, p);
    let got = run(&mut l, 40, |t| {
        if t >= 11.0 {
            sun(at_rate(0.036), 0.0)
        } else {
            sun(at_rate(0.001), 0.0)
        }
    });
    assert_eq!(got[1], (11.0, SunAcquisition, Detumble, Reason::Tumbling));
    // a dwell of 0.3 s at T = 0.1: exactly three samples (0.1 * 3 rounds above 0.3)
    let p = ModeParams {
        period: 0.1,
        min_dwell: 0.3,
        ..ModeParams::default()
    };
    let mut l = ModeLogic::new(p, 1, 0.0).unwrap();
    let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.1).collect();
    let hit = t
        .iter()
        .position(|&tk| l.sample(tk, &at_rate(0.0)).transition.is_some());
    assert_eq!(hit, Some(3));
}

#[test]
fn fault_confirmation_needs_the_flag_held_for_the_confirm_time() {
    let p = ModeParams {
        fault_confirm_time: 3.0,
        ..ModeParams::default()
    };
    let mut l = logic(FinePointing, p.clone());
    fn flag(on: &'static [f64]) -> impl Fn(f64) -> Inputs {
        move |t| Inputs {
            actuator_fault: if on.contains(&t) { 1.0 } else { 0.0 },
            ..converged(at_rate(0.0))
        }
    }
    // held from t = 5: 5, 6, 7 held 0, 1, 2 s; at t = 8 held 3 s
    assert_eq!(
        first(&mut l, 30, flag(&[5.0, 6.0, 7.0, 8.0, 9.0])),
        Some((8.0, Safe, Reason::Fault))
    );
    let mut l = logic(FinePointing, p);
    // interrupted at 8: counted again from 9, confirmed at 12
    assert_eq!(
        first(&mut l, 30, flag(&[5.0, 6.0, 7.0, 9.0, 10.0, 11.0, 12.0, 13.0])),
        Some((12.0, Safe, Reason::Fault))
    );
}

#[test]
fn the_nis_filter_is_the_geometric_series_and_restarts_at_the_entry_into_determination() {
    // updates x_0 = a, x_j = b (j >= 1), every other sample without an update:
    // avg_n = b + (a - b) alpha^n after n + 1 updates, alpha = exp(-T / tau) = exp(-1/30)
    let (a, b, alpha) = (4.5, 1.25, (-1.0f64 / 30.0).exp());
    let p = ModeParams {
        min_dwell: 1e6,
        ..ModeParams::default()
    };
    let mut l = logic(Determination, p);
    let mut n = -1;
    for k in 0..200 {
        let update = k % 2 == 0;
        let x = if k == 0 { a } else { b };
        let u = Inputs {
            nis: 2.0 * x,
            nis_dim: if update { 2 } else { 0 },
            ..at_rate(0.0)
        };
        let o = l.sample(k as f64, &u);
        n += update as i32;
        let want = b + (a - b) * alpha.powi(n);
        assert!(
            (o.q.nis_avg.unwrap() - want).abs() < 1e-13,
            "k {k}: {:?} vs {want}",
            o.q.nis_avg
        );
    }
    // SUN_ACQUISITION -> DETERMINATION at t = 10 drops the average: the first update after it starts anew
    let mut l = logic(SunAcquisition, ModeParams::default());
    let u = |t: f64| Inputs {
        nis: if t <= 10.0 { 30.0 } else { 3.0 },
        nis_dim: 3,
        ..sun(at_rate(0.0), 0.0)
    };
    for k in 0..=10 {
        l.sample(k as f64, &u(k as f64));
    }
    assert_eq!((l.s.mode, l.s.nis_avg, l.s.last.nis_avg), (Determination, None, None));
    assert_eq!(l.sample(11.0, &u(11.0)).q.nis_avg, Some(1.0));
}

#[test]
fn no_chatter_inside_the_bands() {
    // 1000 samples of a rate oscillating inside (rate_detumbled, rate_tumbling) = (0.00873, 0.0349) rad/s
    let wander = |t: f64| at_rate(0.0218 + 0.013 * (0.7 * t).sin());
    for m in [Detumble, SunAcquisition] {
        let mut l = logic(m, ModeParams::default());
        assert_eq!(run(&mut l, 1000, wander), []);
        assert_eq!(l.s.changes, 0);
    }
    // and a sun angle inside (10, 30) deg in DETERMINATION
    let mut l = logic(Determination, ModeParams::default());
    assert_eq!(
        run(&mut l, 1000, |t| sun(
            at_rate(0.0),
            (20.0 + 9.9 * (1.3 * t).sin()) * DEG
        )),
        []
    );
    // the same rate crossing the band edges does change the mode (the test can fail)
    let mut l = logic(SunAcquisition, ModeParams::default());
    assert!(!run(&mut l, 1000, |t| at_rate(0.0218 + 0.03 * (0.7 * t).sin())).is_empty());
}

#[test]
fn the_selection_table_and_estimator_init() {
    let p = ModeParams {
        init_duration: 3.0,
        ..ModeParams::default()
    };
    let want = [
        (Safe, 1.0, 0.0, 0.0),
        (Detumble, 0.0, 1.0, 0.0),
        (SunAcquisition, 1.0, 0.0, 0.0),
        (Determination, 1.0, 0.0, 0.0),
        (FinePointing, 2.0, 0.0, 1.0),
    ];
    for (m, ts, ds, ce) in want {
        let l = logic(m, p.clone());
        let s = l.selection();
        assert_eq!(
            (s.torque_select, s.dipole_select, s.controller_enable),
            (ts, ds, ce),
            "{m:?}"
        );
    }
    // DETERMINATION entered at t = 10: estimator_init = 1 on the samples 10, 11, 12
    let mut l = logic(SunAcquisition, p);
    let init: Vec<f64> = (0..16)
        .map(|k| {
            l.sample(k as f64, &sun(at_rate(0.0), 0.0));
            l.selection().estimator_init
        })
        .collect();
    assert_eq!(
        init,
        [0.0; 10]
            .into_iter()
            .chain([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
            .collect::<Vec<_>>()
    );
}

#[test]
fn parameter_rules_name_the_parameters_and_the_log_line_names_the_condition() {
    let d = ModeParams::default;
    for (p, mode, names) in [
        (
            ModeParams {
                rate_detumbled: 0.0349,
                ..d()
            },
            1,
            ["rate_detumbled", "rate_tumbling"],
        ),
        (
            ModeParams {
                sun_angle_lost: 0.1,
                ..d()
            },
            1,
            ["sun_angle_acquired", "sun_angle_lost"],
        ),
        (
            ModeParams {
                sigma_diverged: 0.001,
                ..d()
            },
            1,
            ["sigma_converged", "sigma_diverged"],
        ),
        (ModeParams { nis_max: 10.0, ..d() }, 1, ["nis_max", "nis_diverged"]),
        (
            ModeParams {
                nis_time_constant: 0.0,
                ..d()
            },
            1,
            ["nis_time_constant", "> 0"],
        ),
        (ModeParams { period: -1.0, ..d() }, 1, ["sample_period", "> 0"]),
        (
            ModeParams {
                sun_axis: [0.0; 3],
                ..d()
            },
            1,
            ["sun_axis", "non-zero"],
        ),
        (d(), 5, ["initial_mode", "5"]),
    ] {
        let e = ModeLogic::new(p, mode, 0.0).unwrap_err();
        assert!(names.iter().all(|n| e.contains(n)), "{e}");
    }
    let mut l = logic(Detumble, d());
    let lines: Vec<String> = (0..12)
        .filter_map(|k| {
            let o = l.sample(k as f64, &at_rate(0.0071));
            l.describe(&o)
        })
        .collect();
    assert_eq!(
        lines,
        ["t = 10 s: DETUMBLE -> SUN_ACQUISITION (rate 0.0071 rad/s < rate_detumbled 0.00873; DETUMBLED)"]
    );
    assert_eq!(
        (num(1e30), num(12.5), num(0.15), num(-0.000123456)),
        ("1.000e30".into(), "12.5".into(), "0.15".into(), "-0.0001235".into())
    );
}
