//! Shared math used by the models: attitude representations and conversions, integrators,
//! relative orbital motion, predictive-control gains, counter-based random numbers, the orbit
//! environment.
//! Each module carries its own unit tests against closed-form results.

pub mod attitude;
pub mod environment;
pub mod integrate;
pub mod predictive_control;
pub mod random;
pub mod relative_orbit;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
