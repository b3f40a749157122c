//! Attitude estimation (issue 37): units between the sensors and the controllers. `Mekf` reads the
//! gyro's `w_meas`, the star tracker's `q_meas`/`valid` and optionally body directions with their
//! reference directions, and gives `q_est`, `w_est` (to the controllers' `q_*`, `w_*` inputs by
//! explicit connections). Value references of `Mekf`: inputs 0–20, outputs from 40, diagnostics
//! (covariance, innovation, NIS) from 50; `sample_period` 100.

crate::fmus! {
    mekf::Mekf,
}
