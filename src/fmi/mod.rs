//! The FMI layer, written once for every model: one room per FMI version over one shared C boundary.
//! Models never see anything in here; a model crate reaches it only through `export_fmus!`.
//!
//! | module | what |
//! |---|---|
//! | [`types`] | status codes, logger callback types, the states of the state machine, log categories |
//! | [`live`] | the handles handed to the master (instances, FMU states): tokens that are never reused, looked up without a lock |
//! | [`boundary`] | live instance table, panic guard, C arrays and out-pointers, one instantiate for every interface |
//! | [`instance`] | one FMU instance: state machine, initialization, stepping (`logging`, `values`: value access, `me`: Model Exchange, `jacobian`: directional derivatives) |
//! | [`state`], `state_calls` | FMU state snapshots, their byte format, and the call bodies both versions share |
//! | [`fmi2`] | FMI 2.0: `common` (C types, state table, `call`, instantiate, life cycle, get/set), `cs`, `me`, `state`, `export` |
//! | [`fmi3`] | FMI 3.0: `common` (state tables, `call3`, life cycle, the instantiate request), `values`, `cs`, `me`, `state`, `unsupported`, `export` (+ `export_values`) |
//! | `library_path` | the path of the loaded library (the model is picked by its file name) |
//!
//! Imports run one way: `fmi2/*` and `fmi3/*` → `boundary` → `state` → `instance` → `types`, `live` (and the model
//! contract in `crate::model`); the files of a version import their `common`, never each other, and
//! neither version imports the other.
//!
//! Call flow, e.g. a master setting a parameter:
//! 1. `fmi2SetReal` (the `#[no_mangle]` wrapper that `export_fmus!` expands in the user's `cdylib`, `fmi2/export.rs`)
//! 2. → `fmi2::common::fmi2SetReal` → `call` (live-instance lookup in `boundary`, state check against `mask::SET`, panic guard)
//! 3. → `Instance::set_values` (`instance`: value reference → declaration, causality/variability rules, bounds, finiteness)
//! 4. → the model's field through its `Variables` table (`crate::model`), e.g. `PdControllerVars::wn`.

// The pub functions of this layer are the C boundary: they receive the master's raw pointers, check them (null,
// and the live-instance/FMU-state tables of `live`) before any dereference, and are called only from the
// `#[no_mangle]` wrappers that the export macros expand. Marking them `unsafe` would only move the same trust
// into those macros, so clippy's not_unsafe_ptr_arg_deref is wrong here.
#![allow(clippy::not_unsafe_ptr_arg_deref)]

pub mod boundary;
pub mod fmi2;
pub mod fmi3;
pub mod instance;
mod library_path;
pub mod live;
pub mod state;
mod state_calls;
#[cfg(test)]
mod state_nan_tests;
pub mod types;

pub use types::{FsmState, Status, LOG_CATEGORIES};
