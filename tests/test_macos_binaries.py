"""The macOS binaries (cross-built on Linux by scripts/build_macos.sh with Zig as the linker), checked
structurally: no macOS machine is available to run them, so they are built, not run. Read here from their
Mach-O headers with the layouts of Apple's mach-o/loader.h and mach-o/fat.h (not with our own packager's
code):

- every FMI 2.0 FMU carries binaries/darwin64/<Model>.dylib, a universal file with an x86_64 and an arm64
  slice; every FMI 3.0 FMU the same two slices under x86_64-darwin and aarch64-darwin; one build for all
  models;
- each slice is a 64-bit Mach-O dynamic library (MH_DYLIB) of its CPU, exporting (in its export trie and in
  its symbol table) exactly the fmi2*/fmi3* functions of the Linux x86-64 build: the 44 FMI 2.0 and the 75
  FMI 3.0 functions;
- it loads only system libraries (every LC_LOAD_DYLIB under /usr/lib or /System), declares the oldest
  macOS it runs on (10.12 on Intel, 11.0 on Apple silicon: the Rust targets' minimums), and the arm64
  slice carries an embedded code signature (macOS refuses unsigned arm64 code);
- the loop FMUs keep a platform only where the container's binary and every FMU inside them carry it.

Skipped where the FMUs carry no macOS binaries and the cross tools are missing; in CI (CI=true) a failure."""

from __future__ import annotations

import os
import struct
import subprocess
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"

MH_MAGIC_64, FAT_MAGIC, MH_DYLIB = 0xFEEDFACF, 0xCAFEBABE, 6
CPU_TYPE_X86_64, CPU_TYPE_ARM64 = 0x01000007, 0x0100000C
LC_SYMTAB, LC_LOAD_DYLIB, LC_ID_DYLIB, LC_CODE_SIGNATURE = 0x2, 0xC, 0xD, 0x1D
LC_LOAD_WEAK_DYLIB, LC_REEXPORT_DYLIB, LC_LOAD_UPWARD_DYLIB, LC_LAZY_LOAD_DYLIB = 0x80000018, 0x8000001F, 0x80000023, 0x20
LC_DYLD_INFO_ONLY, LC_DYLD_EXPORTS_TRIE, LC_BUILD_VERSION, LC_VERSION_MIN_MACOSX = 0x80000022, 0x80000033, 0x32, 0x24
DYLIB_LOADS = {LC_LOAD_DYLIB, LC_LOAD_WEAK_DYLIB, LC_REEXPORT_DYLIB, LC_LOAD_UPWARD_DYLIB, LC_LAZY_LOAD_DYLIB}
N_EXT, N_TYPE, N_SECT = 0x01, 0x0E, 0x0E
CSMAGIC_EMBEDDED_SIGNATURE = 0xFADE0CC0


def _uleb(data: bytes, off: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        b = data[off]
        off += 1
        value |= (b & 0x7F) << shift
        shift += 7
        if b < 0x80:
            return value, off


def export_trie(data: bytes, start: int, size: int) -> set[str]:
    """Every name with terminal information in a dyld export trie (mach-o/loader.h, "export trie")."""
    names: set[str] = set()
    stack = [(0, "")]
    seen = set()
    while stack:
        node, prefix = stack.pop()
        if node in seen or node >= size:
            raise AssertionError(f"malformed export trie at node {node}")
        seen.add(node)
        off = start + node
        terminal, off = _uleb(data, off)
        if terminal:
            names.add(prefix)
        off += terminal
        count, off = data[off], off + 1
        for _ in range(count):
            end = data.index(b"\0", off)
            edge = data[off:end].decode()
            child, off = _uleb(data, end + 1)
            stack.append((child, prefix + edge))
    return names


class MachO:
    """The fields of one thin 64-bit Mach-O file that the checks need."""

    def __init__(self, data: bytes):
        magic, cpu, _sub, filetype, ncmds, _size, _flags, _ = struct.unpack_from("<IiiIIIII", data, 0)
        assert magic == MH_MAGIC_64, f"not a thin 64-bit Mach-O file (magic {magic:#x})"
        self.data, self.cputype, self.filetype = data, cpu & 0xFFFFFFFF, filetype
        self.dylibs: list[str] = []
        self.install_name = None
        self.symtab_exports: set[str] = set()
        self.trie_exports: set[str] | None = None
        self.min_os: tuple[int, int] | None = None
        self.signature_magic: int | None = None
        off = 32
        for _ in range(ncmds):
            cmd, cmdsize = struct.unpack_from("<II", data, off)
            if cmd in DYLIB_LOADS or cmd == LC_ID_DYLIB:
                name_off = struct.unpack_from("<I", data, off + 8)[0]
                name = data[off + name_off:off + cmdsize].split(b"\0", 1)[0].decode()
                if cmd == LC_ID_DYLIB:
                    self.install_name = name
                else:
                    self.dylibs.append(name)
            elif cmd == LC_SYMTAB:
                symoff, nsyms, stroff, _ = struct.unpack_from("<IIII", data, off + 8)
                for i in range(nsyms):
                    strx, ntype, _sect, _desc, _value = struct.unpack_from("<IBBHQ", data, symoff + 16 * i)
                    if ntype & N_EXT and ntype & N_TYPE == N_SECT:
                        self.symtab_exports.add(data[stroff + strx:data.index(b"\0", stroff + strx)].decode())
            elif cmd == LC_DYLD_EXPORTS_TRIE:
                dataoff, datasize = struct.unpack_from("<II", data, off + 8)
                self.trie_exports = export_trie(data, dataoff, datasize)
            elif cmd == LC_DYLD_INFO_ONLY:
                export_off, export_size = struct.unpack_from("<II", data, off + 40)
                if export_size:
                    self.trie_exports = export_trie(data, export_off, export_size)
            elif cmd == LC_BUILD_VERSION:
                minos = struct.unpack_from("<I", data, off + 12)[0]
                self.min_os = (minos >> 16, (minos >> 8) & 0xFF)
            elif cmd == LC_VERSION_MIN_MACOSX:
                v = struct.unpack_from("<I", data, off + 8)[0]
                self.min_os = (v >> 16, (v >> 8) & 0xFF)
            elif cmd == LC_CODE_SIGNATURE:
                dataoff = struct.unpack_from("<I", data, off + 8)[0]
                self.signature_magic = struct.unpack_from(">I", data, dataoff)[0]
            off += cmdsize


def fat_slices(data: bytes) -> dict[int, bytes]:
    """{CPU type: slice} of a universal Mach-O file (big-endian fat header, mach-o/fat.h)."""
    magic, n = struct.unpack_from(">II", data, 0)
    assert magic == FAT_MAGIC, f"not a universal Mach-O file (magic {magic:#x})"
    out = {}
    for i in range(n):
        cpu, _sub, off, size, align = struct.unpack_from(">iiIII", data, 8 + 20 * i)
        assert off % (1 << align) == 0, "slice not at its declared alignment"
        out[cpu & 0xFFFFFFFF] = data[off:off + size]
    return out


def fmu_names() -> list[str]:
    return sorted(p.stem for p in FMUS.glob("*.fmu"))


@pytest.fixture(scope="module")
def slices():
    """{CPU type: thin dylib} of AttitudePlant, after checking every FMU carries the same macOS build."""
    names = fmu_names()
    assert names, "no FMUs in fmus/ (scripts/build_fmus.sh)"
    have = [n for n in names if f"binaries/darwin64/{n}.dylib" in zipfile.ZipFile(FMUS / f"{n}.fmu").namelist()]
    if not have:
        tools = subprocess.run([str(ROOT / "scripts" / "build_macos.sh"), "--check"], capture_output=True, text=True)
        msg = "the FMUs carry no macOS binaries (scripts/build_macos.sh; " + (tools.stderr.strip() or "tools installed") + ")"
        if os.environ.get("CI") == "true" or tools.returncode == 0:
            pytest.fail(msg)
        pytest.skip(msg)
    assert have == names, f"FMUs without darwin64: {sorted(set(names) - set(have))}"
    fats = set()
    for n in names:
        with zipfile.ZipFile(FMUS / f"{n}.fmu") as z2, zipfile.ZipFile(FMUS / "fmi3" / f"{n}.fmu") as z3:
            fat = z2.read(f"binaries/darwin64/{n}.dylib")
            s = fat_slices(fat)
            assert set(s) == {CPU_TYPE_X86_64, CPU_TYPE_ARM64}
            assert z3.read(f"binaries/x86_64-darwin/{n}.dylib") == s[CPU_TYPE_X86_64]
            assert z3.read(f"binaries/aarch64-darwin/{n}.dylib") == s[CPU_TYPE_ARM64]
            fats.add(fat)
    assert len(fats) == 1, "one build serves every model"
    return fat_slices(fats.pop())


@pytest.fixture(scope="module")
def linux_exports(tmp_path_factory) -> set[str]:
    so = tmp_path_factory.mktemp("mac") / "AttitudePlant.so"
    so.write_bytes(zipfile.ZipFile(FMUS / "AttitudePlant.fmu").read("binaries/linux64/AttitudePlant.so"))
    out = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True, text=True, check=True).stdout
    return {ln.split()[-1] for ln in out.splitlines() if ln.split() and ln.split()[-1].startswith(("fmi2", "fmi3"))}


@pytest.mark.parametrize("cpu", [CPU_TYPE_X86_64, CPU_TYPE_ARM64], ids=["x86_64", "arm64"])
def test_slice_is_a_dylib_of_its_cpu_exporting_every_fmi_function(slices, linux_exports, cpu):
    m = MachO(slices[cpu])
    assert m.cputype == cpu and m.filetype == MH_DYLIB
    assert len({s for s in linux_exports if s.startswith("fmi2")}) == 44
    assert len({s for s in linux_exports if s.startswith("fmi3")}) == 75
    want = {"_" + s for s in linux_exports}  # C names carry a leading underscore on macOS
    assert m.trie_exports is not None, "no export trie: dyld would find no symbol"
    assert {s for s in m.trie_exports if s.startswith(("_fmi2", "_fmi3"))} == want
    assert {s for s in m.symtab_exports if s.startswith(("_fmi2", "_fmi3"))} == want


@pytest.mark.parametrize("cpu", [CPU_TYPE_X86_64, CPU_TYPE_ARM64], ids=["x86_64", "arm64"])
def test_slice_loads_only_system_libraries_and_declares_its_macos(slices, cpu):
    m = MachO(slices[cpu])
    assert m.dylibs, "a cdylib with libc links libSystem"
    outside = [d for d in m.dylibs if not d.startswith(("/usr/lib/", "/System/Library/"))]
    assert not outside, outside
    assert "/usr/lib/libSystem.B.dylib" in m.dylibs
    assert m.install_name and m.install_name.endswith(".dylib")
    assert m.min_os == ((10, 12) if cpu == CPU_TYPE_X86_64 else (11, 0)), m.min_os


def test_arm64_slice_is_signed(slices):
    """Apple silicon runs no unsigned code: the linker's ad-hoc signature must be embedded."""
    assert MachO(slices[CPU_TYPE_ARM64]).signature_magic == CSMAGIC_EMBEDDED_SIGNATURE


def _platforms(names: list[str], prefix: str) -> set[str]:
    return {n[len(prefix):].split("/")[1] for n in names
            if n.startswith(prefix + "binaries/") and n.count("/") == prefix.count("/") + 2}


def test_loop_fmus_carry_a_platform_only_where_every_nested_fmu_does():
    loops = sorted((FMUS / "loops").glob("*.fmu"))
    if not loops:
        pytest.skip("no loop FMUs in fmus/loops (scripts/build_fmus.sh with the venv)")
    for f in loops:
        names = zipfile.ZipFile(f).namelist()
        nested = sorted({n.split("/")[1] for n in names if n.startswith("resources/") and n.endswith("/modelDescription.xml")
                         and n.count("/") == 2})
        top = _platforms(names, "")
        assert nested and top, f.name
        for m in nested:
            inner = _platforms(names, f"resources/{m}/")
            assert top <= inner, f"{f.name}: the container claims {sorted(top - inner)} which {m} lacks"
            assert inner <= top, f"{f.name}: {m} carries {sorted(inner - top)} that the container cannot load"


def test_strip_unshared_platforms_drops_what_one_nested_fmu_lacks(tmp_path):
    from scfmu.export.loops import strip_unshared_platforms

    fmu = tmp_path / "loop.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        for n in ["binaries/darwin64/container_fmu.dylib", "binaries/linux64/container_fmu.so",
                  "binaries/win64/container_fmu.dll", "modelDescription.xml",
                  "resources/A/binaries/linux64/A.so", "resources/A/binaries/win64/A.dll",
                  "resources/A/binaries/aarch64-linux/A.so", "resources/A/modelDescription.xml",
                  "resources/B/binaries/linux64/B.so", "resources/B/binaries/darwin64/B.dylib",
                  "resources/B/binaries/win64/B.dll", "resources/B/modelDescription.xml", "resources/container.json"]:
            z.writestr(n, n)
    assert strip_unshared_platforms(fmu) == ["linux64", "win64"]
    names = zipfile.ZipFile(fmu).namelist()
    assert not [n for n in names if "darwin64" in n or "aarch64-linux" in n], names
    assert "resources/container.json" in names and zipfile.ZipFile(fmu).read("resources/B/binaries/win64/B.dll") == b"resources/B/binaries/win64/B.dll"
