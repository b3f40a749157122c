//! Three-axis attitude controllers. Every controller embeds the common port block
//! (`crate::models::ports::AttitudeControllerPorts`: `q_*`, `w_*`, `q_ref_*`, `w_ref_*` → `torque_cmd_*`), so they
//! swap as black boxes; what several controllers share lives in `shared/` (not FMUs). The safe-mode
//! `SunSafeController` reads the gyro and the sun sensor instead (its own ports, by the sensors' names).
//!
//! A new controller: one file here, and one line in the list below.

pub mod shared;

crate::fmus! {
    pd_controller::PdController,
    lqr_controller::LqrController,
    pole_placement_controller::PolePlacementController,
    mrac_controller::MracController,
    fuzzy_pd_controller::FuzzyPdController,
    adaptive_fuzzy_controller::AdaptiveFuzzyController,
    feedback_linearizing_controller::FeedbackLinearizingController,
    sliding_mode_controller::SlidingModeController,
    type2_fuzzy_smc_controller::Type2FuzzySmcController,
    sun_safe_controller::SunSafeController,
}
