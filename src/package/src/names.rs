//! The valid names a packaging-time refusal lists, so that a user sees what to write instead.

use spacecraft_fmus::catalogue::{Causality, ModelDescription};

/// The FMI names of the model's variables of `causality`, comma-separated (`(none)` when there are none).
pub fn of_causality(m: &ModelDescription, causality: Causality) -> String {
    let names: Vec<&str> = m
        .variables
        .iter()
        .filter(|d| d.causality == causality)
        .map(|d| d.name.as_str())
        .collect();
    if names.is_empty() {
        "(none)".into()
    } else {
        names.join(", ")
    }
}

/// The inputs and continuous states (what a derivative may depend on), comma-separated.
pub fn inputs_and_states(m: &ModelDescription) -> String {
    let mut names = vec![of_causality(m, Causality::Input)];
    names.extend(m.states.iter().flatten().map(|x| x.name.clone()));
    names.join(", ")
}
