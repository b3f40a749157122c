//! Three-axis attitude family (papers 000, 003, 004): the plant (`plant/`), the command and metrics
//! FMUs, and the controllers (`control/`, which has its own list). Value references follow the
//! family table in `crate::models`.

pub mod control;

crate::fmus! {
    plant::AttitudePlant,
    command::AttitudeCommand,
    metrics::AttitudeMetrics,
}
