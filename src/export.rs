//! The export API: everything a crate needs to turn its own models into FMUs through this project's
//! FMI layer, in one place. The project's own models use exactly this path (`src/cdylib` calls
//! [`export_fmus!`](crate::export_fmus) with the registry), so every build of the project's FMUs exercises it.
//!
//! A model crate is a `cdylib` that depends on `spacecraft_fmus`, declares each model's variables with
//! [`declare_variables!`](crate::declare_variables), implements [`Model`], and exports the FMI 2.0 and
//! FMI 3.0 functions for its models (Co-Simulation, and Model Exchange for a model that declares its
//! continuous states) with one line:
//!
//! ```
//! use spacecraft_fmus::export::*;
//!
//! declare_variables! {
//!     /// Variables of a saturating gain.
//!     pub struct SatGainVars {
//!         // vr => field: kind = start, causality, unit, description[, bound]
//!         0 => u: Real = 0.0, Input, "N.m", "Torque demand";
//!         1 => y: Real = 0.0, Output, "N.m", "Torque command";
//!         100 => gain: Real = 1.0, Parameter, "", "Gain", Positive;
//!         101 => limit: Real = 1e30, Parameter, "N.m", "Largest |y| (1e30 = no limit)", Limit;
//!     }
//! }
//!
//! /// A static law keeps no state: an empty struct.
//! #[derive(Clone, Serialize, Deserialize)]
//! pub struct SatGain;
//!
//! impl Model for SatGain {
//!     type Vars = SatGainVars;
//!     const INFO: ModelInfo = ModelInfo {
//!         name: "SatGain",
//!         description: "y = clamp(gain u, -limit, limit)",
//!         feedthrough: Feedthrough::AllInputs,
//!         ..ModelInfo::DEFAULT
//!     };
//!     const EVOLVING: &'static [&'static str] = &[];
//!     fn initialize(_v: &mut SatGainVars, _exp: &Experiment) -> Result<Self, String> {
//!         Ok(SatGain)
//!     }
//!     fn outputs(&self, v: &mut SatGainVars, _t: f64) -> ModelResult {
//!         v.y = (v.gain * v.u).clamp(-v.limit, v.limit);
//!         Ok(())
//!     }
//! }
//!
//! // the FMI 2.0 and FMI 3.0 entry points of this shared library, for these models
//! export_fmus!(SatGain);
//!
//! // a model is tested as plain Rust, without the C layer:
//! let mut m = Fmu::<SatGain>::default();
//! (m.v.gain, m.v.limit, m.v.u) = (2.0, 3.0, 5.0);
//! m.initialize(&Experiment::default()).unwrap();
//! m.outputs(0.0).unwrap();
//! assert_eq!(m.v.y, 3.0);
//! // a bound is checked before the model initializes, with a message naming the parameter
//! m.v.gain = -1.0;
//! assert!(m.initialize(&Experiment::default()).unwrap_err().contains("gain = -1 must be > 0"));
//! ```
//!
//! The packaging tool (`src/package`, binary `fmu-package`) builds such a crate, reads the
//! declarations back from the built library (the [`Catalogue`] of `crate::catalogue`, exported by
//! `export_fmus!` as the C symbol `spacecraft_fmus_catalogue`), writes `modelDescription.xml` and
//! `documentation/index.html` from it alone and zips one `.fmu` per model. The runtime renders no XML
//! and links no packaging code.
//!
//! Texts cite publications by a bracketed key (`"... after [Smith-2020] Eq. 4"`); the library declares
//! them as a `&[Reference]` passed to `export_fmus!` (`references: MY_PAPERS; MyModel`), and the
//! packaging tool expands each cited key in the model's documentation and refuses an undeclared one.

pub use crate::catalogue::{
    read_catalogue, BoundDescription, Catalogue, ClockDescription, FamilyDescription, FeedthroughDescription,
    LayerInfo, ModelDescription, PackageInfo, Reference, ReferenceDescription, StateDescription, TerminalDescription,
    VariableDescription, CATALOGUE_FORMAT, RUNTIME_VERSION,
};
pub use crate::math;
pub use crate::model::{
    check, check_derived, check_finite_state, Bound, Causality, ClockDecl, Experiment, Extras, Family, Feedthrough,
    Fmu, Model, ModelEntry, ModelInfo, ModelResult, ParamEnum, Start, StateDecl, VarDecl, VarKind, Variability,
    Variables, CLOCK_VR_BASE, DERIVATIVE_VR_BASE, RESERVED_VR_START, STATE_VR_BASE, SWITCH,
};
pub use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};
pub use crate::{declare_variables, export_fmus, param_enum};
pub use nalgebra::{Quaternion, Vector3};
pub use serde::{Deserialize, Serialize};

/// The description of a model entry, as the library exports it.
pub fn describe(e: &ModelEntry) -> ModelDescription {
    let i = e.info;
    ModelDescription {
        name: i.name.into(),
        description: i.description.into(),
        source: i.source.into(),
        equations_html: i.equations_html.into(),
        feedthrough: match i.feedthrough {
            Feedthrough::None => FeedthroughDescription::None,
            Feedthrough::AllInputs => FeedthroughDescription::AllInputs,
            // FMI scalar names (a vector stem expanded)
            Feedthrough::Some(_) => FeedthroughDescription::Some(
                crate::model::scalar_list(e)
                    .unwrap_or_default()
                    .into_iter()
                    .map(|(o, ins)| (o.to_string(), ins.iter().map(|s| s.to_string()).collect()))
                    .collect(),
            ),
        },
        default_stop_time: i.default_stop_time,
        default_step: i.default_step,
        variable_step: i.variable_step,
        guid: crate::model::guid::guid(e).as_str().into(),
        variables: e.decls.iter().map(describe_variable).collect(),
        states: e.states.map(|l| {
            l.iter()
                .map(|x| StateDescription {
                    name: x.name.into(),
                    unit: x.unit.into(),
                    description: x.description.into(),
                    depends: x.depends.map(|d| d.iter().map(|n| n.to_string()).collect()),
                    starts_from: x.starts_from.iter().map(|n| n.to_string()).collect(),
                })
                .collect()
        }),
        clocks: e
            .clocks
            .iter()
            .map(|c| ClockDescription {
                name: c.name.into(),
                description: c.description.into(),
                interval: c.interval.into(),
                shift: c.shift.into(),
                steps: c.steps,
                outputs: crate::model::clocked_outputs(e, c),
            })
            .collect(),
        terminals: crate::models::ports::terminals(e.decls),
    }
}

fn describe_variable(d: &VarDecl) -> VariableDescription {
    VariableDescription {
        vr: d.vr,
        name: d.name.into(),
        kind: d.kind,
        causality: d.causality,
        variability: d.variability,
        unit: d.unit.into(),
        description: d.description.into(),
        start: d.start,
        bound: match d.bound {
            Bound::Any => BoundDescription::Any,
            Bound::Positive => BoundDescription::Positive,
            Bound::NonNegative => BoundDescription::NonNegative,
            Bound::Limit => BoundDescription::Limit,
            Bound::Range(a, b) => BoundDescription::Range(a, b),
            Bound::Choice(c) => BoundDescription::Choice(c.to_vec()),
        },
    }
}

/// What this crate's FMI layer reserves and offers (the same in every library built on it).
pub fn layer_info() -> LayerInfo {
    LayerInfo {
        log_categories: crate::fmi::LOG_CATEGORIES
            .iter()
            .map(|(n, d)| (n.to_string(), d.to_string()))
            .collect(),
        time_vr: crate::fmi::fmi3::TIME_VR,
        state_vr_base: STATE_VR_BASE,
        derivative_vr_base: DERIVATIVE_VR_BASE,
        reserved_vr_start: RESERVED_VR_START,
        clock_vr_base: CLOCK_VR_BASE,
    }
}

/// The catalogue of a list of models exported by `package`, with its families and bibliography.
pub fn catalogue(models: &[ModelEntry], package: PackageInfo, extras: Extras) -> Catalogue {
    Catalogue {
        format: CATALOGUE_FORMAT,
        runtime_version: RUNTIME_VERSION.into(),
        package,
        layer: layer_info(),
        families: extras
            .families
            .iter()
            .map(|f| FamilyDescription {
                slug: f.slug.into(),
                title: f.title.into(),
                overview: f.overview.into(),
                models: f.fmus.iter().map(|e| e.info.name.into()).collect(),
            })
            .collect(),
        references: extras.references.iter().map(ReferenceDescription::of).collect(),
        models: models.iter().map(describe).collect(),
    }
}

/// The catalogue as bytes (`crate::catalogue::catalogue_to_bytes`), what `spacecraft_fmus_catalogue` returns.
pub fn catalogue_bytes(models: &[ModelEntry], package: PackageInfo, extras: Extras) -> Vec<u8> {
    crate::catalogue::catalogue_to_bytes(&catalogue(models, package, extras))
}

/// The project's own catalogue (every registered model, its families and bibliography), as
/// `src/cdylib` exports it: for tests and tools that render the project's pages without loading
/// the library.
pub fn project_catalogue() -> Catalogue {
    catalogue(
        crate::registry::ALL,
        PackageInfo {
            name: "spacecraft_fmus_cdylib".into(),
            version: "0.1.0".into(),
            authors: "spacecraft_fmus contributors".into(),
            license: "BSD-2-Clause".into(),
        },
        crate::registry::EXTRAS,
    )
}

/// Generates the FMI 2.0 and FMI 3.0 entry points (Co-Simulation and Model Exchange) of a shared library for
/// the given models, plus `spacecraft_fmus_catalogue` (the declarations, for the packaging tool). Use it once,
/// at the root of a `cdylib` crate:
///
/// ```ignore
/// spacecraft_fmus::export_fmus!(MyController, MyPlant);               // model types
/// spacecraft_fmus::export_fmus!(references: MY_PAPERS; MyController);   // ... citing a &[Reference]
/// spacecraft_fmus::export_fmus!(list: MODELS);                          // a const &[ModelEntry]
/// spacecraft_fmus::export_fmus!(list: MODELS, references: MY_PAPERS);
/// spacecraft_fmus::export_fmus!(list: MODELS, families: FAMILIES, references: MY_PAPERS);
/// ```
///
/// One library may hold several models: each FMU carries the same binary under its own name
/// (`binaries/<platform>/<Model>.<ext>`), and `fmi2Instantiate` picks the model by that file name and
/// checks the GUID (`fmi3InstantiateCoSimulation`: the instantiationToken, the same GUID). Every function goes through the layer in `spacecraft_fmus::fmi` (`fmi2`, `fmi3`: state machine,
/// status and logging, panics caught, validated FMU states).
#[macro_export]
macro_rules! export_fmus {
    (list: $list:expr, families: $families:expr, references: $references:expr $(,)?) => {
        const _: () = {
            static MODELS: &[$crate::model::ModelEntry] = $list;
            static EXTRAS: $crate::export::Extras =
                $crate::export::Extras { families: $families, references: $references };

            /// The declarations of this library's models, for the packaging tool: `*size` bytes at the
            /// returned address, valid while the library is loaded.
            #[no_mangle]
            pub extern "C" fn spacecraft_fmus_catalogue(size: *mut usize) -> *const u8 {
                static BYTES: ::std::sync::OnceLock<Vec<u8>> = ::std::sync::OnceLock::new();
                match ::std::panic::catch_unwind(|| BYTES.get_or_init(|| {
                    $crate::export::catalogue_bytes(MODELS, $crate::export::PackageInfo {
                        name: env!("CARGO_PKG_NAME").into(),
                        version: env!("CARGO_PKG_VERSION").into(),
                        authors: env!("CARGO_PKG_AUTHORS").into(),
                        license: env!("CARGO_PKG_LICENSE").into(),
                    }, EXTRAS)
                })) {
                    Ok(bytes) => {
                        if !size.is_null() {
                            // SAFETY: non-null pointer from the caller.
                            unsafe { *size = bytes.len() };
                        }
                        bytes.as_ptr()
                    }
                    Err(_) => ::std::ptr::null(),
                }
            }

            $crate::__export_fmi2!(MODELS);
            $crate::__export_fmi3!(MODELS);
        };
    };
    (list: $list:expr, references: $references:expr $(,)?) => {
        $crate::export_fmus!(list: $list, families: &[], references: $references);
    };
    (list: $list:expr $(,)?) => {
        $crate::export_fmus!(list: $list, families: &[], references: &[]);
    };
    (references: $references:expr; $($Model:ty),+ $(,)?) => {
        $crate::export_fmus!(list: &[$($crate::model::ModelEntry::of::<$Model>()),+], families: &[], references: $references);
    };
    ($($Model:ty),+ $(,)?) => {
        $crate::export_fmus!(list: &[$($crate::model::ModelEntry::of::<$Model>()),+], families: &[], references: &[]);
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_catalogue_round_trips_and_carries_what_the_packager_needs() {
        let pkg = PackageInfo {
            name: "p".into(),
            version: "1.2.3".into(),
            authors: "A:B".into(),
            license: "MIT".into(),
        };
        let bytes = catalogue_bytes(crate::registry::ALL, pkg.clone(), crate::registry::EXTRAS);
        let cat = read_catalogue(&bytes).unwrap();
        assert_eq!(cat.models.len(), crate::registry::COUNT);
        assert_eq!(cat.runtime_version, RUNTIME_VERSION);
        assert_eq!(cat.package, pkg);
        assert_eq!(cat.layer.time_vr, crate::fmi::fmi3::TIME_VR);
        assert_eq!(cat.layer.log_categories.len(), crate::fmi::LOG_CATEGORIES.len());
        assert_eq!(cat.families.len(), crate::registry::FAMILIES.len());
        assert_eq!(cat.references.len(), crate::models::references::ALL.len());
        for (m, e) in cat.models.iter().zip(crate::registry::ALL) {
            // the packaging tool's GUID (from the owned copy) is the runtime's (from the declarations)
            assert_eq!(crate::catalogue::guid_of(m), m.guid, "{}", e.info.name);
            assert_eq!(m.guid, crate::model::guid::guid(e).as_str());
            assert_eq!(m.variables.len(), e.decls.len());
            for (a, b) in m.variables.iter().zip(e.decls) {
                assert_eq!(
                    (a.vr, a.name.as_str(), a.unit.as_str(), a.start),
                    (b.vr, b.name, b.unit, b.start)
                );
                assert_eq!(a.bound.min_max(), b.bound.min_max());
                assert_eq!((a.initial(), a.has_start()), (b.initial(), b.has_start()));
            }
            assert_eq!(m.texts(), e.texts());
        }
        // one changed character gives another GUID
        let mut other = cat.models[0].clone();
        other.variables[0].description.push('.');
        assert_ne!(crate::catalogue::guid_of(&other), cat.models[0].guid);
    }
}
