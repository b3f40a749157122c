//! Spacecraft guidance and control units as FMI 2.0 and FMI 3.0 FMUs (Co-Simulation, and Model
//! Exchange where the equations are continuous), and the runtime that exports them — ours and anyone's.
//!
//! - `export`: the public export API in one place — the model contract, the declaration macros,
//!   [`export_fmus!`] (which generates a shared library's FMI entry points) and the catalogue the
//!   packaging tool reads back. Start there (docs/export.md walks through a model of your own).
//! - `fmi`: the FMI 2.0 and 3.0 C functions (Co-Simulation and Model Exchange), state machine, logging and
//!   FMU state, written once, one folder per version over one C boundary; exported by `export_fmus!` in the crate that builds the shared library, never by this one (an rlib).
//! - `catalogue`: the declaration vocabulary (variables, model header, states, references) and the
//!   owned catalogue a library exports, the packaging tool's only input.
//! - `model`: what a model is (declared variables + init/outputs/step), the declaration macro, GUIDs.
//! - `models`: the project's FMUs, one folder per family; `registry` lists them.
//! - `math`: shared math (attitude conventions, integrators, ...), unit-tested on its own.
//! - `units`: the unit table every declared unit must come from; `text`: const string helpers.
//!
//! Workspace members next to this crate: `src/cdylib` (the shared library of the project's FMUs: one
//! `export_fmus!` line over the registry, like a user's crate) and `src/package` (the packaging tool
//! `fmu-package`: modelDescription.xml, documentation, `.fmu` archives and the generated model pages;
//! the only code that links an XML writer and `zip`).

pub mod catalogue;
pub mod export;
pub mod fmi;
pub mod math;
pub mod model;
pub mod models;
pub mod registry;
pub mod text;
pub mod units;

/// The linear-algebra crate of the declarations (`Vec3`, `Diag3`, `Quat` fields), re-exported so that
/// a model crate uses the same version.
pub use nalgebra;
