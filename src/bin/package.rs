//! `package`: writes `modelDescription/<Model>.xml` and `fmus/<Model>.fmu` for every model.
//!
//! Usage: `package [--lib PATH] [--win64-lib PATH] [--fmus DIR] [--xml DIR] [--check]`
//! - `--lib`: the release cdylib of this machine (default `target/release/libspacecraft_fmus.so`)
//! - `--win64-lib`: also store this Windows x86-64 build (`spacecraft_fmus.dll`) as
//!   `binaries/win64/<Model>.dll` in every FMU (scripts/build_fmus.sh passes it when the cross
//!   toolchain built it)
//! - `--check`: only report stale files in the XML folder, exit 1 if any

use std::path::PathBuf;
use std::process::ExitCode;

use spacecraft_fmus::package::{stale_model_descriptions, write_fmu, write_model_descriptions, Binary, LIB_EXT, PLATFORM};
use spacecraft_fmus::registry;

fn main() -> ExitCode {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut lib = root.join(format!("target/release/libspacecraft_fmus.{LIB_EXT}"));
    let mut fmus = root.join("fmus");
    let mut xml = root.join("modelDescription");
    let mut win64: Option<PathBuf> = None;
    let mut check = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--lib" => lib = args.next().map(PathBuf::from).unwrap_or(lib),
            "--win64-lib" => win64 = args.next().map(PathBuf::from),
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
        let stale = stale_model_descriptions(&xml);
        if stale.is_empty() {
            println!("modelDescription/ is up to date ({} models)", registry::ALL.len());
            return ExitCode::SUCCESS;
        }
        eprintln!("stale modelDescription files: {}", stale.join(", "));
        return ExitCode::FAILURE;
    }
    let library = match std::fs::read(&lib) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("package: cannot read {} ({e}); run `cargo build --release` first", lib.display());
            return ExitCode::FAILURE;
        }
    };
    let win64_bytes = match &win64 {
        None => None,
        Some(p) => match std::fs::read(p) {
            Ok(b) => Some(b),
            Err(e) => {
                eprintln!("package: cannot read the win64 library {} ({e})", p.display());
                return ExitCode::FAILURE;
            }
        },
    };
    let mut binaries = vec![Binary::host(&library)];
    if let Some(b) = &win64_bytes {
        if PLATFORM == "win64" {
            eprintln!("package: --win64-lib given on a win64 host; use --lib");
            return ExitCode::FAILURE;
        }
        binaries.push(Binary { platform: "win64", ext: "dll", bytes: b });
    }
    if let Err(e) = write_model_descriptions(&xml) {
        eprintln!("package: cannot write model descriptions: {e}");
        return ExitCode::FAILURE;
    }
    for e in registry::ALL {
        match write_fmu(e, &binaries, &fmus) {
            Ok(p) => println!("wrote {} ({})", p.display(), binaries.iter().map(|b| b.platform).collect::<Vec<_>>().join(" + ")),
            Err(err) => {
                eprintln!("package: {}: {err}", e.info.name);
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
