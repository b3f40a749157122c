//! The Dormand–Prince 5(4) Butcher tableau of the engines' Model Exchange stepper: the one table of the
//! `spacecraft_dopri` crate (`src/dopri/`, tested there against the order conditions), which the FMU
//! runtime's plant integrator uses too.

pub use spacecraft_dopri::{A, B, C, E, P};
