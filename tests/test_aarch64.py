"""The Linux aarch64 binaries (cross-built by scripts/build_aarch64.sh) run here under user-mode emulation
(qemu-aarch64 with the aarch64 C library of /usr/aarch64-linux-gnu): every FMI 2.0 FMU carries
binaries/aarch64-linux/<Model>.so and every FMI 3.0 FMU the same file under the FMI 3.0 tuple
aarch64-linux; it is an AArch64 ELF shared object exporting the same fmi2*/fmi3* functions as the x86-64
build and needing only the C library. Plain C masters, each compiled once with gcc (x86-64, native) and
once with aarch64-linux-gnu-gcc (run under qemu), give the same results on both CPUs:

- the AttitudePlant + PdController closed loop (tests/loader/fmi_loop.c, 1000 steps of 0.05 s): states,
  rates, torques and wheel momentum bit for bit at every step; the Euler angles (atan2/asin of each
  platform's C library) within 1 ulp; with nonlinear controllers (exp/tanh of the C library) every output
  within 4 ulp;
- the hostile masters' bad-input sections (tests/hostile/fmi_hostile.c, both versions: hang-prone
  calls, extreme parameters, mutated FMU states, every Model Exchange entry point abused, FMI 3.0 abuse):
  the same report line, character for character (counts of refused calls, accepted mutations, events and
  the printed w_x to 17 digits).

Skipped only where qemu-aarch64 or the cross compiler is missing (scripts/setup.sh installs qemu-user and
gcc-aarch64-linux-gnu); in CI (CI=true) that is a failure, as are FMUs without aarch64 binaries."""

from __future__ import annotations

import os
import re
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from test_win64 import LIBM_OUTPUTS, NONLINEAR_CONTROLLERS, OUT, loop_args, parse_loop, ulps

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"
LOADER = ROOT / "tests" / "loader" / "fmi_loop.c"
HOSTILE2 = ROOT / "tests" / "hostile" / "fmi_hostile.c"
CROSS_GCC = "aarch64-linux-gnu-gcc"
CROSS_NM = "aarch64-linux-gnu-nm"
CROSS_READELF = "aarch64-linux-gnu-readelf"
QEMU = shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")
SYSROOT = Path("/usr/aarch64-linux-gnu")
MISSING = ("qemu-aarch64 or aarch64-linux-gnu-gcc not installed (scripts/setup.sh installs qemu-user and "
           "gcc-aarch64-linux-gnu)")
# e_machine of an ELF file for AArch64 (ELF for the Arm 64-bit Architecture); x86-64 is 62
EM_AARCH64, EM_X86_64 = 183, 62
# the libraries a Rust std cdylib may need on Linux: glibc's, its loader and the unwinder
SYSTEM_SONAMES = {"libc.so.6", "libm.so.6", "libdl.so.2", "libpthread.so.0", "librt.so.1", "libgcc_s.so.1",
                  "ld-linux-aarch64.so.1", "ld-linux-x86-64.so.2"}


@pytest.fixture(scope="module", autouse=True)
def aarch64_tools():
    if QEMU is None or shutil.which(CROSS_GCC) is None or not SYSROOT.is_dir():
        if os.environ.get("CI") == "true":
            pytest.fail(MISSING)
        pytest.skip(MISSING)


def fmu_names() -> list[str]:
    return sorted(p.stem for p in FMUS.glob("*.fmu"))


def elf_machine(data: bytes) -> tuple[int, int]:
    """(EI_CLASS, e_machine) of an ELF file: (2, 183) for a 64-bit AArch64 object."""
    assert data[:4] == b"\x7fELF", data[:4]
    assert data[5] == 1, "little-endian"
    return data[4], struct.unpack_from("<H", data, 18)[0]


@pytest.fixture(scope="module")
def fmus_with_aarch64():
    names = fmu_names()
    assert names, "no FMUs in fmus/ (run scripts/build_fmus.sh)"
    missing = [n for n in names
               if f"binaries/aarch64-linux/{n}.so" not in zipfile.ZipFile(FMUS / f"{n}.fmu").namelist()]
    assert not missing, (f"FMUs without binaries/aarch64-linux: {missing}; the cross toolchain is installed, "
                         "so rebuild with scripts/build_fmus.sh (without SCFMU_NO_AARCH64=1)")
    return names


def test_every_fmu_carries_one_aarch64_build_in_both_fmi_versions(fmus_with_aarch64):
    builds = set()
    for n in fmus_with_aarch64:
        with zipfile.ZipFile(FMUS / f"{n}.fmu") as z2, zipfile.ZipFile(FMUS / "fmi3" / f"{n}.fmu") as z3:
            so = z2.read(f"binaries/aarch64-linux/{n}.so")
            assert z3.read(f"binaries/aarch64-linux/{n}.so") == so
            assert elf_machine(so) == (2, EM_AARCH64)
            assert elf_machine(z2.read(f"binaries/linux64/{n}.so")) == (2, EM_X86_64)
            assert elf_machine(z3.read(f"binaries/x86_64-linux/{n}.so")) == (2, EM_X86_64)
            builds.add(so)
    assert len(builds) == 1, "one cross build serves every model"


@pytest.fixture(scope="module")
def work(tmp_path_factory, fmus_with_aarch64):
    """A folder with the x86-64 and aarch64 builds of the masters (<name>, <name>.arm) and the FMUs' binaries
    under their own file names (the library finds its model by its file name): x86/<Model>.so and
    arm/<Model>.so (FMI 2.0), x86_3/AttitudePlant.so and arm_3/AttitudePlant.so (FMI 3.0); and the GUIDs."""
    d = tmp_path_factory.mktemp("aarch64")
    for src, name, extra in ((LOADER, "fmi_loop", ["-ldl"]), (HOSTILE2, "fmi_hostile", ["-pthread", "-ldl", "-lm"])):
        for cc, suffix in (("gcc", ""), (CROSS_GCC, ".arm")):
            subprocess.run([cc, "-O1", "-Wall", "-Werror", "-o", str(d / (name + suffix)), str(src), *extra], check=True)
        assert elf_machine((d / f"{name}.arm").read_bytes())[1] == EM_AARCH64
    for sub in ("x86", "arm", "x86_3", "arm_3"):
        (d / sub).mkdir()
    info = {}
    for model in ("AttitudePlant", "PdController", *NONLINEAR_CONTROLLERS):
        with zipfile.ZipFile(FMUS / f"{model}.fmu") as z:
            (d / "x86" / f"{model}.so").write_bytes(z.read(f"binaries/linux64/{model}.so"))
            (d / "arm" / f"{model}.so").write_bytes(z.read(f"binaries/aarch64-linux/{model}.so"))
            root = ET.fromstring(z.read("modelDescription.xml"))
        info[model] = (root.get("guid"), {v.get("name"): int(v.get("valueReference"))
                                          for v in root.iter("ScalarVariable")})
    with zipfile.ZipFile(FMUS / "fmi3" / "AttitudePlant.fmu") as z:
        (d / "x86_3" / "AttitudePlant.so").write_bytes(z.read("binaries/x86_64-linux/AttitudePlant.so"))
        (d / "arm_3" / "AttitudePlant.so").write_bytes(z.read("binaries/aarch64-linux/AttitudePlant.so"))
        info["token3"] = re.search(r'instantiationToken="([^"]+)"', z.read("modelDescription.xml").decode()).group(1)
    return d, info


def run_native(d: Path, sub: str, prog: str, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([str(d / prog), *args], cwd=d / sub, capture_output=True, text=True, timeout=timeout)


def run_arm(d: Path, sub: str, prog: str, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    # -L: the aarch64 dynamic loader and C library (libc6-arm64-cross) for the emulated process
    return subprocess.run([QEMU, "-L", str(SYSROOT), str(d / f"{prog}.arm"), *args], cwd=d / sub,
                          capture_output=True, text=True, timeout=timeout)


def test_the_arm_master_really_runs_emulated(work):
    """The aarch64 master cannot run natively here (so the comparisons below are not x86-64 against
    itself); under qemu the aarch64 library finds its own file name (it refuses another model's GUID,
    naming AttitudePlant), and the x86-64 library does not load into the emulated process."""
    d, info = work
    with pytest.raises(OSError):
        subprocess.run([str(d / "fmi_loop.arm"), "instantiate", "./AttitudePlant.so", "x"], cwd=d / "arm",
                       capture_output=True, timeout=30)
    p = run_arm(d, "arm", "fmi_loop", "instantiate", "./AttitudePlant.so", info["PdController"][0])
    assert p.stdout.split() == ["null"], p.stdout + p.stderr
    assert "does not match AttitudePlant's GUID" in p.stderr, p.stderr
    p = run_arm(d, "arm", "fmi_loop", "instantiate", "./AttitudePlant.so", info["AttitudePlant"][0])
    assert p.stdout.split() == ["instance"], p.stdout + p.stderr
    p = run_arm(d, "x86", "fmi_loop", "instantiate", "./AttitudePlant.so", info["AttitudePlant"][0])
    assert p.returncode != 0 and "FAIL" in p.stdout + p.stderr, p.stdout + p.stderr


def exported(nm: str, lib: Path) -> set[str]:
    out = subprocess.run([nm, "-D", "--defined-only", str(lib)], capture_output=True, text=True, check=True).stdout
    return {ln.split()[-1] for ln in out.splitlines() if ln.split() and ln.split()[-1].startswith(("fmi2", "fmi3"))}


def needed(lib: Path) -> set[str]:
    out = subprocess.run([CROSS_READELF, "-d", str(lib)], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out))


def test_aarch64_build_exports_the_same_fmi_functions_and_needs_only_the_c_library(work):
    d, _ = work
    arm, x86 = exported(CROSS_NM, d / "arm" / "AttitudePlant.so"), exported("nm", d / "x86" / "AttitudePlant.so")
    assert arm == x86 and len({s for s in arm if s.startswith("fmi2")}) == 44
    assert len({s for s in arm if s.startswith("fmi3")}) == 75
    deps = needed(d / "arm" / "AttitudePlant.so")
    assert deps and deps <= SYSTEM_SONAMES, deps
    assert "libc.so.6" in deps


def run_loops(work, controller: str, steps: int = 1000, dt: float = 0.05):
    d, info = work
    args = loop_args(info, "so", steps, dt, controller)
    native = run_native(d, "x86", "fmi_loop", *args)
    assert native.returncode == 0, native.stdout[-2000:] + native.stderr[-2000:]
    arm = run_arm(d, "arm", "fmi_loop", *args)
    assert arm.returncode == 0, arm.stdout[-2000:] + arm.stderr[-2000:]
    head_x86, rows_x86 = parse_loop(native.stdout)
    head_arm, rows_arm = parse_loop(arm.stdout)
    assert head_x86 == head_arm == "fmi2GetTypesPlatform=default fmi2GetVersion=2.0"
    assert len(rows_x86) == len(rows_arm) == steps
    return rows_x86, rows_arm


def test_pd_loop_on_aarch64_is_bit_identical_to_x86_64(work):
    """AttitudePlant + PdController, 1000 steps of 0.05 s from a 0.5/-0.3/0.8 rad attitude: every state,
    rate, torque and wheel momentum has the same IEEE-754 bits at every step on both CPUs (Rust never
    fuses a multiply and an add on its own, and sqrt is correctly rounded on both); the Euler angles come
    from glibc's atan2/asin, whose aarch64 and x86-64 builds may differ in the last bit: within 1 ulp."""
    rows_x86, rows_arm = run_loops(work, "PdController")
    differing = 0
    for k, (a, b) in enumerate(zip(rows_x86, rows_arm), start=1):
        for name, (va, ba), (vb, bb) in zip(OUT, a, b):
            if name in LIBM_OUTPUTS:
                assert ulps(va, vb) <= 1, f"step {k} {name}: x86-64 {va!r} aarch64 {vb!r}"
                differing += ba != bb
            else:
                assert ba == bb, f"step {k} {name}: x86-64 {va!r} ({ba:016x}) != aarch64 {vb!r} ({bb:016x})"
    print(f"Euler-angle values differing in the last bit: {differing} of {3 * len(rows_x86)}")
    first, last = [v for v, _ in rows_x86[0]], [v for v, _ in rows_x86[-1]]
    assert abs(first[0]) < 0.99 and max(abs(x) for x in first[4:7]) > 1e-3
    assert abs(abs(last[0]) - 1.0) < 1e-9 and max(abs(x) for x in last[1:7]) < 1e-6, last


def test_nonlinear_controller_loop_on_aarch64_agrees_with_x86_64(work):
    """The type-2 fuzzy sliding-mode controller (exp, tanh of the C library): every output of every step
    within 4 ulp on the two CPUs."""
    rows_x86, rows_arm = run_loops(work, "Type2FuzzySmcController")
    for k, (a, b) in enumerate(zip(rows_x86, rows_arm), start=1):
        for name, (va, _), (vb, _) in zip(OUT, a, b):
            assert ulps(va, vb) <= 4 or abs(va - vb) < 1e-300, f"step {k} {name}: x86-64 {va!r} aarch64 {vb!r}"


# The bad-input sections of the two hostile masters, with the arguments tests/test_hardening.py
# uses (fewer fuzz iterations: the emulated CPU is ~10x slower).
HOSTILE_FMI2 = [("hang",), ("extreme",), ("fuzz", "1000", "20261123"), ("me", "2000", "300"), ("cycles", "50")]
HOSTILE_FMI3 = [("abuse",), ("me",), ("mixed",)]


@pytest.mark.parametrize("args", HOSTILE_FMI2, ids=lambda a: " ".join(a))
def test_hostile_fmi2_master_reports_the_same_on_aarch64(work, args):
    d, info = work
    guid = info["AttitudePlant"][0]
    native = run_native(d, "x86", "fmi_hostile", "./AttitudePlant.so", guid, *args)
    arm = run_arm(d, "arm", "fmi_hostile", "./AttitudePlant.so", guid, *args)
    assert native.returncode == 0 and native.stdout.startswith("ok"), native.stdout + native.stderr[-2000:]
    assert arm.returncode == 0 and arm.stdout.startswith("ok"), arm.stdout + arm.stderr[-2000:]
    assert arm.stdout == native.stdout


@pytest.mark.parametrize("args", HOSTILE_FMI3, ids=lambda a: " ".join(a))
def test_hostile_fmi3_master_reports_the_same_on_aarch64(work, args):
    d, info = work
    native = run_native(d, "x86_3", "fmi_hostile", "-3", "./AttitudePlant.so", info["token3"], *args)
    arm = run_arm(d, "arm_3", "fmi_hostile", "-3", "./AttitudePlant.so", info["token3"], *args)
    assert native.returncode == 0 and native.stdout.startswith("ok"), native.stdout + native.stderr[-2000:]
    assert arm.returncode == 0 and arm.stdout.startswith("ok"), arm.stdout + arm.stderr[-2000:]
    assert arm.stdout == native.stdout
