//! The ADCS mode layer (issue 44): `ModeManager` (the mode state machine of [`modes`], sampled at its own
//! rate), `EstimateGate` (the pointing controller sees the estimate only in its mode) and `CommandSwitch`
//! (the actuator commands of the mode). Value references: `ModeManager` inputs 0–14 (`w_meas` 0–2,
//! `sun_valid` 3, `sun_meas` 4–6, `p_att` 7–9, `nis` 10, `nis_dim` 11, `actuator_fault` 12, `recover` 13,
//! `safe_request` 14), outputs 20–26 (`mode` 20, `time_in_mode` 21, `mode_changes` 22, `torque_select` 23,
//! `dipole_select` 24, `estimator_init` 25, `controller_enable` 26), diagnostics 30–34, parameters 100–117
//! and Integer options 120–121; `EstimateGate` inputs `q_est` 0–3, `w_est` 4–6, `q_ref` 7–10, `w_ref`
//! 11–13, `enable` 14, outputs `q` 20–23, `w` 24–26; `CommandSwitch` inputs `torque_safe` 0–2,
//! `torque_fine` 3–5, `m_bdot` 6–8, `torque_select` 9, `dipole_select` 10, outputs `torque_cmd` 20–22,
//! `m_cmd` 23–25.

pub mod mode_codes;
mod mode_log;
pub mod modes;

crate::fmus! {
    mode_manager::ModeManager,
    estimate_gate::EstimateGate,
    command_switch::CommandSwitch,
}
