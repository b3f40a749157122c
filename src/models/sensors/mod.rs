//! Sensors and timing (issue 26): units that sit between `AttitudePlant` and the attitude controllers.
//! The sensors read the plant's true outputs by name (`q_*`, `w_*`) and give `*_meas` outputs that a
//! scenario wires to the controllers' `q_*`, `w_*` inputs by explicit connections; `SampleHold` turns a
//! controller into a sampled one. Shared blocks, the sampling schedule and the delay line live in
//! `shared/` (not FMUs). Value references: truth inputs `q` 0–3, `w` 4–6; outputs from 20, diagnostics
//! from 30; `sample_period` 100, `seed` 140, the plant's orbit parameters 160–164, the sun's longitude 165;
//! the environment inputs (`environment_inputs` 191, as the plant's): `b_eci` 7–9, `sun_eci` 10–12,
//! `eclipse` 13 from `Environment`, `r` 14–16, `jd_utc` 17 from `Orbit`.

pub mod shared;

crate::fmus! {
    gyro::Gyro,
    star_tracker::StarTracker,
    sun_sensor::SunSensor,
    magnetometer::Magnetometer,
    sample_hold::SampleHold,
    ephemeris::Ephemeris,
}
