"""The wheels: scripts/build_wheel.sh --platform all packages the built FMUs into one wheel per platform whose
binaries they carry (manylinux x86_64 and aarch64, win_amd64, macOS x86_64 and arm64), each tagged for its
platform and carrying only that platform's binaries; the Linux x86-64 one, installed with pip into a fresh
virtual environment, in a folder outside the repository, with no Rust toolchain on PATH, runs `scfmu run
default` (the run 000-6 metrics, EULERINT 156.4 deg·s, the CSV and PNG) from the FMUs inside the wheel.
Dependencies come from the pip cache or the package index, as for a user."""

import os
import re
import shutil
import struct
import subprocess
import venv
import zipfile
from pathlib import Path

import pytest
from packaging.tags import sys_tags
from packaging.utils import parse_wheel_filename
from scfmu.engines.cs_face import checkout_build

ROOT = Path(__file__).resolve().parents[1]
# platform -> (FMI 2.0 folder in the wheel, FMI 3.0 tuple, binary check, compiled loop library (None: not built
# for macOS, scripts/build_macos.sh), tag pattern)
ELF_X86_64, ELF_AARCH64 = ("ELF", 62), ("ELF", 183)
MACHO_X86_64, MACHO_ARM64 = ("Mach-O", 0x01000007), ("Mach-O", 0x0100000C)
PLATFORMS = {
    "linux-x86_64": ("linux64", "x86_64-linux", ELF_X86_64, "linux64/libscfmu_native_loop.so", r"manylinux_2_(\d+)_x86_64"),
    "linux-aarch64": ("linux64", "aarch64-linux", ELF_AARCH64, "linux64/libscfmu_native_loop.so", r"manylinux_2_(\d+)_aarch64"),
    "win-amd64": ("win64", "x86_64-windows", ("PE", 0x8664), "win64/scfmu_native_loop.dll", r"win_amd64"),
    "macos-x86_64": ("darwin64", "x86_64-darwin", MACHO_X86_64, None, r"macosx_10_12_x86_64"),
    "macos-arm64": ("darwin64", "aarch64-darwin", MACHO_ARM64, None, r"macosx_11_0_arm64"),
}
# each platform's Model Exchange wrapper (cargo build --release, the cross-build scripts)
ME_CS = {plat: checkout_build(p[1]) for plat, p in PLATFORMS.items()}
# the FMI 2.0 folders of fmus/<Model>.fmu that make each platform's wheel
SOURCE_FOLDER = {"linux-x86_64": "linux64", "linux-aarch64": "aarch64-linux", "win-amd64": "win64",
                 "macos-x86_64": "darwin64", "macos-arm64": "darwin64"}


def binary_kind(data: bytes) -> tuple[str, int]:
    """(format, machine) read from the file's own header: ELF e_machine, PE machine, thin Mach-O cputype."""
    if data[:4] == b"\x7fELF":
        return "ELF", struct.unpack_from("<H", data, 18)[0]
    if data[:2] == b"MZ":
        pe = struct.unpack_from("<I", data, 0x3C)[0]
        assert data[pe:pe + 4] == b"PE\0\0"
        return "PE", struct.unpack_from("<H", data, pe + 4)[0]
    if data[:4] == b"\xcf\xfa\xed\xfe":
        return "Mach-O", struct.unpack_from("<I", data, 4)[0]
    return "unknown", 0


def expected_platforms() -> list[str]:
    names = zipfile.ZipFile(ROOT / "fmus" / "AttitudePlant.fmu").namelist()
    have = {n.split("/")[1] for n in names if n.startswith("binaries/")}
    return [p for p in PLATFORMS if SOURCE_FOLDER[p] in have]


@pytest.fixture(scope="module")
def wheels(tmp_path_factory) -> dict[str, Path]:
    """{platform: wheel} from one run of scripts/build_wheel.sh --platform all --no-fmu-build."""
    if not list((ROOT / "fmus").glob("*.fmu")):
        pytest.fail("no FMUs in fmus/ (scripts/build_fmus.sh)")
    d = tmp_path_factory.mktemp("wheels")
    r = subprocess.run([str(ROOT / "scripts" / "build_wheel.sh"), "--no-fmu-build", "--platform", "all",
                        "--out", str(d / "dist")], capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    written = re.findall(r"^build_wheel: wrote (\S+) .* for (\S+)\)$", r.stdout, re.M)
    out = {plat: Path(path) for path, plat in written}
    assert sorted(out) == sorted(expected_platforms()), r.stdout
    assert Path(r.stdout.strip().splitlines()[-1]) in out.values()
    if os.environ.get("CI") == "true":  # scripts/setup.sh installs every cross toolchain there
        assert sorted(out) == sorted(PLATFORMS), "CI builds every platform's binaries"
    return out


@pytest.fixture(scope="module")
def installed(tmp_path_factory, wheels):
    d = tmp_path_factory.mktemp("wheel")
    wheel = wheels["linux-x86_64"]
    assert wheel.is_file() and wheel.suffix == ".whl"
    env_dir = d / "venv"
    venv.EnvBuilder(with_pip=True, clear=True).create(env_dir)
    py = env_dir / "bin" / "python"
    # requirements.txt pins the same versions the suite runs with; the wheel's own requirements are ranges
    pins = [line.split("#")[0].strip() for line in (ROOT / "requirements.txt").read_text().splitlines()]
    pins = [p for p in pins if p.split("==")[0].split("[")[0] in ("fmpy", "numpy", "scipy", "matplotlib", "lxml", "tqdm")]
    r = subprocess.run([str(py), "-m", "pip", "install", "--quiet", str(wheel), *pins], capture_output=True,
                       text=True, timeout=1200)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return env_dir, wheel


def _clean_env(env_dir: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("SCFMU_", "PYTHON", "VIRTUAL_ENV"))}
    env["PATH"] = str(env_dir / "bin")  # the venv only: no cargo, no rustc, no compiler
    return env


def test_wheel_carries_every_fmu_and_the_data(installed):
    import zipfile
    _, wheel = installed
    names = zipfile.ZipFile(wheel).namelist()
    fmus = {Path(n).name for n in names if n.startswith("scfmu/fmus/") and n.endswith(".fmu")}
    assert fmus == {p.name for p in (ROOT / "fmus").glob("*.fmu")}
    for data in ("scfmu/papers/paper002/data/gains.json", "scfmu/papers/paper003/data/tuned.json",
                 "scfmu/papers/paper004/data/nodes.json"):
        assert data in names
    assert not [n for n in names if "/tests/" in n], "the package's tests are not shipped"
    # the compiled engine's loop library (cargo build --release), for this platform
    assert "scfmu/engines/native_loop/bin/linux64/libscfmu_native_loop.so" in names
    # the FMI 3.0 twins too
    assert {Path(n).name for n in names if n.startswith("scfmu/fmus/fmi3/")} == {p.name for p in (ROOT / "fmus").glob("*.fmu")}


def glibc_versions(lib: Path, objdump: str) -> set[tuple[int, int]]:
    """The glibc symbol versions an ELF file needs, as objdump lists its dynamic symbols."""
    out = subprocess.run([objdump, "-T", str(lib)], capture_output=True, text=True, check=True).stdout
    return {(int(a), int(b)) for a, b in re.findall(r"\(GLIBC_(\d+)\.(\d+)\)", out)}


@pytest.mark.parametrize("plat", list(PLATFORMS))
def test_platform_wheel_is_tagged_and_carries_only_its_platform_binaries(wheels, plat, tmp_path):
    if plat not in wheels:
        pytest.skip(f"the FMUs carry no {SOURCE_FOLDER[plat]} binaries (cross toolchain not installed)")
    wheel = wheels[plat]
    folder, tuple3, kind, loop, tag_re = PLATFORMS[plat]
    _, _, _, tags = parse_wheel_filename(wheel.name)
    assert len(tags) == 1
    tag = next(iter(tags))
    assert (tag.interpreter, tag.abi) == ("py3", "none")
    m = re.fullmatch(tag_re, tag.platform)
    assert m, tag.platform
    z = zipfile.ZipFile(wheel)
    meta = z.read(next(n for n in z.namelist() if n.endswith(".dist-info/WHEEL"))).decode()
    assert f"Tag: py3-none-{tag.platform}" in meta
    # pip on this machine (Linux x86-64) takes the x86-64 Linux wheel and no other
    here = {str(t) for t in sys_tags()}
    assert (f"py3-none-{tag.platform}" in here) == (plat == "linux-x86_64")
    fmus = [n for n in z.namelist() if n.startswith("scfmu/fmus/") and n.endswith(".fmu")]
    assert len(fmus) == 2 * len(list((ROOT / "fmus").glob("*.fmu")))
    shipped = []
    for n in fmus:
        model = Path(n).stem
        inner = zipfile.ZipFile(z.open(n))
        bins = [b for b in inner.namelist() if b.startswith("binaries/")]
        want = f"binaries/{tuple3 if '/fmi3/' in n else folder}/{model}"
        assert len(bins) == 1 and bins[0].startswith(want + "."), (n, bins)
        data = inner.read(bins[0])
        assert binary_kind(data) == kind, (n, binary_kind(data))
        assert "modelDescription.xml" in inner.namelist()
        shipped.append(data)
    loops = [n for n in z.namelist() if n.startswith("scfmu/engines/native_loop/bin/")]
    assert loops == ([f"scfmu/engines/native_loop/bin/{loop}"] if loop else []), loops
    shipped += [z.read(n) for n in loops]
    for data in shipped[-len(loops):] if loops else []:
        assert binary_kind(data) == kind
    # the Model Exchange wrapper of this platform (scfmu/engines/cs_face.py), wherever it was built
    me_cs = [n for n in z.namelist() if n.startswith("scfmu/engines/me_cs/bin/")]
    lib = ROOT / ME_CS[plat]
    assert me_cs == ([f"scfmu/engines/me_cs/bin/{tuple3}/{lib.name}"] if lib.is_file() else []), me_cs
    for n in me_cs:
        assert z.read(n) == lib.read_bytes() and binary_kind(z.read(n)) == kind
        shipped.append(z.read(n))
    assert not [n for n in z.namelist() if n.endswith((".ssp",)) or "/loops/" in n], "no SSP or loop files"
    if plat.startswith("linux"):
        # manylinux_2_N: N is the newest glibc symbol version any shipped binary needs (PEP 600)
        objdump = "objdump" if plat == "linux-x86_64" else "aarch64-linux-gnu-objdump"
        if shutil.which(objdump) is None:
            pytest.skip(f"{objdump} not installed")
        newest = set()
        for i, data in enumerate(set(shipped)):
            f = tmp_path / f"lib{i}.so"
            f.write_bytes(data)
            newest |= glibc_versions(f, objdump)
        assert max(newest) == (2, int(m.group(1))), (sorted(newest)[-3:], tag.platform)


def test_installed_wheel_uses_its_compiled_loop(installed, tmp_path):
    env_dir, _ = installed
    r = subprocess.run([str(env_dir / "bin" / "python"), "-c",
                        "from scfmu.engines import compiled, resolve_engine; "
                        "print(compiled.library_path()); print(resolve_engine('auto'))"],
                       cwd=tmp_path, env=_clean_env(env_dir), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    path, engine = r.stdout.split()
    assert Path(path).is_relative_to(env_dir) and engine == "compiled"


def test_installed_wheel_finds_its_model_exchange_wrapper(installed, tmp_path):
    """The installed wheel's Co-Simulation faces take the wrapper the wheel ships, not the checkout's."""
    env_dir, _ = installed
    r = subprocess.run([str(env_dir / "bin" / "python"), "-c",
                        "from scfmu.engines.cs_face import wrapper_libraries; print(wrapper_libraries())"],
                       cwd=tmp_path, env=_clean_env(env_dir), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "'x86_64-linux': " in r.stdout and "me_cs/bin/x86_64-linux/libscfmu_me_cs.so" in r.stdout, r.stdout
    assert str(env_dir) in r.stdout and str(ROOT / "target") not in r.stdout, r.stdout


def test_installed_wheel_runs_default_outside_the_repository(installed, tmp_path):
    env_dir, _ = installed
    env = _clean_env(env_dir)
    assert shutil.which("cargo", path=env["PATH"]) is None and shutil.which("rustc", path=env["PATH"]) is None
    work = tmp_path / "elsewhere"
    work.mkdir()
    r = subprocess.run([str(env_dir / "bin" / "scfmu"), "run", "default"], cwd=work, env=env, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    m = re.search(r"eulerint_deg_s\s+([0-9.]+)", r.stdout)
    assert m and abs(float(m.group(1)) - 156.4) < 0.05, r.stdout
    assert (work / "out" / "default" / "default.csv").stat().st_size > 100_000
    assert (work / "out" / "default" / "default.png").stat().st_size > 10_000
    # the FMUs came from the wheel, not from this checkout
    r = subprocess.run([str(env_dir / "bin" / "python"), "-c", "import scfmu; print(scfmu.fmu_dir())"], cwd=work,
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "site-packages" in r.stdout, r.stdout + r.stderr
    assert not Path(r.stdout.strip()).resolve().is_relative_to(ROOT), r.stdout  # not the checkout's fmus/


def test_installed_wheel_lists_scenarios_and_subcommands(installed, tmp_path):
    env_dir, _ = installed
    env = _clean_env(env_dir)
    r = subprocess.run([str(env_dir / "bin" / "scfmu"), "--help"], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0
    for sub in ("run", "scenarios", "campaign", "export", "report", "paper"):
        assert re.search(rf"^\s+{sub}\b", r.stdout, re.M), r.stdout
    r = subprocess.run([str(env_dir / "bin" / "python"), "-m", "scfmu", "scenarios", "paper003/*"], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "paper003/T2FSMC/U" in r.stdout, r.stdout + r.stderr
