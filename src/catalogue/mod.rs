//! The catalogue: what a model library declares, and everything the packaging tool needs to turn it
//! into FMUs. Two halves, one vocabulary:
//! - [`decl`] (re-exported here and by `crate::model`): the static declarations models are written in —
//!   variables ([`VarDecl`] with [`Causality`], [`Variability`], [`VarKind`], [`Start`], [`Bound`]),
//!   the header [`ModelInfo`] with its [`Feedthrough`], the Model Exchange states ([`StateDecl`]) and the
//!   value references the layer reserves, and the publications a library cites ([`Reference`]);
//! - [`library`]: the owned [`Catalogue`] a built library exports (`spacecraft_fmus_catalogue`, written by
//!   `export_fmus!`): every model's declarations and GUID, the exporting package, the FMI layer's log
//!   categories and reserved value references ([`LayerInfo`]), the families with their overviews, and
//!   the bibliography. The packaging tool (`src/package`) reads this and nothing else: it never links
//!   the registry or the FMI layer.
//!
//! [`fingerprint`] computes a model's GUID from either half.

pub mod decl;
pub mod fingerprint;
pub mod library;

pub use decl::*;
pub use fingerprint::guid_of;
pub use library::*;
