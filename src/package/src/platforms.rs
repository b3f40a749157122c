//! Platform folders of the binaries inside an archive, for every platform the project builds.
//!
//! A build is named by the platform key given to `fmu-package --add-lib KEY=PATH`:
//!
//! | key              | built by                     | FMI 2.0 folder            | FMI 3.0 folder    |
//! |------------------|------------------------------|---------------------------|-------------------|
//! | `linux64`        | cargo (host, x86-64)         | `linux64`                 | `x86_64-linux`    |
//! | `win64`          | scripts/build_win64.sh       | `win64`                   | `x86_64-windows`  |
//! | `aarch64-linux`  | scripts/build_aarch64.sh     | `aarch64-linux`           | `aarch64-linux`   |
//! | `x86_64-darwin`  | scripts/build_macos.sh       | `darwin64` (universal)    | `x86_64-darwin`   |
//! | `aarch64-darwin` | scripts/build_macos.sh       | `darwin64` (universal)    | `aarch64-darwin`  |
//! | `darwin64`       | a macOS machine (one arch)   | `darwin64`                | by its CPU type   |
//!
//! FMI 2.0 names no folder for aarch64 Linux: `linux64` is taken by the x86-64 build, so the FMI 3.0
//! tuple `aarch64-linux` is used (the platform wheel for aarch64 Linux, scripts/build_wheel.sh, moves it
//! to `linux64`, the folder fmpy loads on such a machine). FMI 2.0 has one `darwin64` folder for both
//! Mac CPUs: the two macOS builds are joined into one universal ("fat") Mach-O file there, the form
//! macOS itself loads on either CPU.

use std::borrow::Cow;

/// Shared-library extension of a platform key (`None` for a key we do not know).
pub fn lib_ext(key: &str) -> Option<&'static str> {
    match key {
        "linux64" | "aarch64-linux" => Some("so"),
        "win64" => Some("dll"),
        "darwin64" | "x86_64-darwin" | "aarch64-darwin" => Some("dylib"),
        _ => None,
    }
}

/// Every platform key `--add-lib` accepts, for messages.
pub const KEYS: &str = "linux64, win64, aarch64-linux, x86_64-darwin, aarch64-darwin or darwin64";

/// Mach-O CPU types (mach/machine.h) of the two Mac CPUs.
const CPU_X86_64: u32 = 0x0100_0007;
const CPU_ARM64: u32 = 0x0100_000c;

/// The CPU type of a thin 64-bit Mach-O file, `None` for anything else.
pub fn macho_cputype(bytes: &[u8]) -> Option<u32> {
    match bytes.get(0..8) {
        Some([0xcf, 0xfa, 0xed, 0xfe, c @ ..]) => Some(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        _ => None,
    }
}

/// FMI 3.0 platform tuple of a build. A `darwin64` build is told apart by its Mach-O CPU type.
pub fn tuple(key: &str, bytes: &[u8]) -> Option<&'static str> {
    match key {
        "linux64" => Some("x86_64-linux"),
        "win64" => Some("x86_64-windows"),
        "aarch64-linux" => Some("aarch64-linux"),
        "x86_64-darwin" => Some("x86_64-darwin"),
        "aarch64-darwin" => Some("aarch64-darwin"),
        "darwin64" => match macho_cputype(bytes) {
            Some(CPU_X86_64) => Some("x86_64-darwin"),
            Some(CPU_ARM64) => Some("aarch64-darwin"),
            _ => None,
        },
        _ => None,
    }
}

/// One universal ("fat") Mach-O file holding the thin 64-bit slices given, each at a 2^14-byte aligned
/// offset (the page size of arm64 macOS); header fields big-endian as mach-o/fat.h defines them.
pub fn universal_macho(slices: &[&[u8]]) -> Result<Vec<u8>, String> {
    const ALIGN: u32 = 14;
    let mut header = vec![];
    header.extend(0xcafe_babe_u32.to_be_bytes());
    header.extend((slices.len() as u32).to_be_bytes());
    let mut offset = 1usize << ALIGN;
    let mut body: Vec<u8> = vec![];
    for s in slices {
        let cpu = macho_cputype(s).ok_or("a macOS build is not a thin 64-bit Mach-O file")?;
        let sub = u32::from_le_bytes(s[8..12].try_into().unwrap());
        header.extend(cpu.to_be_bytes());
        header.extend(sub.to_be_bytes());
        header.extend(
            u32::try_from(offset)
                .map_err(|_| "a macOS build is too large")?
                .to_be_bytes(),
        );
        header.extend(
            u32::try_from(s.len())
                .map_err(|_| "a macOS build is too large")?
                .to_be_bytes(),
        );
        header.extend(ALIGN.to_be_bytes());
        body.resize(offset - (1 << ALIGN), 0);
        body.extend_from_slice(s);
        offset = (1 << ALIGN) + body.len().div_ceil(1 << ALIGN) * (1 << ALIGN);
    }
    header.resize(1 << ALIGN, 0);
    header.extend(body);
    Ok(header)
}

/// One binary of an archive: (platform folder, file extension, bytes).
pub type Binary<'a> = (&'static str, &'static str, Cow<'a, [u8]>);

/// The FMI 2.0 archive's binaries: `(folder, extension, bytes)` in the order given, the two macOS builds
/// joined into one universal `darwin64` file at the place of the first.
pub fn fmi2_binaries<'a>(builds: &[(&'a str, &'a [u8])]) -> Result<Vec<Binary<'a>>, String> {
    let macs: Vec<&[u8]> = builds
        .iter()
        .filter(|(k, _)| matches!(*k, "x86_64-darwin" | "aarch64-darwin"))
        .map(|(_, b)| *b)
        .collect();
    if !macs.is_empty() && builds.iter().any(|(k, _)| *k == "darwin64") {
        return Err("give darwin64 or the x86_64-darwin/aarch64-darwin builds, not both".into());
    }
    let mut out = vec![];
    let mut mac_done = false;
    for (key, bytes) in builds {
        let folder: &'static str = match *key {
            "linux64" => "linux64",
            "win64" => "win64",
            "aarch64-linux" => "aarch64-linux",
            "darwin64" => "darwin64",
            "x86_64-darwin" | "aarch64-darwin" => {
                if mac_done {
                    continue;
                }
                mac_done = true;
                let joined = if macs.len() == 1 {
                    Cow::Borrowed(macs[0])
                } else {
                    Cow::Owned(universal_macho(&macs)?)
                };
                out.push(("darwin64", "dylib", joined));
                continue;
            }
            other => return Err(format!("unknown platform {other:?} (known: {KEYS})")),
        };
        out.push((folder, lib_ext(key).unwrap(), Cow::Borrowed(*bytes)));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thin(cpu: u32, len: usize) -> Vec<u8> {
        let mut b = vec![0xcf, 0xfa, 0xed, 0xfe];
        b.extend(cpu.to_le_bytes());
        b.extend(3u32.to_le_bytes());
        b.resize(len, 0xab);
        b
    }

    #[test]
    fn two_mac_builds_become_one_universal_file_with_aligned_slices() {
        let (x, a) = (thin(CPU_X86_64, 20_000), thin(CPU_ARM64, 5_000));
        let fat = universal_macho(&[&x, &a]).unwrap();
        let be = |o: usize| u32::from_be_bytes(fat[o..o + 4].try_into().unwrap()) as usize;
        assert_eq!((be(0), be(4)), (0xcafe_babe, 2));
        for (i, s) in [&x, &a].iter().enumerate() {
            let e = 8 + 20 * i;
            assert_eq!(be(e), macho_cputype(s).unwrap() as usize);
            assert_eq!(be(e + 4), 3);
            let (off, size) = (be(e + 8), be(e + 12));
            assert_eq!(off % (1 << 14), 0);
            assert_eq!(&fat[off..off + size], s.as_slice());
        }
        assert_eq!(be(8 + 8), 16_384);
        assert_eq!(be(28 + 8), 16_384 * 3, "20 000 bytes take two pages");
        assert!(universal_macho(&[b"ELF.........."]).is_err());
    }

    #[test]
    fn folders_of_every_platform() {
        let (x, a) = (thin(CPU_X86_64, 64), thin(CPU_ARM64, 64));
        let builds: Vec<(&str, &[u8])> = vec![
            ("linux64", b"ELF"),
            ("x86_64-darwin", &x),
            ("win64", b"MZ"),
            ("aarch64-linux", b"ELFa"),
            ("aarch64-darwin", &a),
        ];
        let f = fmi2_binaries(&builds).unwrap();
        let names: Vec<_> = f.iter().map(|(d, e, _)| format!("{d}.{e}")).collect();
        assert_eq!(names, ["linux64.so", "darwin64.dylib", "win64.dll", "aarch64-linux.so"]);
        assert_eq!(&f[1].2[0..4], &[0xca, 0xfe, 0xba, 0xbe]);
        let one = fmi2_binaries(&[("aarch64-darwin", &a)]).unwrap();
        assert_eq!(one[0].2.as_ref(), a.as_slice(), "one macOS build stays thin");
        assert!(fmi2_binaries(&[("darwin64", &a), ("x86_64-darwin", &x)]).is_err());
        assert!(fmi2_binaries(&[("win32", b"MZ")]).is_err());
        let t: Vec<_> = builds.iter().map(|(k, b)| tuple(k, b).unwrap()).collect();
        assert_eq!(
            t,
            [
                "x86_64-linux",
                "x86_64-darwin",
                "x86_64-windows",
                "aarch64-linux",
                "aarch64-darwin"
            ]
        );
        assert_eq!(tuple("darwin64", &a), Some("aarch64-darwin"));
        assert_eq!(tuple("darwin64", b"junk"), None);
        assert_eq!(lib_ext("aarch64-linux"), Some("so"));
        assert_eq!(lib_ext("win32"), None);
    }
}
