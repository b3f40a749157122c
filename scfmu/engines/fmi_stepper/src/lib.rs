//! The Model Exchange stepper of scfmu's engines, written once for the Co-Simulation face of a Model
//! Exchange unit (`scfmu/engines/me_cs`, a library inside a wrapped FMU) and the compiled loop
//! (`scfmu/engines/native_loop`): both advance a Model Exchange unit over a communication step with its
//! inputs held, through the same code.
//!
//! * [`fmi`]: the unit's Model Exchange functions, typed once per FMI version (2.0 and 3.0), loaded from
//!   the unit's shared library ([`dynlib`]) or taken from pointers the caller already has;
//! * [`values`]: the value getters and setters and `doStep` of a unit, typed once per FMI version (the
//!   compiled loop's propagation and its Co-Simulation units);
//! * [`Stepper`]: one integrator family of explicit Runge–Kutta methods over one set of work vectors,
//!   chosen per unit ([`Method`]): the Dormand–Prince 5(4) pair ([`tableau`]) with local extrapolation,
//!   adaptive steps under `rtol`/`atol` (Hairer, Nørsett & Wanner's first step, SciPy's `RK45` step-size
//!   control) and its fourth-order continuous extension; or the classic Runge–Kutta 4 with a fixed step
//!   (the communication step, or `max_step` when smaller). `max_step` bounds the adaptive steps too.
//!
//! One communication step from t to t_end: integrate the continuous states, stopping at the unit's next
//! time event; after every accepted step call `completedIntegratorStep` and look for a sign change of an
//! event indicator (a state event). A state event is located by ONE method for both integrators:
//! bisection on the fraction of the accepted step to 1e-12 relative in time, with the state inside the
//! step given by the integrator (Dormand–Prince: its continuous extension, no extra evaluation; RK4: a
//! re-integrated partial step). At a time event, a state event or when the unit asks for it (step event),
//! the event iteration (`enterEventMode`, `newDiscreteStates` / `updateDiscreteStates` until no update is
//! needed; the next time event taken over), then continuous-time mode again with the states re-read.
//!
//! No dependency on the FMU crate; nothing here panics on a unit's answer (statuses come back as
//! [`Stop`]).

mod dopri;
pub mod dynlib;
pub mod fmi;
mod rk4;
mod stepper;
pub mod tableau;
mod unit;
pub mod values;

#[cfg(test)]
mod tests;

pub use fmi::{MeUnit, Table};
pub use stepper::Stepper;
pub use unit::*;
