//! The FMU models, one folder per family. Each family's `mod.rs` lists its FMUs with `fmus!` (that list
//! is the family's part of `crate::registry`); what several models of a family share (laws, variable
//! blocks) lives in non-FMU modules beside them (e.g. `attitude/control/shared/`), general math in
//! `crate::math`. Port blocks that every unit of a kind embeds are public, in [`ports`]; the
//! publications the models cite (by `[key]` in their texts) are listed in [`references`].
//!
//! Value references (the same parameter has the same value reference across a family; checked over the
//! registry by `tests/model_description.rs`):
//!
//! | range   | what |
//! |---------|------|
//! | 0–99    | ports: inputs and outputs (diagnostic outputs from 30 up) |
//! | 100–199 | parameters (Integer options from 120 up in controllers, 140 up in plants) |
//! | 200–299 | calculated parameters |
//!
//! Family-wide assignments:
//! - attitude controllers: ports 0–13 in (`q` 0–3, `w` 4–6, `q_ref` 7–10, `w_ref` 11–13), 20–22 out
//!   (`torque_cmd`); reserved 14–19 for further common inputs: `h_wheel` 14–16 (sliding-mode controllers),
//!   `w_ref_dot` 17–19 (`PdController`, `AttitudeCommand`'s output of that name); inputs of the controllers
//!   fed by sensors instead of an estimate and a command (`SunSafeController`, extension: 60–69): `w_meas`
//!   60–62 (the Gyro's output), `sun_meas` 63–65, `sun_valid` 66 (the SunSensor's outputs); nominal inertia
//!   `inertia_xx/yy/zz` 100–102; `wn` 103, `zeta` 104; `error_law` 121, `defuzz` 122; fuzzy output set values
//!   `c_small` 215, `c_big` 216 (calculated); fuzzy input
//!   scales `e_scale` 115, `edot_scale` 116, `sigma` 117, `mf_half_width` 118; MRAC block
//!   (`shared::mrac::MracVariables`) outputs 30–44, parameters 100–110 and 120, calculated 200–205;
//!   `SunSafeController`: `sun_axis` 105–107, `spin_rate` 108, `torque_max` 109, diagnostics `sun_angle` 30,
//!   `sun_seen` 31, calculated `k_p` 200–202, `k_d` 203–205 (as `PdController`'s `k_d`).
//! - attitude command (`AttitudeCommand`): inputs `r` 0–2, `v` 3–5, `sun_eci` 6–8; outputs `q_ref` 10–13,
//!   `w_ref` 14–16, `roll/pitch/yaw_ref` 17–19, `w_ref_dot` 20–22; `sun_axis` 105–107, `secondary_axis`
//!   108–110, `target_eci` 111–113.
//! - attitude plant: `inertia_xx/yy/zz` 100–102 as in the controllers; `integrator` 140,
//!   `max_internal_step` 130; ports 0–80 (`actuator_fault` 80, the health flag), parameters 100–198
//!   (`fault_clear_time` 198), facets 210–269.
//! - estimation: `Mekf` inputs 0–25 (`q_coarse` 21–24, `init_request` 25), outputs from 40, parameters
//!   100–128 (`sigma_att_coarse` 128).
//! - paper 004 (`FeedbackLinearizingController`, `ReferenceCorrector`): `q_ref_dot` 50–52 and
//!   `q_ref_ddot` 53–55 (controller inputs = corrector outputs), `u_ol` 56–58; gains `k_q` 160–162,
//!   `k_qdot` 163–165; the corrector's plant-copy parameters keep the plant's references
//!   (`init_euler321_*` 110–112, `init_w` 113–115, `u_max` 120–122, `effectiveness` 123–125,
//!   `max_internal_step` 130), `mode` 150, `node_{x,y,z}_{0..5}` 170–187, `spline_t_end` 188.
//! - formation: the controller's leader-orbit and mass parameters keep the plant's references (`mu` 100,
//!   `semi_major_axis` 101, `eccentricity` 102, `mass` 104); its own `T1` 114, `T2` 115, `c` 116,
//!   `c_x/y/z` 117–119, `init_int_error` 150–152, `structure` 120.
//! - sensors: truth inputs `q` 0–3 (the plant's attitude), `w` 4–6 (the plant's rate); measured outputs
//!   from 20 (`w_meas`, `q_meas` + `valid` 24, `sun_meas` + `valid` 23, `b_meas`; `SampleHold` `y_1…8`
//!   20–27 from `u_1…8` 0–7), diagnostics from 30; `sample_period` 100, `seed` 140, the plant's orbit
//!   parameters with the plant's references (`mu` 160 … `earth_dipole` 164), `sun_ecliptic_longitude` 165;
//!   environment inputs (`environment_inputs` 191, as the plant's) `b_eci` 7–9, `sun_eci` 10–12,
//!   `eclipse` 13, `r` 14–16, `jd_utc` 17; `SunSensor`'s `shadow` 141, `sun_fraction_min` 114.
//! - environment: epoch `epoch_year` … `epoch_second` 100–105 (`environment::epoch::EpochParams`);
//!   `Environment`: position `r` 0–2, outputs 20–29, diagnostics 30–39, `hp_exponent` 106, `density_model` 120.
//! - adcs (`adcs/mod.rs`): `ModeManager` inputs `w_meas` 0–2, `sun_valid` 3, `sun_meas` 4–6, `p_att` 7–9,
//!   `nis` 10, `nis_dim` 11, `actuator_fault` 12, `recover` 13, `safe_request` 14; outputs `mode` 20,
//!   `time_in_mode` 21, `mode_changes` 22, `torque_select` 23, `dipole_select` 24, `estimator_init` 25,
//!   `controller_enable` 26; diagnostics `rate` 30, `sigma_att` 31, `nis_avg` 32, `sun_angle` 33,
//!   `last_reason` 34; `sample_period` 100, `rate_detumbled` 101, `rate_tumbling` 102, `rate_safe` 103,
//!   `sun_angle_acquired` 104, `sun_angle_lost` 105, `sun_axis` 106–108, `sigma_converged` 109,
//!   `sigma_diverged` 110, `nis_max` 111, `nis_diverged` 112, `nis_time_constant` 113, `min_dwell` 114,
//!   `fault_confirm_time` 115, `recover_time` 116, `init_duration` 117, `initial_mode` 120,
//!   `safe_on_divergence` 121. `EstimateGate`: `q_est` 0–3, `w_est` 4–6, `q_ref` 7–10, `w_ref` 11–13
//!   (the controllers' references), `enable` 14 in; `q` 20–23, `w` 24–26 out. `CommandSwitch`:
//!   `torque_safe` 0–2, `torque_fine` 3–5, `m_bdot` 6–8, `torque_select` 9, `dipole_select` 10 in;
//!   `torque_cmd` 20–22, `m_cmd` 23–25 out (the plant's input names).
//! - plants of every family: `integrator` is an Integer with codes 0 RK4, 1 Euler, 2 Dormand–Prince.

pub mod adcs;
pub mod attitude;
pub mod environment;
pub mod estimation;
pub mod formation;
pub mod ports;
pub mod references;
pub mod sensors;
pub mod single_axis;

#[cfg(test)]
mod clock_tests;
