//! Shared math used by the models: attitude representations and conversions, integrators, the
//! Riccati equation (LQR), pole placement and fuzzy inference.
//! Each module carries its own unit tests against closed-form results.

pub mod attitude;
pub mod fuzzy;
pub mod integrate;
pub mod pole_placement;
pub mod riccati;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
