//! The committed FMI 3.0 terminals files (`modelDescription/fmi3/terminalsAndIcons/<Model>.xml`) read by
//! an independent parser, fmi-schema's `Fmi3TerminalsAndIcons` (strict: an unknown element or attribute is
//! an error): each parses, every terminal passes fmi-schema's matching-rule check (plug and bus need unique
//! member names), and fmi-schema resolves every member to a variable of the model's FMI 3.0 description
//! (`resolve_terminals`); they are also what the catalogue gives today (not stale).

use std::path::Path;

use fmi_schema::fmi3::{resolve_terminals, Fmi3ModelDescription, Fmi3TerminalsAndIcons};

#[test]
fn fmi_schema_reads_and_resolves_every_committed_terminals_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription/fmi3");
    let cat = spacecraft_fmus::export::project_catalogue();
    let stale = spacecraft_fmus_package::terminals::stale_terminals(&cat, &root.join("terminalsAndIcons"));
    assert!(
        stale.is_empty(),
        "stale {stale:?}: run scripts/build_fmus.sh and commit"
    );
    let mut n = 0;
    for m in cat.models.iter().filter(|m| !m.terminals.is_empty()) {
        let text = std::fs::read_to_string(root.join("terminalsAndIcons").join(format!("{}.xml", m.name))).unwrap();
        let t: Fmi3TerminalsAndIcons = fmi_schema::deserialize(&text).unwrap_or_else(|e| panic!("{}: {e:?}", m.name));
        assert_eq!(t.fmi_version, "3.0");
        let list = &t.terminals.as_ref().unwrap().terminals;
        assert_eq!(list.len(), m.terminals.len(), "{}", m.name);
        for x in list {
            x.validate_matching_rule()
                .unwrap_or_else(|e| panic!("{}.{}: {e:?}", m.name, x.name));
        }
        let md_text = std::fs::read_to_string(root.join(format!("{}.xml", m.name))).unwrap();
        let md: Fmi3ModelDescription =
            fmi_schema::deserialize(&md_text).unwrap_or_else(|e| panic!("{}: {e:?}", m.name));
        let resolved = resolve_terminals(&t, &md).unwrap_or_else(|e| panic!("{}: {e:?}", m.name));
        let members: usize = resolved.terminals.iter().map(|r| r.members.len()).sum();
        assert_eq!(
            members,
            m.terminals.iter().map(|x| x.members.len()).sum::<usize>(),
            "{}",
            m.name
        );
        n += 1;
    }
    assert!(n >= 30, "only {n} models have terminals");
}
