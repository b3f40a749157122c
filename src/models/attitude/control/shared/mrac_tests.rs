//! Unit tests of `mrac.rs` (kept apart so the law's file reads as the law).

use super::*;
use crate::math::attitude::{quat, quat_derivative};

fn inputs(q: Quaternion<f64>, w: Vector3<f64>, q_ref: Quaternion<f64>) -> AttitudeControllerPorts {
    AttitudeControllerPorts {
        q,
        w,
        q_ref,
        ..Default::default()
    }
}

/// With Î = I the quaternion law gives ẍ = v exactly: checked by a central second difference of
/// x = 2 q_v along the true rigid-body motion under the (held) torque.
#[test]
fn exact_inertia_feedback_linearises() {
    let inertia = Vector3::new(1000.0, 500.0, 700.0);
    let core = MracCore {
        coordinates: MracCoordinates::Quaternion,
        lambda: 2.0,
        gamma: 0.0,
        ihat_min: [1.0; 3],
        gains: ReferenceGains::Fixed {
            lambda1: 2.0,
            lambda2: 1.0,
        },
    };
    let q = quat(0.8, 0.3, -0.4, 0.2).normalize();
    let w = Vector3::new(0.05, -0.12, 0.2);
    let q_ref = quat(0.9, -0.2, 0.3, 0.1).normalize();
    let st = MracState {
        xm: [0.1, -0.2, 0.05],
        xm_dot: [0.01, 0.02, -0.03],
        ihat: inertia.into(),
        started: true,
    };
    let inp = inputs(q, w, q_ref);
    let o = mrac_outputs(&core, &st, &inp).unwrap();
    let f = |q: Quaternion<f64>, w: Vector3<f64>| {
        let wdot = (o.torque - w.cross(&inertia.component_mul(&w))).component_div(&inertia);
        (quat_derivative(&q, &w), wdot)
    };
    let x_at = |h: f64| {
        // RK4 of the rigid body over h (h may be negative)
        let (k1q, k1w) = f(q, w);
        let (k2q, k2w) = f(q + k1q * (h / 2.0), w + k1w * (h / 2.0));
        let (k3q, k3w) = f(q + k2q * (h / 2.0), w + k2w * (h / 2.0));
        let (k4q, _) = f(q + k3q * h, w + k3w * h);
        let qn = q + (k1q + k2q * 2.0 + k3q * 2.0 + k4q) * (h / 6.0);
        qn.vector().into_owned() * 2.0
    };
    let h = 1e-3;
    let xdd = (x_at(h) - q.vector().into_owned() * 4.0 + x_at(-h)) / (h * h);
    assert!(
        (xdd - o.sig.v).norm() < 1e-6 * o.sig.v.norm().max(1e-3),
        "{xdd} vs {}",
        o.sig.v
    );
}

#[test]
fn estimate_respects_lower_bound() {
    let core = MracCore {
        coordinates: MracCoordinates::Linear,
        lambda: 2.0,
        gamma: 1e9,
        ihat_min: [50.0; 3],
        gains: ReferenceGains::Fixed {
            lambda1: 2.0,
            lambda2: 1.0,
        },
    };
    let inp = inputs(
        quat(1.0, 0.0, 0.0, 0.0),
        Vector3::new(0.3, -0.3, 0.2),
        quat(0.9, 0.3, 0.2, 0.1).normalize(),
    );
    let mut st = MracState {
        ihat: [500.0; 3],
        ..Default::default()
    };
    let meas = core.measure(&inp);
    for _ in 0..100 {
        st = core.step(&st, &meas, 0.01).unwrap();
        assert!(st.ihat.iter().all(|&v| v >= 50.0));
    }
}
