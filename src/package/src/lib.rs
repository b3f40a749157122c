//! `fmu-package`, the packaging tool, as a library: reads the models a built shared library declares
//! (its catalogue, see `spacecraft_fmus::export`), checks the declarations, and writes
//! `modelDescription.xml`, `documentation/index.html` and one `.fmu` archive per model. One build per
//! platform serves every model of a library: it is copied into each archive as
//! `binaries/linux64/<Model>.so` (and `binaries/win64/<Model>.dll` when a Windows build is given), and
//! `fmi2Instantiate` picks the model by file name and GUID. All platforms share one `modelDescription.xml`.
//! The same library also exports the FMI 3.0 functions: [`write_fmu3`] writes the FMI 3.0 archive
//! (`fmus/fmi3/<Model>.fmu`, `binaries/<platform tuple>/<Model>.<ext>`, FMI 3.0 model description).
//!
//! This crate, not the runtime, links the XML writer and `zip`.

pub mod build;
pub mod description;
pub mod description3;
pub mod docs;
mod load;
pub mod names;
pub mod platforms;
pub mod references;
pub mod structure;

use std::fs;
use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

use crate::description::{check_declarations, documentation_html, model_description};
use crate::description3::model_description3;
use spacecraft_fmus::export::{read_catalogue, PackageInfo, RUNTIME_VERSION};
use spacecraft_fmus::model::guid::compute_fresh;
use spacecraft_fmus::model::ModelEntry;

/// A model to package: its declarations, the GUID its binary accepts and the package exporting it.
#[derive(Clone, Copy)]
pub struct Unit {
    pub entry: ModelEntry,
    pub guid: &'static str,
    pub package: &'static PackageInfo,
}

impl Unit {
    /// A model of this process's registry (the project's own models, for pages and tests).
    pub fn registered(entry: &ModelEntry) -> Unit {
        static PROJECT: std::sync::OnceLock<PackageInfo> = std::sync::OnceLock::new();
        Unit {
            entry: *entry,
            guid: Box::leak(spacecraft_fmus::model::guid::guid(entry).as_str().into()),
            package: PROJECT.get_or_init(description::project_package),
        }
    }

    pub fn name(&self) -> &'static str {
        self.entry.info.name
    }
}

/// The models a built shared library declares, read from its catalogue and checked: the declarations
/// must be consistent ([`check_declarations`]) and each GUID must be the one this tool computes from the
/// same declarations (otherwise the library was built with another version of `spacecraft_fmus`).
pub fn units_of_library(lib: &Path) -> Result<Vec<Unit>, String> {
    let bytes = load::catalogue_bytes(lib)?;
    let cat = read_catalogue(&bytes).map_err(|e| format!("{}: {e}", lib.display()))?;
    if cat.models.is_empty() {
        return Err(format!("{}: the library declares no model", lib.display()));
    }
    let package: &'static PackageInfo = Box::leak(Box::new(cat.package));
    let mut units = Vec::new();
    for m in cat.models {
        let guid: &'static str = Box::leak(m.guid.clone().into_boxed_str());
        let entry = m.into_entry();
        check_declarations(&entry)?;
        let fresh = compute_fresh(&entry);
        if fresh != guid {
            return Err(format!(
                "{}: the library was built with spacecraft_fmus {} and this tool is {RUNTIME_VERSION} (GUID {guid} vs {fresh}); build both from the same spacecraft_fmus",
                entry.info.name, cat.runtime_version
            ));
        }
        if units.iter().any(|u: &Unit| u.name() == entry.info.name) {
            return Err(format!("the library declares two models named {}", entry.info.name));
        }
        units.push(Unit { entry, guid, package });
    }
    Ok(units)
}

/// Platform folder of the binary inside the FMU.
pub const PLATFORM: &str = if cfg!(all(target_os = "linux", target_pointer_width = "64")) {
    "linux64"
} else if cfg!(all(target_os = "windows", target_pointer_width = "64")) {
    "win64"
} else if cfg!(target_os = "macos") {
    "darwin64"
} else {
    "unknown"
};

/// Shared-library file extension of the platform.
pub const LIB_EXT: &str = if cfg!(target_os = "windows") {
    "dll"
} else if cfg!(target_os = "macos") {
    "dylib"
} else {
    "so"
};

/// Shared-library extension of a platform key (`None` for one we do not build); keys: [`platforms`].
pub fn platform_lib_ext(platform: &str) -> Option<&'static str> {
    platforms::lib_ext(platform)
}

/// A model-description writer: FMI 2.0 ([`model_description`]) or FMI 3.0 ([`model_description3`]).
type Render = fn(&ModelEntry, &str, &PackageInfo) -> String;

fn write_rendered(units: &[Unit], dir: &Path, render: Render) -> std::io::Result<Vec<String>> {
    fs::create_dir_all(dir)?;
    let mut written = vec![];
    for u in units {
        let p = dir.join(format!("{}.xml", u.name()));
        fs::write(&p, render(&u.entry, u.guid, u.package))?;
        written.push(p.display().to_string());
    }
    Ok(written)
}

fn stale_rendered(units: &[Unit], dir: &Path, render: Render, prefix: &str) -> Vec<String> {
    units
        .iter()
        .filter(|u| {
            fs::read_to_string(dir.join(format!("{}.xml", u.name())))
                .ok()
                .as_deref()
                != Some(render(&u.entry, u.guid, u.package).as_str())
        })
        .map(|u| format!("{prefix}{}", u.name()))
        .collect()
}

/// Writes `<dir>/<Model>.xml` for every unit; returns the paths written.
pub fn write_model_descriptions(units: &[Unit], dir: &Path) -> std::io::Result<Vec<String>> {
    write_rendered(units, dir, model_description)
}

/// Names of the units whose committed `<dir>/<Model>.xml` differs from the generated one.
pub fn stale_model_descriptions(units: &[Unit], dir: &Path) -> Vec<String> {
    stale_rendered(units, dir, model_description, "")
}

/// Writes `<dir>/<Model>.xml` (FMI 3.0) for every unit; returns the paths written.
pub fn write_model_descriptions3(units: &[Unit], dir: &Path) -> std::io::Result<Vec<String>> {
    write_rendered(units, dir, model_description3)
}

/// Names of the units whose committed FMI 3.0 `<dir>/<Model>.xml` differs from the generated one.
pub fn stale_model_descriptions3(units: &[Unit], dir: &Path) -> Vec<String> {
    stale_rendered(units, dir, model_description3, "fmi3/")
}

/// FMI 3.0 platform tuple of a build ([`platforms::tuple`]). A `darwin64` build is told apart by its
/// Mach-O CPU type (x86_64 or arm64).
pub fn platform_tuple(b: &Binary) -> Option<&'static str> {
    platforms::tuple(b.platform, b.bytes)
}

/// One platform's build of the cdylib, to be stored as `binaries/<platform>/<Model>.<ext>`.
#[derive(Clone, Copy, Debug)]
pub struct Binary<'a> {
    /// Platform key ([`platforms`]): `linux64`, `win64`, `aarch64-linux`, `x86_64-darwin`, `aarch64-darwin`, `darwin64`.
    pub platform: &'a str,
    /// Shared-library extension on that platform: `so`, `dll`, `dylib`.
    pub ext: &'a str,
    pub bytes: &'a [u8],
}

impl<'a> Binary<'a> {
    /// The build for the platform this code was compiled for.
    pub fn host(bytes: &'a [u8]) -> Self {
        Binary {
            platform: PLATFORM,
            ext: LIB_EXT,
            bytes,
        }
    }
}

/// Writes one `.fmu` archive (deterministic: fixed timestamps, fixed order) holding the model
/// description, one binary per entry of `binaries` (in the given order; the macOS builds joined into
/// one universal `darwin64` file, [`platforms::fmi2_binaries`]) and the documentation.
pub fn write_fmu(unit: &Unit, binaries: &[Binary], out_dir: &Path) -> std::io::Result<std::path::PathBuf> {
    let name = unit.entry.info.name;
    let builds: Vec<(&str, &[u8])> = binaries.iter().map(|b| (b.platform, b.bytes)).collect();
    let folders = platforms::fmi2_binaries(&builds).map_err(std::io::Error::other)?;
    let files: Vec<(String, &[u8])> = folders
        .iter()
        .map(|(dir, ext, bytes)| (format!("binaries/{dir}/{name}.{ext}"), bytes.as_ref()))
        .collect();
    write_archive(
        unit,
        &model_description(&unit.entry, unit.guid, unit.package),
        &files,
        out_dir,
    )
}

/// Writes one FMI 3.0 `.fmu` archive: the FMI 3.0 model description, the same binaries under FMI 3.0
/// platform tuples (`binaries/x86_64-linux/<Model>.so`, ...) and the documentation. Deterministic.
pub fn write_fmu3(unit: &Unit, binaries: &[Binary], out_dir: &Path) -> std::io::Result<std::path::PathBuf> {
    let name = unit.entry.info.name;
    let files = binaries
        .iter()
        .map(|b| {
            let tuple = platform_tuple(b).ok_or_else(|| {
                std::io::Error::other(format!("no FMI 3.0 platform tuple for the {} binary", b.platform))
            })?;
            Ok((format!("binaries/{tuple}/{name}.{}", b.ext), b.bytes))
        })
        .collect::<std::io::Result<Vec<_>>>()?;
    write_archive(
        unit,
        &model_description3(&unit.entry, unit.guid, unit.package),
        &files,
        out_dir,
    )
}

/// The archive both FMI versions share: `modelDescription.xml`, the binaries at their paths, then
/// `documentation/index.html`, with fixed timestamps and order.
fn write_archive(
    unit: &Unit,
    description: &str,
    binaries: &[(String, &[u8])],
    out_dir: &Path,
) -> std::io::Result<std::path::PathBuf> {
    let entry = &unit.entry;
    if binaries.is_empty() {
        return Err(std::io::Error::other("no binary to package"));
    }
    fs::create_dir_all(out_dir)?;
    let path = out_dir.join(format!("{}.fmu", entry.info.name));
    let mut zip = ZipWriter::new(fs::File::create(&path)?);
    let opts = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .last_modified_time(DateTime::default());
    let add = |zip: &mut ZipWriter<fs::File>, name: &str, data: &[u8], mode: u32| -> std::io::Result<()> {
        zip.start_file(name, opts.unix_permissions(mode))
            .map_err(std::io::Error::other)?;
        zip.write_all(data)
    };
    add(&mut zip, "modelDescription.xml", description.as_bytes(), 0o644)?;
    for (name, bytes) in binaries {
        add(&mut zip, name, bytes, 0o755)?;
    }
    add(
        &mut zip,
        "documentation/index.html",
        documentation_html(entry, unit.guid).as_bytes(),
        0o644,
    )?;
    zip.finish().map_err(std::io::Error::other)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_archive_holds_every_platform_binary_and_one_model_description() {
        let unit = Unit::registered(&spacecraft_fmus::registry::ALL[0]);
        let entry = &unit.entry;
        let dir = std::env::temp_dir().join(format!("scfmu-package-test-{}", std::process::id()));
        let bins = [
            Binary {
                platform: "linux64",
                ext: "so",
                bytes: b"ELF...",
            },
            Binary {
                platform: "win64",
                ext: "dll",
                bytes: b"MZ...",
            },
        ];
        let path = write_fmu(&unit, &bins, &dir).unwrap();
        let mut zip = zip::ZipArchive::new(fs::File::open(&path).unwrap()).unwrap();
        let names: Vec<String> = (0..zip.len())
            .map(|i| zip.by_index(i).unwrap().name().unwrap().to_string())
            .collect();
        let n = entry.info.name;
        assert_eq!(
            names,
            vec![
                "modelDescription.xml".to_string(),
                format!("binaries/linux64/{n}.so"),
                format!("binaries/win64/{n}.dll"),
                "documentation/index.html".to_string(),
            ]
        );
        let mut dll = vec![];
        std::io::Read::read_to_end(&mut zip.by_name(&format!("binaries/win64/{n}.dll")).unwrap(), &mut dll).unwrap();
        assert_eq!(dll, b"MZ...");
        assert!(write_fmu(&unit, &[], &dir).is_err());
        fs::remove_dir_all(&dir).ok();
        assert_eq!(platform_lib_ext("win64"), Some("dll"));
        // FMI 3.0: the same binaries under platform tuples
        let path3 = write_fmu3(&unit, &bins, &dir.join("fmi3")).unwrap();
        let mut zip3 = zip::ZipArchive::new(fs::File::open(&path3).unwrap()).unwrap();
        let names3: Vec<String> = (0..zip3.len())
            .map(|i| zip3.by_index(i).unwrap().name().unwrap().to_string())
            .collect();
        assert_eq!(
            names3[1..3],
            [
                format!("binaries/x86_64-linux/{n}.so"),
                format!("binaries/x86_64-windows/{n}.dll")
            ]
        );
        let mut x = String::new();
        std::io::Read::read_to_string(&mut zip3.by_name("modelDescription.xml").unwrap(), &mut x).unwrap();
        assert!(x.contains(r#"fmiVersion="3.0""#));
        let mac = |cpu: u8| [0xcf, 0xfa, 0xed, 0xfe, cpu, 0, 0, 0x01];
        assert_eq!(
            platform_tuple(&Binary {
                platform: "darwin64",
                ext: "dylib",
                bytes: &mac(0x0c)
            }),
            Some("aarch64-darwin")
        );
        assert_eq!(
            platform_tuple(&Binary {
                platform: "darwin64",
                ext: "dylib",
                bytes: &mac(0x07)
            }),
            Some("x86_64-darwin")
        );
        assert_eq!(
            platform_tuple(&Binary {
                platform: "darwin64",
                ext: "dylib",
                bytes: b"junk"
            }),
            None
        );
        fs::remove_dir_all(&dir).ok();
        assert_eq!(platform_lib_ext("win32"), None);
    }
}
