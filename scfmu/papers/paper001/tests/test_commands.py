"""`scfmu paper 001 ...`: the formation command runs and writes what it promises."""

import subprocess
import sys


def _run(args, timeout=600):
    r = subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


def test_paper001_script_short_horizon(tmp_path):
    """Case a only, 20 s at 0.01 s, no plots: the script's wiring and report, not the paper's numbers."""
    out = _run(["paper", "001", "formation", "--cases", "a", "--t-end", "20", "--dt", "0.01", "--no-plots",
                "--out", tmp_path])
    assert "settling" in out.lower()
