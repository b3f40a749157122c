//! FMI 2.0: one room over the shared C boundary. `common` holds what every FMI 2.0 function shares
//! (C types, the state table, `call`, `fmi2Instantiate`, life cycle, get/set); `cs` the Co-Simulation
//! functions, `me` the Model Exchange functions, `state` FMU states and directional derivatives, and
//! `export` the `#[no_mangle]` wrappers that `export_fmus!` expands. The files import `common`, the
//! boundary and the instance, never each other, and nothing here imports FMI 3.0.

pub mod common;
pub mod cs;
mod export;
pub mod me;
pub mod state;

/// Every FMI 2.0 function and C type in one path (`spacecraft_fmus::fmi::fmi2::*`), for Rust code
/// that drives the layer directly (the integration tests, the benches).
pub use self::{common::*, cs::*, me::*, state::*};
