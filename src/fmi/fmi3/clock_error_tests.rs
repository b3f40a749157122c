//! Clock and Scheduled Execution calls the standard does not allow, each with fmi3Error and a message
//! naming the reason; the interval and shift queries; the clock bookkeeping in FMU states.

use std::ffi::{c_int, c_void};

use super::clock_tests::{entry, instantiate, last, outputs, set, Log, Master};
use super::*;
use crate::model::CLOCK_VR_BASE;

const SAMPLE: u32 = CLOCK_VR_BASE;
const DELIVERY: u32 = CLOCK_VR_BASE + 1;

/// A StarTracker (period 0.2 s, latency 0.1 s) after initialization at t = 0.
fn star_tracker(master: Master, log: &Log) -> Instance3 {
    let e = entry("StarTracker");
    let c = instantiate(e, master, log);
    assert!(!c.is_null(), "{}", last(log));
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), 0);
    set(c, e, "sample_period", 0.2);
    set(c, e, "latency", 0.1);
    assert_eq!(fmi3ExitInitializationMode(c), 0, "{}", last(log));
    c
}

fn update(c: Instance3) -> (c_int, f64) {
    let (mut a, mut b, mut d, mut f, mut g, mut t) = (0, 0, 0, 0, 0, 0.0);
    (
        fmi3UpdateDiscreteStates(c, &mut a, &mut b, &mut d, &mut f, &mut g, &mut t),
        t,
    )
}

fn step(c: Instance3, t: f64, h: f64) -> c_int {
    fmi3DoStep(c, t, h, 1, &mut 0, &mut 0, &mut 0, &mut 0.0)
}

#[test]
fn interval_and_shift_come_from_the_parameters() {
    let log = Log::default();
    let c = star_tracker(Master::Clocked, &log);
    let vrs = [SAMPLE, DELIVERY];
    let (mut iv, mut q, mut sh) = ([0.0; 2], [0 as c_int; 2], [9.0; 2]);
    assert_eq!(
        fmi3GetIntervalDecimal(c, vrs.as_ptr(), 2, iv.as_mut_ptr(), q.as_mut_ptr()),
        0
    );
    assert_eq!((iv, q), ([0.2, 0.2], [2, 2])); // fmi3IntervalChanged the first time
    assert_eq!(
        fmi3GetIntervalDecimal(c, vrs.as_ptr(), 2, iv.as_mut_ptr(), q.as_mut_ptr()),
        0
    );
    assert_eq!(q, [1, 1]); // then fmi3IntervalUnchanged
    assert_eq!(fmi3GetShiftDecimal(c, vrs.as_ptr(), 2, sh.as_mut_ptr()), 0);
    assert_eq!(sh, [0.0, 0.1]);
    let (mut k, mut r) = (0u64, 0u64);
    assert_eq!(
        fmi3GetIntervalFraction(c, &SAMPLE, 1, &mut k, &mut r, q.as_mut_ptr()),
        3
    );
    assert!(last(&log).contains("supportsFraction"), "{}", last(&log));
    fmi3FreeInstance(c);
    let c = star_tracker(Master::Clocked, &log);
    assert_eq!(fmi3SetIntervalDecimal(c, &SAMPLE, 1, &0.5), 3);
    assert!(
        last(&log).contains("fmi3SetIntervalDecimal") && last(&log).contains("from parameters"),
        "{}",
        last(&log)
    );
    fmi3FreeInstance(c);
}

#[test]
fn a_clock_not_due_is_refused() {
    let log = Log::default();
    let c = star_tracker(Master::Clocked, &log);
    // at t = 0 the sample clock is due, the delivery clock (shift 0.1) is not
    assert_eq!(fmi3SetClock(c, &DELIVERY, 1, &1), 3);
    let m = last(&log);
    assert!(
        m.contains("fmi3SetClock") && m.contains("delivery_clock is not due at t = 0") && m.contains("t = 0.1"),
        "{m}"
    );
    fmi3FreeInstance(c);
}

#[test]
fn a_step_passing_an_unactivated_tick_is_refused() {
    let log = Log::default();
    let c = star_tracker(Master::Clocked, &log);
    assert_eq!(fmi3SetClock(c, &SAMPLE, 1, &1), 0);
    assert_eq!(update(c), (0, 0.1));
    assert_eq!(fmi3EnterStepMode(c), 0);
    assert_eq!(step(c, 0.0, 0.1), 0); // to the delivery tick: allowed
    assert_eq!(step(c, 0.1, 0.1), 3); // past it, not activated
    let m = last(&log);
    assert!(
        m.contains("fmi3DoStep") && m.contains("passes the tick t = 0.1 of clock delivery_clock"),
        "{m}"
    );
    fmi3FreeInstance(c);
    // a tick at the start that was never activated
    let c = star_tracker(Master::Clocked, &log);
    assert_eq!(update(c).0, 0);
    assert_eq!(fmi3EnterStepMode(c), 0);
    assert_eq!(step(c, 0.0, 0.05), 3);
    assert!(
        last(&log).contains("passes the tick t = 0 of clock sample_clock"),
        "{}",
        last(&log)
    );
    fmi3FreeInstance(c);
}

#[test]
fn activation_of_a_value_reference_that_is_no_clock_is_refused() {
    let log = Log::default();
    let c = star_tracker(Master::Scheduled, &log);
    assert_eq!(fmi3ActivateModelPartition(c, 20, 0.0), 3);
    let m = last(&log);
    assert!(
        m.contains("fmi3ActivateModelPartition") && m.contains("value reference 20 is not a clock"),
        "{m}"
    );
    fmi3FreeInstance(c);
    let c = star_tracker(Master::Scheduled, &log);
    assert_eq!(fmi3ActivateModelPartition(c, DELIVERY, 0.0), 3); // not due
    assert!(last(&log).contains("not due at t = 0"), "{}", last(&log));
    fmi3FreeInstance(c);
    let c = star_tracker(Master::Clocked, &log);
    assert_eq!(fmi3SetClock(c, &(CLOCK_VR_BASE + 2), 1, &1), 3);
    assert!(last(&log).contains("is not a clock of StarTracker"), "{}", last(&log));
    fmi3FreeInstance(c);
}

#[test]
fn scheduled_execution_of_a_model_without_clocks_is_null() {
    let log = Log::default();
    let e = entry("PdController");
    let c = instantiate(e, Master::Scheduled, &log);
    assert!(c.is_null());
    assert!(last(&log).contains("PdController has no clocks"), "{}", last(&log));
    let c = instantiate(e, Master::Clocked, &log);
    assert!(c.is_null());
    assert!(last(&log).contains("eventModeUsed = true"), "{}", last(&log));
    // a clocked model without Event Mode runs sampled; it says so only with debug logging on (status
    // OK, category logCalls), so a master without debug logging sees no warning
    let n = log.lock().unwrap().len();
    let c = instantiate(entry("Gyro"), Master::Sampled, &log);
    assert!(!c.is_null());
    assert_eq!(log.lock().unwrap().len(), n, "{}", last(&log));
    assert_eq!(fmi3EnterEventMode(c), 3);
    fmi3FreeInstance(c);
}

#[test]
fn get_clock_on_an_input_clock_is_an_error() {
    let log = Log::default();
    let c = star_tracker(Master::Clocked, &log);
    let mut v = 0u8;
    assert_eq!(fmi3GetClock(c, &SAMPLE, 1, &mut v), 3);
    assert!(last(&log).contains("sample_clock is an input clock"), "{}", last(&log));
    fmi3FreeInstance(c);
}

/// Runs the clocked StarTracker to t = 1 from its state at t = 0.4, twice: from the live instance and
/// from an FMU state taken at 0.4 (restored directly, and serialized then deserialized): the same outputs.
#[test]
fn fmu_states_carry_the_clock_bookkeeping() {
    let e = entry("StarTracker");
    let log = Log::default();
    let c = star_tracker(Master::Clocked, &log);
    let advance = |c: Instance3, from: f64, to: f64| -> Vec<Vec<u64>> {
        let mut rows = Vec::new();
        let mut t = from;
        while t < to - 1e-9 {
            let k = (t / 0.1).round() as u32; // ticks every 0.1 s: sample at even k, delivery at odd k
            let q = [1.0, 0.01 * k as f64, 0.0, 0.0];
            let n = (q.iter().map(|x| x * x).sum::<f64>()).sqrt();
            for (name, x) in ["q_w", "q_x", "q_y", "q_z"].iter().zip(q) {
                set(c, e, name, x / n);
            }
            let clock = if k.is_multiple_of(2) { SAMPLE } else { DELIVERY };
            assert_eq!(fmi3SetClock(c, &clock, 1, &1), 0, "t = {t}: {}", last(&log));
            let (s, next) = update(c);
            assert_eq!(s, 0);
            rows.push(outputs(c, e));
            assert_eq!(fmi3EnterStepMode(c), 0);
            assert_eq!(step(c, t, next - t), 0, "{}", last(&log));
            assert_eq!(fmi3EnterEventMode(c), 0);
            t = next;
        }
        rows
    };
    advance(c, 0.0, 0.4);
    let mut state: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi3GetFMUState(c, &mut state), 0);
    let mut size = 0usize;
    assert_eq!(fmi3SerializedFMUStateSize(c, state, &mut size), 0);
    let mut bytes = vec![0u8; size];
    assert_eq!(fmi3SerializeFMUState(c, state, bytes.as_mut_ptr(), size), 0);
    let live = advance(c, 0.4, 1.0);
    assert_eq!(fmi3SetFMUState(c, state), 0, "{}", last(&log));
    assert_eq!(advance(c, 0.4, 1.0), live);
    let mut back: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut back),
        0,
        "{}",
        last(&log)
    );
    assert_eq!(fmi3SetFMUState(c, back), 0);
    assert_eq!(advance(c, 0.4, 1.0), live);
    // a state of a clocked instance does not go into a sampled one
    let other = instantiate(e, Master::Sampled, &log);
    assert_eq!(fmi3SetFMUState(other, state), 3);
    assert!(last(&log).contains("clock"), "{}", last(&log));
    fmi3FreeInstance(other);
    fmi3FreeFMUState(c, &mut state);
    fmi3FreeFMUState(c, &mut back);
    fmi3FreeInstance(c);
}

static LOCKS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static UNLOCKS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
unsafe extern "C" fn lock() {
    LOCKS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
}
unsafe extern "C" fn unlock() {
    UNLOCKS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
}

/// The importer's preemption callbacks are called once each around every activation, and the
/// instance is in Clock Activation Mode: no step, no Event Mode, no fmi3SetClock.
#[test]
fn scheduled_execution_calls_the_preemption_callbacks_around_each_activation() {
    let e = entry("Gyro");
    let log = Log::default();
    let token = std::ffi::CString::new(crate::model::guid::guid(e).as_str()).unwrap();
    let env = &log as *const Log as *mut c_void;
    let c = fmi3InstantiateScheduledExecution(
        crate::registry::ALL,
        c"se".as_ptr(),
        token.as_ptr(),
        std::ptr::null(),
        0,
        0,
        env,
        Some(super::clock_tests::record),
        std::ptr::null(),
        Some(lock),
        Some(unlock),
    );
    assert!(!c.is_null());
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), 0);
    set(c, e, "sample_period", 0.5);
    assert_eq!(fmi3ExitInitializationMode(c), 0);
    for k in 0..3 {
        assert_eq!(
            fmi3ActivateModelPartition(c, SAMPLE, 0.5 * k as f64),
            0,
            "{}",
            last(&log)
        );
    }
    use std::sync::atomic::Ordering::SeqCst;
    assert_eq!((LOCKS.load(SeqCst), UNLOCKS.load(SeqCst)), (3, 3));
    assert_eq!(fmi3ActivateModelPartition(c, SAMPLE, 1.0), 3); // the tick at 1.0 is done
    assert!(last(&log).contains("next tick is at t = 1.5"), "{}", last(&log));
    let calls: [(&str, &dyn Fn() -> c_int); 3] = [
        ("fmi3DoStep", &|| step(c, 1.0, 0.5)),
        ("fmi3EnterEventMode", &|| fmi3EnterEventMode(c)),
        ("fmi3SetClock", &|| fmi3SetClock(c, &SAMPLE, 1, &1)),
    ];
    for (f, call) in calls {
        assert_eq!(call(), 3, "{f}");
        assert!(last(&log).contains(f), "{}", last(&log));
    }
    fmi3FreeInstance(c);
}

/// A clocked run starts on the sample grid k·T from t = 0 (where the units count their samples); an
/// off-grid start is refused at fmi3ExitInitializationMode, naming the clock and the parameter.
#[test]
fn a_clocked_start_off_the_sample_grid_is_refused() {
    let e = entry("StarTracker");
    for (t0, ok) in [(0.4, true), (0.1, false)] {
        let log = Log::default();
        let c = instantiate(e, Master::Clocked, &log);
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, t0, 0, 0.0), 0);
        set(c, e, "sample_period", 0.2);
        let status = fmi3ExitInitializationMode(c);
        if ok {
            assert_eq!(status, 0, "{}", last(&log));
        } else {
            assert_eq!(status, 3);
            let msg = last(&log);
            assert!(
                msg.contains("sample_clock") && msg.contains("not a multiple of sample_period"),
                "{msg}"
            );
        }
        fmi3FreeInstance(c);
    }
}

/// fmi3GetDirectionalDerivative is allowed in Clock Activation Mode (FMI 3.0, Scheduled Execution API):
/// a held clocked output does not move with the inputs between ticks (0), `sun_angle` (not clocked) does.
#[test]
fn directional_derivatives_in_clock_activation_mode() {
    let log = Log::default();
    let c = star_tracker(Master::Scheduled, &log);
    let (unknowns, knowns, seed) = ([20u32, 30], [1u32], [1.0]);
    let mut out = [f64::NAN; 2];
    let status = fmi3GetDirectionalDerivative(
        c,
        unknowns.as_ptr(),
        2,
        knowns.as_ptr(),
        1,
        seed.as_ptr(),
        1,
        out.as_mut_ptr(),
        2,
    );
    assert_eq!(status, 0, "{}", last(&log));
    assert_eq!(out[0], 0.0);
    assert!(out[1].is_finite());
    fmi3FreeInstance(c);
}
