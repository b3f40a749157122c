//! What the benches share: the plant configuration of paper 003 that `plant_step.rs` times and
//! `environment_step.rs` times beside the environment units, and an instance made through the exported
//! FMI 2.0 functions, set up and in Initialization Mode.

use std::ffi::{c_void, CString};

use spacecraft_fmus::fmi::fmi2::*;
use spacecraft_fmus::model::guid::guid;
use spacecraft_fmus::registry;

/// A Co-Simulation instance of `model` by `fmi2Instantiate`, after `fmi2SetupExperiment` and
/// `fmi2EnterInitializationMode`. The logger is never called on the success path; NULL avoids defining a
/// C-variadic function, which stable Rust cannot do.
pub fn instantiate(model: &str) -> *mut c_void {
    let entry = registry::find(model).unwrap();
    let g = CString::new(guid(entry).as_str()).unwrap();
    let name = CString::new("bench").unwrap();
    let cb = Box::leak(Box::new(CallbackFunctions {
        logger: None,
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::null_mut(),
    }));
    let c = fmi2Instantiate(registry::ALL, name.as_ptr(), 1, g.as_ptr(), std::ptr::null(), cb, 0, 0);
    assert!(!c.is_null());
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
    assert_eq!(fmi2EnterInitializationMode(c), 0);
    c
}

/// Paper 003 configuration: full inertia, wheels with lag, magnetorquers, gravity gradient,
/// constant + sinusoidal + white-noise disturbance torques.
pub const REALS: &[(&str, f64)] = &[
    ("inertia_xx", 4.0),
    ("inertia_yy", 5.0),
    ("inertia_zz", 3.5),
    ("inertia_xy", 0.05),
    ("inertia_xz", -0.03),
    ("inertia_yz", 0.02),
    ("init_w_x", 0.01),
    ("init_w_y", -0.005),
    ("wheel_time_constant", 0.1),
    ("dist_const_x", 5e-4),
    ("dist_sin_amp_x", 5e-4),
    ("dist_sin_amp_y", 5e-4),
    ("dist_sin_amp_z", 5e-4),
    ("dist_sin_freq", 0.1),
    ("dist_noise_std_x", 5e-4),
    ("dist_noise_std_y", 5e-4),
    ("dist_noise_std_z", 5e-4),
];
pub const INTS: &[(&str, i32)] = &[("actuator_mode", 1), ("mtq_enable", 1), ("gg_enable", 1)];
