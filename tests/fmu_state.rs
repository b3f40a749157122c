//! FMU state through the C ABI: get/set and serialize/deserialize restore the complete model state
//! (continuation is bit-identical), and foreign or corrupted states are refused.

mod common;

use std::ffi::c_void;

use common::*;
use spacecraft_fmus::fmi::fmi2::*;

const OUTPUTS: &[&str] = &["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "h_total_ref_x"];

fn tumbling_plant() -> TestFmu {
    let mut p = TestFmu::new("AttitudePlant");
    p.init(
        &[
            ("inertia_xy", 30.0),
            ("init_w_x", 0.1),
            ("init_w_y", -0.05),
            ("init_w_z", 0.2),
            ("u_max_y", 0.5),
        ],
        &[],
    );
    p
}

/// Runs n steps of 0.1 s from t with a time-varying torque; returns the output history bits.
fn run(p: &TestFmu, t0: f64, n: usize) -> Vec<u64> {
    let mut bits = vec![];
    for k in 0..n {
        let t = t0 + k as f64 * 0.1;
        p.set("torque_cmd_x", (0.3 * t).sin());
        p.set("torque_cmd_y", 1.0);
        assert_eq!(p.step(t, 0.1), OK);
        bits.extend(p.gets(OUTPUTS).iter().map(|x| x.to_bits()));
    }
    bits
}

#[test]
fn get_set_state_continuation_is_bit_identical() {
    let p = tumbling_plant();
    run(&p, 0.0, 20);
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    let first = run(&p, 2.0, 30);
    assert_eq!(fmi2SetFMUstate(p.c, s), OK);
    let again = run(&p, 2.0, 30);
    assert_eq!(first, again);
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
    assert!(s.is_null());
}

fn serialize(p: &TestFmu, s: *mut c_void) -> Vec<u8> {
    let mut size = 0usize;
    assert_eq!(fmi2SerializedFMUstateSize(p.c, s, &mut size), OK);
    let mut buf = vec![0u8; size];
    assert_eq!(fmi2SerializeFMUstate(p.c, s, buf.as_mut_ptr() as *mut _, size), OK);
    buf
}

#[test]
fn serialized_state_restores_in_a_new_instance_bit_identically() {
    let p = tumbling_plant();
    run(&p, 0.0, 15);
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    let bytes = serialize(&p, s);
    let expected = run(&p, 1.5, 25);

    // A fresh instance, never initialized by hand, continues from the bytes alone.
    let q = TestFmu::new("AttitudePlant");
    let mut s2: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(q.c, bytes.as_ptr() as *const _, bytes.len(), &mut s2),
        OK,
        "{:?}",
        q.messages()
    );
    assert_eq!(fmi2SetFMUstate(q.c, s2), OK);
    assert_eq!(run(&q, 1.5, 25), expected);
    assert_eq!(fmi2FreeFMUstate(q.c, &mut s2), OK);
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
}

#[test]
fn corrupted_or_foreign_bytes_are_refused() {
    let p = tumbling_plant();
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    let bytes = serialize(&p, s);
    let q = TestFmu::new("AttitudePlant");
    let try_bytes = |b: &[u8]| {
        let mut out: *mut c_void = std::ptr::null_mut();
        let st = fmi2DeSerializeFMUstate(q.c, b.as_ptr() as *const _, b.len(), &mut out);
        assert!(out.is_null(), "no state may be created from bad bytes");
        st
    };
    // every single-byte corruption is caught (magic, version, length, payload or CRC)
    for i in 0..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        assert_eq!(try_bytes(&b), ERROR, "flip at byte {i} accepted");
    }
    assert_eq!(try_bytes(&bytes[..bytes.len() - 1]), ERROR);
    assert_eq!(try_bytes(&[]), ERROR);
    assert_eq!(try_bytes(&[0u8; 64]), ERROR);
    assert!(
        q.last_message().contains("fmi2DeSerializeFMUstate"),
        "{}",
        q.last_message()
    );
    // a state of another model is refused by name
    let other = TestFmu::new("AttitudeMetrics");
    let mut so: *mut c_void = std::ptr::null_mut();
    let b = serialize(&p, s);
    assert_eq!(
        fmi2DeSerializeFMUstate(other.c, b.as_ptr() as *const _, b.len(), &mut so),
        ERROR
    );
    assert!(
        other.last_message().contains("belongs to AttitudePlant"),
        "{}",
        other.last_message()
    );
    // the instance is still usable after the refusals
    let mut good: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(q.c, bytes.as_ptr() as *const _, bytes.len(), &mut good),
        OK
    );
    assert_eq!(fmi2FreeFMUstate(q.c, &mut good), OK);
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
}

#[test]
fn unknown_state_handles_are_refused() {
    let p = tumbling_plant();
    let mut bogus = 0xdead_beef_u64;
    let fake = &mut bogus as *mut u64 as *mut c_void;
    assert_eq!(fmi2SetFMUstate(p.c, fake), ERROR);
    assert_eq!(fmi2SetFMUstate(p.c, std::ptr::null_mut()), ERROR);
    let mut f = fake;
    assert_eq!(fmi2FreeFMUstate(p.c, &mut f), ERROR);
    // double free
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    let copy = s;
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
    assert_eq!(fmi2SetFMUstate(p.c, copy), ERROR);
    let mut c2 = copy;
    assert_eq!(fmi2FreeFMUstate(p.c, &mut c2), ERROR);
    assert!(p.last_message().contains("already freed"), "{}", p.last_message());
    // still stepping fine
    assert_eq!(p.step(0.0, 0.1), OK);
}

#[test]
fn restoring_a_state_leaves_the_error_state() {
    let p = tumbling_plant();
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    // a torque so large that the state overflows puts the instance into the error state
    p.set("torque_cmd_z", 1e300);
    p.set("torque_cmd_x", 1e300);
    assert_eq!(p.step(0.0, 100.0), ERROR);
    assert_eq!(p.step(0.0, 0.1), ERROR, "no stepping in the error state");
    assert_eq!(fmi2SetFMUstate(p.c, s), OK);
    p.set("torque_cmd_z", 0.0);
    p.set("torque_cmd_x", 0.0);
    assert_eq!(p.step(0.0, 0.1), OK, "{:?}", p.messages());
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
}

// ----- Model Exchange: the time of the last event travels with the FMU state -------------------------

/// One event iteration at the current time: (valuesChanged, next time event).
fn event_iteration(p: &TestFmu) -> (bool, Option<f64>) {
    let mut info = EventInfo2 {
        new_discrete_states_needed: 0,
        terminate_simulation: 0,
        nominals_of_continuous_states_changed: 0,
        values_of_continuous_states_changed: 0,
        next_event_time_defined: 0,
        next_event_time: f64::NAN,
    };
    assert_eq!(fmi2NewDiscreteStates(p.c, &mut info), OK, "{:?}", p.messages());
    assert_eq!(info.new_discrete_states_needed, 0);
    (
        info.values_of_continuous_states_changed != 0,
        (info.next_event_time_defined != 0).then_some(info.next_event_time),
    )
}

/// A plant as Model Exchange with a fault at t = 2 s and noise held for 0.3 s (time events at
/// 0.3, 0.6, …, 1.8, 2.0, 2.1, …), in continuous-time mode at t = 0.
fn me_plant() -> TestFmu {
    let mut p = TestFmu::new_me("AttitudePlant");
    p.init(
        &[
            ("fault_time", 2.0),
            ("dist_noise_std_x", 1e-3),
            ("dist_noise_hold", 0.3),
            ("init_w_z", 0.01),
        ],
        &[],
    );
    assert_eq!(event_iteration(&p).1, Some(0.3));
    assert_eq!(fmi2EnterContinuousTimeMode(p.c), OK);
    p
}

/// The master's event handling at time t: set time, event mode, iteration, back to continuous time.
fn event_at(p: &TestFmu, t: f64) -> Option<f64> {
    assert_eq!(fmi2SetTime(p.c, t), OK, "{:?}", p.messages());
    assert_eq!(fmi2EnterEventMode(p.c), OK);
    let next = event_iteration(p).1;
    assert_eq!(fmi2EnterContinuousTimeMode(p.c), OK);
    next
}

/// Restoring an FMU state (get/set and serialize/deserialize) restores the time of the last event
/// with it: the solver may again go back to any time after the restored state's last event, may not
/// go back before it, and the next time event is the restored model's at the restored time.
/// (Before the fix the instance kept the last event of the run it had been taken from.)
#[test]
fn model_exchange_restore_brings_back_the_time_of_the_last_event() {
    let p = me_plant();
    assert_eq!(event_at(&p, 0.3), Some(0.6));
    assert_eq!(fmi2SetTime(p.c, 0.5), OK);
    // state A: continuous-time mode at t = 0.5, last event at 0.3
    let mut a: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut a), OK);
    let a_bytes = serialize(&p, a);
    // on to the fault at t = 2 (events at 0.6, 0.9, ..., 1.8 on the way), state B just after it
    let mut t = 0.6;
    while t < 2.0 {
        t = event_at(&p, t).expect("a next time event");
    }
    assert_eq!(t, 2.0);
    assert_eq!(event_at(&p, 2.0), Some(2.1));
    let mut b: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut b), OK);
    let b_bytes = serialize(&p, b);
    assert_eq!(fmi2SetTime(p.c, 1.5), ERROR, "before the last event");
    assert!(
        p.last_message().contains("fmi2SetTime") && p.last_message().contains("before the last event at t = 2"),
        "{}",
        p.last_message()
    );

    // back to A: t = 0.45 lies after A's last event (0.3), so the solver may evaluate there
    assert_eq!(fmi2SetFMUstate(p.c, a), OK);
    assert_eq!(fmi2SetTime(p.c, 0.45), OK, "{:?}", p.last_message());
    assert_eq!(fmi2SetTime(p.c, 0.25), ERROR, "before A's last event at 0.3");
    assert!(
        p.last_message().contains("before the last event at t = 0.3"),
        "{}",
        p.last_message()
    );
    // the next time event comes from the restored model and time
    assert_eq!(event_at(&p, 0.5), Some(0.6));

    // B restored into a fresh instance through its bytes (that instance's own last event is at 0)
    let q = me_plant();
    let mut qb: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(q.c, b_bytes.as_ptr() as *const _, b_bytes.len(), &mut qb),
        OK,
        "{:?}",
        q.messages()
    );
    assert_eq!(fmi2SetFMUstate(q.c, qb), OK);
    assert_eq!(fmi2SetTime(q.c, 1.5), ERROR, "before B's last event at 2");
    assert!(
        q.last_message().contains("before the last event at t = 2"),
        "{}",
        q.last_message()
    );
    assert_eq!(fmi2SetTime(q.c, 2.05), OK);
    assert_eq!(event_at(&q, 2.05), Some(2.1));
    // and A's bytes into it: back to 0.3 as the last event
    let mut qa: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(q.c, a_bytes.as_ptr() as *const _, a_bytes.len(), &mut qa),
        OK
    );
    assert_eq!(fmi2SetFMUstate(q.c, qa), OK);
    assert_eq!(fmi2SetTime(q.c, 0.4), OK, "{}", q.last_message());
    assert_eq!(event_at(&q, 0.4), Some(0.6));
    for s in [&mut a, &mut b] {
        assert_eq!(fmi2FreeFMUstate(p.c, s), OK);
    }
    for s in [&mut qa, &mut qb] {
        assert_eq!(fmi2FreeFMUstate(q.c, s), OK);
    }
}
