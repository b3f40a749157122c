//! Attitude estimation and determination (issue 37): units between the sensors and the controllers that
//! turn measurements into an attitude estimate, and the B-dot detumbling law on the magnetometer.
//! `Mekf` reads the gyro's `w_meas`, the star tracker's `q_meas`/`valid` and optionally body directions with
//! their reference directions, and gives `q_est`, `w_est` (to the controllers' `q_*`, `w_*` inputs by
//! explicit connections); value references: inputs 0–20, the coarse re-initialisation `q_coarse` 21–24
//! and `init_request` 25, outputs from 40, diagnostics (covariance, innovation, NIS) from 50;
//! `sample_period` 100, `sigma_att_coarse` 128.
//! `Triad` and `Quest` are static laws (Model Exchange as well as Co-Simulation) solving Wahba's problem
//! from the sun sensor's and the magnetometer's body-frame directions and their reference-frame
//! directions (`crate::math::wahba`); `BDot` is sampled at its own rate with the sensors' integer sample
//! schedule. Value references: observation inputs `sun_meas` 0–2, `b_meas` 3–5, further observations
//! 6–11, reference directions `sun_ref` 12–14, `b_ref` 15–17, 18–23; estimate `q_est` 40–43, `loss` 44;
//! `min_separation` 100, weights 101–104; `BDot`: `b_meas` 3–5 in (as the Magnetometer's output),
//! `m_cmd` 20–22 out (as the plant's input), `sample_period` 100 as in the sensors.

pub mod shared;

crate::fmus! {
    mekf::Mekf,
    triad::Triad,
    quest::Quest,
    bdot::BDot,
}
