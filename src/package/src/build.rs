//! Building a model crate: `cargo build --release --lib` for the host, and the Windows x86-64 cross
//! build through `scripts/build_win64.sh` when its toolchain is installed.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Extension of the host's shared libraries.
pub const HOST_LIB_EXT: &str = if cfg!(target_os = "macos") {
    "dylib"
} else if cfg!(windows) {
    "dll"
} else {
    "so"
};

/// Builds the `cdylib` of the package at `manifest` in release mode and returns the library's path.
/// Compiler messages go to stderr as cargo renders them, so an error in a model declaration reads as
/// it does in `cargo build`.
pub fn cargo_build(manifest: &Path, locked: bool) -> Result<PathBuf, String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.args([
        "build",
        "--release",
        "--lib",
        "--message-format=json-render-diagnostics",
        "--manifest-path",
    ])
    .arg(manifest);
    if locked {
        cmd.arg("--locked");
    }
    let out = cmd
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo build of {} failed (messages above)", manifest.display()));
    }
    let want = manifest
        .canonicalize()
        .map_err(|e| format!("{}: {e}", manifest.display()))?;
    let mut libs = vec![];
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let Ok(msg) = serde_json::from_str::<serde_json::Value>(line) else {
            continue;
        };
        if msg["reason"] != "compiler-artifact"
            || !msg["target"]["crate_types"]
                .as_array()
                .is_some_and(|t| t.iter().any(|x| x == "cdylib"))
        {
            continue;
        }
        let from = msg["manifest_path"]
            .as_str()
            .map(PathBuf::from)
            .and_then(|p| p.canonicalize().ok());
        if from.as_deref() != Some(want.as_path()) {
            continue;
        }
        for f in msg["filenames"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|f| f.as_str())
        {
            if f.ends_with(&format!(".{HOST_LIB_EXT}")) {
                libs.push(PathBuf::from(f));
            }
        }
    }
    match libs.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(format!(
            "{} builds no cdylib: add crate-type = [\"cdylib\"] under [lib]",
            manifest.display()
        )),
        _ => Err(format!(
            "{} builds several shared libraries: {libs:?}",
            manifest.display()
        )),
    }
}

/// The project's cross-build script, next to this tool's sources.
fn win64_script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/build_win64.sh")
}

/// Whether the Windows cross toolchain is installed; `Err` says what is missing.
pub fn win64_available() -> Result<(), String> {
    let script = win64_script();
    if !script.exists() {
        return Err(format!("{} not found", script.display()));
    }
    let out = Command::new(&script)
        .arg("--check")
        .stdout(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", script.display()))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).trim().to_string())
    }
}

/// Cross-builds the package at `manifest` for Windows x86-64 and returns the DLL named like the host
/// library `host_lib` (`libname.so` → `name.dll`).
pub fn win64_build(manifest: &Path, host_lib: &Path) -> Result<PathBuf, String> {
    let script = win64_script();
    let out = Command::new(&script)
        .arg("--manifest-path")
        .arg(manifest)
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", script.display()))?;
    if !out.status.success() {
        return Err(format!(
            "the Windows cross build of {} failed (messages above)",
            manifest.display()
        ));
    }
    let dir = String::from_utf8_lossy(&out.stdout)
        .lines()
        .last()
        .unwrap_or_default()
        .trim()
        .to_string();
    let stem = host_lib
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = stem.strip_prefix("lib").unwrap_or(&stem);
    let dll = Path::new(&dir).join(format!("{stem}.dll"));
    if dll.is_file() {
        Ok(dll)
    } else {
        Err(format!("the Windows cross build did not produce {}", dll.display()))
    }
}
