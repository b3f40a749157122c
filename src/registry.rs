//! Every FMU this crate builds, listed once: each family folder declares its FMUs with `fmus!`, and
//! this list concatenates the families. The C ABI's model lookup and the tests iterate over [`ALL`];
//! `src/cdylib` exports it with [`EXTRAS`], and the packaging tool sees it only through that catalogue.

pub use crate::model::Family;
use crate::model::{concat, total_len, Extras, ModelEntry};
use crate::models::{adcs, attitude, environment, estimation, formation, sensors, single_axis};

/// One [`Family`] a row: slug, FMU list, folder under `src/models/` (its README.md is the overview), title.
macro_rules! families {
    ($( $slug:literal, $fmus:expr, $dir:literal, $title:literal; )*) => {
        &[$( Family { slug: $slug, title: $title, overview: include_str!(concat!("models/", $dir, "/README.md")), fmus: $fmus } ),*]
    };
}

/// The families, each a folder under `src/models/` and a page `docs/models/<slug>.md` (title and overview
/// go into the catalogue the library exports).
pub const FAMILIES: &[Family] = families! {
    "attitude", attitude::FMUS, "attitude", "Three-axis attitude: plant, command, metrics and reference corrector";
    "attitude-control", attitude::control::FMUS, "attitude/control", "Three-axis attitude controllers";
    "single-axis", single_axis::FMUS, "single_axis", "Single axis with reaction-wheel lag: plant, PID and fractional-order PID";
    "formation", formation::FMUS, "formation", "Formation flying: relative orbit, command and predictive PID";
    "sensors", sensors::FMUS, "sensors", "Sensors and timing: gyro, star tracker, sun sensor, magnetometer, sample-and-hold";
    "estimation", estimation::FMUS, "estimation", "Attitude estimation, determination and detumbling: MEKF, TRIAD, QUEST, B-dot";
    "environment", environment::FMUS, "environment", "Orbital environment: orbit, geomagnetic field, sun, eclipse and atmosphere";
    "adcs", adcs::FMUS, "adcs", "ADCS modes: mode manager, estimate gate and command switch";
};

const LISTS: [&[ModelEntry]; 8] = [
    FAMILIES[0].fmus,
    FAMILIES[1].fmus,
    FAMILIES[2].fmus,
    FAMILIES[3].fmus,
    FAMILIES[4].fmus,
    FAMILIES[5].fmus,
    FAMILIES[6].fmus,
    FAMILIES[7].fmus,
];
const _: () = assert!(FAMILIES.len() == LISTS.len(), "every family goes into the registry");

const LIST: [ModelEntry; total_len(&LISTS)] = concat(&LISTS, LISTS[0][0]);

/// Every registered FMU, grouped by family.
pub const ALL: &[ModelEntry] = &LIST;

/// Number of registered FMUs.
pub const COUNT: usize = LIST.len();

/// What `src/cdylib` exports besides the models: the families and the project's bibliography.
pub const EXTRAS: Extras = Extras {
    families: FAMILIES,
    references: crate::models::references::ALL,
};

pub fn find(name: &str) -> Option<&'static ModelEntry> {
    ALL.iter().find(|e| e.info.name == name)
}
