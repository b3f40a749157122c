//! What the stepper and the tables share: FMI statuses, the integrator settings, why a step stopped,
//! and the Model Exchange calls a unit answers ([`Unit`]). A leaf module: the crate root re-exports it.

pub const OK: i32 = 0;
pub const WARNING: i32 = 1;
pub const DISCARD: i32 = 2;
pub const ERROR: i32 = 3;

/// The integrator of a unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Dormand–Prince 5(4), adaptive.
    DormandPrince,
    /// Classic Runge–Kutta 4, fixed step.
    Rk4,
}

/// A unit's integrator and its tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub method: Method,
    /// Relative and absolute tolerance of the adaptive method (> 0).
    pub rtol: f64,
    pub atol: f64,
    /// The largest step (s; 0: none, the fixed step is then the communication step).
    pub max_step: f64,
}

/// Why a step stopped before its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// A call of the unit returned this status (above Warning).
    Failed(i32),
    /// The unit asked to terminate (`completedIntegratorStep` or the event iteration), at [`Stepper::t`].
    Terminate,
    /// The stepper could not go on: a step size below its minimum, more than a million steps in one
    /// communication step, or an event iteration that did not settle in 1000 rounds.
    Solver,
}

/// What the stepper needs from a Model Exchange unit (FMI 2.0 or 3.0), statuses as ints (0 OK,
/// 1 Warning, 2 Discard, 3 Error, 4 Fatal). [`MeUnit`] is the one over an FMU; the tests have their own.
pub trait Unit {
    fn set_time(&mut self, t: f64) -> i32;
    fn set_states(&mut self, x: &[f64]) -> i32;
    fn get_states(&mut self, x: &mut [f64]) -> i32;
    fn derivatives(&mut self, dx: &mut [f64]) -> i32;
    fn indicators(&mut self, z: &mut [f64]) -> i32;
    /// `completedIntegratorStep`: (status, enter event mode, terminate).
    fn completed(&mut self) -> (i32, bool, bool);
    fn enter_event_mode(&mut self) -> i32;
    /// One `newDiscreteStates` / `updateDiscreteStates`: (status, more needed, terminate, next event time).
    fn update(&mut self) -> (i32, bool, bool, Option<f64>);
    fn enter_continuous_mode(&mut self) -> i32;
}
