//! Every FMU this crate builds, listed once. Packaging, the GUID table, the C ABI's model lookup and
//! the tests all iterate over this list.

use std::sync::OnceLock;

use crate::model::ModelEntry;
use crate::models::{
    attitude_command::AttitudeCommand, attitude_metrics::AttitudeMetrics, attitude_plant::AttitudePlant, pd_controller::PdController,
    predictive_pid_controller::PredictivePidController, relative_orbit_plant::RelativeOrbitPlant,
    relative_position_command::RelativePositionCommand, single_axis_plant::SingleAxisPlant,
};

pub fn all() -> &'static [ModelEntry] {
    static ALL: OnceLock<Vec<ModelEntry>> = OnceLock::new();
    ALL.get_or_init(|| {
        vec![
            ModelEntry::of::<AttitudePlant>(),
            ModelEntry::of::<AttitudeCommand>(),
            ModelEntry::of::<PdController>(),
            ModelEntry::of::<AttitudeMetrics>(),
            ModelEntry::of::<SingleAxisPlant>(),
            ModelEntry::of::<RelativeOrbitPlant>(),
            ModelEntry::of::<RelativePositionCommand>(),
            ModelEntry::of::<PredictivePidController>(),
        ]
    })
}

pub fn find(name: &str) -> Option<&'static ModelEntry> {
    all().iter().find(|e| e.info.name == name)
}
