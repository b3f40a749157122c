"""The README's default scenario script runs and writes what it promises."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_default_scenario_prints_metrics_and_writes_csv_png(tmp_path):
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "run_default.py"), "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "eulerint_deg_s" in r.stdout and "settling_alpha_s" in r.stdout and "effort_abs_Nms" in r.stdout
    csv = (tmp_path / "default_run.csv").read_text().splitlines()
    assert len(csv) == 3002, "header + 3001 samples (0 to 30 s, 0.01 s)"
    assert (tmp_path / "default_run.png").stat().st_size > 10_000
