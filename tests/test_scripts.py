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


def _run(args, timeout=600):
    r = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=timeout, cwd=ROOT)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


def test_paper000_study_runs_every_experiment(tmp_path):
    """The full study (40 runs, 30 s each) with its plots: the README promises it."""
    out = _run([ROOT / "scripts" / "paper000_study.py", "--out", tmp_path])
    assert "000-11L2" in out and "R2-0.8-AdaptFuzzy-L2" in out
    assert (tmp_path / "summary.csv").exists()
    assert len(list(tmp_path.glob("*.png"))) >= 10


def test_wheel_fault_script(tmp_path):
    out = _run([ROOT / "scripts" / "run_wheel_fault.py", "--out", tmp_path, "--t-end", "20"])
    assert (tmp_path / "wheel_fault.png").exists() and (tmp_path / "wheel_fault.csv").exists(), out


def test_paper001_script_short_horizon(tmp_path):
    """Case a only, 20 s at 0.01 s, no plots: the script's wiring and report, not the paper's numbers."""
    out = _run([ROOT / "scripts" / "paper001_formation.py", "--cases", "a", "--t-end", "20", "--dt", "0.01", "--no-plots",
                "--out", tmp_path])
    assert "settling" in out.lower()
