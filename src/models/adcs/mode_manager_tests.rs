//! `ModeManager` through `Fmu` as the FMI layer drives it: samples on the integer grid with a shorter
//! communication step, the due sample computed from the current inputs, one log line per change, refusals.

use nalgebra::Vector3;

use super::*;
use crate::model::Fmu;

fn unit(edit: impl FnOnce(&mut ModeManagerVars)) -> Fmu<ModeManager> {
    let mut f = Fmu::<ModeManager>::default();
    edit(&mut f.v);
    f.initialize(&Experiment::default()).unwrap();
    f
}

#[test]
fn samples_on_its_grid_and_logs_each_change_once() {
    // DETUMBLE at 0.005 rad/s < rate_detumbled: the change is due at the sample t = 10 s (min_dwell 10 s);
    // with h = 0.25 s it shows at the communication point t = 10 and is logged by the step that takes it
    let mut f = unit(|v| v.w_meas = Vector3::new(0.0, 0.003, 0.004));
    let h = 0.25;
    let mut seen = vec![];
    for n in 0..60 {
        let t = n as f64 * h;
        f.outputs(t).unwrap();
        seen.push((t, f.v.mode, f.v.mode_changes, f.v.time_in_mode, f.v.torque_select, f.v.dipole_select));
        f.step(t, h).unwrap();
        let log = f.take_log();
        if t == 10.0 {
            assert_eq!(log, ["t = 10 s: DETUMBLE -> SUN_ACQUISITION (rate 0.005 rad/s < rate_detumbled 0.00873; DETUMBLED)"]);
        } else {
            assert!(log.is_empty(), "t = {t}: {log:?}");
        }
    }
    assert_eq!(seen[39], (9.75, 1, 0, 9.0, 0.0, 1.0));
    assert_eq!(seen[40], (10.0, 2, 1, 0.0, 1.0, 0.0));
    assert_eq!(seen[45], (11.25, 2, 1, 1.0, 1.0, 0.0));
    assert_eq!((f.v.last_reason, f.v.sun_angle), (7, std::f64::consts::FRAC_PI_2));
    assert!((f.v.rate - 0.005).abs() < 1e-17, "{}", f.v.rate);
    assert!(f.take_log().is_empty(), "taken once");
}

#[test]
fn a_long_step_takes_every_sample_and_logs_every_change_in_order() {
    // SAFE with recover = 1 and a rate of 0.05 rad/s: RECOVER to DETUMBLE at 10, nothing more in 25 s
    // while the rate stays; a step of 25 s takes the samples 0..=24 (the one at its end belongs to the next)
    let mut f = unit(|v| {
        v.initial_mode = 0;
        v.recover = 1.0;
        v.w_meas = Vector3::new(0.05, 0.0, 0.0);
    });
    f.step(0.0, 25.0).unwrap();
    assert_eq!(f.take_log(), ["t = 10 s: SAFE -> DETUMBLE (recover >= 0.5, rate 0.05 rad/s > rate_tumbling 0.0349; RECOVER)"]);
    f.v.w_meas = Vector3::new(0.001, 0.0, 0.0);
    f.step(25.0, 30.0).unwrap(); // samples 25..=54: DETUMBLED at 25 (dwell 15 s), SUN_ACQUISITION stays (no sun)
    assert_eq!(f.take_log().len(), 1);
    f.outputs(55.0).unwrap();
    assert_eq!((f.v.mode, f.v.mode_changes, f.v.time_in_mode), (2, 2, 30.0));
}

#[test]
fn bad_inputs_and_parameters_are_refused_by_name() {
    let mut f = unit(|v| v.p_att = Vector3::new(1e-6, -1e-9, 0.0));
    let e = f.outputs(0.0).unwrap_err();
    assert!(e.contains("p_att") && e.contains(">= 0"), "{e}");
    assert!(f.step(0.0, 1.0).unwrap_err().contains("p_att"));
    let mut f = unit(|v| v.nis_dim = -1);
    assert!(f.outputs(0.0).unwrap_err().contains("nis_dim"));
    let mut f = Fmu::<ModeManager>::default();
    f.v.sun_angle_acquired = 0.6;
    let e = f.initialize(&Experiment::default()).unwrap_err();
    assert!(e.contains("sun_angle_acquired") && e.contains("sun_angle_lost"), "{e}");
}

/// DETERMINATION with a converged covariance and the sun on its axis; the estimator updates at t = k + 0.5
/// only (between the manager's samples, as a star tracker seen behind a coupling delay): the per-sample
/// inputs nis/nis_dim are 0 at every sample, the running sums grow by 3 (dimension) and 3.0 (NIS) per update.
fn determination_with_updates_between_samples(nis_source: i32) -> (i32, i32) {
    let mut f = unit(|v| {
        v.initial_mode = 3;
        v.nis_source = nis_source;
        v.p_att = Vector3::new(1e-8, 1e-8, 1e-8);
        (v.sun_valid, v.sun_meas) = (1.0, Vector3::new(1.0, 0.0, 0.0));
    });
    let h = 0.5;
    for n in 0..60 {
        let t = n as f64 * h;
        f.outputs(t).unwrap();
        f.step(t, h).unwrap();
        if n % 2 == 0 {
            (f.v.nis_sum, f.v.nis_dim_sum) = (f.v.nis_sum + 3.0, f.v.nis_dim_sum + 3.0); // the update at t + 0.5
        }
    }
    f.outputs(30.0).unwrap();
    (f.v.mode, f.v.last_reason)
}

#[test]
fn running_sums_see_every_update_the_per_sample_inputs_miss() {
    assert_eq!(determination_with_updates_between_samples(0), (3, 0), "no update at any sample: no NIS, no hand-over");
    assert_eq!(determination_with_updates_between_samples(1), (4, 11), "NIS/dim = 1 < nis_max: CONVERGED");
}

#[test]
fn a_running_sum_that_decreases_is_refused() {
    let mut f = unit(|v| v.nis_source = 1);
    f.v.nis_dim_sum = 6.0;
    f.step(0.0, 1.0).unwrap();
    f.v.nis_dim_sum = 3.0;
    let e = f.step(1.0, 1.0).unwrap_err();
    assert!(e.contains("running sums that do not decrease") && e.contains("nis_dim_sum = 3"), "{e}");
}
