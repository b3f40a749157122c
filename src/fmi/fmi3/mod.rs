//! FMI 3.0: one room over the version-neutral core, the same instances as FMI 2.0. `common` holds what
//! every FMI 3.0 function shares (the `FMI3` dialect, state tables, `call3`, `time`, life cycle); `values`
//! get/set for both interfaces; `cs` Co-Simulation, `me` Model Exchange (and the functions both interfaces
//! export with ME rules); `state` FMU states, directional derivatives and variable dependencies;
//! `clocks` clocked Co-Simulation and Scheduled Execution; `unsupported` the functions of features these FMUs do not declare; `export` (and `export_values`) the
//! `#[no_mangle]` wrappers. The files import `common`, the boundary and the instance, never each other, and
//! nothing here imports FMI 2.0.

#[cfg(test)]
mod clock_error_tests;
#[cfg(test)]
mod clock_tests;
pub mod clocks;
pub mod common;
pub mod cs;
mod export;
mod export_values;
pub mod me;
pub mod state;
#[cfg(test)]
mod tests;
pub mod unsupported;
pub mod values;

/// Every FMI 3.0 function in one path (`spacecraft_fmus::fmi::fmi3::*`), for Rust code that drives the
/// layer directly.
pub use self::{clocks::*, common::*, cs::*, me::*, state::*, unsupported::*, values::*};
