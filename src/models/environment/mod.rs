//! Orbital environment (issue 43): the true environment at the spacecraft — geomagnetic field, sun,
//! shadow, atmosphere — as opposed to the on-board `Ephemeris` of the sensors family. The epoch block
//! (`epoch.rs`, value references 100–105) is shared by the family's models.

pub mod epoch;

crate::fmus! {
    environment::Environment,
}
