//! The Model Exchange part of a declaration: the continuous states a model publishes, what each
//! state's derivative depends on, and the value references the layer gives them.

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
/// First value reference reserved for the layer (continuous states, their derivatives; FMI 3.0 `time`).
pub const RESERVED_VR_START: u32 = STATE_VR_BASE;
