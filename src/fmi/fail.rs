//! How a call of the shared code fails: a status and a typed reason. Most reasons are plain text that
//! names no function; those that would name a function, an argument or a state of one interface carry
//! their data instead, and are worded when logged, with the names of the [`Dialect`] of the instance
//! (`Reason::render`), so that each room reports them in its own standard's words.

use super::types::{Arg, Dialect, FsmState, Status};

/// Why a call failed.
#[derive(Debug, Clone, PartialEq)]
pub enum Reason {
    /// A message that reads the same through every interface.
    Text(String),
    /// The state machine does not allow the call in this state.
    IllegalCall(FsmState),
    /// A fixed parameter set outside Instantiated and Initialization Mode.
    FixedParameter { name: &'static str, state: FsmState },
    /// A step whose end lies beyond the stop time of the experiment.
    BeyondStopTime { end: f64, stop: f64 },
    /// A continuous state set as a variable where only the Model Exchange call may set it.
    StateByValue { name: &'static str },
    /// An array of the Model Exchange calls with the wrong number of elements.
    Length {
        arg: Arg,
        n: usize,
        model: &'static str,
        states: usize,
    },
    /// A continuous state that is not finite (`k`-th element of the states array).
    NonFiniteState { k: usize, name: &'static str, value: f64 },
    /// An FMU state taken through another interface (`taken_by`: that interface's `version`).
    OtherInterface { what: &'static str, taken_by: String },
    /// A reason followed by more text.
    Then(Box<Reason>, &'static str),
}

impl Reason {
    /// The message, in the words of the interface `d`.
    pub fn render(&self, d: &Dialect) -> String {
        match self {
            Reason::Text(s) => s.clone(),
            Reason::IllegalCall(s) => format!("not allowed in state {} (illegal call sequence)", (d.state_name)(*s)),
            Reason::FixedParameter { name, state } => format!(
                "parameter {name} is fixed and cannot be set after initialization (state {})",
                (d.state_name)(*state)
            ),
            Reason::BeyondStopTime { end, stop } => {
                format!("step to {end} goes beyond stopTime {stop} set in {}", d.setup_experiment)
            }
            Reason::StateByValue { name } => format!(
                "{name} is a continuous state: set it with {} (Model Exchange)",
                d.set_continuous_states
            ),
            Reason::Length { arg, n, model, states } => format!(
                "{} has {n} elements, but {model} has {states} continuous states",
                (d.argument)(*arg)
            ),
            Reason::NonFiniteState { k, name, value } => format!(
                "{}[{k}] ({name}) = {value} is not finite",
                (d.argument)(Arg::States).trim_end_matches("[]")
            ),
            Reason::OtherInterface { what, taken_by } => format!(
                "{what} was taken by an {taken_by} instance; this instance runs {} (a state is restored only through the interface version that took it)",
                d.version
            ),
            Reason::Then(first, more) => format!("{}{more}", first.render(d)),
        }
    }
}

impl From<String> for Reason {
    fn from(s: String) -> Self {
        Reason::Text(s)
    }
}

impl From<&str> for Reason {
    fn from(s: &str) -> Self {
        Reason::Text(s.to_string())
    }
}

/// Failure of a call: the status to return and the reason to log.
#[derive(Debug)]
pub struct Fail {
    pub status: Status,
    pub reason: Reason,
}

impl Fail {
    pub fn error(reason: impl Into<Reason>) -> Self {
        Fail {
            status: Status::Error,
            reason: reason.into(),
        }
    }
    pub fn discard(reason: impl Into<Reason>) -> Self {
        Fail {
            status: Status::Discard,
            reason: reason.into(),
        }
    }
    pub fn warning(reason: impl Into<Reason>) -> Self {
        Fail {
            status: Status::Warning,
            reason: reason.into(),
        }
    }
}

pub type CallResult<T = ()> = Result<T, Fail>;
