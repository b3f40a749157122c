//! The clock bookkeeping of an instance (what `clocks.rs` keeps between calls and an FMU state carries):
//! plain data, so that the instance and the FMU states can hold it without the partition code.

use serde::{Deserialize, Serialize};

/// How an instance runs its clocks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClockMode {
    /// Not clocked (or a clocked model stepped as a sampled unit without clocks).
    #[default]
    Off,
    /// The master activates due clocks at events; the step only advances time.
    Stepped,
    /// The master activates one partition at a time (the Activation state).
    Scheduled,
}

/// Clock bookkeeping, part of an FMU state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Clocks {
    pub mode: ClockMode,
    /// Activated at the current event and not yet run.
    pub active: Vec<bool>,
    /// Index k of each clock's next tick.
    pub next: Vec<i64>,
    /// Whether the interval of each clock was reported to the master already (its qualifier).
    pub reported: Vec<bool>,
    /// The held clocked outputs: (declaration index, value), clock by clock.
    pub held: Vec<(usize, f64)>,
    /// The instant whose outputs were computed before its partitions ran, and those outputs.
    pub snap: Option<(f64, Vec<(usize, f64)>)>,
}
