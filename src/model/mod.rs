//! What a model is. A model declares its variables once (`declare_variables!`, one row per port or
//! parameter, vectors and quaternions as one row) and implements [`Model`]: build its internal state
//! from the parameters, compute outputs, advance a step. The FMI layer (`crate::fmi`) sees models only
//! through this module, so a model never touches C types or XML.
//!
//! The declaration vocabulary (`VarDecl`, `ModelInfo`, `Feedthrough`, `StateDecl`, bounds, …) lives in
//! `crate::catalogue` and is re-exported here; this module keeps what runs: the variable block
//! ([`Variables`]), the [`Model`] contract, the registry entry [`ModelEntry`] (which can build a model)
//! and the [`Experiment`] a master sets up. The packaging tool sees none of it, only the owned catalogue
//! a built library exports (`crate::export`).

mod contract;
mod declare;
mod entry;
pub mod feedthrough;
pub mod guid;
mod instance;
pub mod leaves;
mod param;
#[cfg(test)]
mod restore_tests;

pub use crate::catalogue::decl::{
    initial_of, Bound, Causality, ClockDecl, Feedthrough, Initial, ModelInfo, Reference, Start, StateDecl, VarDecl,
    VarKind, Variability, CLOCK_VR_BASE, DERIVATIVE_VR_BASE, RESERVED_VR_START, STATE_VR_BASE, SWITCH,
};
pub use crate::text::same_str;
pub use contract::{
    check_derived, check_finite_state, Experiment, Model, ModelResult, SlotFn, SlotMut, Value, ValueFn, Variables,
    TOLERANCE_MAX, TOLERANCE_MIN,
};
pub use declare::{concat, field_problem, no_duplicate_names, no_duplicate_vrs, total_len};
pub use entry::{clocked_outputs, scalar_list, Extras, Family, ModelEntry};
pub use instance::{DynModel, Fmu};
pub use param::ParamEnum;

/// Checks of relations between parameters that a single [`Bound`] cannot express; each returns a
/// message naming the parameters.
pub mod check {
    /// `lo <= hi` for two parameters that span a range.
    pub fn ordered(lo_name: &str, lo: f64, hi_name: &str, hi: f64) -> Result<(), String> {
        if lo <= hi {
            Ok(())
        } else {
            Err(format!(
                "parameters {lo_name} = {lo} and {hi_name} = {hi}: need {lo_name} <= {hi_name}"
            ))
        }
    }
}

/// Declares the FMU modules of a family folder and lists them for the registry, one line per FMU:
///
/// ```ignore
/// fmus! {
///     pd_controller::PdController,
///     lqr_controller::LqrController,
/// }
/// ```
/// expands to `pub mod pd_controller; pub use pd_controller::PdController; …` and
/// `pub const FMUS: &[ModelEntry]`, which `crate::registry` concatenates.
#[macro_export]
macro_rules! fmus {
    ($( $module:ident :: $Model:ident ),* $(,)?) => {
        $( pub mod $module; pub use $module::$Model; )*
        /// The FMUs of this folder, in registry order.
        pub const FMUS: &[$crate::model::ModelEntry] = &[ $( $crate::model::ModelEntry::of::<$Model>() ),* ];
    };
}
