//! Spacecraft guidance and control units as FMI 2.0 Co-Simulation FMUs.
//!
//! - `fmi`: the FMI 2.0 CS C ABI, state machine, logging and FMU state, written once.
//! - `model`: what a model is (declared variables + init/outputs/step), the declaration macro, GUIDs.
//! - `models`: the FMUs, one folder per family; `registry` lists them.
//! - `description`: modelDescription.xml and documentation generated from the declarations (packaging).
//! - `math`: shared math (attitude conventions, integrators, ...), unit-tested on its own.
//! - `docs`, `references`: the generated model pages under docs/ and the publications they cite.
//! - `package`: writes `fmus/<Model>.fmu` and `modelDescription/<Model>.xml`.

pub mod description;
pub mod docs;
pub mod fmi;
pub mod math;
pub mod model;
pub mod models;
pub mod package;
pub mod references;
pub mod registry;
pub mod units;
