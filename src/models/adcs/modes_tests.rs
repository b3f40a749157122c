//! Unit tests of the mode logic: every transition a–f on its condition and not inside its band, and the
//! priorities (`modes_timing_tests.rs`: dwell, fault confirmation, NIS filter, chatter, selection, rules).
//! The expected sample times are counted by hand from the thresholds (T = 1 s, min_dwell = 10 s unless a
//! test says otherwise).

use super::*;
use Mode::*;

const DEG: f64 = std::f64::consts::PI / 180.0;

fn logic(mode: Mode, p: ModeParams) -> ModeLogic {
    ModeLogic::new(p, mode.code(), 0.0).unwrap()
}

/// Inputs with a rate of magnitude `rate` (about a skew axis) and everything else at its start value.
fn at_rate(rate: f64) -> Inputs {
    Inputs {
        w_meas: Vector3::new(1.0, -2.0, 2.0) / 3.0 * rate,
        ..Inputs::default()
    }
}

/// A valid sun `angle` away from the x axis (the default sun_axis).
fn sun(u: Inputs, angle: f64) -> Inputs {
    Inputs {
        sun_valid: 1.0,
        sun_meas: Vector3::new(angle.cos(), 0.0, angle.sin()) * 3.0,
        ..u
    }
}

/// The transitions of samples t = 0, 1, …, n-1 with inputs u(t): (t, from, to, reason).
fn run(l: &mut ModeLogic, n: usize, u: impl Fn(f64) -> Inputs) -> Vec<(f64, Mode, Mode, Reason)> {
    (0..n)
        .filter_map(|k| {
            let t = k as f64;
            l.sample(t, &u(t)).transition.map(|tr| (t, tr.from, tr.to, tr.reason))
        })
        .collect()
}

fn first(l: &mut ModeLogic, n: usize, u: impl Fn(f64) -> Inputs) -> Option<(f64, Mode, Reason)> {
    run(l, n, u).first().map(|&(t, _, to, r)| (t, to, r))
}

#[test]
fn d_detumble_ends_after_the_dwell_below_rate_detumbled_and_not_inside_the_band() {
    let mut l = logic(Detumble, ModeParams::default());
    assert_eq!(
        first(&mut l, 30, |_| at_rate(0.008)),
        Some((10.0, SunAcquisition, Reason::Detumbled))
    );
    let mut l = logic(Detumble, ModeParams::default());
    assert_eq!(run(&mut l, 100, |_| at_rate(0.009)), []); // above rate_detumbled 0.00873: in the band
}

#[test]
fn e_sun_acquisition_returns_to_detumble_at_once_above_rate_tumbling_and_goes_on_with_the_sun() {
    let mut l = logic(SunAcquisition, ModeParams::default());
    assert_eq!(
        first(&mut l, 5, |_| at_rate(0.035)),
        Some((0.0, Detumble, Reason::Tumbling))
    );
    let mut l = logic(SunAcquisition, ModeParams::default());
    assert_eq!(run(&mut l, 100, |_| at_rate(0.034)), []); // below rate_tumbling 0.0349
    let go = |t: f64| sun(at_rate(0.005), if t < 14.0 { 11.0 * DEG } else { 9.0 * DEG });
    let mut l = logic(SunAcquisition, ModeParams::default());
    assert_eq!(first(&mut l, 30, go), Some((14.0, Determination, Reason::SunAcquired)));
    let mut l = logic(SunAcquisition, ModeParams::default());
    assert_eq!(
        first(&mut l, 30, |_| sun(at_rate(0.005), 9.0 * DEG)),
        Some((10.0, Determination, Reason::SunAcquired))
    );
    // each condition alone missing: invalid sun, sun in the band, rate in the band, zero sun vector
    for u in [
        Inputs {
            sun_valid: 0.0,
            ..sun(at_rate(0.005), 9.0 * DEG)
        },
        sun(at_rate(0.005), 11.0 * DEG),
        sun(at_rate(0.009), 9.0 * DEG),
        Inputs {
            sun_meas: Vector3::zeros(),
            ..sun(at_rate(0.005), 9.0 * DEG)
        },
    ] {
        let mut l = logic(SunAcquisition, ModeParams::default());
        assert_eq!(run(&mut l, 50, |_| u), [], "{u:?}");
    }
}

/// Converged estimator inputs: sigma 0.005 rad, nis/nis_dim = 2/3.
fn converged(u: Inputs) -> Inputs {
    Inputs {
        p_att: Vector3::new(1e-6, 2.5e-5, 4e-6),
        nis: 2.0,
        nis_dim: 3,
        ..u
    }
}

#[test]
fn f_determination_tumbling_sun_lost_and_converged() {
    let base = sun(at_rate(0.005), 20.0 * DEG); // sun inside the band
    let mut l = logic(Determination, ModeParams::default());
    assert_eq!(
        first(&mut l, 5, |_| Inputs {
            w_meas: Vector3::new(0.0, 0.036, 0.0),
            ..base
        }),
        Some((0.0, Detumble, Reason::Tumbling))
    );
    let mut l = logic(Determination, ModeParams::default());
    assert_eq!(
        first(&mut l, 5, |_| sun(base, 31.0 * DEG)),
        Some((0.0, SunAcquisition, Reason::SunLost))
    );
    let mut l = logic(Determination, ModeParams::default());
    assert_eq!(
        first(&mut l, 30, |_| converged(base)),
        Some((10.0, FinePointing, Reason::Converged))
    );
    // not converged: sigma above, NIS above, or no update since the entry; sun lost needs a valid sun
    for u in [
        Inputs {
            p_att: Vector3::new(1e-4, 0.0, 0.0),
            ..converged(base)
        },
        Inputs {
            nis: 9.3,
            ..converged(base)
        },
        Inputs {
            nis_dim: 0,
            ..converged(base)
        },
        Inputs {
            sun_valid: 0.0,
            ..sun(base, 60.0 * DEG)
        },
        base,
    ] {
        let mut l = logic(Determination, ModeParams::default());
        assert_eq!(run(&mut l, 50, |_| u), [], "{u:?}");
    }
}

#[test]
fn b_fine_pointing_goes_to_safe_on_rate_and_divergence_unless_switched_off() {
    let ok = converged(at_rate(0.01));
    for (u, reason) in [
        (at_rate(0.151), Reason::RateHigh),
        (
            Inputs {
                p_att: Vector3::new(0.0, 0.0, 0.0883 * 0.0883),
                ..ok
            },
            Reason::DivergedSigma,
        ),
        (Inputs { nis: 31.0, ..ok }, Reason::DivergedNis), // 31/3 > 10
    ] {
        let mut l = logic(FinePointing, ModeParams::default());
        assert_eq!(first(&mut l, 5, |_| u), Some((0.0, Safe, reason)));
        let mut l = logic(
            FinePointing,
            ModeParams {
                safe_on_divergence: false,
                ..ModeParams::default()
            },
        );
        let want = if reason == Reason::RateHigh {
            vec![(0.0, FinePointing, Safe, reason)]
        } else {
            vec![]
        };
        assert_eq!(run(&mut l, 50, |_| u), want);
    }
    let mut l = logic(FinePointing, ModeParams::default());
    assert_eq!(
        run(&mut l, 50, |_| Inputs {
            nis: 29.0,
            nis_dim: 3,
            p_att: Vector3::repeat(0.08 * 0.08),
            ..at_rate(0.149)
        }),
        []
    );
}

#[test]
fn a_fault_and_safe_request_end_every_mode_at_once_and_c_safe_recovers_after_the_dwell() {
    for m in [Detumble, SunAcquisition, Determination, FinePointing] {
        let mut l = logic(m, ModeParams::default());
        assert_eq!(
            first(&mut l, 3, |_| Inputs {
                actuator_fault: 0.5,
                ..at_rate(0.0)
            }),
            Some((0.0, Safe, Reason::Fault))
        );
        let mut l = logic(m, ModeParams::default());
        assert_eq!(
            first(&mut l, 3, |_| Inputs {
                safe_request: 1.0,
                ..at_rate(0.0)
            }),
            Some((0.0, Safe, Reason::SafeRequest))
        );
    }
    let mut l = logic(Safe, ModeParams::default());
    assert_eq!(
        run(&mut l, 50, |_| Inputs {
            actuator_fault: 1.0,
            safe_request: 1.0,
            ..at_rate(0.0)
        }),
        []
    );
    let mut l = logic(Safe, ModeParams::default());
    assert_eq!(
        first(&mut l, 30, |_| Inputs {
            recover: 1.0,
            ..at_rate(0.036)
        }),
        Some((10.0, Detumble, Reason::Recover))
    );
    let mut l = logic(Safe, ModeParams::default());
    assert_eq!(
        first(&mut l, 30, |_| Inputs {
            recover: 1.0,
            ..at_rate(0.034)
        }),
        Some((10.0, SunAcquisition, Reason::Recover))
    );
    let mut l = logic(
        Safe,
        ModeParams {
            recover_time: 17.0,
            ..ModeParams::default()
        },
    );
    assert_eq!(
        first(&mut l, 30, |_| at_rate(0.0)),
        Some((17.0, SunAcquisition, Reason::Recover))
    );
    // no recovery while the fault stands, nor without a command
    let mut l = logic(Safe, ModeParams::default());
    assert_eq!(
        run(&mut l, 50, |_| Inputs {
            recover: 1.0,
            actuator_fault: 1.0,
            ..at_rate(0.0)
        }),
        []
    );
    let mut l = logic(Safe, ModeParams::default());
    assert_eq!(
        run(&mut l, 50, |_| Inputs {
            recover: 0.49,
            ..at_rate(0.0)
        }),
        []
    );
}

#[test]
fn priorities_within_a_sample() {
    let all = Inputs {
        actuator_fault: 1.0,
        safe_request: 1.0,
        nis: 300.0,
        nis_dim: 3,
        p_att: Vector3::repeat(1.0),
        ..at_rate(1.0)
    };
    let mut l = logic(FinePointing, ModeParams::default());
    assert_eq!(first(&mut l, 1, |_| all), Some((0.0, Safe, Reason::Fault)));
    let mut l = logic(FinePointing, ModeParams::default());
    assert_eq!(
        first(&mut l, 1, |_| Inputs {
            actuator_fault: 0.0,
            ..all
        }),
        Some((0.0, Safe, Reason::SafeRequest))
    );
    let mut l = logic(FinePointing, ModeParams::default());
    assert_eq!(
        first(&mut l, 1, |_| Inputs {
            actuator_fault: 0.0,
            safe_request: 0.0,
            ..all
        }),
        Some((0.0, Safe, Reason::RateHigh))
    );
    let mut l = logic(FinePointing, ModeParams::default());
    let slow = Inputs {
        actuator_fault: 0.0,
        safe_request: 0.0,
        ..Inputs {
            w_meas: Vector3::zeros(),
            ..all
        }
    };
    assert_eq!(first(&mut l, 1, |_| slow), Some((0.0, Safe, Reason::DivergedSigma)));
    // DETERMINATION: tumbling before sun lost; one transition per sample (the new mode waits for the next)
    let mut l = logic(Determination, ModeParams::default());
    assert_eq!(
        run(&mut l, 2, |_| sun(at_rate(0.04), 90.0 * DEG)),
        [(0.0, Determination, Detumble, Reason::Tumbling)]
    );
}

#[path = "modes_timing_tests.rs"]
mod timing;
