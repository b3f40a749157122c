//! One FMU instance: state machine, initialization and stepping. Called only from the rooms of the two
//! interfaces, after their null and state checks; `logging.rs` adds the logging, `values.rs` value access
//! with the causality/variability rules, `me.rs` the Model Exchange methods and `jacobian.rs` the
//! directional derivatives (each an `impl Instance` over this file's types). The instance knows the
//! interface it serves only through its [`Dialect`], which words its failures.

use std::collections::HashSet;
use std::ffi::{c_void, CString};

use serde::{Deserialize, Serialize};

mod clock_book;
mod clocks;
mod jacobian;
mod logging;
pub mod me;
mod values;

pub use crate::fmi::fail::{CallResult, Fail, Reason};
use crate::fmi::types::{Dialect, FsmState, PrintfLogFn, Status, TextLogFn, LOG_CATEGORIES};
use crate::math::sample_grid;
pub use clock_book::{ClockMode, Clocks};

/// The master's logger, by the shape of its callback.
#[derive(Clone, Copy)]
pub enum Logger {
    None,
    /// Takes the instance name and a printf format.
    Printf(PrintfLogFn),
    /// Takes plain text (the instance name is prefixed to it).
    Text(TextLogFn),
}
use crate::model::{DynModel, Experiment, ModelEntry, VarDecl, VarKind, TOLERANCE_MAX, TOLERANCE_MIN};

/// Index of declarations by (kind, value reference): value references are small integers, so a
/// vector per kind is the fastest lookup for the per-step get/set calls.
#[derive(Default)]
struct VrIndex {
    real: Vec<Option<u16>>,
    integer: Vec<Option<u16>>,
    boolean: Vec<Option<u16>>,
}

impl VrIndex {
    fn new(decls: &[VarDecl]) -> Self {
        let mut ix = VrIndex::default();
        for (i, d) in decls.iter().enumerate() {
            let v = match d.kind {
                VarKind::Real => &mut ix.real,
                VarKind::Integer => &mut ix.integer,
                VarKind::Boolean => &mut ix.boolean,
            };
            let vr = d.vr as usize;
            if v.len() <= vr {
                v.resize(vr + 1, None);
            }
            v[vr] = Some(i as u16);
        }
        ix
    }
    #[inline]
    fn get(&self, kind: VarKind, vr: u32) -> Option<usize> {
        let v = match kind {
            VarKind::Real => &self.real,
            VarKind::Integer => &self.integer,
            VarKind::Boolean => &self.boolean,
        };
        v.get(vr as usize).copied().flatten().map(usize::from)
    }
}

/// Everything an instance carries besides its model: where it is in the state machine, its time and
/// experiment, and which cached values are stale. FMU states (snapshots and their serialized form)
/// copy it whole together with the model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Run {
    pub fsm: FsmState,
    pub time: f64,
    pub exp: Experiment,
    /// Outputs must be recomputed before the next get (an input, parameter or the state changed).
    pub outputs_dirty: bool,
    /// Parameters changed during initialization: derived quantities must be recomputed.
    pub params_dirty: bool,
    /// Model Exchange: time of the last event (the solver may not go back before it); -inf before
    /// initialization. Part of the run so that an FMU state restores it with the time it belongs to.
    pub event_time: f64,
}

impl Run {
    /// Consistency of a decoded run state: finite time, a sane experiment, a reachable state.
    pub fn validate(&self) -> Result<(), String> {
        if !self.time.is_finite() {
            return Err(format!("time {} is not finite", self.time));
        }
        // -inf: no event yet, only in the states an instance can be in before it is initialized
        let uninitialized = matches!(
            self.fsm,
            FsmState::Instantiated | FsmState::InitializationMode | FsmState::Terminated | FsmState::Error
        );
        if !((self.event_time == f64::NEG_INFINITY && uninitialized)
            || (self.event_time.is_finite() && self.event_time <= self.time + 2e-9 * self.event_time.abs().max(1.0)))
        {
            return Err(format!(
                "time of the last event (event_time) {} is not finite or lies after the time {}",
                self.event_time, self.time
            ));
        }
        let e = &self.exp;
        if !e.start_time.is_finite()
            || e.tolerance.is_some_and(|t| !(t.is_finite() && t > 0.0))
            || e.stop_time.is_some_and(|s| !(s.is_finite() && s >= e.start_time))
        {
            return Err(format!("experiment {e:?} is not valid"));
        }
        // only the states in which an FMU state can be taken (Fatal is not one)
        if !matches!(
            self.fsm,
            FsmState::Instantiated
                | FsmState::InitializationMode
                | FsmState::StepMode
                | FsmState::Terminated
                | FsmState::Error
                | FsmState::EventMode
                | FsmState::ContinuousTimeMode
                | FsmState::Activation
        ) {
            return Err(format!(
                "state machine state {:?} cannot be restored (no FMU state can be taken in it)",
                self.fsm
            ));
        }
        Ok(())
    }

    pub const INSTANTIATED: Run = Run {
        fsm: FsmState::Instantiated,
        time: 0.0,
        exp: Experiment {
            start_time: 0.0,
            tolerance: None,
            stop_time: None,
        },
        outputs_dirty: true,
        params_dirty: true,
        event_time: f64::NEG_INFINITY,
    };
}

pub struct Instance {
    pub name: CString,
    pub entry: &'static ModelEntry,
    logger: Logger,
    env: *mut c_void,
    /// The interface that created the instance: only its calls reach it, and it words the failures.
    pub dialect: &'static Dialect,
    /// Instantiated as Model Exchange (else Co-Simulation).
    pub model_exchange: bool,
    debug_logging: bool,
    categories: HashSet<&'static str>,
    pub run: Run,
    pub model: Box<dyn DynModel>,
    index: VrIndex,
    /// The clocks' bookkeeping (a clocked model driven by clocks; else mode `Off` and empty).
    pub clocks: Clocks,
    /// Scheduled Execution: the importer's lock and unlock callbacks, called around each activation.
    pub preemption: Option<(unsafe extern "C" fn(), unsafe extern "C" fn())>,
}

impl Instance {
    pub fn new(
        name: CString,
        entry: &'static ModelEntry,
        dialect: &'static Dialect,
        logger: Logger,
        env: *mut c_void,
        logging_on: bool,
    ) -> Self {
        Instance {
            name,
            entry,
            logger,
            env,
            dialect,
            model_exchange: false,
            debug_logging: logging_on,
            categories: LOG_CATEGORIES.iter().map(|(n, _)| *n).collect(),
            run: Run::INSTANTIATED,
            model: (entry.create)(),
            index: VrIndex::new(entry.decls),
            clocks: Clocks {
                reported: vec![false; entry.clocks.len()],
                ..Clocks::default()
            },
            preemption: None,
        }
    }

    // ----- life cycle ---------------------------------------------------------------------------

    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> CallResult {
        if !start.is_finite() {
            return Err(Fail::error(format!("startTime {start} is not finite")));
        }
        if let Some(tol) = tolerance {
            if !(tol.is_finite() && tol > 0.0) {
                return Err(Fail::error(format!("tolerance {tol} must be finite and > 0")));
            }
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(Fail::error(format!(
                    "stopTime {stop} must be finite and >= startTime {start}"
                )));
            }
        }
        self.check_time_grid(start, stop)?;
        self.run.exp = Experiment {
            start_time: start,
            tolerance,
            stop_time: stop,
        };
        self.run.time = start;
        // the adaptive integrators honour [TOLERANCE_MIN, TOLERANCE_MAX] only: say so when clamping
        if let Some(tol) = tolerance {
            let used = self.run.exp.tolerance_or_default();
            if used != tol {
                return Err(Fail::warning(format!(
                    "tolerance {tol:e} is outside [{TOLERANCE_MIN:e}, {TOLERANCE_MAX:e}], the range the adaptive integrators honour; {used:e} is used (the experiment is set up)"
                )));
            }
        }
        Ok(())
    }

    /// A start or stop time beyond the exact range of the model's integer time grid (2^53 periods,
    /// `Model::time_grid` with the current parameters) is refused with the bound named.
    pub fn check_time_grid(&self, start: f64, stop: Option<f64>) -> CallResult {
        let Some(period) = self.model.time_grid() else {
            return Ok(());
        };
        sample_grid::check_time("startTime", start, period).map_err(Fail::error)?;
        if let Some(stop) = stop {
            sample_grid::check_time("stopTime", stop, period).map_err(Fail::error)?;
        }
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> CallResult {
        self.check_time_grid(self.run.exp.start_time, self.run.exp.stop_time)?;
        self.run.fsm = FsmState::InitializationMode;
        self.run.params_dirty = true;
        self.run.outputs_dirty = true;
        Ok(())
    }

    /// Applies the parameters. On invalid parameters the instance stays in initialization mode, so
    /// the master may correct them and call again.
    pub fn exit_initialization_mode(&mut self) -> CallResult {
        self.check_time_grid(self.run.exp.start_time, self.run.exp.stop_time)?;
        self.model.initialize(&self.run.exp).map_err(Fail::error)?;
        self.run.params_dirty = false;
        self.run.outputs_dirty = true;
        // inputs not yet consistent: a warning here (a Co-Simulation master may still set them before the
        // first step); outputs read after this call, or a step, with the same inputs are refused
        let warning = match self.ensure_outputs_or_keep() {
            Err(f) if f.status == Status::Warning => Some(f),
            other => {
                other?;
                None
            }
        };
        if self.clocks.mode != ClockMode::Off {
            self.check_clock_start()?;
        }
        self.run.fsm = match (self.model_exchange, self.clocks.mode) {
            (true, _) | (false, ClockMode::Stepped) => FsmState::EventMode,
            (false, ClockMode::Scheduled) => FsmState::Activation,
            (false, ClockMode::Off) => FsmState::StepMode,
        };
        if self.clocks.mode != ClockMode::Off {
            self.start_clocks(self.clocks.mode);
        }
        self.run.event_time = self.run.time;
        warning.map_or(Ok(()), Err)
    }

    pub fn do_step(&mut self, t: f64, h: f64) -> CallResult {
        if !(h.is_finite() && h > 0.0) {
            return Err(Fail::error(format!("communicationStepSize {h} must be finite and > 0")));
        }
        let tol = 1e-9 * self.run.time.abs().max(1.0);
        if !t.is_finite() || (t - self.run.time).abs() > tol {
            return Err(Fail::error(format!(
                "currentCommunicationPoint {t} does not match the FMU time {}",
                self.run.time
            )));
        }
        if let Some(stop) = self.run.exp.stop_time {
            if t + h > stop + 1e-9 * stop.abs().max(1.0) {
                return Err(Fail::error(Reason::BeyondStopTime { end: t + h, stop }));
            }
        }
        if let Some(period) = self.model.time_grid() {
            sample_grid::check_time("the step's end t + h =", t + h, period).map_err(Fail::error)?;
        }
        if self.clocks.mode == ClockMode::Stepped {
            // the partitions ran at their ticks: the step only advances time
            self.check_no_tick_passed(t, h)?;
        } else if let Err(reason) = self.model.do_step(t, h) {
            self.run.fsm = FsmState::Error;
            return Err(Fail::error(format!("step from t = {t} failed: {reason}")));
        }
        for line in self.model.take_log() {
            self.log(Status::Ok, "logEvents", &line);
        }
        // Continue on the master's grid: no accumulation of round-off in the FMU time.
        self.run.time = t + h;
        self.run.outputs_dirty = true; // computed when read
        Ok(())
    }

    pub fn reset(&mut self) {
        self.model = (self.entry.create)();
        self.run = Run::INSTANTIATED;
        self.clocks = Clocks {
            mode: self.clocks.mode,
            reported: vec![false; self.entry.clocks.len()],
            ..Clocks::default()
        };
    }
}

/// A variable the layer publishes for a Model Exchange model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LayerVar {
    State(usize),
    Derivative(usize),
}
