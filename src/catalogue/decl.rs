//! The declaration vocabulary every model is written in (static, `const`-friendly): variables with
//! causality, variability, kind, start and bound; the model header ([`ModelInfo`]) with its
//! feed-through; the continuous states of Model Exchange ([`StateDecl`]) and the value references the
//! layer reserves for them; the publications a library cites ([`Reference`]). The runtime reads these
//! through `crate::model`; the catalogue ([`super::library`]) is their owned copy for the packager.

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

/// `initial` follows from causality and variability (FMI 2.0 table of section 2.2.7):
/// parameters and constants are exact, outputs/locals/calculated parameters are calculated,
/// inputs carry no `initial` attribute (they still have a start value).
pub const fn initial_of(causality: Causality, variability: Variability) -> Option<Initial> {
    match causality {
        Causality::Parameter => Some(Initial::Exact),
        Causality::Input => None,
        Causality::CalculatedParameter | Causality::Output => Some(Initial::Calculated),
        Causality::Local => match variability {
            Variability::Constant => Some(Initial::Exact),
            _ => Some(Initial::Calculated),
        },
    }
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
        initial_of(self.causality, self.variability)
    }

    /// Whether the XML carries a `start` attribute (not allowed for `initial="calculated"`).
    pub const fn has_start(&self) -> bool {
        !matches!(self.initial(), Some(Initial::Calculated))
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

/// A continuous state of a Model Exchange model: published as the local variable `name` and its
/// derivative `der(name)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateDecl {
    pub name: &'static str,
    /// Unit of the state (from the unit table; "" for none). The derivative carries no unit attribute.
    pub unit: &'static str,
    pub description: &'static str,
    /// The inputs and states (FMI scalar names, e.g. `torque_cmd_x`, `state_w_x`) the derivative of
    /// this state depends on for some parameter values; `None` = every input and every state. It is
    /// written to `<Derivatives>` (FMI 2.0) / `<ContinuousStateDerivative>` (FMI 3.0), and the
    /// packaging tool refuses a name that is neither an input nor a state.
    pub depends: Option<&'static [&'static str]>,
    /// The inputs the start value is taken from (e.g. a reference model that starts at the
    /// measurement); empty = the start is a function of the parameters only. Written to the
    /// `<InitialUnknowns>` entries of the state, of the derivatives that read it and of the outputs.
    pub starts_from: &'static [&'static str],
}

impl StateDecl {
    /// A state whose derivative may depend on every input and state (declare less with
    /// [`Self::depends_on`]) and whose start depends on the parameters only.
    pub const fn new(name: &'static str, unit: &'static str, description: &'static str) -> Self {
        StateDecl {
            name,
            unit,
            description,
            depends: None,
            starts_from: &[],
        }
    }

    /// The exact list of inputs and states the derivative depends on (an empty list: on none).
    pub const fn depends_on(self, names: &'static [&'static str]) -> Self {
        StateDecl {
            depends: Some(names),
            ..self
        }
    }

    /// The inputs the start value reads ([`StateDecl::starts_from`]).
    pub const fn starting_from(self, inputs: &'static [&'static str]) -> Self {
        StateDecl {
            starts_from: inputs,
            ..self
        }
    }
}

/// Value reference of continuous state i (Real, local): `STATE_VR_BASE + i`. Value references from
/// [`RESERVED_VR_START`] on belong to the layer; a declaration may not use them.
pub const STATE_VR_BASE: u32 = 1_000_000_000;
/// Value reference of the derivative of continuous state i: `DERIVATIVE_VR_BASE + i`.
pub const DERIVATIVE_VR_BASE: u32 = 1_000_100_000;
/// Value reference of clock i of a clocked model ([`ClockDecl`], FMI 3.0 only): `CLOCK_VR_BASE + i`.
pub const CLOCK_VR_BASE: u32 = 1_000_200_000;
/// First value reference reserved for the layer (continuous states, their derivatives; FMI 3.0 `time`).
pub const RESERVED_VR_START: u32 = STATE_VR_BASE;

/// A time-based periodic input clock of a sampled model (FMI 3.0 only; FMI 2.0 is unchanged): it ticks
/// at t_start + shift + k·interval (k = 0, 1, …), both taken from the model's parameters, so the
/// model description declares it `intervalVariability="fixed"` without `intervalDecimal` and the importer
/// reads them with `fmi3GetIntervalDecimal` / `fmi3GetShiftDecimal` in Initialization Mode. Clock i of a
/// model has value reference [`CLOCK_VR_BASE`] + i; in Scheduled Execution its priority is i (a lower
/// index runs first when two clocks tick at the same instant).
///
/// The clock's model partition, at a tick t_k, with the inputs the unit holds at t_k (inputs are not
/// clocked): first the listed `outputs` are computed (`Model::outputs` at t_k, from the state before
/// the tick) and held until the clock's next tick; then, if `steps`, the state advances over one interval
/// (`Model::step(t_k, interval)`). That is the model's own arithmetic in the order a sampled run reads
/// and steps it, so a clocked run gives the sampled run's outputs bit for bit. An output that no clock
/// lists (a diagnostic that follows the inputs between samples) is computed whenever it is read, as
/// without clocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockDecl {
    /// Variable name of the clock (`sample_clock`, `delivery_clock`).
    pub name: &'static str,
    pub description: &'static str,
    /// Name of the Real parameter (fixed) whose value is the interval T in seconds.
    pub interval: &'static str,
    /// Name of the Real parameter (fixed) whose value is the shift of the first tick from the start
    /// time in seconds; "" = no shift.
    pub shift: &'static str,
    /// Whether the partition advances the model's state over one interval at each tick.
    pub steps: bool,
    /// The outputs the partition computes at each tick (FMI scalar names or vector stems such as
    /// `q_meas`): the clocked variables of this clock.
    pub outputs: &'static [&'static str],
}

/// A publication a library cites. Texts (model descriptions, sources, equations, variable
/// descriptions, family overviews) cite it by its bracketed key (`[Navabi-2019] Eq. 37`); the
/// packaging tool expands every cited key into the full reference and refuses a key the library does
/// not declare. The project's own bibliography is `crate::models::references`; a model crate passes its
/// own list to `export_fmus!` (`references: MY_REFERENCES`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Citation key, written in text as `[key]` (letters, digits and at least one '-').
    pub key: &'static str,
    pub authors: &'static str,
    pub title: &'static str,
    /// Journal, year and language notes, as far as known ("" = not recorded; likewise `authors`).
    pub venue: &'static str,
    /// A description standing in for the title when the title is not recorded ("" otherwise).
    pub subject: &'static str,
    /// What the library takes from it.
    pub used_for: &'static str,
}

/// Every `[key]`-shaped citation in `text` (letters, digits and '-', with a letter and a '-'), in order.
pub fn cited_keys(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find('[') {
        let after = &rest[i + 1..];
        match after.find(']') {
            Some(j)
                if j > 0
                    && after[..j].chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
                    && after[..j].chars().any(|c| c.is_ascii_alphabetic())
                    && after[..j].contains('-') =>
            {
                out.push(&after[..j]);
                rest = &after[j + 1..];
            }
            _ => rest = after,
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn citations_are_bracketed_keys_with_a_dash() {
        let t = "as in [Navabi-2019] Eq. 5 and [Moradi-FTC]; not a key: [0, 1] or [x] or [2-3]";
        assert_eq!(super::cited_keys(t), ["Navabi-2019", "Moradi-FTC"]);
    }
}
