//! Shared math used by the models: attitude representations and conversions, integrators, the
//! Riccati equation (LQR), pole placement, fuzzy inference, relative orbital motion, predictive-control
//! gains, counter-based random numbers, the sample grid of the sampled units (a master's rounded
//! time taken as the grid instant), the orbit environment (the attitude plant's simple one; the true one of
//! the environment family: time scales and Earth orientation, the IAU 1980 nutation and SGP4's TEME frame,
//! IGRF-14, the sun and its shadow, atmospheric density; the drag and solar-pressure forces on a facet
//! model), Grünwald–Letnikov fractional calculus with the PID / PI^λD^μ laws, and interval type-2 fuzzy
//! inference (Karnik–Mendel type reduction).
//! Each module carries its own unit tests against closed-form results.

pub mod atmosphere;
pub mod attitude;
pub mod attitude_kalman;
pub mod dopri_tableau;
pub mod environment;
pub mod fractional;
pub mod fuzzy;
pub mod igrf;
mod igrf14_coefficients;
pub mod integrate;
pub mod nutation;
pub mod orbit;
pub mod pole_placement;
pub mod predictive_control;
pub mod random;
pub mod relative_orbit;
pub mod riccati;
pub mod sample_grid;
pub mod spline;
pub mod sun;
pub mod surface_forces;
pub mod time_scales;
pub mod type2_fuzzy;
pub mod wahba;

pub use nalgebra::{Matrix3, Quaternion, Vector3};
