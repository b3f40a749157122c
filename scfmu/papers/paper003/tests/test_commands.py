"""`scfmu paper 003 ...`: the wheel-fault command runs and writes what it promises."""

import subprocess
import sys


def _run(args, timeout=600):
    r = subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


def test_wheel_fault_script(tmp_path):
    out = _run(["paper", "003", "wheel-fault", "--out", tmp_path, "--t-end", "20"])
    assert (tmp_path / "wheel_fault.png").exists() and (tmp_path / "wheel_fault.csv").exists(), out
