//! Packaging: `modelDescription/<Model>.xml` and `fmus/<Model>.fmu` for every registered model.
//! One cdylib build per platform serves every FMU: it is copied into each archive as
//! `binaries/linux64/<Model>.so` (and, when the Windows cross build exists, `binaries/win64/<Model>.dll`
//! next to it), and `fmi2Instantiate` picks the model by file name and GUID. All platforms share the one
//! `modelDescription.xml`.

use std::fs;
use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

use crate::description::{documentation_html, model_description};
use crate::model::ModelEntry;
use crate::registry;

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

/// Shared-library extension of an FMI 2.0 platform folder (`None` for a folder we do not build).
pub fn platform_lib_ext(platform: &str) -> Option<&'static str> {
    match platform {
        "linux64" => Some("so"),
        "win64" => Some("dll"),
        "darwin64" => Some("dylib"),
        _ => None,
    }
}

/// Writes `modelDescription/<Model>.xml` for every model; returns the paths written.
pub fn write_model_descriptions(dir: &Path) -> std::io::Result<Vec<String>> {
    fs::create_dir_all(dir)?;
    let mut written = vec![];
    for e in registry::ALL {
        let p = dir.join(format!("{}.xml", e.info.name));
        fs::write(&p, model_description(e))?;
        written.push(p.display().to_string());
    }
    Ok(written)
}

/// Names of the models whose committed `modelDescription/<Model>.xml` differs from the generated one.
pub fn stale_model_descriptions(dir: &Path) -> Vec<String> {
    registry::ALL
        .iter()
        .filter(|e| fs::read_to_string(dir.join(format!("{}.xml", e.info.name))).ok().as_deref() != Some(model_description(e).as_str()))
        .map(|e| e.info.name.to_string())
        .collect()
}

/// One platform's build of the cdylib, to be stored as `binaries/<platform>/<Model>.<ext>`.
#[derive(Clone, Copy, Debug)]
pub struct Binary<'a> {
    /// FMI 2.0 platform folder: `linux64`, `win64`, `darwin64`.
    pub platform: &'a str,
    /// Shared-library extension on that platform: `so`, `dll`, `dylib`.
    pub ext: &'a str,
    pub bytes: &'a [u8],
}

impl<'a> Binary<'a> {
    /// The build for the platform this code was compiled for.
    pub fn host(bytes: &'a [u8]) -> Self {
        Binary { platform: PLATFORM, ext: LIB_EXT, bytes }
    }
}

/// Writes one `.fmu` archive (deterministic: fixed timestamps, fixed order) holding the model
/// description, one binary per entry of `binaries` (in the given order) and the documentation.
pub fn write_fmu(entry: &ModelEntry, binaries: &[Binary], out_dir: &Path) -> std::io::Result<std::path::PathBuf> {
    if binaries.is_empty() {
        return Err(std::io::Error::other("no binary to package"));
    }
    fs::create_dir_all(out_dir)?;
    let path = out_dir.join(format!("{}.fmu", entry.info.name));
    let mut zip = ZipWriter::new(fs::File::create(&path)?);
    let opts = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated).last_modified_time(DateTime::default());
    let add = |zip: &mut ZipWriter<fs::File>, name: &str, data: &[u8], mode: u32| -> std::io::Result<()> {
        zip.start_file(name, opts.unix_permissions(mode)).map_err(std::io::Error::other)?;
        zip.write_all(data)
    };
    add(&mut zip, "modelDescription.xml", model_description(entry).as_bytes(), 0o644)?;
    for b in binaries {
        add(&mut zip, &format!("binaries/{}/{}.{}", b.platform, entry.info.name, b.ext), b.bytes, 0o755)?;
    }
    add(&mut zip, "documentation/index.html", documentation_html(entry).as_bytes(), 0o644)?;
    zip.finish().map_err(std::io::Error::other)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_archive_holds_every_platform_binary_and_one_model_description() {
        let entry = &registry::ALL[0];
        let dir = std::env::temp_dir().join(format!("scfmu-package-test-{}", std::process::id()));
        let bins = [
            Binary { platform: "linux64", ext: "so", bytes: b"ELF..." },
            Binary { platform: "win64", ext: "dll", bytes: b"MZ..." },
        ];
        let path = write_fmu(entry, &bins, &dir).unwrap();
        let mut zip = zip::ZipArchive::new(fs::File::open(&path).unwrap()).unwrap();
        let names: Vec<String> = (0..zip.len()).map(|i| zip.by_index(i).unwrap().name().unwrap().to_string()).collect();
        let n = entry.info.name;
        assert_eq!(names, vec![
            "modelDescription.xml".to_string(),
            format!("binaries/linux64/{n}.so"),
            format!("binaries/win64/{n}.dll"),
            "documentation/index.html".to_string(),
        ]);
        let mut dll = vec![];
        std::io::Read::read_to_end(&mut zip.by_name(&format!("binaries/win64/{n}.dll")).unwrap(), &mut dll).unwrap();
        assert_eq!(dll, b"MZ...");
        assert!(write_fmu(entry, &[], &dir).is_err());
        fs::remove_dir_all(&dir).ok();
        assert_eq!(platform_lib_ext("win64"), Some("dll"));
        assert_eq!(platform_lib_ext("win32"), None);
    }
}
