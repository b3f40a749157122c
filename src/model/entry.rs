//! The registry entry of one FMU ([`ModelEntry`], which can build the model), the scalar feed-through
//! list derived from it, and the [`Family`] lists and [`Extras`] a library exports with its models
//! (re-exported by `crate::model` and `crate::export`).

use super::contract::{Model, Variables};
use super::feedthrough::{names, Checked};
use super::instance::{DynModel, Fmu};
use crate::catalogue::decl::{Causality, ClockDecl, Feedthrough, ModelInfo, Reference, StateDecl, VarDecl};

/// Registry entry of one FMU.
#[derive(Clone, Copy)]
pub struct ModelEntry {
    pub info: &'static ModelInfo,
    pub decls: &'static [VarDecl],
    /// Model Exchange: the continuous states ([`Model::STATES`]); `None` = Co-Simulation only.
    pub states: Option<&'static [StateDecl]>,
    /// FMI 3.0 clocks of a sampled model ([`Model::CLOCKS`]); empty = not clocked.
    pub clocks: &'static [ClockDecl],
    pub create: fn() -> Box<dyn DynModel>,
}

impl ModelEntry {
    pub const fn of<M: Model>() -> Self {
        let () = Checked::<M>::FEEDTHROUGH; // a compile error naming a mistyped feed-through name
        ModelEntry {
            info: &M::INFO,
            decls: M::Vars::DECLS,
            states: M::STATES,
            clocks: M::CLOCKS,
            create: || Box::new(Fmu::<M>::default()),
        }
    }

    /// Whether the model offers Model Exchange.
    pub const fn model_exchange(&self) -> bool {
        self.states.is_some()
    }

    /// The continuous states (empty for a Co-Simulation-only model or a static law).
    pub fn state_decls(&self) -> &'static [StateDecl] {
        self.states.unwrap_or(&[])
    }

    /// Every text of the model that may cite publications: description, source, equations and the
    /// variable descriptions (read by the model description, the documentation pages and the reference list).
    pub fn texts(&self) -> Vec<&'static str> {
        let mut t = vec![self.info.description, self.info.source, self.info.equations_html];
        t.extend(self.decls.iter().map(|d| d.description));
        t.extend(self.state_decls().iter().map(|d| d.description));
        t
    }

    pub fn decl(&self, name: &str) -> Option<&'static VarDecl> {
        self.decls.iter().find(|d| d.name == name)
    }
}

/// The feed-through list of a [`Feedthrough::Some`] model with every name an FMI scalar name, in the
/// order given (stems replaced by their components in declaration order, each input once per output
/// entry); `None` for [`Feedthrough::None`] and [`Feedthrough::AllInputs`]. A name that matches no
/// variable is kept as it is (so that the packaging tool can refuse it by name).
pub fn scalar_list(entry: &ModelEntry) -> Option<Vec<(&'static str, Vec<&'static str>)>> {
    let Feedthrough::Some(list) = entry.info.feedthrough else {
        return None;
    };
    let expand = |name: &'static str, causality: Causality| -> Vec<&'static str> {
        let found: Vec<&'static str> = entry
            .decls
            .iter()
            .filter(|d| d.causality == causality && names(entry.decls, name, d))
            .map(|d| d.name)
            .collect();
        if found.is_empty() {
            vec![name]
        } else {
            found
        }
    };
    let mut out = Vec::new();
    for (o, ins) in list {
        let mut inputs: Vec<&'static str> = Vec::new();
        for i in ins.iter().flat_map(|i| expand(i, Causality::Input)) {
            if !inputs.contains(&i) {
                inputs.push(i);
            }
        }
        for o in expand(o, Causality::Output) {
            out.push((o, inputs.clone()));
        }
    }
    Some(out)
}

/// A family of models: a page `docs/models/<slug>.md` with a title, a Markdown overview and the
/// models in page order (the project's families are `crate::registry::FAMILIES`; a model crate may
/// declare its own and pass them to `export_fmus!`).
pub struct Family {
    pub slug: &'static str,
    pub title: &'static str,
    /// Markdown overview (the project's: the family folder's README.md).
    pub overview: &'static str,
    pub fmus: &'static [ModelEntry],
}

/// What a library exports besides its models: its families and its bibliography (both may be empty).
#[derive(Clone, Copy)]
pub struct Extras {
    pub families: &'static [Family],
    pub references: &'static [Reference],
}

impl Extras {
    pub const NONE: Extras = Extras {
        families: &[],
        references: &[],
    };
}

/// The FMI scalar names of the outputs clock `c` of `entry` computes at its ticks ([`ClockDecl::outputs`],
/// vector stems replaced by their components), in declaration order.
pub fn clocked_outputs(entry: &ModelEntry, c: &ClockDecl) -> Vec<String> {
    entry
        .decls
        .iter()
        .filter(|d| d.causality == Causality::Output && c.outputs.iter().any(|n| names(entry.decls, n, d)))
        .map(|d| d.name.to_string())
        .collect()
}
