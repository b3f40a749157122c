//! `fmu-package`, the packaging tool, as a library: reads the models a built shared library declares
//! (its catalogue, see `spacecraft_fmus::export`), checks the declarations, and writes
//! `modelDescription.xml`, `documentation/index.html` and one `.fmu` archive per model. One build per
//! platform serves every model of a library: it is copied into each archive as
//! `binaries/linux64/<Model>.so` (and `binaries/win64/<Model>.dll` when a Windows build is given), and
//! `fmi2Instantiate` picks the model by file name and GUID. All platforms share one `modelDescription.xml`.
//! The same library also exports the FMI 3.0 functions: [`write_fmu3`] writes the FMI 3.0 archive
//! (`fmus/fmi3/<Model>.fmu`, `binaries/<platform tuple>/<Model>.<ext>`, FMI 3.0 model description).
//!
//! The only input is the library's catalogue (`spacecraft_fmus::catalogue`): declarations, GUIDs,
//! package, the FMI layer's log categories and reserved value references, families and bibliography.
//! This crate never uses the runtime's registry or FMI layer (its unit tests build the project's
//! catalogue in-process with `spacecraft_fmus::export::project_catalogue`, as `src/cdylib` exports it).
//!
//! Files: [`checks`] (what the type system cannot check), [`structure`] (dependency lists), [`xml`]
//! (XML helpers and the elements both versions share), [`fmi2`] and [`fmi3`] (the two model
//! descriptions), [`clocks`] (the FMI 3.0 clocks of sampled models), [`html`]
//! (documentation/index.html), [`docs`] (the Markdown model pages), [`platforms`] and [`build`]
//! (binaries), `load` (reading a library's catalogue).
//!
//! This crate, not the runtime, links the XML writer and `zip`.

pub mod build;
pub mod checks;
pub mod clocks;
pub mod docs;
pub mod fmi2;
pub mod fmi3;
pub mod html;
mod load;
pub mod names;
pub mod platforms;
pub mod structure;
pub mod terminals;
pub mod xml;

use std::fs;
use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

pub use crate::checks::check_catalogue;
pub use crate::fmi2::model_description;
pub use crate::fmi3::model_description3;
pub use crate::html::documentation_html;
use spacecraft_fmus::catalogue::{guid_of, read_catalogue, Catalogue, ModelDescription, RUNTIME_VERSION};

/// The catalogue a built shared library declares, checked: the declarations must be consistent
/// ([`check_catalogue`]), the names unique, and each GUID the one this tool computes from the same
/// declarations (otherwise the library was built with another version of `spacecraft_fmus`).
pub fn read_library(lib: &Path) -> Result<Catalogue, String> {
    let bytes = load::catalogue_bytes(lib)?;
    let cat = read_catalogue(&bytes).map_err(|e| format!("{}: {e}", lib.display()))?;
    if cat.models.is_empty() {
        return Err(format!("{}: the library declares no model", lib.display()));
    }
    check_catalogue(&cat)?;
    for (i, m) in cat.models.iter().enumerate() {
        let fresh = guid_of(m);
        if fresh != m.guid {
            return Err(format!(
                "{}: the library was built with spacecraft_fmus {} and this tool is {RUNTIME_VERSION} (GUID {} vs {fresh}); build both from the same spacecraft_fmus",
                m.name, cat.runtime_version, m.guid
            ));
        }
        if cat.models[..i].iter().any(|o| o.name == m.name) {
            return Err(format!("the library declares two models named {}", m.name));
        }
    }
    Ok(cat)
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
type Render = fn(&Catalogue, &ModelDescription) -> String;

fn write_rendered(cat: &Catalogue, dir: &Path, render: Render) -> std::io::Result<Vec<String>> {
    fs::create_dir_all(dir)?;
    let mut written = vec![];
    for m in &cat.models {
        let p = dir.join(format!("{}.xml", m.name));
        fs::write(&p, render(cat, m))?;
        written.push(p.display().to_string());
    }
    Ok(written)
}

fn stale_rendered(cat: &Catalogue, dir: &Path, render: Render, prefix: &str) -> Vec<String> {
    cat.models
        .iter()
        .filter(|m| {
            fs::read_to_string(dir.join(format!("{}.xml", m.name))).ok().as_deref() != Some(render(cat, m).as_str())
        })
        .map(|m| format!("{prefix}{}", m.name))
        .collect()
}

/// Writes `<dir>/<Model>.xml` for every model; returns the paths written.
pub fn write_model_descriptions(cat: &Catalogue, dir: &Path) -> std::io::Result<Vec<String>> {
    write_rendered(cat, dir, model_description)
}

/// Names of the models whose committed `<dir>/<Model>.xml` differs from the generated one.
pub fn stale_model_descriptions(cat: &Catalogue, dir: &Path) -> Vec<String> {
    stale_rendered(cat, dir, model_description, "")
}

/// Writes `<dir>/<Model>.xml` (FMI 3.0) for every model; returns the paths written.
pub fn write_model_descriptions3(cat: &Catalogue, dir: &Path) -> std::io::Result<Vec<String>> {
    write_rendered(cat, dir, model_description3)
}

/// Names of the models whose committed FMI 3.0 `<dir>/<Model>.xml` differs from the generated one.
pub fn stale_model_descriptions3(cat: &Catalogue, dir: &Path) -> Vec<String> {
    stale_rendered(cat, dir, model_description3, "fmi3/")
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
pub fn write_fmu(
    cat: &Catalogue,
    m: &ModelDescription,
    binaries: &[Binary],
    out_dir: &Path,
) -> std::io::Result<std::path::PathBuf> {
    let name = &m.name;
    let builds: Vec<(&str, &[u8])> = binaries.iter().map(|b| (b.platform, b.bytes)).collect();
    let folders = platforms::fmi2_binaries(&builds).map_err(std::io::Error::other)?;
    let files: Vec<(String, &[u8])> = folders
        .iter()
        .map(|(dir, ext, bytes)| (format!("binaries/{dir}/{name}.{ext}"), bytes.as_ref()))
        .collect();
    write_archive(cat, m, &model_description(cat, m), &files, out_dir)
}

/// Writes one FMI 3.0 `.fmu` archive: the FMI 3.0 model description, the same binaries under FMI 3.0
/// platform tuples (`binaries/x86_64-linux/<Model>.so`, ...) and the documentation. Deterministic.
pub fn write_fmu3(
    cat: &Catalogue,
    m: &ModelDescription,
    binaries: &[Binary],
    out_dir: &Path,
) -> std::io::Result<std::path::PathBuf> {
    let name = &m.name;
    let files = binaries
        .iter()
        .map(|b| {
            let tuple = platform_tuple(b).ok_or_else(|| {
                std::io::Error::other(format!("no FMI 3.0 platform tuple for the {} binary", b.platform))
            })?;
            Ok((format!("binaries/{tuple}/{name}.{}", b.ext), b.bytes))
        })
        .collect::<std::io::Result<Vec<_>>>()?;
    let terminals = terminals::terminals_and_icons(cat, m);
    let mut files = files;
    if let Some(t) = &terminals {
        files.push((terminals::ARCHIVE_PATH.to_string(), t.as_bytes()));
    }
    write_archive(cat, m, &model_description3(cat, m), &files, out_dir)
}

/// The archive both FMI versions share: `modelDescription.xml`, the binaries at their paths (and, FMI
/// 3.0, the terminals file), then `documentation/index.html`, with fixed timestamps and order.
fn write_archive(
    cat: &Catalogue,
    m: &ModelDescription,
    description: &str,
    binaries: &[(String, &[u8])],
    out_dir: &Path,
) -> std::io::Result<std::path::PathBuf> {
    if binaries.is_empty() {
        return Err(std::io::Error::other("no binary to package"));
    }
    fs::create_dir_all(out_dir)?;
    let path = out_dir.join(format!("{}.fmu", m.name));
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
        add(
            &mut zip,
            name,
            bytes,
            if name.starts_with("binaries/") { 0o755 } else { 0o644 },
        )?;
    }
    add(
        &mut zip,
        "documentation/index.html",
        documentation_html(cat, m).as_bytes(),
        0o644,
    )?;
    zip.finish().map_err(std::io::Error::other)?;
    Ok(path)
}

/// The project's catalogue for the unit tests (what `src/cdylib` exports, built in this process).
#[cfg(test)]
pub(crate) mod tests_support {
    pub fn project() -> spacecraft_fmus::catalogue::Catalogue {
        spacecraft_fmus::export::project_catalogue()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_platforms() -> [Binary<'static>; 2] {
        [
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
        ]
    }

    #[test]
    fn one_archive_holds_every_platform_binary_and_one_model_description() {
        let cat = tests_support::project();
        let m = &cat.models[0];
        let dir = std::env::temp_dir().join(format!("scfmu-package-test-{}", std::process::id()));
        let bins = two_platforms();
        let path = write_fmu(&cat, m, &bins, &dir).unwrap();
        let mut zip = zip::ZipArchive::new(fs::File::open(&path).unwrap()).unwrap();
        let names: Vec<String> = (0..zip.len())
            .map(|i| zip.by_index(i).unwrap().name().unwrap().to_string())
            .collect();
        let n = &m.name;
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
        assert!(write_fmu(&cat, m, &[], &dir).is_err());
        fs::remove_dir_all(&dir).ok();
        assert_eq!(platform_lib_ext("win64"), Some("dll"));
    }

    #[test]
    fn the_fmi3_archive_holds_the_same_binaries_under_platform_tuples() {
        let cat = tests_support::project();
        let m = &cat.models[0];
        let n = &m.name;
        let dir = std::env::temp_dir().join(format!("scfmu-package-test3-{}", std::process::id()));
        let bins = two_platforms();
        let path3 = write_fmu3(&cat, m, &bins, &dir.join("fmi3")).unwrap();
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
