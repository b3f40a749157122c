//! Every FMU this crate builds, listed once. Packaging, the GUID table, the C ABI's model lookup and
//! the tests all iterate over this list.

use std::sync::OnceLock;

use crate::model::ModelEntry;
use crate::models::{
    adaptive_fuzzy_controller::AdaptiveFuzzyController, attitude_command::AttitudeCommand, attitude_metrics::AttitudeMetrics,
    attitude_plant::AttitudePlant, fuzzy_pd_controller::FuzzyPdController, lqr_controller::LqrController, mrac_controller::MracController,
    pd_controller::PdController, pole_placement_controller::PolePlacementController, predictive_pid_controller::PredictivePidController,
    relative_orbit_plant::RelativeOrbitPlant, relative_position_command::RelativePositionCommand, single_axis_plant::SingleAxisPlant,
    fopid_controller::FopidController, pid_controller::PidController,
};

pub fn all() -> &'static [ModelEntry] {
    static ALL: OnceLock<Vec<ModelEntry>> = OnceLock::new();
    ALL.get_or_init(|| {
        vec![
            // three-axis attitude: plant, reference, metrics, controllers (papers 000, 003, 004)
            ModelEntry::of::<AttitudePlant>(),
            ModelEntry::of::<AttitudeCommand>(),
            ModelEntry::of::<AttitudeMetrics>(),
            ModelEntry::of::<PdController>(),
            ModelEntry::of::<LqrController>(),
            ModelEntry::of::<PolePlacementController>(),
            ModelEntry::of::<MracController>(),
            ModelEntry::of::<FuzzyPdController>(),
            ModelEntry::of::<AdaptiveFuzzyController>(),
            // single axis (paper 002)
            ModelEntry::of::<SingleAxisPlant>(),
            ModelEntry::of::<PidController>(),
            ModelEntry::of::<FopidController>(),
            // relative orbit (paper 001)
            ModelEntry::of::<RelativeOrbitPlant>(),
            ModelEntry::of::<RelativePositionCommand>(),
            ModelEntry::of::<PredictivePidController>(),
        ]
    })
}

pub fn find(name: &str) -> Option<&'static ModelEntry> {
    all().iter().find(|e| e.info.name == name)
}
