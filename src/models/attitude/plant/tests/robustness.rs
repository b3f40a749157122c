//! Derived values, restored FMU states and the bound on the work of one step.

use super::super::kinematics::{ATT, W};
use super::*;

#[test]
fn derived_values_must_be_finite() {
    // orbit_rate = sqrt(mu / r^3) overflows for a tiny radius: an initialization error, not fmi2OK with inf
    let mut p = Fmu::<AttitudePlant>::default();
    p.v.orbit_radius = 1e-110;
    let e = p.initialize(&Experiment::default()).unwrap_err();
    assert!(e.contains("orbit_rate"), "{e}");
    let mut p = Fmu::<AttitudePlant>::default();
    (p.v.wheel_torque_coeff, p.v.wheel_max_current) = (1e300, 1e300);
    assert!(p.initialize(&Experiment::default()).unwrap_err().contains("wheel_torque_max"));
}

#[test]
fn restored_states_are_validated() {
    let mut p = plant(full_inertia);
    p.step(0.0, 0.1).unwrap();
    assert!(p.validate(&Experiment::default()).is_ok());
    // a stored internal step that no longer matches the parameter (e.g. crafted bytes) is refused
    let mut bad = p.clone();
    bad.model_mut().stepper.max_step = 1e-22;
    assert!(bad.validate(&Experiment::default()).unwrap_err().contains("stepper.max_step"));
    let mut bad = p.clone();
    bad.model_mut().x[W] = f64::NAN;
    assert!(bad.validate(&Experiment::default()).unwrap_err().contains("not finite"));
    let mut bad = p.clone();
    bad.model_mut().x[ATT] = 2.0;
    assert!(bad.validate(&Experiment::default()).unwrap_err().contains("unit norm"));
    let mut bad = p.clone();
    bad.v.inertia_scale.y = -1.0;
    assert!(bad.validate(&Experiment::default()).unwrap_err().contains("inertia_scale_y"));
}

#[test]
fn work_per_step_is_bounded() {
    let mut p = plant(|v| v.max_internal_step = 1e-6);
    let e = p.step(0.0, 10.0).unwrap_err();
    assert!(e.contains("internal steps"), "{e}");
    let mut p = plant(|_| {});
    assert!(p.step(0.0, 1e12).is_err());
    assert!(p.step(0.0, 0.01).is_ok(), "a refused step changes nothing");
}
