//! `terminalsAndIcons/terminalsAndIcons.xml` of an FMI 3.0 archive (FMI 3.0 section 2.4.9): the model's
//! terminals from the catalogue (`ModelDescription::terminals`), each `<Terminal name matchingRule
//! terminalKind description>` with one `<TerminalMemberVariable variableName memberName
//! variableKind="signal">` per member. A model without terminals gets no file. The project commits the
//! files as `modelDescription/fmi3/terminalsAndIcons/<Model>.xml`.

use std::fs;
use std::path::Path;

use spacecraft_fmus::catalogue::{Catalogue, ModelDescription};

use crate::xml::{document, empty, end, finish, start};

/// Path of the file inside an FMI 3.0 archive.
pub const ARCHIVE_PATH: &str = "terminalsAndIcons/terminalsAndIcons.xml";

/// The document, or `None` for a model without terminals.
pub fn terminals_and_icons(_cat: &Catalogue, m: &ModelDescription) -> Option<String> {
    if m.terminals.is_empty() {
        return None;
    }
    let mut w = document();
    start(&mut w, "fmiTerminalsAndIcons", &[("fmiVersion", "3.0".into())]);
    start(&mut w, "Terminals", &[]);
    for t in &m.terminals {
        let mut attrs = vec![("name", t.name.clone()), ("matchingRule", t.matching_rule.clone())];
        if !t.kind.is_empty() {
            attrs.push(("terminalKind", t.kind.clone()));
        }
        if !t.description.is_empty() {
            attrs.push(("description", t.description.clone()));
        }
        start(&mut w, "Terminal", &attrs);
        for (member, variable) in &t.members {
            empty(
                &mut w,
                "TerminalMemberVariable",
                &[
                    ("variableName", variable.clone()),
                    ("memberName", member.clone()),
                    ("variableKind", "signal".into()),
                ],
            );
        }
        end(&mut w, "Terminal");
    }
    end(&mut w, "Terminals");
    end(&mut w, "fmiTerminalsAndIcons");
    Some(finish(w))
}

/// Writes `<dir>/<Model>.xml` for every model with terminals; returns the paths written.
pub fn write_terminals(cat: &Catalogue, dir: &Path) -> std::io::Result<Vec<String>> {
    fs::create_dir_all(dir)?;
    let mut written = vec![];
    for m in &cat.models {
        let p = dir.join(format!("{}.xml", m.name));
        match terminals_and_icons(cat, m) {
            Some(x) => {
                fs::write(&p, x)?;
                written.push(p.display().to_string());
            }
            None if p.exists() => fs::remove_file(&p)?,
            None => {}
        }
    }
    Ok(written)
}

/// `fmi3/terminalsAndIcons/<Model>` of every model whose committed file differs from the generated one
/// (or exists when the model has no terminals).
pub fn stale_terminals(cat: &Catalogue, dir: &Path) -> Vec<String> {
    cat.models
        .iter()
        .filter(|m| fs::read_to_string(dir.join(format!("{}.xml", m.name))).ok() != terminals_and_icons(cat, m))
        .map(|m| format!("fmi3/terminalsAndIcons/{}", m.name))
        .collect()
}
