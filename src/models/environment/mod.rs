//! Orbital environment (issue 43): where the spacecraft is and what surrounds it. `Orbit` propagates the
//! position and velocity in an Earth-centred inertial frame (numerically with J2–J4 and drag, or SGP4
//! from a two-line element set) and gives the LVLH frame the pointing modes need. Value references:
//! inputs from 0 (`rho` 0), outputs from 10, diagnostics from 30; parameters 100–139, Integer options
//! from 140.

crate::fmus! {
    orbit::Orbit,
}
