//! The health flag `actuator_fault`, transient faults (`fault_clear_time`) and the shared magnetorquers
//! (`mtq_mode` 2), against closed forms.

use nalgebra::Vector3;

use super::super::exchange::next_time_event;
use super::*;

/// Spherical inertia (no gyroscopic coupling), u_max = 10 N·m, a loss of effectiveness on x, a bias on y
/// and a stuck z in [1.05 s, 2.37 s) (neither instant on the 0.1 s grid).
fn transient(v: &mut AttitudePlantVars) {
    (v.inertia.x, v.inertia.y, v.inertia.z) = (800.0, 800.0, 800.0);
    (v.u_max.x, v.u_max.y, v.u_max.z) = (10.0, 10.0, 10.0);
    (v.effectiveness.x, v.fault_bias.y, v.fault_stuck_z, v.fault_stuck_value.z) = (0.1, 2.0, 1, 7.0);
    (v.fault_time, v.fault_clear_time) = (1.05, 2.37);
    (v.torque_cmd.x, v.torque_cmd.y, v.torque_cmd.z) = (5.0, 1.0, -3.0);
}

#[test]
fn faults_act_in_their_window_and_the_flag_follows_it() {
    let mut p = plant(transient);
    for k in 0..30 {
        let t = k as f64 * 0.1;
        p.outputs(t).unwrap();
        let on = (1.05..2.37).contains(&t);
        let want = if on { Vector3::new(1.0, 3.0, 7.0) } else { Vector3::new(5.0, 1.0, -3.0) };
        assert_eq!((p.v.actuator_fault, p.v.torque_applied), (if on { 1.0 } else { 0.0 }, want), "t = {t}");
        p.step(t, 0.1).unwrap();
    }
    // the window is cut exactly: ω(3) = ∫ τ dt / J with τ piecewise constant
    p.outputs(3.0).unwrap();
    let w = (Vector3::new(5.0, 1.0, -3.0) * (3.0 - 1.32) + Vector3::new(1.0, 3.0, 7.0) * 1.32) / 800.0;
    assert!((p.v.w - w).amax() < 1e-15, "{} vs {w}", p.v.w);
    // the instants are time events of Model Exchange; a permanent fault (1e30) has no end event
    assert_eq!([0.0, 1.05, 2.0, 2.37].map(|t| next_time_event(&p.v, t)), [Some(1.05), Some(2.37), Some(2.37), None]);
    p.v.fault_clear_time = 1e30;
    assert_eq!(next_time_event(&p.v, 1.05), None);
}

#[test]
fn the_flag_is_zero_without_a_configured_fault_and_a_clear_before_the_onset_is_refused() {
    let mut p = plant(|v| (v.fault_time, v.fault_clear_time) = (1.0, 2.0));
    for t in [0.0, 1.0, 1.5, 2.0, 3.0] {
        p.outputs(t).unwrap();
        assert_eq!(p.v.actuator_fault, 0.0, "t = {t}");
    }
    for fault in [|v: &mut AttitudePlantVars| v.effectiveness.y = 0.5, |v: &mut AttitudePlantVars| v.fault_stuck_x = 1, |v: &mut AttitudePlantVars| v.fault_bias.z = -1e-3] {
        let mut p = Fmu::<AttitudePlant>::default();
        fault(&mut p.v);
        (p.v.fault_time, p.v.fault_clear_time) = (2.0, 2.0);
        let e = p.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("fault_clear_time = 2 s is not after fault_time = 2 s"), "{e}");
    }
}

/// mtq_mode 2: m = clamp(m_cmd + k (h_w × B)/|B|²) per axis; with torque_cmd = 0, no wheel lag and
/// unsaturated wheels the wheels take the dumping share's torque, so the body feels clamp(m_cmd) × B.
#[test]
fn shared_coils_sum_the_command_and_the_dumping_and_feed_forward_only_the_dumping() {
    let p = plant(|v| {
        (v.actuator_mode, v.mtq_enable, v.mtq_mode) = (1, 1, 2);
        (v.init_h_wheel.x, v.init_h_wheel.y, v.init_h_wheel.z) = (2e-3, -1e-3, 4e-3);
        (v.m_cmd.x, v.m_cmd.y, v.m_cmd.z) = (0.2, -3.0, 0.1); // limit 1 A.m2: y clamps
    });
    let (h, b) = (p.v.h_wheel, p.v.b_body);
    let lim = Vector3::repeat(1.0);
    let raw = h.cross(&b) * (0.005 / b.norm_squared());
    let m = (p.v.m_cmd + raw).zip_map(&lim, |x, l| x.clamp(-l, l));
    assert!((p.v.dipole - m).amax() < 1e-15, "{} vs {m}", p.v.dipole);
    let body = Vector3::new(0.2, -1.0, 0.1).cross(&b);
    assert!((p.v.torque_applied - body).amax() < 1e-20, "{} vs {body}", p.v.torque_applied);
}

#[test]
fn shared_coils_without_a_command_are_the_dumping_law_bit_for_bit() {
    let run = |mode: i32| {
        let mut p = plant(|v| {
            (v.actuator_mode, v.mtq_enable, v.mtq_mode, v.wheel_time_constant) = (1, 1, mode, 0.2);
            v.mtq_max_current = 1e4; // unsaturated: mtq_mode 0 does not scale the dipole
            (v.init_h_wheel.x, v.init_h_wheel.y, v.init_h_wheel.z) = (0.01, 0.02, -0.015);
            full_inertia(v);
        });
        let mut out = vec![];
        run(&mut p, 20.0, 0.1, |p| out.push([p.v.q.coords.as_slice(), p.v.w.as_slice(), p.v.h_wheel.as_slice(), p.v.dipole.as_slice(), p.v.torque_applied.as_slice()].concat()));
        out
    };
    assert_eq!(run(2), run(0));
}
