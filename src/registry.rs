//! Every FMU this crate builds, listed once: each family folder declares its FMUs with `fmus!`, and
//! this list concatenates the families. The C ABI's model lookup and the tests iterate over [`ALL`];
//! `src/cdylib` exports it with [`EXTRAS`], and the packaging tool sees it only through that catalogue.

pub use crate::model::Family;
use crate::model::{concat, total_len, Extras, ModelEntry};
use crate::models::{adcs, attitude, environment, estimation, formation, sensors, single_axis};

/// The families, each a folder under `src/models/` and a page `docs/models/<slug>.md` (title and overview
/// go into the catalogue the library exports).
pub const FAMILIES: &[Family] = &[
    Family {
        slug: "attitude",
        title: "Three-axis attitude: plant, command, metrics and reference corrector",
        overview: include_str!("models/attitude/README.md"),
        fmus: attitude::FMUS,
    },
    Family {
        slug: "attitude-control",
        title: "Three-axis attitude controllers",
        overview: include_str!("models/attitude/control/README.md"),
        fmus: attitude::control::FMUS,
    },
    Family {
        slug: "single-axis",
        title: "Single axis with reaction-wheel lag: plant, PID and fractional-order PID",
        overview: include_str!("models/single_axis/README.md"),
        fmus: single_axis::FMUS,
    },
    Family {
        slug: "formation",
        title: "Formation flying: relative orbit, command and predictive PID",
        overview: include_str!("models/formation/README.md"),
        fmus: formation::FMUS,
    },
    Family {
        slug: "sensors",
        title: "Sensors and timing: gyro, star tracker, sun sensor, magnetometer, sample-and-hold",
        overview: include_str!("models/sensors/README.md"),
        fmus: sensors::FMUS,
    },
    Family {
        slug: "estimation",
        title: "Attitude estimation, determination and detumbling: MEKF, TRIAD, QUEST, B-dot",
        overview: include_str!("models/estimation/README.md"),
        fmus: estimation::FMUS,
    },
    Family {
        slug: "environment",
        title: "Orbital environment: orbit, geomagnetic field, sun, eclipse and atmosphere",
        overview: include_str!("models/environment/README.md"),
        fmus: environment::FMUS,
    },
    Family {
        slug: "adcs",
        title: "ADCS modes: mode manager, estimate gate and command switch",
        overview: include_str!("models/adcs/README.md"),
        fmus: adcs::FMUS,
    },
];

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
