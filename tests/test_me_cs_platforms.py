"""The Model Exchange wrapper (scfmu/engines/me_cs, the library of a unit's Co-Simulation face,
scfmu/engines/cs_face.py) on every platform the project's FMUs carry:

- the cross builds (scripts/build_aarch64.sh, build_macos.sh, build_win64.sh, called by build_fmus.sh) give
  a wrapper for each platform whose FMU binaries were built, an AArch64 ELF / x86-64 and arm64 Mach-O / PE
  x86-64 library (read from its own header here) exporting every fmi2*/fmi3* function of the Linux x86-64
  build, among them the FMI 2.0 and FMI 3.0 Co-Simulation entry points a face needs, and loading nothing
  but the system's C library;
- a face carries the wrapper in every platform folder where both the wrapper and the unit have a binary
  (darwin64: one universal file whose slices are the thin builds byte for byte), and no other platform:
  a unit without a platform's binary gets no face there;
- a loop FMU with the Model Exchange AttitudePlant carries the platforms of the Co-Simulation loop FMUs
  for which the wrapper is built;
- under qemu-aarch64 the aarch64 face of AttitudePlant (FMI 2.0), driven with PdController by the C master
  tests/loader/fmi_loop.c, gives the x86-64 face's trajectory: bit for bit with RK4 (plain arithmetic);
  with the adaptive Dormand-Prince method (whose step control calls the C library's pow) within 1e-12
  relative, and within 1e-9 of the loop with the plant's own Co-Simulation build.

- under Wine the win64 face, driven the same way by the MinGW build of the master, gives the linux64 face's
  trajectory: attitude, rates, torques and wheel momentum bit for bit, the Euler angles (each platform's
  C library) within 1 ulp.

Skipped where the FMUs carry no binaries of a platform (its cross toolchain not installed) or qemu/Wine are
missing; in CI (CI=true) the missing tools are a failure."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from test_aarch64 import CROSS_GCC, CROSS_NM, CROSS_READELF, EM_AARCH64, EM_X86_64, QEMU, SYSROOT, SYSTEM_SONAMES
from test_aarch64 import elf_machine, exported
from test_macos_binaries import CPU_TYPE_ARM64, CPU_TYPE_X86_64, MH_DYLIB, MachO, fat_slices
from test_win64 import SYSTEM_DLLS, assert_same_bits, loop_args, parse_loop
from scfmu.engines.cs_face import checkout_build

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"
LOADER = ROOT / "tests" / "loader" / "fmi_loop.c"
HOST = ROOT / checkout_build("x86_64-linux")
# platform tuple -> (the cross script's output, the FMI 2.0 folder of fmus/<Model>.fmu that says it was built)
CROSS = {tup: (checkout_build(tup), folder) for tup, folder in
         [("aarch64-linux", "aarch64-linux"), ("x86_64-windows", "win64"), ("x86_64-darwin", "darwin64"),
          ("aarch64-darwin", "darwin64")]}
TUPLES = list(CROSS)
# The Co-Simulation entry points fmpy's container (and any master) calls on a face, written out from the
# FMI 2.0.4 (section 4.2) and FMI 3.0 (section 4.2) standards rather than read from our own binary
FMI2_FACE = {"fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
             "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate",
             "fmi2Reset", "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2SetReal", "fmi2SetInteger",
             "fmi2SetBoolean", "fmi2DoStep"}
FMI3_FACE = {"fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateCoSimulation", "fmi3FreeInstance",
             "fmi3EnterInitializationMode", "fmi3ExitInitializationMode", "fmi3Terminate", "fmi3Reset",
             "fmi3GetFloat64", "fmi3SetFloat64", "fmi3GetInt32", "fmi3SetInt32", "fmi3GetBoolean",
             "fmi3SetBoolean", "fmi3DoStep", "fmi3EnterStepMode"}


def fmu_folders() -> set[str]:
    names = zipfile.ZipFile(FMUS / "AttitudePlant.fmu").namelist()
    return {n.split("/")[1] for n in names if n.startswith("binaries/")}


def built(tup: str) -> Path:
    """The cross-built wrapper of platform ``tup``; skips (fails in CI) when that platform's FMU binaries were
    not built either (its toolchain missing), fails when they were and the wrapper was not."""
    path, folder = CROSS[tup]
    if folder not in fmu_folders():
        msg = f"the FMUs carry no {folder} binaries (its cross toolchain not installed: scripts/setup.sh)"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)
    lib = ROOT / path
    assert lib.is_file(), f"the FMUs carry {folder} but the wrapper {path} was not built (scripts/build_fmus.sh)"
    return lib


@pytest.fixture(scope="module")
def host_exports() -> set[str]:
    assert HOST.is_file(), "cargo build --release"
    return exported("nm", HOST)


def pe_header(data: bytes) -> tuple[int, int]:
    """(PE machine, characteristics) of a PE image (Microsoft PE/COFF specification)."""
    pe = struct.unpack_from("<I", data, 0x3C)[0]
    assert data[:2] == b"MZ" and data[pe:pe + 4] == b"PE\0\0"
    return struct.unpack_from("<H", data, pe + 4)[0], struct.unpack_from("<H", data, pe + 4 + 18)[0]


@pytest.mark.parametrize("tup", TUPLES)
def test_cross_built_wrapper_is_found_and_is_a_library_of_its_platform(tup):
    from scfmu.engines.cs_face import wrapper_libraries

    lib = built(tup)
    assert wrapper_libraries().get(tup) == lib, "the face's lookup finds the cross build"
    data = lib.read_bytes()
    if tup == "aarch64-linux":
        assert elf_machine(data) == (2, EM_AARCH64)
        assert struct.unpack_from("<H", data, 16)[0] == 3, "ET_DYN: a shared object"
    elif tup == "x86_64-windows":
        machine, characteristics = pe_header(data)
        assert machine == 0x8664 and characteristics & 0x2000, "an x86-64 DLL (IMAGE_FILE_DLL)"
    else:
        m = MachO(data)
        assert m.filetype == MH_DYLIB
        assert m.cputype == (CPU_TYPE_X86_64 if tup == "x86_64-darwin" else CPU_TYPE_ARM64)


@pytest.mark.parametrize("tup", TUPLES)
def test_cross_built_wrapper_exports_the_co_simulation_entry_points(tup, host_exports, tmp_path):
    """Every fmi2*/fmi3* function of the Linux x86-64 wrapper (the FMI 2.0 and 3.0 Co-Simulation entry points
    of a face among them), and it needs only the platform's system libraries."""
    assert FMI2_FACE | FMI3_FACE <= host_exports, sorted(FMI2_FACE | FMI3_FACE - host_exports)
    lib = built(tup)
    if tup == "aarch64-linux":
        assert exported(CROSS_NM, lib) == host_exports
        out = subprocess.run([CROSS_READELF, "-d", str(lib)], capture_output=True, text=True, check=True).stdout
        deps = {ln.split("[")[1].rstrip("]") for ln in out.splitlines() if "(NEEDED)" in ln}
        assert deps and deps <= SYSTEM_SONAMES, deps
    elif tup == "x86_64-windows":
        from test_win64 import pe_imports_exports
        imports, exports = pe_imports_exports(lib)
        assert {s for s in exports if s.startswith(("fmi2", "fmi3"))} == host_exports
        assert {d.lower() for d in imports} <= SYSTEM_DLLS, imports
    else:
        m = MachO(lib.read_bytes())
        want = {"_" + s for s in host_exports}  # C names carry a leading underscore on macOS
        assert m.trie_exports is not None and {s for s in m.trie_exports if s.startswith(("_fmi2", "_fmi3"))} == want
        assert {s for s in m.symtab_exports if s.startswith(("_fmi2", "_fmi3"))} == want
        assert m.dylibs and all(d.startswith(("/usr/lib/", "/System/Library/")) for d in m.dylibs), m.dylibs
        assert m.min_os == ((10, 12) if tup == "x86_64-darwin" else (11, 0))


def _platforms(names, prefix: str = "") -> set[str]:
    return {n[len(prefix):].split("/")[1] for n in names
            if n.startswith(prefix + "binaries/") and n.count("/") == prefix.count("/") + 2}


def _unit(fmu: Path, solver: dict | None = None):
    """The plan unit of the default scenario's plant as Model Exchange, from FMU file ``fmu``."""
    from scfmu.scenario import get
    from scfmu.scenario.plan import build_plan

    sc = get("default", stop_time=1.0).with_models({"plant": str(fmu)})
    sc.component("plant").interface = "me"
    if solver:
        sc.component("plant").solver = solver
    return next(u for u in build_plan(sc).units if u.name == "plant")


def _built_tuples() -> set[str]:
    from scfmu.engines.cs_face import wrapper_libraries
    return set(wrapper_libraries())


@pytest.mark.parametrize("fmi", [2, 3])
def test_face_carries_the_wrapper_wherever_the_unit_and_the_wrapper_have_a_binary(fmi, tmp_path):
    from scfmu.engines.cs_face import cs_face

    fmu = FMUS / "AttitudePlant.fmu" if fmi == 2 else FMUS / "fmi3" / "AttitudePlant.fmu"
    have = _built_tuples()
    unit_folders = _platforms(zipfile.ZipFile(fmu).namelist())
    if fmi == 2:
        want = {f for f, tups in {"linux64": {"x86_64-linux"}, "aarch64-linux": {"aarch64-linux"},
                                  "win64": {"x86_64-windows"}, "darwin64": {"x86_64-darwin", "aarch64-darwin"}}.items()
                if f in unit_folders and tups & have}
    else:
        want = unit_folders & have
    face = cs_face(_unit(fmu), tmp_path)
    z = zipfile.ZipFile(face)
    names = z.namelist()
    assert _platforms(names) == want, sorted(names)
    if "aarch64-linux" in have:
        assert "aarch64-linux" in want, "the all-platform FMUs carry aarch64-linux"
    for folder in want:
        ext = {"linux64": "so", "win64": "dll", "darwin64": "dylib"}.get(folder) or \
            {"linux": "so", "windows": "dll", "darwin": "dylib"}[folder.split("-")[1]]
        wrapper = z.read(f"binaries/{folder}/scfmu_me_cs.{ext}")
        assert f"binaries/{folder}/AttitudePlant.{ext}" in names, "the unit's own library beside it"
        if folder == "darwin64":
            slices = fat_slices(wrapper)
            assert set(slices) == {CPU_TYPE_X86_64, CPU_TYPE_ARM64}
            assert slices[CPU_TYPE_X86_64] == (ROOT / CROSS["x86_64-darwin"][0]).read_bytes()
            assert slices[CPU_TYPE_ARM64] == (ROOT / CROSS["aarch64-darwin"][0]).read_bytes()
        elif folder in ("linux64", "x86_64-linux"):
            assert wrapper == HOST.read_bytes()
        else:
            tup = {"win64": "x86_64-windows"}.get(folder, folder)
            assert wrapper == (ROOT / CROSS[tup][0]).read_bytes()


def test_face_offers_no_platform_or_cpu_the_unit_lacks(tmp_path):
    """A unit without its aarch64 Linux binary and with an Intel-only darwin64 file: its face offers no
    aarch64-linux, and its darwin64 wrapper has the x86-64 slice only."""
    from scfmu.engines.cs_face import cs_face

    for tup in ("aarch64-linux", "x86_64-darwin", "aarch64-darwin"):
        built(tup)  # skips (fails in CI) without that platform's cross build
    have = _built_tuples()
    src = FMUS / "AttitudePlant.fmu"
    fmu = tmp_path / "AttitudePlant.fmu"
    with zipfile.ZipFile(src) as zi, zipfile.ZipFile(fmu, "w") as zo:
        for info in zi.infolist():
            if info.filename.startswith("binaries/aarch64-linux/"):
                continue
            data = zi.read(info)
            if info.filename == "binaries/darwin64/AttitudePlant.dylib":
                data = fat_slices(data)[CPU_TYPE_X86_64]  # the Intel build alone, thin
            zo.writestr(info, data)
    z = zipfile.ZipFile(cs_face(_unit(fmu), tmp_path / "faces"))
    assert _platforms(z.namelist()) == {"linux64", "darwin64"} | ({"win64"} if "x86_64-windows" in have else set())
    wrapper = z.read("binaries/darwin64/scfmu_me_cs.dylib")
    assert set(fat_slices(wrapper)) == {CPU_TYPE_X86_64}


@pytest.mark.parametrize("fmi", [2, 3])
def test_loop_fmu_with_the_model_exchange_plant_carries_the_platforms_of_the_cs_loop(fmi, tmp_path, monkeypatch):
    """fmus/loops/default.fmu (Co-Simulation units) against the same loop with the plant as Model Exchange
    (nested as its face): the same platforms wherever the wrapper is built (darwin64 with the macOS builds;
    not aarch64-linux, for which fmpy ships no container binary; win64 once the Windows wrapper builds)."""
    from scfmu.engines import native
    from scfmu.export.loops import write_loop_fmu
    from scfmu.scenario import get

    cs_loop = FMUS / "loops" / "default.fmu"
    if not cs_loop.is_file():
        pytest.skip("no fmus/loops/default.fmu (scripts/build_fmus.sh with the venv)")
    cs = _platforms(zipfile.ZipFile(cs_loop).namelist())
    monkeypatch.setattr(native, "CACHE", tmp_path / "cache")
    sc = get("default", stop_time=1.0)
    if fmi == 3:
        sc = sc.with_models({"plant": str(FMUS / "fmi3" / "AttitudePlant.fmu")})
    sc.component("plant").interface = "me"
    loop = write_loop_fmu(sc, tmp_path / "loop_me.fmu")
    names = zipfile.ZipFile(loop).namelist()
    key = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "darwin64": "x86_64-darwin"}
    want = {p for p in cs if key[p] in _built_tuples()}
    assert _platforms(names) == want
    if "darwin64" in fmu_folders():
        assert "darwin64" in want
    plant = next(n.split("/")[1] for n in names if n.endswith("/resources/scfmu_me_cs.txt"))
    inner = _platforms(names, f"resources/{plant}/")
    folder = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "darwin64": "x86_64-darwin"} if fmi == 3 else {}
    assert inner == {folder.get(p, p) for p in want}
    for p in want:
        ext = {"linux64": "so", "win64": "dll", "darwin64": "dylib"}[p]
        assert f"resources/{plant}/binaries/{folder.get(p, p)}/scfmu_me_cs.{ext}" in names


@pytest.fixture(scope="module")
def qemu_work(tmp_path_factory):
    """The C master built for both CPUs, PdController's two builds, and the AttitudePlant face (FMI 2.0) with
    RK4 and with the default adaptive method, unpacked."""
    if QEMU is None or shutil.which(CROSS_GCC) is None or not SYSROOT.is_dir():
        if os.environ.get("CI") == "true":
            pytest.fail("qemu-aarch64 or aarch64-linux-gnu-gcc not installed (scripts/setup.sh)")
        pytest.skip("qemu-aarch64 or aarch64-linux-gnu-gcc not installed (scripts/setup.sh)")
    built("aarch64-linux")
    import xml.etree.ElementTree as ET

    from scfmu.engines.cs_face import cs_face
    d = tmp_path_factory.mktemp("face_aarch64")
    subprocess.run(["gcc", "-O1", "-Wall", "-Werror", "-o", str(d / "fmi_loop"), str(LOADER), "-ldl"], check=True)
    subprocess.run([CROSS_GCC, "-O1", "-Wall", "-Werror", "-o", str(d / "fmi_loop.arm"), str(LOADER), "-ldl"],
                   check=True)
    assert elf_machine((d / "fmi_loop.arm").read_bytes())[1] == EM_AARCH64
    info = {}
    for model in ("AttitudePlant", "PdController"):
        with zipfile.ZipFile(FMUS / f"{model}.fmu") as z:
            (d / f"{model}.so").write_bytes(z.read(f"binaries/linux64/{model}.so"))  # the plant: Co-Simulation
            (d / f"{model}.arm.so").write_bytes(z.read(f"binaries/aarch64-linux/{model}.so"))
            root = ET.fromstring(z.read("modelDescription.xml"))
        info[model] = (root.get("guid"), {v.get("name"): int(v.get("valueReference"))
                                          for v in root.iter("ScalarVariable")})
    faces = {}
    for name, solver in (("rk4", {"method": "RK4"}), ("dopri", None)):
        face = cs_face(_unit(FMUS / "AttitudePlant.fmu", solver), d / "cache")
        with zipfile.ZipFile(face) as z:
            z.extractall(d / name)
            assert elf_machine(z.read("binaries/aarch64-linux/scfmu_me_cs.so"))[1] == EM_AARCH64
            assert elf_machine(z.read("binaries/linux64/scfmu_me_cs.so"))[1] == EM_X86_64
        faces[name] = d / name
    return d, info, faces


def _run_face(work, solver: str | None, arm: bool, steps: int = 200, dt: float = 0.05):
    """Rows of the C master's loop with the plant's face (``solver``: "rk4" or "dopri") or, for None, the
    plant's own Co-Simulation build; on aarch64 under qemu for ``arm``."""
    d, info, faces = work
    args = loop_args(info, "so", steps, dt, "PdController")
    args[2] = str(d / ("PdController.arm.so" if arm else "PdController.so"))
    env = dict(os.environ)
    if solver is None:
        args[0] = str(d / ("AttitudePlant.arm.so" if arm else "AttitudePlant.so"))
    else:
        face = faces[solver]
        args[0] = str(face / "binaries" / ("aarch64-linux" if arm else "linux64") / "scfmu_me_cs.so")
        env["FMI_LOOP_PLANT_RESOURCES"] = (face / "resources").as_uri()
    cmd = [QEMU, "-L", str(SYSROOT), str(d / "fmi_loop.arm")] if arm else [str(d / "fmi_loop")]
    r = subprocess.run([*cmd, *args], cwd=d, env=env, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    head, rows = parse_loop(r.stdout)
    assert head == "fmi2GetTypesPlatform=default fmi2GetVersion=2.0" and len(rows) == steps
    return rows


def test_rk4_face_on_aarch64_is_bit_identical_to_x86_64(qemu_work):
    """AttitudePlant's face (FMI 2.0, RK4 at the communication step) + PdController, 200 steps of 0.05 s:
    states, rates, torques and wheel momentum have the same bits on both CPUs; the Euler angles (glibc's
    atan2/asin per CPU) within 1 ulp; the loop really moves and settles towards the command."""
    x86, arm = _run_face(qemu_work, "rk4", False), _run_face(qemu_work, "rk4", True)
    assert_same_bits(x86, arm, "x86-64", "aarch64")
    first, last = np.array([v for v, _ in x86[0]]), np.array([v for v, _ in x86[-1]])
    assert max(abs(first[4:7])) > 1e-3 and max(abs(last[4:7])) < max(abs(first[4:7]))
    print(f"q0 after 10 s: {last[0]!r} on both CPUs")


def test_adaptive_face_on_aarch64_agrees_with_x86_64(qemu_work):
    """The same loop with the face's default adaptive Dormand-Prince 5(4) (its step control calls pow of each
    CPU's C library): every output of every step within 1e-12 relative of the x86-64 run (measured: 0, the
    same bits). And the face integrates the right equations: its attitude and rates stay within 1e-9 of
    the loop with the plant's own Co-Simulation build (an independent integrator; measured 3.6e-13)."""
    x86, arm = _run_face(qemu_work, "dopri", False), _run_face(qemu_work, "dopri", True)
    cs = _run_face(qemu_work, None, False)
    states = max(abs(va - vb) for a, b in zip(x86, cs) for (va, _), (vb, _) in list(zip(a, b))[:7])
    print(f"largest attitude/rate difference face vs Co-Simulation plant: {states:.3g}")
    assert states <= 1e-9
    worst = 0.0
    for a, b in zip(x86, arm):
        for (va, _), (vb, _) in zip(a, b):
            worst = max(worst, abs(va - vb) / max(abs(va), abs(vb), 1e-300) if abs(va - vb) > 1e-300 else 0.0)
    print(f"largest relative difference aarch64 vs x86-64: {worst:.3g}")
    assert worst <= 1e-12


@pytest.fixture(scope="module")
def wine_work(tmp_path_factory):
    """The C master built for Windows (MinGW, static), PdController's DLL and the AttitudePlant face (FMI 2.0,
    RK4) unpacked, beside the Linux master and PdController's .so."""
    from test_win64 import MINGW_GCC, WINE

    if WINE is None or shutil.which(MINGW_GCC) is None:
        if os.environ.get("CI") == "true":
            pytest.fail("Wine or x86_64-w64-mingw32-gcc not installed (scripts/setup.sh)")
        pytest.skip("Wine or x86_64-w64-mingw32-gcc not installed (scripts/setup.sh)")
    built("x86_64-windows")
    import xml.etree.ElementTree as ET

    from scfmu.engines.cs_face import cs_face
    d = tmp_path_factory.mktemp("face_win64")
    subprocess.run(["gcc", "-O1", "-Wall", "-Werror", "-o", str(d / "fmi_loop"), str(LOADER), "-ldl"], check=True)
    subprocess.run([MINGW_GCC, "-O1", "-Wall", "-Werror", "-D__USE_MINGW_ANSI_STDIO=1", "-static",
                    "-o", str(d / "fmi_loop.exe"), str(LOADER)], check=True)
    info = {}
    for model in ("AttitudePlant", "PdController"):
        with zipfile.ZipFile(FMUS / f"{model}.fmu") as z:
            (d / f"{model}.so").write_bytes(z.read(f"binaries/linux64/{model}.so"))
            (d / f"{model}.dll").write_bytes(z.read(f"binaries/win64/{model}.dll"))
            root = ET.fromstring(z.read("modelDescription.xml"))
        info[model] = (root.get("guid"), {v.get("name"): int(v.get("valueReference"))
                                          for v in root.iter("ScalarVariable")})
    face = cs_face(_unit(FMUS / "AttitudePlant.fmu", {"method": "RK4"}), d / "cache")
    with zipfile.ZipFile(face) as z:
        z.extractall(d / "face")
    return d, info


def test_rk4_face_under_wine_is_bit_identical_to_linux64(wine_work, monkeypatch):
    """AttitudePlant's win64 face (the Windows wrapper over the unit's win64 DLL) + PdController's DLL under
    Wine, 200 steps of 0.05 s: the same bits as the linux64 face with the .so files, except the Euler angles
    (msvcrt's and glibc's atan2/asin) within 1 ulp."""
    from test_win64 import run_wine

    d, info = wine_work
    face = d / "face"
    args = loop_args(info, "so", 200, 0.05, "PdController")
    args[0] = str(face / "binaries" / "linux64" / "scfmu_me_cs.so")
    env = dict(os.environ, FMI_LOOP_PLANT_RESOURCES=(face / "resources").as_uri())
    linux = subprocess.run([str(d / "fmi_loop"), *args], cwd=d, env=env, capture_output=True, text=True, timeout=300)
    assert linux.returncode == 0, linux.stdout[-2000:] + linux.stderr[-2000:]
    win_args = loop_args(info, "dll", 200, 0.05, "PdController")
    win_args[0] = "Z:" + str(face / "binaries" / "win64" / "scfmu_me_cs.dll").replace("/", "\\")
    monkeypatch.setenv("FMI_LOOP_PLANT_RESOURCES", "file:///Z:" + (face / "resources").as_posix())  # Wine's Z: is /
    win = run_wine(d, *win_args)
    assert win.returncode == 0, win.stdout[-2000:] + win.stderr[-2000:]
    (_, rows_linux), (_, rows_win) = parse_loop(linux.stdout), parse_loop(win.stdout)
    assert len(rows_linux) == len(rows_win) == 200
    assert_same_bits(rows_linux, rows_win, "linux64", "win64")
    last = [v for v, _ in rows_win[-1]]
    print(f"q0 after 10 s: {last[0]!r} on both platforms")
    assert max(abs(x) for x in last[4:7]) < 1e-3


@pytest.mark.parametrize("sys_platform,machine,tup,name", [
    ("linux", "x86_64", "x86_64-linux", "libscfmu_me_cs.so"),
    ("linux", "aarch64", "aarch64-linux", "libscfmu_me_cs.so"),
    ("win32", "AMD64", "x86_64-windows", "scfmu_me_cs.dll"),
    ("darwin", "x86_64", "x86_64-darwin", "libscfmu_me_cs.dylib"),
    ("darwin", "arm64", "aarch64-darwin", "libscfmu_me_cs.dylib"),
])
def test_an_installed_package_takes_the_wrapper_of_its_own_platform(sys_platform, machine, tup, name, tmp_path,
                                                                     monkeypatch):
    """An installed package (a wheel: no source checkout around it) with every platform's wrapper under
    scfmu/engines/me_cs/bin/<tuple>/: on each platform, the native engine's wrapper is that platform's."""
    from scfmu.engines import cs_face

    pkg = tmp_path / "site-packages" / "scfmu"
    files = {t: pkg / "engines" / "me_cs" / "bin" / t / n for t, n in (
        ("x86_64-linux", "libscfmu_me_cs.so"), ("aarch64-linux", "libscfmu_me_cs.so"),
        ("x86_64-windows", "scfmu_me_cs.dll"), ("x86_64-darwin", "libscfmu_me_cs.dylib"),
        ("aarch64-darwin", "libscfmu_me_cs.dylib"))}
    for t, f in files.items():
        f.parent.mkdir(parents=True)
        f.write_bytes(t.encode())
    monkeypatch.setattr(cs_face.resources, "files", lambda _: pkg)
    monkeypatch.setattr(cs_face.sys, "platform", sys_platform)
    monkeypatch.setattr(cs_face.platform, "machine", lambda: machine)
    assert cs_face.wrapper_libraries() == files
    assert cs_face.wrapper_library() == files[tup] and files[tup].name == name
    files[tup].unlink()  # that platform's wrapper missing: none (the native engine refuses ME units in one line)
    assert cs_face.wrapper_library() is None


def test_a_truncated_or_foreign_header_is_no_platform():
    """A unit's binary is not trusted: a header that points past the end of the file names no platform
    (and raises nothing)."""
    from scfmu.engines.cs_face import binary_tuples
    pe_cut = b"MZ" + b"\0" * 0x3A + (0x40).to_bytes(4, "little") + b"PE\0\0"  # machine field missing
    fat_cut = b"\xca\xfe\xba\xbe" + (5).to_bytes(4, "big")  # five slices announced, none present
    assert binary_tuples(pe_cut) == set() and binary_tuples(fat_cut) == set()
    assert binary_tuples(b"\x7fELF") == set() and binary_tuples(b"") == set()
    assert binary_tuples(pe_cut + (0x8664).to_bytes(2, "little")) == {"x86_64-windows"}
