//! The valid names a packaging-time refusal lists, so that a user sees what to write instead.

use spacecraft_fmus::model::{Causality, ModelEntry};

/// The FMI names of the model's variables of `causality`, comma-separated (`(none)` when there are none).
pub fn of_causality(entry: &ModelEntry, causality: Causality) -> String {
    let names: Vec<&str> = entry
        .decls
        .iter()
        .filter(|d| d.causality == causality)
        .map(|d| d.name)
        .collect();
    if names.is_empty() {
        "(none)".into()
    } else {
        names.join(", ")
    }
}

/// The inputs and continuous states (what a derivative may depend on), comma-separated.
pub fn inputs_and_states(entry: &ModelEntry) -> String {
    let mut names = vec![of_causality(entry, Causality::Input)];
    names.extend(entry.state_decls().iter().map(|x| x.name.to_string()));
    names.join(", ")
}
