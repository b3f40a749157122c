//! The packaging tool renders from the catalogue alone: outside its unit tests, every path into the
//! runtime crate (`spacecraft_fmus::…`) names the catalogue or the unit table, never the registry, the
//! FMI layer or the runtime's model types, and nothing is leaked into `&'static` runtime types.

use std::path::Path;

#[test]
fn the_packager_reads_only_the_catalogue_and_the_unit_table() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut seen = 0;
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        // a file's unit tests (and the test-only helper) may build the project's catalogue in-process
        let code: String = text
            .split("#[cfg(test)]")
            .next()
            .unwrap()
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        for (i, _) in code.match_indices("spacecraft_fmus::") {
            let module: String = code[i + "spacecraft_fmus::".len()..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            assert!(
                // `export_fmus` appears in messages that tell a user what their crate must call
                ["catalogue", "units", "export_fmus"].contains(&module.as_str()),
                "{}: uses spacecraft_fmus::{module}",
                path.display()
            );
            seen += 1;
        }
        assert!(!code.contains("Box::leak"), "{}: leaks", path.display());
    }
    assert!(
        seen >= 6,
        "only {seen} paths into the runtime crate: is the scan looking at the packager?"
    );
}
