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
