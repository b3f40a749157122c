//! FMI 3.0 Co-Simulation only: `fmi3InstantiateCoSimulation` (Event Mode for clocked models), `fmi3DoStep`,
//! and the Step Mode functions of features these FMUs do not declare (clocked Event Mode: `clocks.rs`).
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int, c_void};

use super::common::{call3, mask3, refuse, request3, require_co_simulation, Instance3, Log3Fn, FMI3};
use crate::fmi::boundary::{self, instance_of, out_ptr, slice, Request};
use crate::fmi::instance::{ClockMode, Fail, Reason};
use crate::fmi::types::Status;
use crate::model::ModelEntry;

/// `fmi3InstantiateCoSimulation` for a library holding `models`: the model is picked by the library's
/// file name and the instantiation token (the GUID), as in `fmi2Instantiate`.
pub fn fmi3InstantiateCoSimulation(
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    event_mode_used: u8,
    early_return_allowed: u8,
    required_intermediate: *const u32,
    n_required_intermediate: usize,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
    _intermediate_update: *const c_void,
) -> Instance3 {
    let _ = early_return_allowed; // allowed, never used: fmi3DoStep always completes the whole step
    let request = request3(
        "fmi3InstantiateCoSimulation",
        models,
        instance_name,
        token,
        logging_on,
        env,
        log_message,
    );
    let c = boundary::instantiate(Request {
        // a model without clocks has no Event Mode in Co-Simulation
        refuse_model: &|entry| {
            (event_mode_used != 0 && entry.clocks.is_empty()).then(|| {
                format!(
                    "eventModeUsed = true, but {} has no Event Mode (hasEventMode = false)",
                    entry.info.name
                )
            })
        },
        check_arguments: &|| {
            if n_required_intermediate > 0 {
                let vrs = unsafe {
                    slice(
                        required_intermediate,
                        n_required_intermediate,
                        "requiredIntermediateVariables[]",
                    )
                }
                .map_err(|f| f.reason.render(&FMI3))?;
                return Err(format!("requiredIntermediateVariables {vrs:?}: this FMU provides no intermediate update (providesIntermediateUpdate = false)"));
            }
            Ok(())
        },
        ..request
    });
    if let Some(inst) = instance_of(c, &FMI3).filter(|i| !i.entry.clocks.is_empty()) {
        if event_mode_used != 0 {
            inst.clocks.mode = ClockMode::Stepped;
        } else {
            // the standard asks clocked FMUs for eventModeUsed = true; kept lenient so that existing
            // importers go on working: the unit samples inside fmi3DoStep as without clocks (said with
            // debug logging on; not a warning, since this is how every existing FMI 3.0 user runs it)
            inst.log(
                Status::Ok,
                "logCalls",
                "fmi3InstantiateCoSimulation: eventModeUsed = false on a clocked FMU: its clocks are not used, the unit samples inside fmi3DoStep (communication points on its sample grid)",
            );
        }
    }
    c
}

pub extern "C" fn fmi3DoStep(
    c: Instance3,
    t: f64,
    h: f64,
    _no_set_prior: u8,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> c_int {
    call3(c, "fmi3DoStep", mask3::ANY, |inst| {
        require_co_simulation(inst)?;
        if mask3::DO_STEP & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(Reason::IllegalCall(inst.run.fsm)));
        }
        inst.trace(|| format!("fmi3DoStep(currentCommunicationPoint={t}, communicationStepSize={h})"));
        let ev = out_ptr(event_handling_needed, "eventHandlingNeeded")?;
        let term = out_ptr(terminate_simulation, "terminateSimulation")?;
        let early = out_ptr(early_return, "earlyReturn")?;
        let last = out_ptr(last_successful_time, "lastSuccessfulTime")?;
        (*ev, *term, *early) = (0, 0, 0);
        let r = inst.do_step(t, h);
        *last = inst.run.time;
        r
    })
}

pub extern "C" fn fmi3GetOutputDerivatives(
    c: Instance3,
    _vr: *const u32,
    _n: usize,
    _order: *const i32,
    _v: *mut f64,
    _nv: usize,
) -> c_int {
    refuse(
        c,
        "fmi3GetOutputDerivatives",
        mask3::OUTPUT_DERIVATIVES,
        "maxOutputDerivativeOrder = 0",
    )
}
