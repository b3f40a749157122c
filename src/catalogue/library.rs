//! The catalogue a shared library exports (`spacecraft_fmus_catalogue`, written by `export_fmus!`):
//! the declarations of [`super::decl`] as owned data, plus everything else the packaging tool writes
//! into an FMU — the GUID of each model, the exporting package, the value references and log
//! categories of the FMI layer the library was built with, the families and their overviews, and the
//! bibliography. The packaging tool reads nothing else.

use serde::{Deserialize, Serialize};

use super::decl::{initial_of, Bound, Causality, Initial, Reference, Start, VarKind, Variability};

/// Version of the catalogue's byte layout; the packaging tool refuses any other.
pub const CATALOGUE_FORMAT: u32 = 6;

/// Version of this crate, recorded in every catalogue (and part of every GUID).
pub const RUNTIME_VERSION: &str = env!("CARGO_PKG_VERSION");

const CATALOGUE_MAGIC: &[u8; 8] = b"SCFMUCAT";

/// What a shared library built with `export_fmus!` declares: every model's header and variables, the
/// GUID the library will accept, and what the packaging tool needs besides. Owned data, so that the
/// packaging tool can read it from the bytes a library exports.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Catalogue {
    pub format: u32,
    pub runtime_version: String,
    /// The Cargo package that built the library: its name, version, authors and license go into every
    /// model description (`author`, `version`, `license`).
    pub package: PackageInfo,
    /// What the FMI layer compiled into the library reserves and offers.
    pub layer: LayerInfo,
    /// Families of models with their overview pages (empty for a library that declares none).
    pub families: Vec<FamilyDescription>,
    /// The publications the library's texts may cite by `[key]`, in the order they are listed.
    pub references: Vec<ReferenceDescription>,
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

/// The FMI layer's side of every model description: its log categories and the value references it
/// gives its own variables (FMI 3.0 `time`, the continuous states and their derivatives).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LayerInfo {
    /// (name, description) of each log category, in `<LogCategories>` order.
    pub log_categories: Vec<(String, String)>,
    /// Value reference of FMI 3.0's independent variable `time`.
    pub time_vr: u32,
    /// Continuous state k has value reference `state_vr_base + k`, its derivative `derivative_vr_base + k`.
    pub state_vr_base: u32,
    pub derivative_vr_base: u32,
    /// Value references from here on (other than `time_vr`) belong to the layer.
    pub reserved_vr_start: u32,
    /// Clock i of a clocked model has value reference `clock_vr_base + i` (FMI 3.0 only).
    pub clock_vr_base: u32,
}

/// A family of models: one page `docs/models/<slug>.md` with a title and a Markdown overview.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FamilyDescription {
    pub slug: String,
    pub title: String,
    pub overview: String,
    /// The names of its models, in page order.
    pub models: Vec<String>,
}

/// A [`Reference`] as owned data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceDescription {
    pub key: String,
    pub authors: String,
    pub title: String,
    pub venue: String,
    pub subject: String,
    pub used_for: String,
}

impl ReferenceDescription {
    pub fn of(r: &Reference) -> Self {
        ReferenceDescription {
            key: r.key.into(),
            authors: r.authors.into(),
            title: r.title.into(),
            venue: r.venue.into(),
            subject: r.subject.into(),
            used_for: r.used_for.into(),
        }
    }
}

/// One model of a [`Catalogue`]: its `ModelInfo` and variable table as owned data, plus the GUID.
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
    /// FMI 3.0 clocks of a sampled model (empty: not clocked).
    pub clocks: Vec<ClockDescription>,
    /// FMI 3.0 terminals (`terminalsAndIcons/terminalsAndIcons.xml`): every vector port, and the groups
    /// of ports that connect together (`crate::models::ports::terminals`); empty = no terminals file.
    pub terminals: Vec<TerminalDescription>,
}

impl ModelDescription {
    /// Whether the model offers Model Exchange.
    pub fn model_exchange(&self) -> bool {
        self.states.is_some()
    }

    /// The continuous states (empty for a Co-Simulation-only model or a static law).
    pub fn state_decls(&self) -> &[StateDescription] {
        self.states.as_deref().unwrap_or(&[])
    }

    pub fn decl(&self, name: &str) -> Option<&VariableDescription> {
        self.variables.iter().find(|d| d.name == name)
    }

    /// Every text of the model that may cite publications: description, source, equations and the
    /// variable and state descriptions.
    pub fn texts(&self) -> Vec<&str> {
        let mut t = vec![self.description.as_str(), &self.source, &self.equations_html];
        t.extend(self.variables.iter().map(|d| d.description.as_str()));
        t.extend(self.state_decls().iter().map(|d| d.description.as_str()));
        t
    }
}

/// A `StateDecl` as owned data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateDescription {
    pub name: String,
    pub unit: String,
    pub description: String,
    pub depends: Option<Vec<String>>,
    pub starts_from: Vec<String>,
}

/// A `ClockDecl` as owned data (`outputs`: FMI scalar names, stems expanded in declaration order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClockDescription {
    pub name: String,
    pub description: String,
    pub interval: String,
    pub shift: String,
    pub steps: bool,
    pub outputs: Vec<String>,
}

/// One FMI 3.0 terminal: a named group of ports with a meaning (`kind`, the standard's `terminalKind`),
/// connected to another terminal by its `matching_rule` (`plug`: member by member, by member name, every
/// member present on both sides; `sequence`: by position). Every member is a signal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TerminalDescription {
    pub name: String,
    pub kind: String,
    pub matching_rule: String,
    pub description: String,
    /// (memberName, variableName) pairs in order: the member name is what matching compares, the variable
    /// the FMI scalar that is read or written.
    pub members: Vec<(String, String)>,
}

/// A `Feedthrough` as owned data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FeedthroughDescription {
    None,
    AllInputs,
    Some(Vec<(String, Vec<String>)>),
}

/// A `VarDecl` as owned data.
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

impl VariableDescription {
    /// As `VarDecl::initial`.
    pub fn initial(&self) -> Option<Initial> {
        initial_of(self.causality, self.variability)
    }

    /// Whether the XML carries a `start` attribute (not allowed for `initial="calculated"`).
    pub fn has_start(&self) -> bool {
        !matches!(self.initial(), Some(Initial::Calculated))
    }
}

/// A `Bound` as owned data, with the same checks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum BoundDescription {
    Any,
    Positive,
    NonNegative,
    Limit,
    Range(f64, f64),
    Choice(Vec<i32>),
}

impl BoundDescription {
    /// The static bound with the same checks; a choice list is checked here, not by `Bound`.
    fn simple(&self) -> Option<Bound> {
        Some(match *self {
            BoundDescription::Any => Bound::Any,
            BoundDescription::Positive => Bound::Positive,
            BoundDescription::NonNegative => Bound::NonNegative,
            BoundDescription::Limit => Bound::Limit,
            BoundDescription::Range(lo, hi) => Bound::Range(lo, hi),
            BoundDescription::Choice(_) => return None,
        })
    }

    /// As `Bound::check_real`.
    pub fn check_real(&self, name: &str, v: f64) -> Result<(), String> {
        self.simple().unwrap_or(Bound::Any).check_real(name, v)
    }

    /// As `Bound::check_integer`.
    pub fn check_integer(&self, name: &str, v: i32) -> Result<(), String> {
        match (self, self.simple()) {
            (BoundDescription::Choice(codes), _) if !codes.contains(&v) => {
                Err(format!("parameter {name} = {v} is not one of {codes:?}"))
            }
            (_, Some(b)) => b.check_integer(name, v),
            _ => Ok(()),
        }
    }

    /// As `Bound::min_max`.
    pub fn min_max(&self) -> (Option<f64>, Option<f64>) {
        match (self, self.simple()) {
            (BoundDescription::Choice(codes), _) => (
                codes.iter().min().map(|&c| c as f64),
                codes.iter().max().map(|&c| c as f64),
            ),
            (_, Some(b)) => b.min_max(),
            (_, None) => (None, None),
        }
    }
}

/// The catalogue as bytes: the magic `SCFMUCAT`, then the postcard encoding of [`Catalogue`].
pub fn catalogue_to_bytes(cat: &Catalogue) -> Vec<u8> {
    let mut out = CATALOGUE_MAGIC.to_vec();
    out.extend(postcard::to_stdvec(cat).expect("a catalogue always serializes"));
    out
}

/// Reads [`catalogue_to_bytes`] back; the message says what is wrong (not a catalogue, another format).
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_foreign_or_older_catalogue_is_named_not_garbled() {
        assert!(read_catalogue(b"nonsense")
            .unwrap_err()
            .contains("not a spacecraft_fmus catalogue"));
        let mut other = CATALOGUE_MAGIC.to_vec();
        other.extend(postcard::to_stdvec(&7u32).unwrap());
        assert!(read_catalogue(&other).unwrap_err().contains("catalogue format 7"));
    }

    #[test]
    fn a_choice_bound_checks_and_writes_like_the_static_one() {
        let owned = BoundDescription::Choice(vec![0, 1, 2]);
        let fixed = super::super::Bound::Choice(&[0, 1, 2]);
        assert_eq!(owned.min_max(), fixed.min_max());
        for v in [-1, 0, 2, 3] {
            assert_eq!(owned.check_integer("k", v), fixed.check_integer("k", v));
        }
        assert_eq!(owned.check_real("k", f64::NAN), fixed.check_real("k", f64::NAN));
    }
}
