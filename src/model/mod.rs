//! What a model is. A model declares its variables once (`declare_variables!`, one row per port or
//! parameter, vectors and quaternions as one row) and implements [`Model`]: build its internal state
//! from the parameters, compute outputs, advance a step. The FMI layer (`crate::fmi`) and the
//! packaging tool (`src/package`, through the catalogue of `crate::export`) see models only through this module, so a model
//! never touches C types or XML.

mod declare;
mod exchange;
pub mod feedthrough;
pub mod guid;
mod instance;
pub mod leaves;
mod param;
#[cfg(test)]
mod restore_tests;

pub use declare::{concat, field_problem, no_duplicate_names, no_duplicate_vrs, same_str, total_len};
pub use exchange::{StateDecl, DERIVATIVE_VR_BASE, RESERVED_VR_START, STATE_VR_BASE};
pub use instance::{DynModel, Fmu};
pub use param::ParamEnum;

use serde::{de::DeserializeOwned, Serialize};

/// FMI 2.0 causality of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

/// FMI 2.0 variability of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    /// The variability a declaration gets: parameters are fixed (read at fmi2ExitInitializationMode),
    /// Real ports continuous, Integer/Boolean ports discrete (FMI 2.0 allows continuous only for Real).
    pub const fn derived(causality: Causality, kind: VarKind) -> Self {
        match (causality, kind) {
            (Causality::Parameter | Causality::CalculatedParameter, _) => Variability::Fixed,
            (_, VarKind::Real) => Variability::Continuous,
            _ => Variability::Discrete,
        }
    }
}

/// FMI 2.0 `initial` attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Approx,
    Calculated,
}

/// Base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum VarKind {
    Real,
    Integer,
    Boolean,
}

/// A start value of the declared kind.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Start {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

/// Admissible values of a parameter, checked by the FMI layer before the model is initialized (so a
/// model's `initialize` only derives values) and written to the modelDescription as `min`/`max`.
/// Every Real is finite anyway: non-finite values are refused when they are set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// Any finite value.
    Any,
    /// > 0.
    Positive,
    /// ≥ 0.
    NonNegative,
    /// ≥ 0, where 1e30 (or more) encodes "no limit".
    Limit,
    /// In [lo, hi].
    Range(f64, f64),
    /// One of the listed integer codes (an enumeration or a 0/1 switch).
    Choice(&'static [i32]),
}

/// The codes of a 0/1 switch.
pub const SWITCH: &[i32] = &[0, 1];

impl Bound {
    /// Checks a Real value; the message names the parameter.
    pub fn check_real(self, name: &str, v: f64) -> Result<(), String> {
        let ok = v.is_finite()
            && match self {
                Bound::Any | Bound::Choice(_) => true,
                Bound::Positive => v > 0.0,
                Bound::NonNegative | Bound::Limit => v >= 0.0,
                Bound::Range(lo, hi) => v >= lo && v <= hi,
            };
        if ok {
            return Ok(());
        }
        Err(match self {
            Bound::Any | Bound::Choice(_) => format!("parameter {name} = {v} is not finite"),
            Bound::Positive => format!("parameter {name} = {v} must be > 0"),
            Bound::NonNegative => format!("parameter {name} = {v} must be >= 0"),
            Bound::Limit => format!("parameter {name} = {v} must be >= 0 (1e30 = no limit)"),
            Bound::Range(lo, hi) => format!("parameter {name} = {v} must lie in [{lo}, {hi}]"),
        })
    }

    /// Checks an Integer value.
    pub fn check_integer(self, name: &str, v: i32) -> Result<(), String> {
        match self {
            Bound::Choice(codes) if !codes.contains(&v) => {
                Err(format!("parameter {name} = {v} is not one of {codes:?}"))
            }
            Bound::Range(lo, hi) if !((v as f64) >= lo && (v as f64) <= hi) => {
                Err(format!("parameter {name} = {v} must lie in [{lo}, {hi}]"))
            }
            Bound::Positive if v <= 0 => Err(format!("parameter {name} = {v} must be > 0")),
            Bound::NonNegative | Bound::Limit if v < 0 => Err(format!("parameter {name} = {v} must be >= 0")),
            _ => Ok(()),
        }
    }

    /// Whether a start value of the declared kind satisfies the bound (const: checked at compile time
    /// for every parameter by `declare_variables!`).
    pub const fn admits(self, start: Start) -> bool {
        match start {
            Start::Boolean(_) => true,
            Start::Real(v) => {
                v.is_finite()
                    && match self {
                        Bound::Any | Bound::Choice(_) => true,
                        Bound::Positive => v > 0.0,
                        Bound::NonNegative | Bound::Limit => v >= 0.0,
                        Bound::Range(lo, hi) => v >= lo && v <= hi,
                    }
            }
            Start::Integer(v) => match self {
                Bound::Choice(codes) => {
                    let mut i = 0;
                    while i < codes.len() {
                        if codes[i] == v {
                            return true;
                        }
                        i += 1;
                    }
                    false
                }
                Bound::Range(lo, hi) => (v as f64) >= lo && (v as f64) <= hi,
                Bound::Positive => v > 0,
                Bound::NonNegative | Bound::Limit => v >= 0,
                Bound::Any => true,
            },
        }
    }

    /// (min, max) for the modelDescription, where the bound has them. `Positive` has no inclusive
    /// minimum in FMI terms and writes none.
    pub fn min_max(self) -> (Option<f64>, Option<f64>) {
        match self {
            Bound::Any | Bound::Positive => (None, None),
            Bound::NonNegative | Bound::Limit => (Some(0.0), None),
            Bound::Range(lo, hi) => (Some(lo), Some(hi)),
            Bound::Choice(codes) => (
                codes.iter().min().map(|&c| c as f64),
                codes.iter().max().map(|&c| c as f64),
            ),
        }
    }
}

/// One declared variable: everything the C ABI, the XML and the HTML documentation need.
#[derive(Clone, Copy, Debug)]
pub struct VarDecl {
    pub vr: u32,
    pub name: &'static str,
    pub kind: VarKind,
    pub causality: Causality,
    pub variability: Variability,
    /// Unit name from `crate::units` ("" = dimensionless, no unit attribute).
    pub unit: &'static str,
    pub description: &'static str,
    pub start: Start,
    pub bound: Bound,
}

impl VarDecl {
    /// Filler for const arrays under construction.
    pub const PLACEHOLDER: VarDecl = VarDecl {
        vr: u32::MAX,
        name: "",
        kind: VarKind::Real,
        causality: Causality::Local,
        variability: Variability::Continuous,
        unit: "",
        description: "",
        start: Start::Real(0.0),
        bound: Bound::Any,
    };

    /// `initial` follows from causality and variability (FMI 2.0 table of section 2.2.7):
    /// parameters and constants are exact, outputs/locals/calculated parameters are calculated,
    /// inputs carry no `initial` attribute (they still have a start value).
    pub const fn initial(&self) -> Option<Initial> {
        match self.causality {
            Causality::Parameter => Some(Initial::Exact),
            Causality::Input => None,
            Causality::CalculatedParameter | Causality::Output => Some(Initial::Calculated),
            Causality::Local => match self.variability {
                Variability::Constant => Some(Initial::Exact),
                _ => Some(Initial::Calculated),
            },
        }
    }

    /// Whether the XML carries a `start` attribute (not allowed for `initial="calculated"`).
    pub const fn has_start(&self) -> bool {
        !matches!(self.initial(), Some(Initial::Calculated))
    }
}

/// A value read from or written to a variable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

/// Mutable access to one variable's storage.
pub enum SlotMut<'a> {
    Real(&'a mut f64),
    Integer(&'a mut i32),
    Boolean(&'a mut bool),
}

/// Accessors of one declared variable, in declaration order (generated by `declare_variables!`).
pub type SlotFn<S> = for<'a> fn(&'a mut S) -> SlotMut<'a>;
pub type ValueFn<S> = fn(&S) -> Value;

/// The variable block of a model, generated by [`declare_variables!`](crate::declare_variables).
/// Variables are addressed by their index in `DECLS` (the FMI layer maps value references to indices).
pub trait Variables: Clone + Default + Serialize + DeserializeOwned + Send + 'static {
    const DECLS: &'static [VarDecl];
    fn slot(&mut self, index: usize) -> Option<SlotMut<'_>>;
    fn value(&self, index: usize) -> Option<Value>;

    /// Checks every parameter against its declared [`Bound`].
    fn check_bounds(&self) -> Result<(), String> {
        for (i, d) in Self::DECLS.iter().enumerate() {
            if d.causality != Causality::Parameter {
                continue;
            }
            match self.value(i) {
                Some(Value::Real(x)) => d.bound.check_real(d.name, x)?,
                Some(Value::Integer(x)) => d.bound.check_integer(d.name, x)?,
                _ => {}
            }
        }
        Ok(())
    }

    /// Every Real variable is finite (a restored state must not smuggle in NaN or infinity).
    fn check_finite(&self) -> Result<(), String> {
        for (i, d) in Self::DECLS.iter().enumerate() {
            if let Some(Value::Real(x)) = self.value(i) {
                if !x.is_finite() {
                    return Err(format!("variable {} = {x} is not finite", d.name));
                }
            }
        }
        Ok(())
    }

    /// Calculated parameters must be finite: a derived value that overflowed is an initialization error.
    fn check_calculated(&self) -> Result<(), String> {
        for (i, d) in Self::DECLS.iter().enumerate() {
            if d.causality == Causality::CalculatedParameter {
                if let Some(Value::Real(x)) = self.value(i) {
                    if !x.is_finite() {
                        return Err(format!(
                            "calculated parameter {} = {x} is not finite (check the parameters it is derived from)",
                            d.name
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

/// Which outputs depend directly (algebraically) on which inputs; written to ModelStructure so that
/// masters can order the calls and detect (the absence of) algebraic loops.
#[derive(Clone, Copy, Debug)]
pub enum Feedthrough {
    /// Outputs depend on the internal state only (plants, sources).
    None,
    /// Every output depends on every input (controllers).
    AllInputs,
    /// Listed outputs depend on the listed inputs; the other outputs on none.
    Some(&'static [(&'static str, &'static [&'static str])]),
}

/// Static description of a model: what goes into the XML header, the documentation and the flags.
/// Start from [`ModelInfo::DEFAULT`] and override what differs.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    /// modelIdentifier = FMU file name.
    pub name: &'static str,
    /// One-line purpose.
    pub description: &'static str,
    /// Where the model comes from (paper title and equations).
    pub source: &'static str,
    /// HTML fragment with the equations, for documentation/index.html.
    pub equations_html: &'static str,
    pub feedthrough: Feedthrough,
    /// DefaultExperiment: stop time and preferred communication step.
    pub default_stop_time: f64,
    pub default_step: f64,
    /// `canHandleVariableCommunicationStepSize`.
    pub variable_step: bool,
}

impl ModelInfo {
    pub const DEFAULT: ModelInfo = ModelInfo {
        name: "",
        description: "",
        source: "",
        equations_html: "",
        feedthrough: Feedthrough::None,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };
}

/// Range of relative tolerances the adaptive integrators honour (fmi2SetupExperiment clamps into it
/// and logs a warning when it does).
pub const TOLERANCE_MIN: f64 = 1e-14;
pub const TOLERANCE_MAX: f64 = 0.1;

/// Values from `fmi2SetupExperiment`.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Experiment {
    pub start_time: f64,
    pub tolerance: Option<f64>,
    pub stop_time: Option<f64>,
}

impl Experiment {
    /// Relative tolerance for adaptive integrators: the master's, clamped into [1e-14, 0.1] (a tighter
    /// value cannot be met in double precision, a looser one is meaningless), or 1e-8.
    pub fn tolerance_or_default(&self) -> f64 {
        self.tolerance
            .filter(|x| *x > 0.0)
            .map_or(1e-8, |x| x.clamp(TOLERANCE_MIN, TOLERANCE_MAX))
    }
}

/// Error from model code; the FMI layer logs it with the calling function's name.
pub type ModelResult = Result<(), String>;

/// For [`Model::validate`]: the named parts of a restored state must be finite.
pub fn check_finite_state<'a>(what: &str, values: impl IntoIterator<Item = &'a f64>) -> ModelResult {
    if values.into_iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("restored state: {what} is not finite"))
    }
}

/// For [`Model::validate`]: a part derived from the parameters must equal the freshly derived one.
pub fn check_derived<T: PartialEq>(what: &str, restored: &T, fresh: &T) -> ModelResult {
    if restored == fresh {
        Ok(())
    } else {
        Err(format!("restored state: {what} does not match the parameters"))
    }
}

/// A model: a variable block plus an internal state built from the parameters.
///
/// Contract with the FMI layer (see [`Fmu`]):
/// - `initialize` runs at `fmi2ExitInitializationMode` (and when outputs are read in initialization
///   mode) after every parameter passed its declared [`Bound`]; it checks what the bounds cannot
///   (relations between parameters), writes calculated parameters into `v` and returns the initial
///   internal state. It must be a function of the parameters (and the experiment) only.
/// - `outputs` computes every output from the inputs and the state; it cannot change the state.
/// - `step` advances the state from `t` to `t + h` with the inputs held (default: no state).
pub trait Model: Clone + Serialize + DeserializeOwned + Send + 'static {
    type Vars: Variables;
    const INFO: ModelInfo;
    fn initialize(v: &mut Self::Vars, exp: &Experiment) -> Result<Self, String>;
    fn outputs(&self, v: &mut Self::Vars, t: f64) -> ModelResult;
    fn step(&mut self, _v: &Self::Vars, _t: f64, _h: f64) -> ModelResult {
        Ok(())
    }
    /// Paths of the serialized fields that evolve with time (struct field names joined by '.', e.g.
    /// `"law.history"`; a path covers everything below it). A state restored from bytes is checked by
    /// the layer without model code ([`leaves::check_restored`]): every other serialized field must
    /// equal what `initialize` gives for the restored parameters, and every number under these paths
    /// must be finite. Required, so that no model forgets it: a field not listed here is compared with
    /// a fresh `initialize`, which refuses any state in which it has evolved (safe by default).
    const EVOLVING: &'static [&'static str];
    /// Invariants of the evolving parts of a restored state beyond finiteness (ranges, buffer lengths
    /// consistent with step counts and memory settings), checked after the layer's own checks; `fresh`
    /// is the state `initialize` builds from the same parameters. Default: none.
    fn validate(&self, _fresh: &Self) -> ModelResult {
        Ok(())
    }
    /// Rebuilds what the serialized state leaves out (`#[serde(skip)]` buffers derivable from the
    /// parameters and the evolving fields), after a restored state passed every check. Default: nothing.
    fn restored(&mut self) -> ModelResult {
        Ok(())
    }

    // ----- Model Exchange (optional) ------------------------------------------------------------

    /// The continuous states when the model also offers FMI 2.0 **Model Exchange** (the importer's
    /// solver integrates them): `None` (default) = Co-Simulation only (e.g. a sampled law); `Some(&[])`
    /// = a static law (outputs from inputs and time, nothing to integrate). The layer publishes each
    /// state as a local variable `name` and its derivative as `der(name)` (value references from
    /// [`STATE_VR_BASE`] and [`DERIVATIVE_VR_BASE`]); the methods below give the layer access.
    const STATES: Option<&'static [StateDecl]> = None;
    /// Writes the continuous state vector (length `STATES.len()`). The inputs are there for a state
    /// whose start is taken from them (e.g. a reference model starting at the measurement): until
    /// the first `set_states`, such a model reports that start.
    fn get_states(&self, _v: &Self::Vars, _x: &mut [f64]) {}
    /// Replaces the continuous state vector (finite values, length checked by the layer).
    fn set_states(&mut self, _x: &[f64]) {}
    /// ẋ at time t for the current inputs and states (length `STATES.len()`); the right-hand side
    /// valid at the instant t (after an event at t, the new one).
    fn derivatives(&self, _v: &Self::Vars, _t: f64, _dx: &mut [f64]) -> ModelResult {
        Ok(())
    }
    /// The next time event strictly after t (a fault onset, a noise-hold boundary, a knot), if any.
    fn next_time_event(&self, _v: &Self::Vars, _t: f64) -> Option<f64> {
        None
    }
    /// Event update at time t (a time event, or an event the model asked for after an integrator
    /// step): may reset states (e.g. project a quaternion back to unit norm); returns whether it did.
    fn event_update(&mut self, _v: &Self::Vars, _t: f64) -> Result<bool, String> {
        Ok(false)
    }
    /// Called after every accepted integrator step at time t; `true` asks the importer for an event
    /// (then [`Model::event_update`] runs), e.g. when a quaternion norm has drifted.
    fn completed_integrator_step(&mut self, _v: &Self::Vars, _t: f64) -> bool {
        false
    }
}

/// Registry entry of one FMU.
#[derive(Clone, Copy)]
pub struct ModelEntry {
    pub info: &'static ModelInfo,
    pub decls: &'static [VarDecl],
    /// Model Exchange: the continuous states ([`Model::STATES`]); `None` = Co-Simulation only.
    pub states: Option<&'static [StateDecl]>,
    pub create: fn() -> Box<dyn DynModel>,
}

impl ModelEntry {
    pub const fn of<M: Model>() -> Self {
        let () = feedthrough::Checked::<M>::FEEDTHROUGH; // a compile error naming a mistyped feed-through name
        ModelEntry {
            info: &M::INFO,
            decls: M::Vars::DECLS,
            states: M::STATES,
            create: || Box::new(Fmu::<M>::default()),
        }
    }

    /// Whether the model offers Model Exchange.
    pub const fn model_exchange(&self) -> bool {
        self.states.is_some()
    }

    /// The continuous states (empty for a Co-Simulation-only model or a static law).
    pub fn state_decls(&self) -> &'static [StateDecl] {
        self.states.unwrap_or(&[])
    }

    /// Every text of the model that may cite publications: description, source, equations and the
    /// variable descriptions (read by the model description, the documentation pages and the reference list).
    pub fn texts(&self) -> Vec<&'static str> {
        let mut t = vec![self.info.description, self.info.source, self.info.equations_html];
        t.extend(self.decls.iter().map(|d| d.description));
        t.extend(self.state_decls().iter().map(|d| d.description));
        t
    }

    pub fn decl(&self, name: &str) -> Option<&'static VarDecl> {
        self.decls.iter().find(|d| d.name == name)
    }
}

/// Checks of relations between parameters that a single [`Bound`] cannot express; each returns a
/// message naming the parameters.
pub mod check {
    /// `lo <= hi` for two parameters that span a range.
    pub fn ordered(lo_name: &str, lo: f64, hi_name: &str, hi: f64) -> Result<(), String> {
        if lo <= hi {
            Ok(())
        } else {
            Err(format!(
                "parameters {lo_name} = {lo} and {hi_name} = {hi}: need {lo_name} <= {hi_name}"
            ))
        }
    }
}

/// Declares the FMU modules of a family folder and lists them for the registry, one line per FMU:
///
/// ```ignore
/// fmus! {
///     pd_controller::PdController,
///     lqr_controller::LqrController,
/// }
/// ```
/// expands to `pub mod pd_controller; pub use pd_controller::PdController; …` and
/// `pub const FMUS: &[ModelEntry]`, which `crate::registry` concatenates.
#[macro_export]
macro_rules! fmus {
    ($( $module:ident :: $Model:ident ),* $(,)?) => {
        $( pub mod $module; pub use $module::$Model; )*
        /// The FMUs of this folder, in registry order.
        pub const FMUS: &[$crate::model::ModelEntry] = &[ $( $crate::model::ModelEntry::of::<$Model>() ),* ];
    };
}
