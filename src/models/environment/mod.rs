//! Orbital environment (issue 43): where the spacecraft is and what surrounds it. `Orbit` propagates the
//! position and velocity in an Earth-centred inertial frame (numerically with J2–J4 and drag, or SGP4
//! from a two-line element set) and gives the LVLH frame the pointing modes need; `Environment` gives the
//! true environment at the spacecraft — geomagnetic field, sun, shadow, atmosphere — as opposed to the
//! on-board `Ephemeris` of the sensors family. The epoch block of `Environment` (`epoch.rs`, value
//! references 100–105) is a calendar date; `Orbit` takes its epoch as a UTC Julian date.

pub mod epoch;

crate::fmus! {
    environment::Environment,
    orbit::Orbit,
}
