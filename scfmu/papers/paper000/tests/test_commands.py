"""`scfmu paper 000 ...`: the paper 000 study command runs and writes what it promises."""

import subprocess
import sys


def _run(args, timeout=600):
    r = subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


def test_paper000_study_runs_every_experiment(tmp_path):
    """The full study (40 runs, 30 s each) with its plots: the README promises it."""
    out = _run(["paper", "000", "study", "--out", tmp_path])
    assert "000-11L2" in out and "R2-0.8-AdaptFuzzy-L2" in out
    assert (tmp_path / "summary.csv").exists()
    assert len(list(tmp_path.glob("*.png"))) >= 10
