//! FMI 2.0: one room over the version-neutral core. `common` holds what every FMI 2.0 function shares
//! (C types, the `FMI2` dialect, the state table, `call`, `fmi2Instantiate`, life cycle, get/set); `cs`
//! the Co-Simulation functions, `me` the Model Exchange functions, `state` FMU states and directional
//! derivatives, `export` the `#[no_mangle]` wrappers that `export_fmus!` expands, `tests` the panic
//! guard. The files import `common`, the boundary and the instance, never each other, and nothing here
//! imports FMI 3.0.

pub mod common;
pub mod cs;
mod export;
pub mod me;
pub mod state;
#[cfg(test)]
mod tests;

/// Every FMI 2.0 function and C type in one path (`spacecraft_fmus::fmi::fmi2::*`), for Rust code
/// that drives the layer directly (the integration tests, the benches).
pub use self::{common::*, cs::*, me::*, state::*};
