//! Shared math used by the models: attitude representations and conversions, integrators.
//! Each module carries its own unit tests against closed-form results.

pub mod attitude;
pub mod integrate;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
