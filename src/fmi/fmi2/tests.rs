//! FMI 2.0 layer tests: a panic inside a call is caught, logged and fatal; a failure of the shared core
//! reads in FMI 2.0's names.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Mutex as StdMutex;

use super::common::*;
use super::cs::fmi2DoStep;
use crate::fmi::types::Status;

type Log = StdMutex<Vec<(c_int, String)>>;

unsafe extern "C" fn record(env: *mut c_void, _n: *const c_char, status: c_int, _c: *const c_char, msg: *const c_char) {
    let log = unsafe { &*(env as *const Log) };
    log.lock()
        .unwrap()
        .push((status, unsafe { CStr::from_ptr(msg) }.to_string_lossy().into_owned()));
}

/// A Co-Simulation instance of a registered model named `p`, logging into `log`.
fn instance(log: &Log, model: &str) -> Component {
    // SAFETY: non-variadic callee with the fixed arguments of fmi2CallbackLogger (see tests/common).
    let logger: LoggerFn = unsafe { std::mem::transmute(record as unsafe extern "C" fn(_, _, _, _, _)) };
    let cb = CallbackFunctions {
        logger: Some(logger),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: log as *const Log as *mut c_void,
    };
    let entry = crate::registry::find(model).unwrap();
    let g = CString::new(crate::model::guid::guid(entry).as_str()).unwrap();
    let c = fmi2Instantiate(
        crate::registry::ALL,
        c"p".as_ptr(),
        1,
        g.as_ptr(),
        std::ptr::null(),
        &cb,
        0,
        0,
    );
    assert!(!c.is_null());
    c
}

fn last(log: &Log) -> (c_int, String) {
    log.lock().unwrap().last().cloned().unwrap()
}

/// A panic inside a call becomes fmi2Fatal with a logged message, and the instance refuses
/// everything afterwards except fmi2FreeInstance.
#[test]
fn panic_is_caught_logged_and_fatal() {
    let log: Box<Log> = Box::new(StdMutex::new(vec![]));
    let c = instance(&log, "AttitudeMetrics");
    let st = call(c, "fmi2Probe", mask::SETUP_EXPERIMENT, |_| {
        panic!("deliberate test panic")
    });
    assert_eq!(st, Status::Fatal as c_int);
    let (status, msg) = last(&log);
    assert_eq!(status, Status::Fatal as c_int);
    assert!(
        msg.contains("fmi2Probe") && msg.contains("deliberate test panic"),
        "{msg}"
    );
    assert_eq!(fmi2EnterInitializationMode(c), Status::Fatal as c_int);
    fmi2FreeInstance(c);
}

/// Issue 47, item 3: the failures of the version-neutral core read in FMI 2.0's names, here through a
/// real call (`fmi3/tests.rs` checks every typed reason in both versions' names).
#[test]
fn the_cores_failures_read_in_fmi2_words() {
    let log: Box<Log> = Box::new(StdMutex::new(vec![]));
    let c = instance(&log, "PidController");
    let ok = Status::Ok as c_int;
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 1.0), ok);
    assert_eq!(fmi2EnterInitializationMode(c), ok);
    assert_eq!(fmi2ExitInitializationMode(c), ok);
    assert_eq!(fmi2DoStep(c, 0.0, 2.0, 1), Status::Error as c_int);
    let want = "fmi2DoStep: step to 2 goes beyond stopTime 1 set in fmi2SetupExperiment";
    assert_eq!(last(&log), (Status::Error as c_int, want.to_string()));
    fmi2FreeInstance(c);
}
