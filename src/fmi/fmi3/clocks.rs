//! FMI 3.0 clocks and Scheduled Execution (FMI 3.0 sections 2.2.9, 4 and 5) over the core's clock
//! bookkeeping (`instance/clocks.rs`): clocked Co-Simulation (`eventModeUsed = true`: Event Mode,
//! `fmi3SetClock`, `fmi3UpdateDiscreteStates`, `fmi3EnterStepMode`), the interval and shift queries, and
//! `fmi3InstantiateScheduledExecution` with `fmi3ActivateModelPartition` (Clock Activation Mode).
//! Every clock is a time-based periodic input clock whose interval and shift come from parameters
//! (`intervalVariability = "fixed"`, no `intervalDecimal`): the FMU tells them, the importer cannot set
//! them, and `supportsFraction` is not declared.
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int, c_void};

use super::common::{call3, mask3, refuse, request3, require_co_simulation, Instance3, Log3Fn};
use crate::fmi::boundary::{self, instance_of, out_ptr, slice, slice_mut, Request};
use crate::fmi::instance::{CallResult, ClockMode, Fail, Instance, Reason};
use crate::fmi::types::{FsmState, Status};
use crate::model::ModelEntry;

/// `fmi3IntervalChanged` and `fmi3IntervalUnchanged` (`fmi3IntervalQualifier`).
const INTERVAL_UNCHANGED: c_int = 1;
const INTERVAL_CHANGED: c_int = 2;

/// The FMI 3.0 lock/unlock preemption callbacks (`void (*)(void)`).
pub type PreemptionFn = unsafe extern "C" fn();

/// A Co-Simulation instance driven by clocks (`eventModeUsed = true`): refuses any other.
fn require_stepped(inst: &Instance) -> CallResult {
    require_co_simulation(inst)?;
    match inst.clocks.mode {
        ClockMode::Stepped => Ok(()),
        ClockMode::Scheduled => Err(Fail::error(
            "not used in Scheduled Execution (this instance was created by fmi3InstantiateScheduledExecution: its partitions run through fmi3ActivateModelPartition)",
        )),
        ClockMode::Off if inst.entry.clocks.is_empty() => {
            Err(Fail::error("this Co-Simulation FMU has no Event Mode and no clocks (hasEventMode = false)"))
        }
        ClockMode::Off => Err(Fail::error(
            "Event Mode is not used: the instance was created with eventModeUsed = false (it runs sampled inside fmi3DoStep)",
        )),
    }
}

/// `call3` for a function allowed in `allowed` on a clocked Co-Simulation instance.
fn stepped(c: Instance3, func: &str, allowed: u16, f: impl FnOnce(&mut Instance) -> CallResult) -> c_int {
    call3(c, func, mask3::ANY, |inst| {
        require_stepped(inst)?;
        if allowed & inst.run.fsm.bit() == 0 {
            return Err(Fail::error(Reason::IllegalCall(inst.run.fsm)));
        }
        f(inst)
    })
}

const EVENT: u16 = FsmState::EventMode.bit();
const STEP: u16 = FsmState::StepMode.bit();

/// `fmi3EnterEventMode` on a Co-Simulation instance: Step Mode to Event Mode.
pub fn enter_event_mode(c: Instance3) -> c_int {
    stepped(c, "fmi3EnterEventMode", STEP, |inst| {
        inst.run.fsm = FsmState::EventMode;
        Ok(())
    })
}

pub extern "C" fn fmi3EnterStepMode(c: Instance3) -> c_int {
    stepped(c, "fmi3EnterStepMode", EVENT, |inst| {
        if let Some(i) = inst.clocks.active.iter().position(|a| *a) {
            return Err(Fail::error(format!(
                "clock {} is active: call fmi3UpdateDiscreteStates before fmi3EnterStepMode",
                inst.entry.clocks[i].name
            )));
        }
        inst.run.fsm = FsmState::StepMode;
        Ok(())
    })
}

/// `fmi3UpdateDiscreteStates` on a Co-Simulation instance: the partitions of the active clocks run (in
/// clock order) and are deactivated; the next event is the earliest next tick.
pub fn update_discrete_states(
    c: Instance3,
    need: *mut u8,
    terminate: *mut u8,
    nominals: *mut u8,
    values: *mut u8,
    defined: *mut u8,
    next: *mut f64,
) -> c_int {
    stepped(c, "fmi3UpdateDiscreteStates", EVENT, |inst| {
        let outs = (
            out_ptr(need, "discreteStatesNeedUpdate")?,
            out_ptr(terminate, "terminateSimulation")?,
            out_ptr(nominals, "nominalsOfContinuousStatesChanged")?,
            out_ptr(values, "valuesOfContinuousStatesChanged")?,
            out_ptr(defined, "nextEventTimeDefined")?,
            out_ptr(next, "nextEventTime")?,
        );
        inst.run_active_partitions()?;
        let t = inst.next_tick()?;
        (*outs.0, *outs.1, *outs.2, *outs.3) = (0, 0, 0, 0);
        *outs.4 = 1;
        *outs.5 = t;
        inst.trace(|| format!("fmi3UpdateDiscreteStates at t = {}: next tick {t}", inst.run.time));
        Ok(())
    })
}

pub extern "C" fn fmi3SetClock(c: Instance3, vr: *const u32, n: usize, v: *const u8) -> c_int {
    call3(c, "fmi3SetClock", mask3::ANY, |inst| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let on = unsafe { slice(v, n, "values[]")? };
        let idx: Vec<usize> = vrs.iter().map(|r| inst.clock_index(*r)).collect::<CallResult<_>>()?;
        require_stepped(inst)?;
        if inst.run.fsm != FsmState::EventMode {
            return Err(Fail::error(format!(
                "{}: clocks are activated in Event Mode only",
                Reason::IllegalCall(inst.run.fsm).render(inst.dialect)
            )));
        }
        for (&i, &a) in idx.iter().zip(on) {
            if a != 0 {
                inst.check_due(i, inst.run.time)?;
            }
        }
        for (&i, &a) in idx.iter().zip(on) {
            inst.clocks.active[i] = a != 0;
        }
        Ok(())
    })
}

pub extern "C" fn fmi3GetClock(c: Instance3, vr: *const u32, n: usize, _v: *mut u8) -> c_int {
    call3(c, "fmi3GetClock", mask3::ANY, |inst| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(r) => {
                let i = inst.clock_index(*r)?;
                Err(Fail::error(format!(
                    "clock {} is an input clock: its state is set by the importer (fmi3SetClock), fmi3GetClock is for output clocks",
                    inst.entry.clocks[i].name
                )))
            }
        }
    })
}

/// Interval or shift of each clock in `vrs`, into `out`.
fn clock_times(
    c: Instance3,
    func: &str,
    vr: *const u32,
    n: usize,
    f: impl Fn(&mut Instance, usize) -> CallResult<f64>,
    out: *mut f64,
) -> c_int {
    // parameters are known from Initialization Mode on
    let allowed = mask3::GET | FsmState::Activation.bit();
    call3(c, func, allowed, |inst| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let dst = unsafe { slice_mut(out, n, "values[]")? };
        for (k, r) in vrs.iter().enumerate() {
            let i = inst.clock_index(*r)?;
            dst[k] = f(inst, i)?;
        }
        Ok(())
    })
}

/// The interval of each clock; its qualifier is `fmi3IntervalChanged` the first time a clock's interval
/// is reported, `fmi3IntervalUnchanged` afterwards (the interval is fixed).
pub extern "C" fn fmi3GetIntervalDecimal(c: Instance3, vr: *const u32, n: usize, i: *mut f64, q: *mut c_int) -> c_int {
    let status = clock_times(
        c,
        "fmi3GetIntervalDecimal",
        vr,
        n,
        |inst, k| Ok(inst.clock_timing(k)?.0),
        i,
    );
    if status != Status::Ok as c_int {
        return status;
    }
    call3(c, "fmi3GetIntervalDecimal", mask3::ANY, |inst| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        let quals = unsafe { slice_mut(q, n, "qualifiers[]")? };
        for (k, r) in vrs.iter().enumerate() {
            let i = inst.clock_index(*r)?;
            quals[k] = if inst.clocks.reported[i] {
                INTERVAL_UNCHANGED
            } else {
                INTERVAL_CHANGED
            };
            inst.clocks.reported[i] = true;
        }
        Ok(())
    })
}

pub extern "C" fn fmi3GetShiftDecimal(c: Instance3, vr: *const u32, n: usize, s: *mut f64) -> c_int {
    clock_times(
        c,
        "fmi3GetShiftDecimal",
        vr,
        n,
        |inst, k| Ok(inst.clock_timing(k)?.1),
        s,
    )
}

pub extern "C" fn fmi3GetIntervalFraction(
    c: Instance3,
    _vr: *const u32,
    _n: usize,
    _k: *mut u64,
    _r: *mut u64,
    _q: *mut c_int,
) -> c_int {
    refuse(
        c,
        "fmi3GetIntervalFraction",
        mask3::ANY,
        "supportsFraction is not declared (the interval is a Real parameter): use fmi3GetIntervalDecimal",
    )
}

pub extern "C" fn fmi3GetShiftFraction(c: Instance3, _vr: *const u32, _n: usize, _k: *mut u64, _r: *mut u64) -> c_int {
    refuse(
        c,
        "fmi3GetShiftFraction",
        mask3::ANY,
        "supportsFraction is not declared (the shift is a Real parameter): use fmi3GetShiftDecimal",
    )
}

macro_rules! no_setting {
    ($($name:ident($($a:ident: $t:ty),*) => $why:literal;)*) => {$(
        pub extern "C" fn $name(c: Instance3, _vr: *const u32, _n: usize, $($a: $t),*) -> c_int {
            $(let _ = $a;)*
            refuse(c, stringify!($name), mask3::ANY, $why)
        }
    )*};
}

no_setting! {
    fmi3SetIntervalDecimal(_i: *const f64) => "the clocks' intervals come from parameters (no intervalDecimal declared): the importer reads them with fmi3GetIntervalDecimal";
    fmi3SetIntervalFraction(_k: *const u64, _r: *const u64) => "the clocks' intervals come from parameters (no intervalDecimal declared) and supportsFraction is not declared";
    fmi3SetShiftDecimal(_s: *const f64) => "the clocks' shifts come from parameters: the importer reads them with fmi3GetShiftDecimal";
    fmi3SetShiftFraction(_k: *const u64, _r: *const u64) => "the clocks' shifts come from parameters and supportsFraction is not declared";
}

// ----- Scheduled Execution ---------------------------------------------------------------------------

/// `fmi3InstantiateScheduledExecution` for a library holding `models`: clocked models only (others
/// give NULL and a message); the preemption callbacks are kept and wrap every activation.
pub fn fmi3InstantiateScheduledExecution(
    models: &'static [ModelEntry],
    instance_name: *const c_char,
    token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    env: *mut c_void,
    log_message: Option<Log3Fn>,
    _clock_update: *const c_void,
    lock: Option<PreemptionFn>,
    unlock: Option<PreemptionFn>,
) -> Instance3 {
    let func = "fmi3InstantiateScheduledExecution";
    let request = request3(func, models, instance_name, token, logging_on, env, log_message);
    let c = boundary::instantiate(Request {
        refuse_model: &|entry| {
            entry.clocks.is_empty().then(|| {
                format!(
                    "{} has no clocks and no <ScheduledExecution> element: use fmi3InstantiateCoSimulation",
                    entry.info.name
                )
            })
        },
        ..request
    });
    if let Some(inst) = instance_of(c, &super::common::FMI3) {
        inst.clocks.mode = ClockMode::Scheduled;
        inst.preemption = lock.zip(unlock);
    }
    c
}

pub extern "C" fn fmi3ActivateModelPartition(c: Instance3, clock: u32, t: f64) -> c_int {
    call3(c, "fmi3ActivateModelPartition", mask3::ANY, |inst| {
        let i = inst.clock_index(clock)?;
        if inst.clocks.mode != ClockMode::Scheduled {
            return Err(Fail::error(
                "Scheduled Execution function, but this instance was not created by fmi3InstantiateScheduledExecution",
            ));
        }
        if inst.run.fsm != FsmState::Activation {
            return Err(Fail::error(Reason::IllegalCall(inst.run.fsm)));
        }
        if !t.is_finite() {
            return Err(Fail::error(format!("activationTime {t} is not finite")));
        }
        inst.trace(|| format!("fmi3ActivateModelPartition(clockReference={clock}, activationTime={t})"));
        let lock = inst.preemption;
        if let Some((l, _)) = lock {
            unsafe { l() };
        }
        let r = inst.run_partition(i, t);
        if r.is_ok() {
            inst.run.time = t;
        }
        if let Some((_, u)) = lock {
            unsafe { u() };
        }
        r
    })
}
