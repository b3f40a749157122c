//! The committed FMI 3.0 terminals files (`modelDescription/fmi3/terminalsAndIcons/<Model>.xml`) read by
//! an independent parser, fmi-schema's `Fmi3TerminalsAndIcons` (strict: an unknown element or attribute is
//! an error): each parses, every terminal passes fmi-schema's matching-rule check (plug and bus need unique
//! member names), and every member names a declared variable of the model; they are also what the catalogue gives today (not stale).

use std::path::Path;

use fmi_schema::fmi3::Fmi3TerminalsAndIcons;

#[test]
fn fmi_schema_reads_every_committed_terminals_file() {
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
        // fmi-schema 0.8.0's strict model-description reader refuses `<BaseUnit A=..>` (valid FMI 3.0), so
        // the members are resolved against the model's declared variables instead of `resolve_terminals`
        for (x, want) in list.iter().zip(&m.terminals) {
            let names: Vec<&str> = x
                .terminal_member_variables
                .iter()
                .map(|v| v.variable_name.as_str())
                .collect();
            assert!(
                names.iter().all(|n| m.decl(n).is_some()),
                "{}.{}: {names:?}",
                m.name,
                x.name
            );
            assert_eq!(names, want.members.iter().map(|(_, v)| v.as_str()).collect::<Vec<_>>());
        }
        n += 1;
    }
    assert!(n >= 30, "only {n} models have terminals");
}
