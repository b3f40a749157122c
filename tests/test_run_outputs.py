"""Issue 34, item 5: outputs a person can read. Every `scfmu run` writes to its own folder, the figure names
the scenario and every unit, printed metrics carry units, and the Python Result carries the printed metrics
(checked against an independent computation of settling time and overshoot from the logged signals)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

from scfmu import simulate
from scfmu.scenario import get

ROOT = Path(__file__).resolve().parents[1]
PD3 = ROOT / "fmus" / "fmi3" / "PdController.fmu"


def scfmu(cwd, *args):
    r = subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True, cwd=cwd,
                       timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def printed_metrics(stdout: str) -> dict:
    out = {}
    for line in stdout.splitlines():
        m = re.fullmatch(r"  (\w+)\s+(\S+)(?: (\S+))?", line)
        if m and m.group(1) not in ("wrote",):
            try:
                out[m.group(1)] = (float(m.group(2)), m.group(3) or "")
            except ValueError:
                pass
    return out


def test_runs_never_overwrite_each_other(tmp_path):
    a = scfmu(tmp_path, "run", "default", "--t-end", "2", "--no-plot")
    b = scfmu(tmp_path, "run", "default", "--t-end", "2", "--fmu", f"controller={PD3}", "--no-plot")
    c = scfmu(tmp_path, "run", "default", "--t-end", "3", "--no-plot")  # another run of the same scenario
    d = scfmu(tmp_path, "run", "default", "--t-end", "2", "--no-plot")  # the first run again: its own folder
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["default", "default+PdController", "default-2"]
    assert "out/default/default.csv" in a.stdout and "out/default+PdController/default.csv" in b.stdout
    assert "out/default-2" in c.stdout and "holds another run" in c.stderr
    assert "out/default/default.csv" in d.stdout and not d.stderr.strip()
    assert json.loads((out / "default" / "run.json").read_text())["scenario"]["stop_time"] == 2.0
    assert json.loads((out / "default-2" / "run.json").read_text())["scenario"]["stop_time"] == 3.0
    # --out chooses the folder; replacing another run's files there is said
    e = scfmu(tmp_path, "run", "default", "--t-end", "1", "--no-plot", "--out", out / "default")
    assert "replaced" in e.stderr


def test_printed_metrics_carry_units_and_equal_the_results(tmp_path):
    r = scfmu(tmp_path, "run", "default", "--t-end", "12", "--engine", "compiled")
    got = printed_metrics(r.stdout)
    assert got["eulerint_deg_s"][1] == "deg.s" and got["settling_s"][1] == "s" and got["ise"][1] == "rad2.s"
    assert got["overshoot_roll_pct"][1] == "%" and got["peak_torque"][1] == "N.m"
    res = simulate(get("default", stop_time=12.0), "compiled")
    for k, (v, _unit) in got.items():
        assert abs(res.metrics[k] - v) <= 1e-5 * max(1.0, abs(v)), k
    # independent: the 2 % settling time of α (band: 2 % of α(0) = 69.3 deg) and the roll overshoot, from the
    # logged signals
    t, alpha = res["time"], res["alpha_deg"]
    outside = np.flatnonzero(np.abs(alpha) > 0.02 * alpha[0])
    assert res.metrics["settling_s"] == t[outside[-1] + 1]
    roll, ref = res["roll"], res["roll_ref"][-1]
    assert abs(res.metrics["overshoot_roll_pct"] - max(0.0, 100.0 * (roll.max() - ref) / ref)) < 1e-9
    png = tmp_path / "out" / "default" / "default.png"
    assert png.stat().st_size > 20000


def test_result_units_and_pandas():
    res = simulate(get("default", stop_time=1.0), "lean")
    assert res.units["w_x"] == "rad/s" and res.units["torque_applied_x"] == "N.m" and res.units["time"] == "s"
    assert res.units["q_w"] == ""  # a quaternion declares no unit: none is invented
    df = res.to_pandas()
    assert df.shape == (101, len(res) - 1) and df.index.name == "time"
    assert np.array_equal(df["w_y"].to_numpy(), res["w_y"])


def test_write_parquet_keeps_every_signal_and_its_unit(tmp_path):
    import pyarrow.parquet as pq

    from scfmu.results import write_parquet

    class Logged(dict):
        units = {"time": "s", "w_x": "rad/s"}

    r = Logged(time=[0.0, 0.5, 1.0], w_x=np.array([1.0, -2.0, 3.5]), mode=[0, 1, 1])
    write_parquet(tmp_path / "r.parquet", r)
    t = pq.read_table(tmp_path / "r.parquet")
    assert t.column_names == ["time", "w_x", "mode"]
    assert [t.schema.field(k).metadata[b"unit"] for k in t.column_names] == [b"s", b"rad/s", b""]
    assert all(str(t.schema.field(k).type) == "double" for k in t.column_names)
    assert t.column("w_x").to_pylist() == [1.0, -2.0, 3.5] and t.column("mode").to_pylist() == [0.0, 1.0, 1.0]
    write_parquet(tmp_path / "plain.parquet", {"a": [1.0]})  # a plain dict: no units, empty metadata
    assert pq.read_table(tmp_path / "plain.parquet").schema.field("a").metadata[b"unit"] == b""
