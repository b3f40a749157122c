//! FMI 3.0 layer tests on a small model with a Boolean (none of the registered models has one): the
//! one-byte `fmi3Boolean` both ways, time, the error → Terminated rule, panics → fmi3Fatal, and FMI 2.0
//! instances being foreign to the FMI 3.0 functions.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Mutex;

use super::*;
use crate::export::*;
use crate::fmi::instance::Reason;
use crate::fmi::types::{Arg, FsmState, Status};

declare_variables! {
    /// Variables of a switchable gain.
    pub struct SwitchVars {
        0 => u: Real = 0.0, Input, "", "Input";
        1 => on: Boolean = false, Input, "", "Switch";
        2 => y: Real = 0.0, Output, "", "u when on, else 0";
        100 => gain: Real = 2.0, Parameter, "", "Gain", Positive;
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Switch;

impl Model for Switch {
    type Vars = SwitchVars;
    const INFO: ModelInfo = ModelInfo {
        name: "Fmi3TestSwitch",
        description: "y = gain u if on",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };
    const EVOLVING: &'static [&'static str] = &[];
    fn initialize(_v: &mut SwitchVars, _e: &Experiment) -> Result<Self, String> {
        Ok(Switch)
    }
    fn outputs(&self, v: &mut SwitchVars, _t: f64) -> ModelResult {
        if v.gain > 1e9 {
            panic!("deliberate test panic");
        }
        v.y = if v.on { v.gain * v.u } else { 0.0 };
        Ok(())
    }
}

static MODELS: &[ModelEntry] = &[ModelEntry::of::<Switch>()];

type Log = Mutex<Vec<(c_int, String)>>;

unsafe extern "C" fn record(env: *mut c_void, status: c_int, _cat: *const c_char, msg: *const c_char) {
    let log = unsafe { &*(env as *const Log) };
    log.lock()
        .unwrap()
        .push((status, unsafe { CStr::from_ptr(msg) }.to_string_lossy().into_owned()));
}

fn new(log: &Log) -> Instance3 {
    let token = CString::new(crate::model::guid::guid(&MODELS[0]).as_str()).unwrap();
    let c = fmi3InstantiateCoSimulation(
        MODELS,
        c"t".as_ptr(),
        token.as_ptr(),
        std::ptr::null(),
        0,
        0,
        0,
        0,
        std::ptr::null(),
        0,
        log as *const Log as *mut c_void,
        Some(record),
        std::ptr::null(),
    );
    assert!(!c.is_null());
    c
}

fn last(log: &Log) -> String {
    log.lock().unwrap().last().map(|m| m.1.clone()).unwrap_or_default()
}

fn step(c: Instance3, t: f64, h: f64) -> c_int {
    let (mut a, mut b, mut e, mut l) = (9u8, 9u8, 9u8, 0.0);
    fmi3DoStep(c, t, h, 1, &mut a, &mut b, &mut e, &mut l)
}

const OK: c_int = Status::Ok as c_int;
const ERROR: c_int = Status::Error as c_int;

#[test]
fn booleans_are_one_byte_and_any_nonzero_byte_is_true() {
    let log: Box<Log> = Box::default();
    let c = new(&log);
    assert_eq!(fmi3SetFloat64(c, [0u32].as_ptr(), 1, [3.0].as_ptr(), 1), OK);
    assert_eq!(fmi3SetBoolean(c, [1u32].as_ptr(), 1, [0xFFu8].as_ptr(), 1), OK);
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), OK);
    assert_eq!(fmi3ExitInitializationMode(c), OK);
    // the getter writes exactly one byte per value, 0 or 1
    let mut out = [7u8; 3];
    assert_eq!(fmi3GetBoolean(c, [1u32, 1].as_ptr(), 2, out.as_mut_ptr(), 2), OK);
    assert_eq!(out, [1, 1, 7]);
    let mut y = [0.0; 2];
    assert_eq!(fmi3GetFloat64(c, [2u32, TIME_VR].as_ptr(), 2, y.as_mut_ptr(), 2), OK);
    assert_eq!(y, [6.0, 0.0]);
    assert_eq!(fmi3SetBoolean(c, [1u32].as_ptr(), 1, [0u8].as_ptr(), 1), OK);
    assert_eq!(fmi3GetFloat64(c, [2u32].as_ptr(), 1, y.as_mut_ptr(), 1), OK);
    assert_eq!(y[0], 0.0);
    assert_eq!(step(c, 0.0, 0.5), OK);
    assert_eq!(fmi3GetFloat64(c, [TIME_VR].as_ptr(), 1, y.as_mut_ptr(), 1), OK);
    assert_eq!(y[0], 0.5);
    // dependencies: y feeds through from both inputs
    let mut n = 0usize;
    assert_eq!(fmi3GetNumberOfVariableDependencies(c, 2, &mut n), OK);
    assert_eq!(n, 2);
    let (mut e1, mut ind, mut e2, mut k) = ([9usize; 2], [9u32; 2], [9usize; 2], [9 as c_int; 2]);
    assert_eq!(
        fmi3GetVariableDependencies(
            c,
            2,
            e1.as_mut_ptr(),
            ind.as_mut_ptr(),
            e2.as_mut_ptr(),
            k.as_mut_ptr(),
            2
        ),
        OK
    );
    assert_eq!((e1, ind, e2, k), ([0, 0], [0, 1], [0, 0], [5, 5]));
    fmi3FreeInstance(c);
}

#[test]
fn an_error_terminates_and_reset_recovers() {
    let log: Box<Log> = Box::default();
    let c = new(&log);
    assert_eq!(fmi3SetBoolean(c, [0u32].as_ptr(), 1, [1u8].as_ptr(), 1), ERROR);
    assert!(
        last(&log).contains("fmi3SetBoolean") && last(&log).contains("value reference 0 is u"),
        "{}",
        last(&log)
    );
    let inst = crate::fmi::boundary::instance_of(c, &FMI3).unwrap();
    assert_eq!(inst.run.fsm, FsmState::Terminated);
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), ERROR);
    assert!(last(&log).contains("not allowed in state Terminated"), "{}", last(&log));
    assert_eq!(fmi3Reset(c), OK);
    assert_eq!(
        crate::fmi::boundary::instance_of(c, &FMI3).unwrap().run.fsm,
        FsmState::Instantiated
    );
    // an FMI 2.0 function does not know an FMI 3.0 instance, and the other way round
    assert_eq!(crate::fmi::fmi2::fmi2EnterInitializationMode(c), ERROR);
    assert!(crate::fmi::boundary::instance_of(c, &crate::fmi::fmi2::FMI2).is_none());
    fmi3FreeInstance(c);
}

#[test]
fn a_panic_is_fatal_and_only_free_instance_is_honoured() {
    let log: Box<Log> = Box::default();
    let c = new(&log);
    assert_eq!(fmi3SetFloat64(c, [100u32].as_ptr(), 1, [1e10].as_ptr(), 1), OK);
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), OK);
    assert_eq!(fmi3ExitInitializationMode(c), Status::Fatal as c_int);
    assert!(
        last(&log).contains("fmi3ExitInitializationMode") && last(&log).contains("deliberate test panic"),
        "{}",
        last(&log)
    );
    assert_eq!(fmi3Reset(c), Status::Fatal as c_int);
    fmi3FreeInstance(c);
}

/// Issue 47, item 3: the failures of the version-neutral core read in FMI 3.0's names, through a real
/// call (FMI 2.0's: `fmi2/tests.rs`), and every typed reason in the names of each version (below).
#[test]
fn the_cores_failures_read_in_fmi3_words() {
    let log: Box<Log> = Box::default();
    let c = new(&log);
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 1, 1.0), OK);
    assert_eq!(fmi3ExitInitializationMode(c), OK);
    assert_eq!(step(c, 0.0, 2.0), ERROR);
    let want = "t: fmi3DoStep: step to 2 goes beyond stopTime 1 set in fmi3EnterInitializationMode";
    assert_eq!(last(&log), want);
    fmi3FreeInstance(c);
}

/// Every typed reason of the core in the names of each version.
#[test]
fn every_reason_reads_in_each_versions_words() {
    let fmi2 = &crate::fmi::fmi2::FMI2;
    let restored = "(a state is restored only through the interface version that took it)";
    // (reason, in FMI 2.0's words, in FMI 3.0's words)
    let cases = [
        (
            Reason::IllegalCall(FsmState::StepMode),
            "not allowed in state StepComplete (illegal call sequence)",
            "not allowed in state Step Mode (illegal call sequence)",
        ),
        (
            Reason::FixedParameter {
                name: "gain",
                state: FsmState::Error,
            },
            "parameter gain is fixed and cannot be set after initialization (state Error)",
            "parameter gain is fixed and cannot be set after initialization (state Terminated)",
        ),
        (
            Reason::StateByValue { name: "s" },
            "s is a continuous state: set it with fmi2SetContinuousStates (Model Exchange)",
            "s is a continuous state: set it with fmi3SetContinuousStates (Model Exchange)",
        ),
        (
            Reason::Length {
                arg: Arg::Nominals,
                n: 3,
                model: "M",
                states: 4,
            },
            "x_nominal[] has 3 elements, but M has 4 continuous states",
            "nominals[] has 3 elements, but M has 4 continuous states",
        ),
        (
            Reason::Length {
                arg: Arg::States,
                n: 3,
                model: "M",
                states: 4,
            },
            "x[] has 3 elements, but M has 4 continuous states",
            "continuousStates[] has 3 elements, but M has 4 continuous states",
        ),
        (
            Reason::NonFiniteState {
                k: 5,
                name: "s",
                value: f64::NAN,
            },
            "x[5] (s) = NaN is not finite",
            "continuousStates[5] (s) = NaN is not finite",
        ),
        (
            Reason::BeyondStopTime { end: 2.5, stop: 2.0 },
            "step to 2.5 goes beyond stopTime 2 set in fmi2SetupExperiment",
            "step to 2.5 goes beyond stopTime 2 set in fmi3EnterInitializationMode",
        ),
    ];
    for (reason, in2, in3) in cases {
        assert_eq!(
            (reason.render(fmi2), reason.render(&FMI3)),
            (in2.to_string(), in3.to_string())
        );
    }
    let other = |v: &str| Reason::OtherInterface {
        what: "FMU state",
        taken_by: v.into(),
    };
    let (a, b) = (other("FMI 3.0").render(fmi2), other("FMI 2.0").render(&FMI3));
    assert_eq!(
        a,
        format!("FMU state was taken by an FMI 3.0 instance; this instance runs FMI 2.0 {restored}")
    );
    assert_eq!(
        b,
        format!("FMU state was taken by an FMI 2.0 instance; this instance runs FMI 3.0 {restored}")
    );
}
