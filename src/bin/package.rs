//! `package`: writes `modelDescription/<Model>.xml`, `fmus/<Model>.fmu` and the generated model pages
//! (`docs/models/<family>.md`, `docs/references.md`) for every model.
//!
//! Usage: `package [--lib PATH] [--add-lib PLATFORM=PATH]... [--fmus DIR] [--xml DIR] [--check]`
//! - `--lib`: the release cdylib of this machine (default `target/release/libspacecraft_fmus.so`)
//! - `--add-lib`: also store another platform's build of the same crate in every FMU, e.g.
//!   `--add-lib win64=target/win64/x86_64-win7-windows-gnu/release/spacecraft_fmus.dll` gives
//!   `binaries/win64/<Model>.dll` (scripts/build_fmus.sh passes it when the cross toolchain built it).
//!   PLATFORM is one of linux64, win64, darwin64; the modelDescription is the same for all.
//! - `--check`: only report stale files in the XML folder, exit 1 if any

use std::path::PathBuf;
use std::process::ExitCode;

use spacecraft_fmus::package::{platform_lib_ext, stale_model_descriptions, write_fmu, write_model_descriptions, Binary, LIB_EXT, PLATFORM};
use spacecraft_fmus::registry;

fn main() -> ExitCode {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut lib = root.join(format!("target/release/libspacecraft_fmus.{LIB_EXT}"));
    let mut fmus = root.join("fmus");
    let mut xml = root.join("modelDescription");
    let mut extra: Vec<(String, PathBuf)> = vec![];
    let mut check = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--lib" => lib = args.next().map(PathBuf::from).unwrap_or(lib),
            "--add-lib" => {
                let spec = args.next().unwrap_or_default();
                match spec.split_once('=') {
                    Some((platform, path)) if platform_lib_ext(platform).is_some() && !path.is_empty() => {
                        extra.push((platform.to_string(), PathBuf::from(path)))
                    }
                    _ => {
                        eprintln!("package: --add-lib wants PLATFORM=PATH with PLATFORM linux64, win64 or darwin64, got {spec:?}");
                        return ExitCode::FAILURE;
                    }
                }
            }
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
    let mut extra_bytes = vec![];
    for (platform, path) in &extra {
        if platform == PLATFORM || extra_bytes.iter().any(|(p, _): &(&str, Vec<u8>)| p == platform) {
            eprintln!("package: two binaries for {platform}");
            return ExitCode::FAILURE;
        }
        match std::fs::read(path) {
            Ok(b) => extra_bytes.push((platform.as_str(), b)),
            Err(e) => {
                eprintln!("package: cannot read the {platform} library {} ({e})", path.display());
                return ExitCode::FAILURE;
            }
        }
    }
    let mut binaries = vec![Binary::host(&library)];
    for (platform, bytes) in &extra_bytes {
        binaries.push(Binary { platform, ext: platform_lib_ext(platform).unwrap_or("so"), bytes });
    }
    if let Err(e) = write_model_descriptions(&xml) {
        eprintln!("package: cannot write model descriptions: {e}");
        return ExitCode::FAILURE;
    }
    if let Err(e) = spacecraft_fmus::docs::write_pages(&root.join("docs")) {
        eprintln!("package: cannot write docs/models and docs/references.md: {e}");
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
