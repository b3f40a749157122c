//! `fmu-package`: builds a model crate and packages every model it exports as an FMU.
//!
//! ```text
//! fmu-package [--crate DIR] [--lib PATH] [--out DIR] [--xml DIR] [--win64 auto|yes|no]
//!             [--add-lib PLATFORM=PATH]... [--locked] [--check]
//! ```
//! - `--crate DIR`: the model crate (a `cdylib` calling `spacecraft_fmus::export_fmus!`); it is built
//!   with `cargo build --release --lib`. Default: this project's `src/cdylib` (all registered models).
//! - `--lib PATH`: package an already built host library instead of building a crate; with `--crate`,
//!   that crate's library as already built (no cargo run: `scripts/build_fmus.sh` passes the library its
//!   own `cargo build` made, which a second cargo run with other unified features would compile again).
//! - `--out DIR`: where `<Model>.fmu` go (default `DIR/fmus`; for the project, `fmus/`); the FMI 3.0
//!   archives of the same models go to `DIR/fmi3/<Model>.fmu`.
//! - `--xml DIR`: also write `<Model>.xml` there, and the FMI 3.0 ones in `DIR/fmi3/` (the project:
//!   `modelDescription/`, always).
//! - `--win64`: add `binaries/win64/<Model>.dll` from `scripts/build_win64.sh`: `auto` (default) when
//!   the cross toolchain is installed, `yes` requires it, `no` skips it (also `SCFMU_NO_WIN64=1`).
//! - `--add-lib PLATFORM=PATH`: store another platform's build of the same crate (linux64, win64,
//!   aarch64-linux, x86_64-darwin, aarch64-darwin, darwin64; folders: src/package/src/platforms.rs).
//! - `--check`: write nothing; exit 1 if the XML folder (and, for the project, the generated pages under
//!   docs/) differ from what the declarations generate.
//!
//! For the project it also writes the model pages `docs/models/<family>.md` and `docs/references.md`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use spacecraft_fmus::catalogue::Catalogue;
use spacecraft_fmus_package::build::{cargo_build, win64_available, win64_build};
use spacecraft_fmus_package::{
    platform_lib_ext, read_library, stale_model_descriptions, stale_model_descriptions3, write_fmu, write_fmu3,
    write_model_descriptions, write_model_descriptions3, Binary, PLATFORM,
};

struct Args {
    krate: Option<PathBuf>,
    lib: Option<PathBuf>,
    out: Option<PathBuf>,
    xml: Option<PathBuf>,
    win64: String,
    extra: Vec<(String, PathBuf)>,
    locked: bool,
    check: bool,
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        krate: None,
        lib: None,
        out: None,
        xml: None,
        win64: "auto".into(),
        extra: vec![],
        locked: false,
        check: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or_else(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--crate" => a.krate = Some(PathBuf::from(value("--crate")?)),
            "--lib" => a.lib = Some(PathBuf::from(value("--lib")?)),
            "--out" | "--fmus" => a.out = Some(PathBuf::from(value("--out")?)),
            "--xml" => a.xml = Some(PathBuf::from(value("--xml")?)),
            "--win64" => {
                a.win64 = value("--win64")?;
                if !["auto", "yes", "no"].contains(&a.win64.as_str()) {
                    return Err(format!("--win64 takes auto, yes or no, not {:?}", a.win64));
                }
            }
            "--add-lib" => {
                let spec = value("--add-lib")?;
                match spec.split_once('=') {
                    Some((platform, path)) if platform_lib_ext(platform).is_some() && !path.is_empty() => {
                        a.extra.push((platform.into(), PathBuf::from(path)))
                    }
                    _ => {
                        return Err(format!(
                            "--add-lib wants PLATFORM=PATH with PLATFORM {}, got {spec:?}",
                            spacecraft_fmus_package::platforms::KEYS
                        ))
                    }
                }
            }
            "--locked" => a.locked = true,
            "--check" => a.check = true,
            "-h" | "--help" => {
                println!(
                    "{}",
                    include_str!("main.rs")
                        .lines()
                        .take_while(|l| l.starts_with("//!"))
                        .map(|l| l.trim_start_matches("//!").strip_prefix(' ').unwrap_or(""))
                        .collect::<Vec<_>>()
                        .join("\n")
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other} (see --help)")),
        }
    }
    Ok(a)
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmu-package: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let args = parse()?;
    // the project this tool was built from (an installed tool keeps working for a user's crate when
    // that folder is gone: it is then never the project, and has no Windows cross-build script)
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let root = root.canonicalize().unwrap_or(root);
    let project_crate = root.join("src/cdylib");
    let krate = args
        .krate
        .clone()
        .or_else(|| args.lib.is_none().then(|| project_crate.clone()));
    let is_project = match &krate {
        Some(k) => k.canonicalize().ok() == project_crate.canonicalize().ok(),
        None => false,
    };
    let manifest = krate.as_ref().map(|k| k.join("Cargo.toml"));
    if let Some(m) = &manifest {
        if !m.is_file() {
            return Err(format!(
                "{} not found: --crate wants the folder of a Cargo package",
                m.display()
            ));
        }
    }
    let lib = match (&args.lib, &manifest) {
        (Some(l), _) => l.clone(),
        (None, Some(m)) => cargo_build(m, args.locked)?,
        (None, None) => unreachable!("a crate or a library is always given"),
    };
    let cat = read_library(&lib)?;
    let xml = args
        .xml
        .clone()
        .or_else(|| is_project.then(|| root.join("modelDescription")));
    let docs = is_project.then(|| root.join("docs"));

    if args.check {
        return check(&cat, xml.as_deref(), docs.as_deref());
    }

    let host = std::fs::read(&lib).map_err(|e| format!("cannot read {} ({e})", lib.display()))?;
    let extra = other_platforms(&args, manifest.as_deref(), &lib)?;
    let mut binaries = vec![Binary::host(&host)];
    for (platform, bytes) in &extra {
        if binaries.iter().any(|b| b.platform == platform) {
            return Err(format!("two binaries for {platform}"));
        }
        binaries.push(Binary {
            platform,
            ext: platform_lib_ext(platform).unwrap_or("so"),
            bytes,
        });
    }

    write_generated(&cat, xml.as_deref(), docs.as_deref())?;
    let out = args.out.clone().unwrap_or_else(|| {
        if is_project {
            root.join("fmus")
        } else {
            krate.clone().unwrap_or_default().join("fmus")
        }
    });
    for m in &cat.models {
        let p = write_fmu(&cat, m, &binaries, &out).map_err(|e| format!("{}: {e}", m.name))?;
        println!(
            "wrote {} ({})",
            p.display(),
            binaries.iter().map(|b| b.platform).collect::<Vec<_>>().join(" + ")
        );
        let p3 = write_fmu3(&cat, m, &binaries, &out.join("fmi3")).map_err(|e| format!("{} (FMI 3.0): {e}", m.name))?;
        println!("wrote {} (FMI 3.0)", p3.display());
    }
    Ok(())
}

/// Writes the XML folder (FMI 2.0 and, in `fmi3/`, FMI 3.0) and, for the project, the generated pages.
fn write_generated(cat: &Catalogue, xml: Option<&Path>, docs: Option<&Path>) -> Result<(), String> {
    if let Some(x) = xml {
        write_model_descriptions(cat, x)
            .map_err(|e| format!("cannot write model descriptions to {}: {e}", x.display()))?;
        write_model_descriptions3(cat, &x.join("fmi3"))
            .map_err(|e| format!("cannot write FMI 3.0 model descriptions to {}/fmi3: {e}", x.display()))?;
        spacecraft_fmus_package::terminals::write_terminals(cat, &x.join("fmi3/terminalsAndIcons"))
            .map_err(|e| format!("cannot write terminals to {}/fmi3/terminalsAndIcons: {e}", x.display()))?;
    }
    if let Some(d) = docs {
        spacecraft_fmus_package::docs::write_pages(d, cat)
            .map_err(|e| format!("cannot write docs/models and docs/references.md: {e}"))?;
    }
    Ok(())
}

/// `--check`: whether the XML folder and (for the project) the generated pages are what the catalogue gives.
fn check(cat: &Catalogue, xml: Option<&Path>, docs: Option<&Path>) -> Result<(), String> {
    let mut stale = vec![];
    if let Some(x) = xml {
        stale.extend(stale_model_descriptions(cat, x));
        stale.extend(stale_model_descriptions3(cat, &x.join("fmi3")));
        stale.extend(spacecraft_fmus_package::terminals::stale_terminals(
            cat,
            &x.join("fmi3/terminalsAndIcons"),
        ));
    }
    if let Some(d) = docs {
        stale.extend(spacecraft_fmus_package::docs::stale_pages(d, cat));
    }
    if stale.is_empty() {
        println!(
            "model descriptions{} are up to date ({} models)",
            if docs.is_some() { " and docs/" } else { "" },
            cat.models.len()
        );
        return Ok(());
    }
    Err(format!("stale generated files: {}", stale.join(", ")))
}

/// The builds of the other platforms: `--add-lib` files, and the Windows cross build where asked for
/// or available.
fn other_platforms(args: &Args, manifest: Option<&Path>, lib: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut extra: Vec<(String, Vec<u8>)> = vec![];
    for (platform, path) in &args.extra {
        let bytes =
            std::fs::read(path).map_err(|e| format!("cannot read the {platform} library {} ({e})", path.display()))?;
        extra.push((platform.clone(), bytes));
    }
    let no_win64 = args.win64 == "no" || std::env::var("SCFMU_NO_WIN64").as_deref() == Ok("1");
    if !no_win64 && !extra.iter().any(|(p, _)| p == "win64") {
        match (manifest, win64_available()) {
            (Some(m), Ok(())) => {
                let dll = win64_build(m, lib)?;
                extra.push((
                    "win64".into(),
                    std::fs::read(&dll).map_err(|e| format!("cannot read {} ({e})", dll.display()))?,
                ));
            }
            (_, Err(why)) if args.win64 == "yes" => {
                return Err(format!("--win64 yes, but the cross toolchain is not usable: {why}"))
            }
            (None, Ok(())) if args.win64 == "yes" => {
                return Err("--win64 yes needs --crate (the crate is cross-built)".into())
            }
            (_, Err(why)) => eprintln!("fmu-package: no Windows binaries ({why}); packaging {PLATFORM} only"),
            (None, Ok(())) => {}
        }
    }
    Ok(extra)
}
