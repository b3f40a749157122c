"""The wheel: scripts/build_wheel.sh packages the built FMUs into a wheel; installed with pip into a fresh
virtual environment, in a folder outside the repository, with no Rust toolchain on PATH, `scfmu run default`
prints the run 000-6 metrics (EULERINT 156.4 deg·s) and writes the CSV and PNG from the FMUs inside the
wheel. Dependencies come from the pip cache or the package index, as for a user."""

import os
import re
import shutil
import subprocess
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    if not list((ROOT / "fmus").glob("*.fmu")):
        pytest.fail("no FMUs in fmus/ (scripts/build_fmus.sh)")
    d = tmp_path_factory.mktemp("wheel")
    r = subprocess.run([str(ROOT / "scripts" / "build_wheel.sh"), "--no-fmu-build", "--out", str(d / "dist")],
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    wheel = Path(r.stdout.strip().splitlines()[-1])
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


def test_installed_wheel_uses_its_compiled_loop(installed, tmp_path):
    env_dir, _ = installed
    r = subprocess.run([str(env_dir / "bin" / "python"), "-c",
                        "from scfmu.engines import compiled, resolve_engine; "
                        "print(compiled.library_path()); print(resolve_engine('auto'))"],
                       cwd=tmp_path, env=_clean_env(env_dir), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    path, engine = r.stdout.split()
    assert Path(path).is_relative_to(env_dir) and engine == "compiled"


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
    assert r.returncode == 0 and "site-packages" in r.stdout and str(ROOT) not in r.stdout, r.stdout + r.stderr


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
