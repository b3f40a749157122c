//! Shared math used by the models: attitude representations and conversions, integrators,
//! counter-based random numbers, the orbit environment.
//! Each module carries its own unit tests against closed-form results.

pub mod attitude;
pub mod environment;
pub mod integrate;
pub mod random;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
