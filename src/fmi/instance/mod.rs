//! One FMU instance: state machine, logging, value access with the causality/variability rules,
//! initialization and stepping. Called only from the FMI 2.0 and 3.0 functions
//! (`fmi2/`, `fmi3/`), after their null and state checks; `me.rs` adds the Model Exchange methods and
//! `jacobian.rs` the directional derivatives.

use std::collections::HashSet;
use std::ffi::{c_int, c_void, CString};

use serde::{Deserialize, Serialize};

mod jacobian;
pub mod me;

use crate::fmi::types::{FsmState, Log3Fn, LoggerFn, Status, LOG_CATEGORIES};
use crate::model::{DERIVATIVE_VR_BASE, STATE_VR_BASE};

/// The master's logger: FMI 2.0 (`fmi2CallbackLogger`) or FMI 3.0 (`fmi3LogMessageCallback`).
#[derive(Clone, Copy)]
pub enum Logger {
    None,
    Fmi2(LoggerFn),
    Fmi3(Log3Fn),
}
use crate::model::{
    Causality, DynModel, Experiment, ModelEntry, SlotMut, Value, VarDecl, VarKind, Variability, RESERVED_VR_START,
    TOLERANCE_MAX, TOLERANCE_MIN,
};

/// Failure of an FMI call: the status to return and the reason to log.
#[derive(Debug)]
pub struct Fail {
    pub status: Status,
    pub reason: String,
}

impl Fail {
    pub fn error(reason: impl Into<String>) -> Self {
        Fail {
            status: Status::Error,
            reason: reason.into(),
        }
    }
    pub fn discard(reason: impl Into<String>) -> Self {
        Fail {
            status: Status::Discard,
            reason: reason.into(),
        }
    }
}

pub type CallResult<T = ()> = Result<T, Fail>;

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
        if !(self.event_time == f64::NEG_INFINITY
            || (self.event_time.is_finite() && self.event_time <= self.time + 2e-9 * self.event_time.abs().max(1.0)))
        {
            return Err(format!(
                "time of the last event {} is not finite or lies after the time {}",
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
        // only the states in which fmi2GetFMUstate can be called on this FMU (StepFailed and
        // StepCanceled are never entered: fmi2DoStep never returns fmi2Pending or fmi2Discard)
        if !matches!(
            self.fsm,
            FsmState::Instantiated
                | FsmState::InitializationMode
                | FsmState::StepComplete
                | FsmState::Terminated
                | FsmState::Error
                | FsmState::EventMode
                | FsmState::ContinuousTimeMode
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
    /// Created by `fmi3InstantiateCoSimulation` (FMI 3.0 calls only) rather than `fmi2Instantiate`.
    pub fmi3: bool,
    /// Instantiated as Model Exchange (`fmi2Instantiate` with fmuType fmi2ModelExchange).
    pub model_exchange: bool,
    debug_logging: bool,
    categories: HashSet<&'static str>,
    pub run: Run,
    pub model: Box<dyn DynModel>,
    index: VrIndex,
}

fn kind_name(k: VarKind) -> &'static str {
    match k {
        VarKind::Real => "Real",
        VarKind::Integer => "Integer",
        VarKind::Boolean => "Boolean",
    }
}

impl Instance {
    pub fn new(name: CString, entry: &'static ModelEntry, logger: Logger, env: *mut c_void, logging_on: bool) -> Self {
        Instance {
            name,
            entry,
            logger,
            env,
            fmi3: false,
            model_exchange: false,
            debug_logging: logging_on,
            categories: LOG_CATEGORIES.iter().map(|(n, _)| *n).collect(),
            run: Run::INSTANTIATED,
            model: (entry.create)(),
            index: VrIndex::new(entry.decls),
        }
    }

    // ----- logging -----------------------------------------------------------------------------

    /// Sends a message to the logger callback. Warnings and errors always go out; other messages
    /// only with debug logging on and their category enabled.
    pub fn log(&self, status: Status, category: &str, message: &str) {
        if matches!(self.logger, Logger::None) {
            return;
        }
        if status < Status::Warning
            && !(self.debug_logging && (self.categories.contains(category) || self.categories.contains("logAll")))
        {
            return;
        }
        let cat = CString::new(category).unwrap_or_default();
        match self.logger {
            Logger::None => {}
            Logger::Fmi2(logger) => {
                // The message is a printf format for C loggers: escape '%'; interior NULs cannot pass.
                let text = CString::new(message.replace('%', "%%").replace('\0', "")).unwrap_or_default();
                // SAFETY: the logger is the master's callback with the fmi2CallbackLogger signature; all
                // strings are valid NUL-terminated for the duration of the call.
                unsafe {
                    logger(
                        self.env,
                        self.name.as_ptr(),
                        status as c_int,
                        cat.as_ptr(),
                        text.as_ptr(),
                    )
                };
            }
            Logger::Fmi3(logger) => {
                // FMI 3.0 messages are plain text (no printf format) and carry no instance name: prefix it.
                let text = CString::new(format!("{}: {}", self.name.to_string_lossy(), message).replace('\0', ""))
                    .unwrap_or_default();
                // SAFETY: the master's fmi3LogMessageCallback; strings valid for the duration of the call.
                unsafe { logger(self.env, status as c_int, cat.as_ptr(), text.as_ptr()) };
            }
        }
    }

    pub fn log_fail(&self, func: &str, fail: &Fail) {
        let category = match fail.status {
            Status::Fatal => "logStatusFatal",
            Status::Error => "logStatusError",
            _ => "logStatusWarning",
        };
        self.log(fail.status, category, &format!("{func}: {}", fail.reason));
    }

    pub fn trace(&self, message: impl FnOnce() -> String) {
        if self.debug_logging && (self.categories.contains("logCalls") || self.categories.contains("logAll")) {
            self.log(Status::Ok, "logCalls", &message());
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> CallResult {
        let known: Vec<&'static str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
        if let Some(bad) = categories.iter().find(|c| !known.contains(&c.as_str())) {
            return Err(Fail::error(format!(
                "unknown log category '{bad}' (declared: {})",
                known.join(", ")
            )));
        }
        self.debug_logging = on;
        if categories.is_empty() {
            self.categories = known.into_iter().collect();
        } else {
            for c in categories {
                let c = known
                    .iter()
                    .find(|k| **k == c.as_str())
                    .copied()
                    .expect("checked above");
                if on {
                    self.categories.insert(c);
                } else {
                    self.categories.remove(c);
                }
            }
        }
        Ok(())
    }

    // ----- variable access ----------------------------------------------------------------------

    /// Declaration index and declaration of a value reference of the given kind.
    #[inline]
    pub(super) fn decl(&self, kind: VarKind, vr: u32) -> CallResult<(usize, &'static VarDecl)> {
        if let Some(i) = self.index.get(kind, vr) {
            return Ok((i, &self.entry.decls[i]));
        }
        self.unknown_vr(kind, vr)
    }

    #[cold]
    fn unknown_vr(&self, kind: VarKind, vr: u32) -> CallResult<(usize, &'static VarDecl)> {
        let other = [VarKind::Real, VarKind::Integer, VarKind::Boolean]
            .into_iter()
            .filter(|k| *k != kind)
            .find_map(|k| self.index.get(k, vr).map(|i| &self.entry.decls[i]));
        Err(match other {
            Some(d) => Fail::error(format!(
                "value reference {vr} is {} ({}), not {}",
                d.name,
                kind_name(d.kind),
                kind_name(kind)
            )),
            None => Fail::error(format!("unknown {} value reference {vr}", kind_name(kind))),
        })
    }

    /// Whether a variable may be set in the current state (FMI 2.0 section 4.2.4 rules).
    fn check_settable(&self, d: &VarDecl) -> CallResult {
        let init = matches!(self.run.fsm, FsmState::Instantiated | FsmState::InitializationMode);
        let ok = match (d.causality, d.variability) {
            (_, Variability::Constant) => false,
            (Causality::Input, _) => true,
            (Causality::Parameter, Variability::Fixed) => init,
            (Causality::Parameter, Variability::Tunable) => true,
            (Causality::Parameter, _) => init,
            _ => false,
        };
        if ok {
            return Ok(());
        }
        Err(Fail::error(match d.causality {
            Causality::Parameter => format!(
                "parameter {} is fixed and cannot be set after initialization (state {:?})",
                d.name, self.run.fsm
            ),
            Causality::Output => format!("{} is an output and cannot be set", d.name),
            Causality::CalculatedParameter => format!("{} is a calculated parameter and cannot be set", d.name),
            _ => format!("{} ({:?}, {:?}) cannot be set", d.name, d.causality, d.variability),
        }))
    }

    /// Sets values of one kind atomically: every entry is checked before any is written, so a
    /// refused call leaves the instance unchanged. `value(i)` is the value for `vrs[i]`.
    pub fn set_values(&mut self, kind: VarKind, vrs: &[u32], value: impl Fn(usize) -> Value) -> CallResult {
        let mut sets_parameter = false;
        for (i, vr) in vrs.iter().enumerate() {
            if kind == VarKind::Real {
                if let Some(var) = self.layer_var(*vr) {
                    let (LayerVar::State(k) | LayerVar::Derivative(k)) = var;
                    let name = self.entry.state_decls()[k].name;
                    return Err(Fail::error(match var {
                        LayerVar::State(_) => format!(
                            "{name} is a continuous state: set it with fmi2SetContinuousStates (Model Exchange)"
                        ),
                        LayerVar::Derivative(_) => format!("der({name}) is a state derivative and cannot be set"),
                    }));
                }
            }
            let (_, d) = self.decl(kind, *vr)?;
            self.check_settable(d)?;
            if let Value::Real(x) = value(i) {
                if !x.is_finite() {
                    return Err(Fail::error(format!(
                        "value {x} for {} is not finite (use 1e30 for \"no limit\")",
                        d.name
                    )));
                }
            }
            sets_parameter |= d.causality == Causality::Parameter;
        }
        // All checked: write (the value references are known to exist with this kind).
        for (i, vr) in vrs.iter().enumerate() {
            let index = self.index.get(kind, *vr).expect("checked above");
            match (self.model.slot(index), value(i)) {
                (Some(SlotMut::Real(s)), Value::Real(x)) => *s = x,
                (Some(SlotMut::Integer(s)), Value::Integer(x)) => *s = x,
                (Some(SlotMut::Boolean(s)), Value::Boolean(x)) => *s = x,
                _ => {
                    return Err(Fail::error(format!(
                        "internal: storage of value reference {vr} does not match its declaration"
                    )))
                }
            }
        }
        self.run.params_dirty |= sets_parameter;
        self.run.outputs_dirty = true;
        Ok(())
    }

    /// During initialization, (re)applies parameters set since the last initialization (what reads the
    /// state or the derivatives needs; the outputs are left to be computed when they are read).
    pub fn ensure_initialized(&mut self) -> CallResult {
        if self.run.fsm == FsmState::InitializationMode && self.run.params_dirty {
            self.model.initialize(&self.run.exp).map_err(Fail::error)?;
            self.run.params_dirty = false;
            self.run.outputs_dirty = true;
        }
        Ok(())
    }

    /// Brings outputs up to date with the inputs most recently set. During initialization the
    /// parameters are (re)applied first so that initial outputs reflect them.
    pub fn ensure_outputs(&mut self) -> CallResult {
        self.ensure_initialized()?;
        if self.run.outputs_dirty && self.run.fsm != FsmState::Instantiated {
            self.model.update_outputs(self.run.time).map_err(Fail::error)?;
            self.run.outputs_dirty = false;
        }
        Ok(())
    }

    /// Reads values of one kind; `write(i, v)` receives the value of `vrs[i]`. Outputs are computed
    /// lazily here; a non-finite output puts the instance into the error state.
    pub fn get_values(&mut self, kind: VarKind, vrs: &[u32], mut write: impl FnMut(usize, Value)) -> CallResult {
        self.ensure_outputs()?;
        for (i, vr) in vrs.iter().enumerate() {
            if kind == VarKind::Real && *vr >= RESERVED_VR_START {
                if let Some(var) = self.layer_var(*vr) {
                    write(i, Value::Real(self.layer_value(var)?));
                    continue;
                }
            }
            let (index, d) = self.decl(kind, *vr)?;
            let v = self
                .model
                .value(index)
                .ok_or_else(|| Fail::error(format!("internal: no storage for {}", d.name)))?;
            if let Value::Real(x) = v {
                if !x.is_finite() && d.causality == Causality::Output {
                    self.run.fsm = FsmState::Error;
                    return Err(Fail::error(format!(
                        "output {} is {x} at t = {}",
                        d.name, self.run.time
                    )));
                }
            }
            write(i, v);
        }
        Ok(())
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
                return Err(Fail {
                    status: Status::Warning,
                    reason: format!(
                        "tolerance {tol:e} is outside [{TOLERANCE_MIN:e}, {TOLERANCE_MAX:e}], the range the adaptive integrators honour; {used:e} is used (the experiment is set up)"
                    ),
                });
            }
        }
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> CallResult {
        self.run.fsm = FsmState::InitializationMode;
        self.run.params_dirty = true;
        self.run.outputs_dirty = true;
        Ok(())
    }

    /// Applies the parameters. On invalid parameters the instance stays in initialization mode, so
    /// the master may correct them and call again.
    pub fn exit_initialization_mode(&mut self) -> CallResult {
        self.model.initialize(&self.run.exp).map_err(Fail::error)?;
        self.run.params_dirty = false;
        self.run.outputs_dirty = true;
        self.ensure_outputs()?;
        self.run.fsm = if self.model_exchange {
            FsmState::EventMode
        } else {
            FsmState::StepComplete
        };
        self.run.event_time = self.run.time;
        Ok(())
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
                return Err(Fail::error(format!(
                    "step to {} goes beyond stopTime {stop} set in fmi2SetupExperiment",
                    t + h
                )));
            }
        }
        if let Err(reason) = self.model.do_step(t, h) {
            self.run.fsm = FsmState::Error;
            return Err(Fail::error(format!("step from t = {t} failed: {reason}")));
        }
        // Continue on the master's grid: no accumulation of round-off in the FMU time.
        self.run.time = t + h;
        self.run.outputs_dirty = true; // computed when read
        Ok(())
    }

    pub fn reset(&mut self) {
        self.model = (self.entry.create)();
        self.run = Run::INSTANTIATED;
    }
}

/// A variable the layer publishes for a Model Exchange model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LayerVar {
    State(usize),
    Derivative(usize),
}

/// The Model Exchange variables the layer adds to a model's own (continuous states and their
/// derivatives, at reserved value references): here, because value access (above) refuses to set them.
impl Instance {
    pub fn n_states(&self) -> usize {
        self.entry.state_decls().len()
    }

    /// The continuous state or derivative behind a value reference, if it is one.
    pub fn layer_var(&self, vr: u32) -> Option<LayerVar> {
        let n = self.n_states();
        let k = |base: u32| vr.checked_sub(base).map(|k| k as usize).filter(|k| *k < n);
        k(STATE_VR_BASE)
            .map(LayerVar::State)
            .or_else(|| k(DERIVATIVE_VR_BASE).map(LayerVar::Derivative))
    }
}
