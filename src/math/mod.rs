//! Shared math used by the models: attitude representations and conversions, integrators, the
//! Riccati equation (LQR), pole placement, fuzzy inference, relative orbital motion, predictive-control
//! gains, counter-based random numbers and the orbit environment.
//! Each module carries its own unit tests against closed-form results.

pub mod attitude;
pub mod environment;
pub mod fuzzy;
pub mod integrate;
pub mod pole_placement;
pub mod predictive_control;
pub mod random;
pub mod relative_orbit;
pub mod riccati;
pub mod spline;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
