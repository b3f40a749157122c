//! `package`: writes `modelDescription/<Model>.xml`, `fmus/<Model>.fmu` and the generated model pages
//! (`docs/models/<family>.md`, `docs/references.md`) for every model.
//!
//! Usage: `package [--lib PATH] [--fmus DIR] [--xml DIR] [--check]`
//! - `--lib`: the release cdylib (default `target/release/libspacecraft_fmus.so`)
//! - `--check`: only report stale files in the XML folder, exit 1 if any

use std::path::PathBuf;
use std::process::ExitCode;

use spacecraft_fmus::package::{stale_model_descriptions, write_fmu, write_model_descriptions, LIB_EXT};
use spacecraft_fmus::registry;

fn main() -> ExitCode {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut lib = root.join(format!("target/release/libspacecraft_fmus.{LIB_EXT}"));
    let mut fmus = root.join("fmus");
    let mut xml = root.join("modelDescription");
    let mut check = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--lib" => lib = args.next().map(PathBuf::from).unwrap_or(lib),
            "--fmus" => fmus = args.next().map(PathBuf::from).unwrap_or(fmus),
            "--xml" => xml = args.next().map(PathBuf::from).unwrap_or(xml),
            "--check" => check = true,
            other => {
                eprintln!("package: unknown argument {other}");
                return ExitCode::FAILURE;
            }
        }
    }
    if check {
        let mut stale = stale_model_descriptions(&xml);
        stale.extend(spacecraft_fmus::docs::stale_pages(&root.join("docs")));
        if stale.is_empty() {
            println!("modelDescription/ and docs/ are up to date ({} models)", registry::ALL.len());
            return ExitCode::SUCCESS;
        }
        eprintln!("stale generated files: {}", stale.join(", "));
        return ExitCode::FAILURE;
    }
    let library = match std::fs::read(&lib) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("package: cannot read {} ({e}); run `cargo build --release` first", lib.display());
            return ExitCode::FAILURE;
        }
    };
    if let Err(e) = write_model_descriptions(&xml) {
        eprintln!("package: cannot write model descriptions: {e}");
        return ExitCode::FAILURE;
    }
    if let Err(e) = spacecraft_fmus::docs::write_pages(&root.join("docs")) {
        eprintln!("package: cannot write docs/models and docs/references.md: {e}");
        return ExitCode::FAILURE;
    }
    for e in registry::ALL {
        match write_fmu(e, &library, &fmus) {
            Ok(p) => println!("wrote {}", p.display()),
            Err(err) => {
                eprintln!("package: {}: {err}", e.info.name);
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
