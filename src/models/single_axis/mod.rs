//! Single-axis family (paper 002): the plant with reaction-wheel lag and saturation, and the PID and
//! fractional PI^λD^μ controllers. Controllers connect `theta` (plant → controller) and `u`
//! (controller → plant); `theta_ref` is set by the master.
//!
//! Value references: plant `u` 0, `torque_dist` 1, outputs 10–14; controllers `theta` 0, `theta_ref` 1,
//! `u` 10, diagnostic `error` 30; gains `kp` 100, `ki` 101, `kd` 102, orders `lambda` 103, `mu` 104,
//! sample time `step` 105, `gl_memory` 120, `history_before_start` 121.

pub mod shared;

crate::fmus! {
    plant::SingleAxisPlant,
    pid_controller::PidController,
    fopid_controller::FopidController,
}
