//! The FMI layer, written once for every model: one room per FMI version over one shared,
//! version-neutral core. Models never see anything in here; a model crate reaches it only through
//! `export_fmus!`.
//!
//! The core (every file here but `fmi2/` and `fmi3/`) names no FMI version: its states are those both
//! standards share, an instance knows the interface it serves only through the [`types::Dialect`] its
//! room gives it (the room's names of states, arguments and calls), and a failure that would name one
//! of those carries its data ([`fail::Reason`]) and is worded with the instance's dialect when it is
//! logged. The rooms hold everything of one version: the C signatures and types, the state tables,
//! the call wrappers with the version's error rules, and the export macros. `tests/test_rust_layers.py`
//! checks that no core file spells a version's name.
//!
//! | module | what |
//! |---|---|
//! | [`types`] | status codes, the two logger callback shapes, the shared states and their masks, log categories, `Dialect` |
//! | [`fail`] | `Fail` (status + reason) and the typed `Reason`, worded by a dialect |
//! | [`live`] | the handles handed to the master (instances, FMU states): tokens that are never reused, looked up without a lock |
//! | [`boundary`] | live instance table, panic guard, C arrays and out-pointers, one instantiate for every interface |
//! | [`instance`] | one FMU instance: state machine, initialization, stepping (`logging`, `values`: value access, `me`: Model Exchange, `jacobian`: directional derivatives) |
//! | [`state`], `state_calls` | FMU state snapshots, their byte format, and the call bodies both versions share |
//! | [`fmi2`] | FMI 2.0: `common` (C types, the `FMI2` dialect, state table, `call`, instantiate, life cycle, get/set), `cs`, `me`, `state`, `export` |
//! | [`fmi3`] | FMI 3.0: `common` (the `FMI3` dialect, state tables, `call3`, life cycle, the instantiate request), `values`, `cs`, `me`, `state`, `unsupported`, `export` (+ `export_values`) |
//! | `library_path` | the path of the loaded library (the model is picked by its file name) |
//!
//! Imports run one way: `fmi2/*` and `fmi3/*` → `boundary` → `state` → `instance` → `fail`, `types`, `live` (and
//! the model contract in `crate::model`); the files of a version import their `common`, never each other, and
//! neither version imports the other.
//!
//! Call flow, e.g. a master setting a parameter:
//! 1. `fmi2SetReal` (the `#[no_mangle]` wrapper that `export_fmus!` expands in the user's `cdylib`, `fmi2/export.rs`)
//! 2. → `fmi2::common::fmi2SetReal` → `call` (live-instance lookup in `boundary` for an instance of the `FMI2`
//!    dialect, state check against `mask::SET`, panic guard)
//! 3. → `Instance::set_values` (`instance`: value reference → declaration, causality/variability rules, bounds, finiteness)
//! 4. → the model's field through its `Variables` table (`crate::model`), e.g. `PdControllerVars::wn`.
//! 5. A refusal comes back as a `Fail`; `call` logs it as `fmi2SetReal: <reason in FMI 2.0 words>`.

// The pub functions of this layer are the C boundary: they receive the master's raw pointers, check them (null,
// and the live-instance/FMU-state tables of `live`) before any dereference, and are called only from the
// `#[no_mangle]` wrappers that the export macros expand. Marking them `unsafe` would only move the same trust
// into those macros, so clippy's not_unsafe_ptr_arg_deref is wrong here.
#![allow(clippy::not_unsafe_ptr_arg_deref)]

pub mod boundary;
pub mod fail;
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
