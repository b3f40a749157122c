//! Model Exchange for `AttitudePlant`: the published states, the time events and how the invariants
//! of the attitude representation are kept when the importer's solver integrates.
//!
//! - Quaternion (kinematics 0 and 4): the solver integrates q̇ = ½ q ⊗ ω freely, which keeps |q| = 1 only
//!   up to its tolerance. After an accepted step whose |q| is off by more than [`NORM_TOLERANCE`] the
//!   plant asks for an event (`fmi2CompletedIntegratorStep` → enterEventMode) and renormalises q in
//!   the event update (valuesOfContinuousStatesChanged); every time event renormalises too. The
//!   threshold is the larger of [`NORM_TOLERANCE`] and the relative tolerance the importer gave in
//!   fmi2SetupExperiment (a solver at rtol 1e-4 drifts about that much per step: a 1e-9 threshold then
//!   asked for an event after every step, and a master that restarts its solver at each event, such as
//!   CVODE in OMSimulator, no longer advanced). The projection is idempotent: within [`ROUNDOFF`] of the
//!   invariant it changes nothing and reports no change, so a master that repeats the event iteration
//!   while values change (or outputs move) settles after one pass.
//! - DCM (kinematics 1) with `dcm_orthonormalize = 1`: the same with ‖AᵀA − I‖ and the nearest
//!   rotation matrix. The sign-continuous output quaternion follows every accepted step.
//! - Euler angles (kinematics 2): the right-hand side refuses the singularity roll = ±90°.


use super::environment::{noise_on, PERMANENT};
use super::variables::AttitudePlantVars;
use crate::math::random::hold_index;
use crate::model::StateDecl;

/// Largest drift of |q| (or of ‖AᵀA − I‖) accepted between events (when the importer gives no looser
/// tolerance).
pub const NORM_TOLERANCE: f64 = 1e-9;

/// Drift that is only the round-off of a normalisation: the event update leaves it alone.
pub use crate::math::attitude::NORM_ROUNDOFF as ROUNDOFF;

/// The drift that asks for a projection event: max(NORM_TOLERANCE, the importer's relative tolerance).
pub fn projection_threshold(exp: &crate::model::Experiment) -> f64 {
    crate::math::attitude::projection_threshold(exp.tolerance, NORM_TOLERANCE)
}

const fn s(name: &'static str, unit: &'static str, description: &'static str, on: &'static [&'static str]) -> StateDecl {
    StateDecl::new(name, unit, description).depends_on(on)
}

// What each derivative reads, over every parameter setting (the union of the kinematics modes):
// q̇ = ½ q ⊗ ω (entry i not on q_i), Ȧ = −[ω×] A (entry (i, j) on the other two entries of column j
// and the two rates other than ω_i), the Euler-angle rates on roll, yaw and ω. The wheel momentum and
// the wheel lag read the command of their axis, their own lag state, and through the magnetorquers
// (m = k h_w × B / |B|², B = A B_R, or B = A b_eci with the environment inputs) every wheel momentum,
// every attitude entry and the field input; with mtq_mode 2 the dumping share of the summed dipole fed
// forward to the wheels, (m − clamp(m_cmd)) × B, reads the dipole commands (axis i the other two; every
// one through the misaligned wheels' momenta). The body rates read
// everything (full inertia, gyroscopic terms, gravity gradient, actuators): no list.
const ATT_ALL: [&str; 9] = ["state_att_1", "state_att_2", "state_att_3", "state_att_4", "state_att_5", "state_att_6", "state_att_7", "state_att_8", "state_att_9"];
const WHEEL_X: [&str; 19] = concat_names(&ATT_ALL, &["state_h_wheel_x", "state_h_wheel_y", "state_h_wheel_z", "state_wheel_torque_x", "torque_cmd_x", "b_eci_x", "b_eci_y", "b_eci_z", "m_cmd_y", "m_cmd_z"]);
const WHEEL_Y: [&str; 19] = concat_names(&ATT_ALL, &["state_h_wheel_x", "state_h_wheel_y", "state_h_wheel_z", "state_wheel_torque_y", "torque_cmd_y", "b_eci_x", "b_eci_y", "b_eci_z", "m_cmd_x", "m_cmd_z"]);
const WHEEL_Z: [&str; 19] = concat_names(&ATT_ALL, &["state_h_wheel_x", "state_h_wheel_y", "state_h_wheel_z", "state_wheel_torque_z", "torque_cmd_z", "b_eci_x", "b_eci_y", "b_eci_z", "m_cmd_x", "m_cmd_y"]);

// the wheel momenta: ḣ_w = −M τ_rw with M = R(δ) diag(k) (actuator misalignment and scale factor) couples
// every wheel axis into every body axis
const H_WHEEL: [&str; 24] = concat_names(&ATT_ALL, &["state_h_wheel_x", "state_h_wheel_y", "state_h_wheel_z", "state_wheel_torque_x",
    "state_wheel_torque_y", "state_wheel_torque_z", "torque_cmd_x", "torque_cmd_y", "torque_cmd_z", "b_eci_x", "b_eci_y", "b_eci_z",
    "m_cmd_x", "m_cmd_y", "m_cmd_z"]);

const fn concat_names<const N: usize>(a: &[&'static str], b: &[&'static str]) -> [&'static str; N] {
    crate::model::concat(&[a, b], "")
}

/// The published continuous states, in the order of the internal state vector.
pub const STATES: [StateDecl; super::kinematics::N] = [
    s("state_att_1", "", "Continuous state: attitude entry 1 (q_w for kinematics 0, 4; A column-major for 1; roll phi for 2, 3)", &["state_att_2", "state_att_3", "state_att_4", "state_w_x", "state_w_y", "state_w_z"]),
    s("state_att_2", "", "Continuous state: attitude entry 2 (q_x; A; pitch theta)", &["state_att_1", "state_att_3", "state_att_4", "state_w_x", "state_w_y", "state_w_z"]),
    s("state_att_3", "", "Continuous state: attitude entry 3 (q_y; A; yaw psi)", &["state_att_1", "state_att_2", "state_att_3", "state_att_4", "state_w_x", "state_w_y", "state_w_z"]),
    s("state_att_4", "", "Continuous state: attitude entry 4 (q_z; A; unused)", &["state_att_1", "state_att_2", "state_att_3", "state_att_5", "state_att_6", "state_w_x", "state_w_y", "state_w_z"]),
    s("state_att_5", "", "Continuous state: attitude entry 5 (DCM only)", &["state_att_4", "state_att_6", "state_w_x", "state_w_z"]),
    s("state_att_6", "", "Continuous state: attitude entry 6 (DCM only)", &["state_att_4", "state_att_5", "state_w_x", "state_w_y"]),
    s("state_att_7", "", "Continuous state: attitude entry 7 (DCM only)", &["state_att_8", "state_att_9", "state_w_y", "state_w_z"]),
    s("state_att_8", "", "Continuous state: attitude entry 8 (DCM only)", &["state_att_7", "state_att_9", "state_w_x", "state_w_z"]),
    s("state_att_9", "", "Continuous state: attitude entry 9 (DCM only)", &["state_att_7", "state_att_8", "state_w_x", "state_w_y"]),
    StateDecl::new("state_w_x", "rad/s", "Continuous state: body rate x (angle rate for kinematics 3)"),
    StateDecl::new("state_w_y", "rad/s", "Continuous state: body rate y (angle rate for kinematics 3)"),
    StateDecl::new("state_w_z", "rad/s", "Continuous state: body rate z (angle rate for kinematics 3)"),
    s("state_h_wheel_x", "N.m.s", "Continuous state: wheel momentum x (actuator mode 1)", &H_WHEEL),
    s("state_h_wheel_y", "N.m.s", "Continuous state: wheel momentum y (actuator mode 1)", &H_WHEEL),
    s("state_h_wheel_z", "N.m.s", "Continuous state: wheel momentum z (actuator mode 1)", &H_WHEEL),
    s("state_wheel_torque_x", "N.m", "Continuous state: lagged wheel torque x (actuator mode 1, wheel lag > 0)", &WHEEL_X),
    s("state_wheel_torque_y", "N.m", "Continuous state: lagged wheel torque y (actuator mode 1, wheel lag > 0)", &WHEEL_Y),
    s("state_wheel_torque_z", "N.m", "Continuous state: lagged wheel torque z (actuator mode 1, wheel lag > 0)", &WHEEL_Z),
];

/// The first time event after t: the fault onset, the fault end (unless permanent) or the next
/// noise-hold boundary.
pub fn next_time_event(v: &AttitudePlantVars, t: f64) -> Option<f64> {
    let fault = Some(v.fault_time).filter(|tf| *tf > t);
    let clear = Some(v.fault_clear_time).filter(|tc| *tc > t && *tc < PERMANENT);
    let noise = noise_on(v)
        .then(|| hold_index(t, v.dist_noise_hold))
        .flatten()
        .map(|k| (k + 1) as f64 * v.dist_noise_hold) // |k| <= 2^53: no overflow
        .filter(|tn| *tn > t);
    [fault, clear, noise].into_iter().flatten().reduce(f64::min)
}

