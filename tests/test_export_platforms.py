"""`scfmu export ssp|loop --platform host|all` (scfmu.export.platforms): a host file keeps only this machine's
binaries at every depth (the archive's own, the units unpacked in a loop FMU, the FMU files inside an SSP
archive), chosen by the binary's header, not its folder's name; it runs and gives the same numbers as the file
with every platform; a unit with no binary for this machine is refused by name."""

from __future__ import annotations

import io
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from scfmu.export.platforms import keep_host_binaries

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"


def elf(machine: int) -> bytes:
    """The first bytes of a 64-bit little-endian ELF shared object for e_machine ``machine`` (System V ABI:
    e_ident[EI_CLASS]=2, [EI_DATA]=1, e_type ET_DYN=3 at 16, e_machine at 18)."""
    ident = b"\x7fELF" + bytes([2, 1, 1]) + bytes(9)
    return ident + struct.pack("<HHI", 3, machine, 1) + bytes(64)


def pe(machine: int) -> bytes:
    """A PE image's first bytes: 'MZ', e_lfanew (at 0x3C) pointing at 'PE\\0\\0' followed by the COFF machine."""
    head = bytearray(0x80)
    head[0:2] = b"MZ"
    struct.pack_into("<I", head, 0x3C, 0x40)
    head[0x40:0x44] = b"PE\0\0"
    struct.pack_into("<H", head, 0x44, machine)
    return bytes(head)


X86_64_SO, AARCH64_SO, AMD64_DLL = elf(62), elf(183), pe(0x8664)


def archive(entries: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in entries.items():
            z.writestr(name, data)
    return buf.getvalue()


def unit(**folders: bytes) -> bytes:
    return archive({"modelDescription.xml": b"<fmiModelDescription/>",
                    **{f"binaries/{f}/u.bin": data for f, data in folders.items()}})


def test_header_decides_at_every_depth(tmp_path):
    # an SSP-like archive: two units as FMU files; the second carries its aarch64 build under linux64 (as the
    # aarch64 wheel's FMUs do): on an aarch64 host linux64 stays, on x86-64 it goes
    a = unit(linux64=X86_64_SO, win64=AMD64_DLL, **{"aarch64-linux": AARCH64_SO})
    b = unit(linux64=AARCH64_SO, **{"x86_64-linux": X86_64_SO})
    loop = archive({"modelDescription.xml": b"<x/>", "binaries/linux64/c.so": X86_64_SO,
                    "binaries/win64/c.dll": AMD64_DLL, "resources/a/binaries/win64/u.dll": AMD64_DLL,
                    "resources/a/binaries/linux64/u.so": X86_64_SO, "resources/a/modelDescription.xml": b"<x/>"})
    ssp = tmp_path / "s.ssp"
    ssp.write_bytes(archive({"SystemStructure.ssd": b"<ssd/>", "resources/a.fmu": a, "resources/b.fmu": b}))
    removed = keep_host_binaries(ssp, host="x86_64-linux")
    assert removed == ["resources/a.fmu:binaries/aarch64-linux", "resources/a.fmu:binaries/win64",
                       "resources/b.fmu:binaries/linux64"]
    with zipfile.ZipFile(ssp) as z:
        inner = {n: sorted(zipfile.ZipFile(io.BytesIO(z.read(n))).namelist()) for n in ("resources/a.fmu",
                                                                                       "resources/b.fmu")}
        assert z.read("SystemStructure.ssd") == b"<ssd/>"
    assert inner["resources/a.fmu"] == ["binaries/linux64/u.bin", "modelDescription.xml"]
    assert inner["resources/b.fmu"] == ["binaries/x86_64-linux/u.bin", "modelDescription.xml"]
    # on an aarch64 machine the linux64 folder of b is its build
    ssp.write_bytes(archive({"SystemStructure.ssd": b"<ssd/>", "resources/b.fmu": b}))
    assert keep_host_binaries(ssp, host="aarch64-linux") == ["resources/b.fmu:binaries/x86_64-linux"]
    # a loop FMU: its own binaries and those of the units unpacked inside it
    fmu = tmp_path / "loop.fmu"
    fmu.write_bytes(loop)
    assert keep_host_binaries(fmu, host="x86_64-linux") == ["binaries/win64", "resources/a/binaries/win64"]
    assert sorted(zipfile.ZipFile(fmu).namelist()) == ["binaries/linux64/c.so", "modelDescription.xml",
                                                        "resources/a/binaries/linux64/u.so",
                                                        "resources/a/modelDescription.xml"]


def test_unit_without_a_build_for_this_machine_is_refused(tmp_path):
    ssp = tmp_path / "s.ssp"
    ssp.write_bytes(archive({"SystemStructure.ssd": b"<ssd/>", "resources/w.fmu": unit(win64=AMD64_DLL)}))
    before = ssp.read_bytes()
    with pytest.raises(ValueError, match=r"s\.ssp:resources/w\.fmu carries no binary for this machine "
                                         r"\(x86_64-linux\): write the file with --platform all"):
        keep_host_binaries(ssp, host="x86_64-linux")
    assert ssp.read_bytes() == before  # nothing written


def scfmu(*args):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=600)


def _platforms(fmu_bytes: bytes) -> set[str]:
    with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
        return {n.split("/")[1] for n in z.namelist() if n.startswith("binaries/") and n.count("/") >= 2}


def test_host_ssp_is_smaller_and_runs_the_same(tmp_path):
    if not (FMUS / "AttitudePlant.fmu").is_file():
        pytest.fail("fmus/ not built (scripts/build_fmus.sh)")
    host = scfmu("export", "ssp", "default", "--out", tmp_path / "host")
    full = scfmu("export", "ssp", "default", "--platform", "all", "--out", tmp_path / "all")
    assert host.returncode == 0 and full.returncode == 0, host.stderr + full.stderr
    h, f = tmp_path / "host" / "default.ssp", tmp_path / "all" / "default.ssp"
    with zipfile.ZipFile(h) as zh, zipfile.ZipFile(f) as zf:
        plant_h, plant_f = zh.read("resources/AttitudePlant.fmu"), zf.read("resources/AttitudePlant.fmu")
    shipped = _platforms((FMUS / "AttitudePlant.fmu").read_bytes())
    assert _platforms(plant_f) == shipped
    assert _platforms(plant_h) == {"linux64"}
    if len(shipped) > 1:
        assert h.stat().st_size < f.stat().st_size / 2, (h.stat().st_size, f.stat().st_size)
    # both run (read back as scenarios with their own unpacked units) and give the same numbers, bit for bit
    from scfmu.engines import run_reference
    from scfmu.scenario import ssp
    out = {}
    for name, path in (("host", h), ("all", f)):
        sc, files = ssp.read_ssp(path, tmp_path / f"unpacked_{name}")
        out[name] = run_reference(sc.with_overrides(stop_time=2.0), path_of=files.__getitem__)
    assert set(out["host"]) == set(out["all"]) and "eulerint_deg_s" in out["host"]
    for k in out["all"]:
        np.testing.assert_array_equal(out["host"][k], out["all"][k], err_msg=k)
    assert out["host"]["eulerint_deg_s"][-1] > 1.0  # the loop moved
    bad = scfmu("export", "ssp", "default", "--platform", "mars")
    assert bad.returncode == 2 and "--platform" in bad.stderr and "host" in bad.stderr
