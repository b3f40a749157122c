//! Drives a model through the exported FMI 2.0 C functions, as a master would, with a logger that
//! records every message. Shared by the Rust integration tests and benchmarks.
#![allow(dead_code)]

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Mutex;

use spacecraft_fmus::fmi::fmi2::LoggerFn;
use spacecraft_fmus::fmi::fmi2::*;
use spacecraft_fmus::model::guid::guid;
use spacecraft_fmus::registry;

pub const OK: c_int = 0;
pub const DISCARD: c_int = 2;
pub const ERROR: c_int = 3;

/// Messages received by the logger: (status, message).
pub type Log = Mutex<Vec<(c_int, String)>>;

/// A non-variadic logger: fmi2CallbackLogger is C-variadic, which stable Rust cannot define. Every
/// message we send is fully formatted, so the variadic part is never read; on the x86-64 and AArch64
/// C ABIs a callee with the fixed arguments only is call-compatible (fmpy's ctypes logger is the same).
unsafe extern "C" fn record(
    env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    _cat: *const c_char,
    msg: *const c_char,
) {
    let log = unsafe { &*(env as *const Log) };
    let text = unsafe { CStr::from_ptr(msg) }.to_string_lossy().replace("%%", "%");
    log.lock().unwrap().push((status, text));
}

pub fn logger() -> LoggerFn {
    // SAFETY: see `record`.
    unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char),
            LoggerFn,
        >(record)
    }
}

pub struct TestFmu {
    pub c: *mut c_void,
    pub model: &'static str,
    pub log: Box<Log>,
    callbacks: Box<CallbackFunctions>,
}

impl TestFmu {
    /// Instantiates `model` (in Co-Simulation mode) with its GUID.
    pub fn new(model: &'static str) -> Self {
        let entry = registry::find(model).expect("registered");
        Self::with_guid(model, &guid(entry))
    }

    /// Instantiates `model` as Model Exchange (fmuType fmi2ModelExchange = 0).
    pub fn new_me(model: &'static str) -> Self {
        let entry = registry::find(model).expect("registered");
        Self::with_type(model, &guid(entry), 0)
    }

    pub fn with_guid(model: &'static str, guid: &str) -> Self {
        Self::with_type(model, guid, 1)
    }

    pub fn with_type(model: &'static str, guid: &str, fmu_type: c_int) -> Self {
        let log: Box<Log> = Box::new(Mutex::new(vec![]));
        let callbacks = Box::new(CallbackFunctions {
            logger: Some(logger()),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &*log as *const Log as *mut c_void,
        });
        let name = CString::new(format!("test_{model}")).unwrap();
        let g = CString::new(guid).unwrap();
        let c = fmi2Instantiate(
            registry::ALL,
            name.as_ptr(),
            fmu_type,
            g.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        );
        TestFmu {
            c,
            model,
            log,
            callbacks,
        }
    }

    pub fn vr(&self, name: &str) -> u32 {
        registry::find(self.model)
            .unwrap()
            .decl(name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .vr
    }

    pub fn init(&mut self, reals: &[(&str, f64)], ints: &[(&str, i32)]) {
        assert_eq!(fmi2SetupExperiment(self.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(self.c), OK);
        for (n, v) in reals {
            self.set(n, *v);
        }
        for (n, v) in ints {
            assert_eq!(fmi2SetInteger(self.c, &self.vr(n), 1, v), OK, "{n}");
        }
        assert_eq!(fmi2ExitInitializationMode(self.c), OK, "{:?}", self.messages());
    }

    pub fn set(&self, name: &str, v: f64) {
        assert_eq!(
            fmi2SetReal(self.c, &self.vr(name), 1, &v),
            OK,
            "set {name}: {:?}",
            self.messages()
        );
    }

    pub fn get(&self, name: &str) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(
            fmi2GetReal(self.c, &self.vr(name), 1, &mut v),
            OK,
            "get {name}: {:?}",
            self.messages()
        );
        v
    }

    pub fn gets(&self, names: &[&str]) -> Vec<f64> {
        let vrs: Vec<u32> = names.iter().map(|n| self.vr(n)).collect();
        let mut out = vec![0.0; names.len()];
        assert_eq!(fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()), OK);
        out
    }

    pub fn step(&self, t: f64, h: f64) -> c_int {
        fmi2DoStep(self.c, t, h, 1)
    }

    pub fn messages(&self) -> Vec<(c_int, String)> {
        self.log.lock().unwrap().clone()
    }

    pub fn last_message(&self) -> String {
        self.log.lock().unwrap().last().map(|m| m.1.clone()).unwrap_or_default()
    }
}

impl Drop for TestFmu {
    fn drop(&mut self) {
        fmi2FreeInstance(self.c);
        let _ = &self.callbacks;
    }
}
