"""Platform wheels (scripts/build_wheel.sh --platform P): copies the built FMUs into the staged package with
only platform P's binary, and prints the wheel's platform tag.

    python3 scripts/wheel_platform.py P STAGE_FMU_DIR NATIVE_LOOP_LIB_OR_- > tag

P is one of PLATFORMS below. For each fmus/<Model>.fmu (FMI 2.0) and fmus/fmi3/<Model>.fmu (FMI 3.0) it
writes STAGE_FMU_DIR/<Model>.fmu and STAGE_FMU_DIR/fmi3/<Model>.fmu holding modelDescription.xml, the
documentation and the one binary of P, under the folder a master looks in on such a machine:

- FMI 3.0: the platform tuple (x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin).
- FMI 2.0: linux64, win64 or darwin64. On aarch64 Linux that is `linux64` too: FMI 2.0 calls the folder
  "64-bit Linux" without naming a CPU, and fmpy (like other FMI 2.0 masters) loads binaries/linux64 there;
  the all-platform FMUs in fmus/ keep the aarch64 build under `aarch64-linux` because `linux64` holds the
  x86-64 one. On macOS the wheel of each CPU carries that CPU's slice of the universal darwin64 file.

The tag: manylinux_2_<N>_<arch> with N the newest glibc symbol version the shipped binaries need (the
rule of PEP 600), win_amd64, or macosx_<major>_<minor>_<arch> with the oldest macOS the binaries declare
(their LC_BUILD_VERSION). Archives are written deterministically (entry order kept, fixed timestamps).
"""

from __future__ import annotations

import re
import struct
import sys
import zipfile
from pathlib import Path

# P: (FMI 2.0 folder in fmus/, FMI 2.0 folder in the wheel, FMI 3.0 tuple, Mach-O CPU type or None)
PLATFORMS = {
    "linux-x86_64": ("linux64", "linux64", "x86_64-linux", None),
    "linux-aarch64": ("aarch64-linux", "linux64", "aarch64-linux", None),
    "win-amd64": ("win64", "win64", "x86_64-windows", None),
    "macos-x86_64": ("darwin64", "darwin64", "x86_64-darwin", 0x01000007),
    "macos-arm64": ("darwin64", "darwin64", "aarch64-darwin", 0x0100000C),
}


def thin_slice(data: bytes, cputype: int) -> bytes:
    """The slice of CPU `cputype` of a universal Mach-O file (or the file itself when it is that thin one)."""
    if data[:4] == b"\xca\xfe\xba\xbe":
        n = struct.unpack_from(">I", data, 4)[0]
        for i in range(n):
            cpu, _, off, size, _ = struct.unpack_from(">iiIII", data, 8 + 20 * i)
            if cpu & 0xFFFFFFFF == cputype:
                return data[off:off + size]
        raise SystemExit(f"wheel_platform: the universal darwin64 file has no slice of CPU type {cputype:#x}")
    if data[:4] == b"\xcf\xfa\xed\xfe" and struct.unpack_from("<I", data, 4)[0] == cputype:
        return data
    raise SystemExit(f"wheel_platform: the darwin64 file is not for CPU type {cputype:#x}")


def macos_min(data: bytes) -> tuple[int, int]:
    """(major, minor) of the oldest macOS a thin Mach-O file declares (LC_BUILD_VERSION or LC_VERSION_MIN_MACOSX)."""
    ncmds = struct.unpack_from("<I", data, 16)[0]
    off = 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, off)
        if cmd == 0x32:  # LC_BUILD_VERSION: platform, minos (xxxx.yy.zz), sdk, ntools
            minos = struct.unpack_from("<I", data, off + 12)[0]
            return minos >> 16, (minos >> 8) & 0xFF
        if cmd == 0x24:  # LC_VERSION_MIN_MACOSX: version, sdk
            v = struct.unpack_from("<I", data, off + 8)[0]
            return v >> 16, (v >> 8) & 0xFF
        off += size
    raise SystemExit("wheel_platform: the macOS build declares no minimum macOS version")


def glibc_needed(data: bytes) -> tuple[int, int]:
    """The newest GLIBC_x.y symbol version named in an ELF file's dynamic string table."""
    found = [(int(a), int(b)) for a, b in re.findall(rb"GLIBC_(\d+)\.(\d+)", data)]
    return max(found) if found else (2, 17)


def filter_fmu(src: Path, dest: Path, keep: str, folder: str, cputype: int | None) -> bytes:
    """Writes `src` without any binary but binaries/<keep>/, stored as binaries/<folder>/; returns it."""
    binary = None
    with zipfile.ZipFile(src) as z, zipfile.ZipFile(dest, "w") as out:
        for info in z.infolist():
            parts = info.filename.split("/")
            if parts[0] == "binaries":
                if len(parts) < 3 or parts[1] != keep:
                    continue
                data = z.read(info)
                if cputype is not None:
                    data = thin_slice(data, cputype)
                binary = data
                name = "/".join(["binaries", folder, *parts[2:]])
                new = zipfile.ZipInfo(name, date_time=info.date_time)
                new.external_attr, new.compress_type = info.external_attr, info.compress_type
                out.writestr(new, data)
            else:
                out.writestr(info, z.read(info), compress_type=info.compress_type)
    if binary is None:
        raise SystemExit(f"wheel_platform: {src} has no binaries/{keep}/ (build it first: scripts/build_fmus.sh)")
    return binary


def main() -> None:
    plat, stage, loop = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    if plat not in PLATFORMS:
        raise SystemExit(f"wheel_platform: --platform takes one of {', '.join(PLATFORMS)}, not {plat!r}")
    src2, dst2, tuple3, cpu = PLATFORMS[plat]
    root = Path(__file__).resolve().parents[1] / "fmus"
    fmus = sorted(root.glob("*.fmu"))
    if not fmus:
        raise SystemExit("wheel_platform: no FMUs in fmus/")
    (stage / "fmi3").mkdir(parents=True, exist_ok=True)
    binaries = []
    for f in fmus:
        binaries.append(filter_fmu(f, stage / f.name, src2, dst2, cpu))
        binaries.append(filter_fmu(root / "fmi3" / f.name, stage / "fmi3" / f.name, tuple3, tuple3, None))
    if loop != "-":
        binaries.append(Path(loop).read_bytes())
    if plat.startswith("linux"):
        major, minor = max(glibc_needed(b) for b in binaries)
        tag = f"manylinux_{major}_{minor}_{plat.split('-')[1]}"
    elif plat == "win-amd64":
        tag = "win_amd64"
    else:
        major, minor = max(macos_min(b) for b in binaries)
        tag = f"macosx_{major}_{minor}_{plat.split('-')[1]}"
    print(tag)


if __name__ == "__main__":
    main()
