//! The export API: everything a crate needs to turn its own models into FMUs through this project's
//! FMI layer, in one place. The project's own models use exactly this path (`src/cdylib` calls
//! [`export_fmus!`](crate::export_fmus) with the registry), so every build of the 24 FMUs exercises it.
//!
//! A model crate is a `cdylib` that depends on `spacecraft_fmus`, declares each model's variables with
//! [`declare_variables!`](crate::declare_variables), implements [`Model`], and exports the FMI 2.0
//! Co-Simulation functions for its models with one line:
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
//! // the FMI 2.0 entry points of this shared library, for these models
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
//! declarations back from the built library ([`catalogue`], exported by `export_fmus!` as the C symbol
//! `spacecraft_fmus_catalogue`), writes `modelDescription.xml` and `documentation/index.html` from
//! them and zips one `.fmu` per model. The runtime renders no XML and links no packaging code.

pub use crate::math;
pub use crate::model::{
    check, check_derived, check_finite_state, Bound, Causality, Experiment, Feedthrough, Fmu, Model, ModelEntry,
    ModelInfo, ModelResult, ParamEnum, Start, StateDecl, VarDecl, VarKind, Variability, Variables, DERIVATIVE_VR_BASE,
    RESERVED_VR_START, STATE_VR_BASE, SWITCH,
};
pub use crate::models::attitude::control::shared::{check_unit_quaternions, AttitudeControllerPorts};
pub use crate::{declare_variables, export_fmus, param_enum};
pub use nalgebra::{Quaternion, Vector3};
pub use serde::{Deserialize, Serialize};

/// Version of the catalogue's byte layout; the packaging tool refuses any other.
pub const CATALOGUE_FORMAT: u32 = 3;

/// Version of this crate, recorded in every catalogue (and part of every GUID).
pub const RUNTIME_VERSION: &str = env!("CARGO_PKG_VERSION");

/// What a shared library built with [`export_fmus!`](crate::export_fmus) declares: every model's
/// header and variables, and the GUID the library will accept. Owned data, so that the packaging tool
/// can read it from the bytes a library exports.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Catalogue {
    pub format: u32,
    pub runtime_version: String,
    /// The Cargo package that built the library: its name, version, authors and license go into every
    /// model description (`author`, `version`, `license`).
    pub package: PackageInfo,
    pub models: Vec<ModelDescription>,
}

/// Metadata of the package that exports the models (captured by `export_fmus!` from the exporting
/// crate's Cargo.toml).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackageInfo {
    pub name: String,
    pub version: String,
    /// Cargo's `authors`, joined by ':' as Cargo passes them.
    pub authors: String,
    pub license: String,
}

/// One model of a [`Catalogue`]: [`ModelInfo`] and the [`VarDecl`] table as owned data, plus the GUID.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelDescription {
    pub name: String,
    pub description: String,
    pub source: String,
    pub equations_html: String,
    pub feedthrough: FeedthroughDescription,
    pub default_stop_time: f64,
    pub default_step: f64,
    pub variable_step: bool,
    pub guid: String,
    pub variables: Vec<VariableDescription>,
    /// Model Exchange: the continuous states; `None` = Co-Simulation only.
    pub states: Option<Vec<StateDescription>>,
}

/// A [`StateDecl`] as owned data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateDescription {
    pub name: String,
    pub unit: String,
    pub description: String,
    pub depends: Option<Vec<String>>,
    pub starts_from: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FeedthroughDescription {
    None,
    AllInputs,
    Some(Vec<(String, Vec<String>)>),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VariableDescription {
    pub vr: u32,
    pub name: String,
    pub kind: VarKind,
    pub causality: Causality,
    pub variability: Variability,
    pub unit: String,
    pub description: String,
    pub start: Start,
    pub bound: BoundDescription,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum BoundDescription {
    Any,
    Positive,
    NonNegative,
    Limit,
    Range(f64, f64),
    Choice(Vec<i32>),
}

impl ModelDescription {
    /// The description of a model entry (what the library exports).
    pub fn of(e: &ModelEntry) -> Self {
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
                    crate::model::feedthrough::scalar_list(e)
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
            variables: e
                .decls
                .iter()
                .map(|d| VariableDescription {
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
                })
                .collect(),
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
        }
    }

    /// A description-only [`ModelEntry`] with the same header and declarations, for tools that render
    /// them (the packaging tool). Its strings are leaked: a tool reads a handful of models once per
    /// process. Its `create` cannot build a model (the code lives in the library the catalogue came from).
    pub fn into_entry(self) -> ModelEntry {
        fn leak(s: String) -> &'static str {
            Box::leak(s.into_boxed_str())
        }
        fn no_model() -> Box<dyn crate::model::DynModel> {
            panic!("a ModelEntry read from a catalogue describes a model; its code is in the library")
        }
        let feedthrough = match self.feedthrough {
            FeedthroughDescription::None => Feedthrough::None,
            FeedthroughDescription::AllInputs => Feedthrough::AllInputs,
            FeedthroughDescription::Some(l) => Feedthrough::Some(Box::leak(
                l.into_iter()
                    .map(|(o, ins)| {
                        (
                            leak(o),
                            &*Box::leak(ins.into_iter().map(leak).collect::<Vec<_>>().into_boxed_slice()),
                        )
                    })
                    .collect::<Vec<_>>()
                    .into_boxed_slice(),
            )),
        };
        let info = Box::leak(Box::new(ModelInfo {
            name: leak(self.name),
            description: leak(self.description),
            source: leak(self.source),
            equations_html: leak(self.equations_html),
            feedthrough,
            default_stop_time: self.default_stop_time,
            default_step: self.default_step,
            variable_step: self.variable_step,
        }));
        let decls: Vec<VarDecl> = self
            .variables
            .into_iter()
            .map(|v| VarDecl {
                vr: v.vr,
                name: leak(v.name),
                kind: v.kind,
                causality: v.causality,
                variability: v.variability,
                unit: leak(v.unit),
                description: leak(v.description),
                start: v.start,
                bound: match v.bound {
                    BoundDescription::Any => Bound::Any,
                    BoundDescription::Positive => Bound::Positive,
                    BoundDescription::NonNegative => Bound::NonNegative,
                    BoundDescription::Limit => Bound::Limit,
                    BoundDescription::Range(a, b) => Bound::Range(a, b),
                    BoundDescription::Choice(c) => Bound::Choice(Box::leak(c.into_boxed_slice())),
                },
            })
            .collect();
        let states: Option<&'static [StateDecl]> = self.states.map(|l| {
            let decl = |x: StateDescription| {
                let starts: &'static [&'static str] = Box::leak(
                    x.starts_from
                        .into_iter()
                        .map(leak)
                        .collect::<Vec<_>>()
                        .into_boxed_slice(),
                );
                let s = StateDecl::new(leak(x.name), leak(x.unit), leak(x.description)).starting_from(starts);
                match x.depends {
                    Some(d) => s.depends_on(Box::leak(
                        d.into_iter().map(leak).collect::<Vec<_>>().into_boxed_slice(),
                    )),
                    None => s,
                }
            };
            &*Box::leak(l.into_iter().map(decl).collect::<Vec<_>>().into_boxed_slice())
        });
        ModelEntry {
            info,
            decls: Box::leak(decls.into_boxed_slice()),
            states,
            create: no_model,
        }
    }
}

/// The catalogue of a list of models exported by `package`.
pub fn catalogue(models: &[ModelEntry], package: PackageInfo) -> Catalogue {
    Catalogue {
        format: CATALOGUE_FORMAT,
        runtime_version: RUNTIME_VERSION.into(),
        package,
        models: models.iter().map(ModelDescription::of).collect(),
    }
}

/// The catalogue as bytes: the magic `SCFMUCAT`, then the postcard encoding of [`Catalogue`].
pub fn catalogue_bytes(models: &[ModelEntry], package: PackageInfo) -> Vec<u8> {
    let mut out = CATALOGUE_MAGIC.to_vec();
    out.extend(postcard::to_stdvec(&catalogue(models, package)).expect("a catalogue always serializes"));
    out
}

const CATALOGUE_MAGIC: &[u8; 8] = b"SCFMUCAT";

/// Reads [`catalogue_bytes`] back; the message says what is wrong (not a catalogue, another format).
pub fn read_catalogue(bytes: &[u8]) -> Result<Catalogue, String> {
    let body = bytes
        .strip_prefix(CATALOGUE_MAGIC)
        .ok_or("not a spacecraft_fmus catalogue (no SCFMUCAT header)")?;
    // the format number is the first field: read it alone first, so a newer layout is named, not garbled
    let (format, _) =
        postcard::take_from_bytes::<u32>(body).map_err(|e| format!("catalogue header unreadable: {e}"))?;
    if format != CATALOGUE_FORMAT {
        return Err(format!("catalogue format {format}, this tool reads format {CATALOGUE_FORMAT} (rebuild the library and the tool from the same spacecraft_fmus)"));
    }
    postcard::from_bytes(body).map_err(|e| format!("catalogue unreadable: {e}"))
}

/// Generates the FMI 2.0 and FMI 3.0 Co-Simulation entry points of a shared library for the given models, plus
/// `spacecraft_fmus_catalogue` (the declarations, for the packaging tool). Use it once, at the root of a
/// `cdylib` crate:
///
/// ```ignore
/// spacecraft_fmus::export_fmus!(MyController, MyPlant);          // model types
/// spacecraft_fmus::export_fmus!(list: spacecraft_fmus::registry::ALL);  // a const &[ModelEntry]
/// ```
///
/// One library may hold several models: each FMU carries the same binary under its own name
/// (`binaries/<platform>/<Model>.<ext>`), and `fmi2Instantiate` picks the model by that file name and
/// checks the GUID (`fmi3InstantiateCoSimulation`: the instantiationToken, the same GUID). Every function goes through the layer in `spacecraft_fmus::fmi` (`fmi2`, `fmi3`: state machine,
/// status and logging, panics caught, validated FMU states).
#[macro_export]
macro_rules! export_fmus {
    (list: $list:expr) => {
        const _: () = {
            static MODELS: &[$crate::model::ModelEntry] = $list;

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
                    })
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
    ($($Model:ty),+ $(,)?) => {
        $crate::export_fmus!(list: &[$($crate::model::ModelEntry::of::<$Model>()),+]);
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_catalogue_round_trips_and_gives_back_the_declarations_and_guids() {
        let pkg = PackageInfo {
            name: "p".into(),
            version: "1.2.3".into(),
            authors: "A:B".into(),
            license: "MIT".into(),
        };
        let bytes = catalogue_bytes(crate::registry::ALL, pkg.clone());
        let cat = read_catalogue(&bytes).unwrap();
        assert_eq!(cat.models.len(), crate::registry::COUNT);
        assert_eq!(cat.runtime_version, RUNTIME_VERSION);
        assert_eq!(cat.package, pkg);
        for (m, e) in cat.models.into_iter().zip(crate::registry::ALL) {
            let guid = m.guid.clone();
            let back = m.into_entry();
            assert_eq!(crate::model::guid::compute_fresh(&back), guid, "{}", e.info.name);
            assert_eq!(guid, crate::model::guid::guid(e).as_str());
            assert_eq!(back.decls.len(), e.decls.len());
            for (a, b) in back.decls.iter().zip(e.decls) {
                assert_eq!(
                    (a.vr, a.name, a.unit, a.bound, a.start),
                    (b.vr, b.name, b.unit, b.bound, b.start)
                );
            }
        }
        assert!(read_catalogue(b"nonsense")
            .unwrap_err()
            .contains("not a spacecraft_fmus catalogue"));
        let mut other = CATALOGUE_MAGIC.to_vec();
        other.extend(postcard::to_stdvec(&7u32).unwrap());
        assert!(read_catalogue(&other).unwrap_err().contains("catalogue format 7"));
    }
}
