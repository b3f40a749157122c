//! Every FMU this crate builds, listed once. Packaging, the GUID table, the C ABI's model lookup and
//! the tests all iterate over this list.

use std::sync::OnceLock;

use crate::model::ModelEntry;
use crate::models::{attitude_command::AttitudeCommand, attitude_metrics::AttitudeMetrics, attitude_plant::AttitudePlant, pd_controller::PdController};
use crate::models::{
    adaptive_fuzzy_controller::AdaptiveFuzzyController, fuzzy_pd_controller::FuzzyPdController, lqr_controller::LqrController, mrac_controller::MracController,
    pole_placement_controller::PolePlacementController,
};

pub fn all() -> &'static [ModelEntry] {
    static ALL: OnceLock<Vec<ModelEntry>> = OnceLock::new();
    ALL.get_or_init(|| {
        vec![
            ModelEntry::of::<AttitudePlant>(),
            ModelEntry::of::<AttitudeCommand>(),
            ModelEntry::of::<PdController>(),
            ModelEntry::of::<AttitudeMetrics>(),
            ModelEntry::of::<LqrController>(),
            ModelEntry::of::<PolePlacementController>(),
            ModelEntry::of::<MracController>(),
            ModelEntry::of::<FuzzyPdController>(),
            ModelEntry::of::<AdaptiveFuzzyController>(),
        ]
    })
}

pub fn find(name: &str) -> Option<&'static ModelEntry> {
    all().iter().find(|e| e.info.name == name)
}
