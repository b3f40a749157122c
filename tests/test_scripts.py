"""The README's commands run and write what they promise."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_default_scenario_prints_metrics_and_writes_csv_png(tmp_path):
    r = subprocess.run([sys.executable, "-m", "scfmu", "run", "default", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "eulerint_deg_s" in r.stdout and "settling_s" in r.stdout and "effort_abs" in r.stdout
    csv = (tmp_path / "default.csv").read_text().splitlines()
    assert len(csv) == 3002, "header + 3001 samples (0 to 30 s, 0.01 s)"
    assert (tmp_path / "default.png").stat().st_size > 10_000


def _run(args, timeout=600):
    r = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=timeout, cwd=ROOT)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


# --- the set-up and build scripts' options (issue 42: the first run installs and builds only what it needs) ---

def _stub_path(tmp_path: Path) -> tuple[dict, Path]:
    """PATH with stand-ins for apt-get, dpkg and dpkg-query that log their arguments (dpkg-query finds no
    package installed, so a set-up that wants system packages asks apt-get for them)."""
    import os
    bin_ = tmp_path / "bin"
    bin_.mkdir()
    log = tmp_path / "calls.log"
    for name, body in (("apt-get", ""), ("dpkg", ""), ("dpkg-query", "exit 1")):
        (bin_ / name).write_text(f'#!/bin/sh\necho "{name} $*" >> "{log}"\n{body}\n')
        (bin_ / name).chmod(0o755)
    return dict(os.environ, PATH=f"{bin_}:{os.environ['PATH']}"), log


def test_run_only_setup_installs_no_system_package_and_cross_does(tmp_path):
    import os
    if os.geteuid() != 0:
        import pytest
        pytest.skip("the apt-get path of scripts/setup.sh is taken as root only")
    env, log = _stub_path(tmp_path)
    for args in (["--run-only"], []):
        r = subprocess.run(["bash", "scripts/setup.sh", *args], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=900)
        assert r.returncode == 0, r.stderr[-2000:]
        assert not log.exists(), f"setup.sh {args} called {log.read_text()}"
    r = subprocess.run(["bash", "scripts/setup.sh", "--cross"], cwd=ROOT, env=env, capture_output=True, text=True,
                       timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    calls = log.read_text()
    assert "apt-get install" in calls and "mingw" in calls and "qemu-user" in calls, calls


def test_script_options_are_checked():
    for script, args, allowed in (("setup.sh", ["--bogus"], "--run-only"),
                                  ("build_fmus.sh", ["--bogus"], "--all-platforms"),
                                  ("build_fmus.sh", ["--platform", "mars"], "win-amd64"),
                                  ("build_wheel.sh", ["--platform", "mars"], "linux-x86_64")):
        r = subprocess.run(["bash", f"scripts/{script}", *args], cwd=ROOT, capture_output=True, text=True, timeout=60)
        assert r.returncode == 2, (script, args, r.returncode, r.stderr)
        assert allowed in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
