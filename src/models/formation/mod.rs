//! Formation flying (paper 001): the relative-orbit plant, the relative-position command and the
//! predictive PID controller. Ports connect by name: `pos_*`, `vel_*` (plant → controller), `pos_ref_*`,
//! `vel_ref_*`, `acc_ref_*` (command → controller), `force_*` (controller → plant).

crate::fmus! {
    plant::RelativeOrbitPlant,
    command::RelativePositionCommand,
    predictive_pid_controller::PredictivePidController,
}
