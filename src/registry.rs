//! Every FMU this crate builds, listed once: each family folder declares its FMUs with `fmus!`, and
//! this list concatenates the families. Packaging, the GUID table, the C ABI's model lookup and the
//! tests all iterate over [`ALL`].

use crate::model::{concat, total_len, ModelEntry};
use crate::models::{attitude, formation, single_axis};

const FAMILIES: &[&[ModelEntry]] = &[
    // three-axis attitude: plant, reference, metrics (papers 000, 003, 004) …
    attitude::FMUS,
    // … and its controllers
    attitude::control::FMUS,
    // single axis (paper 002)
    single_axis::FMUS,
    // formation flying, relative orbit (paper 001)
    formation::FMUS,
];

const LIST: [ModelEntry; total_len(FAMILIES)] = concat(FAMILIES, FAMILIES[0][0]);

/// Every registered FMU, grouped by family.
pub const ALL: &[ModelEntry] = &LIST;

/// Number of registered FMUs.
pub const COUNT: usize = LIST.len();

pub fn find(name: &str) -> Option<&'static ModelEntry> {
    ALL.iter().find(|e| e.info.name == name)
}
