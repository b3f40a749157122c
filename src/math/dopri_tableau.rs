//! The Dormand–Prince 5(4) Butcher tableau of the plants' own adaptive integrator (`integrate`): the one
//! table of the `spacecraft_dopri` crate (`src/dopri/`), which scfmu's Model Exchange stepper uses too.

pub use spacecraft_dopri::{A, B, C, E, P};
