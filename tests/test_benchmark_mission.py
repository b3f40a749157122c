"""The benchmark's mission column (issue 44, ``scfmu benchmark --mission``): every controller as the fine-pointing
law of ``mission/tipoff`` over the same dispersed runs, ranked by the p95 time from separation to on target.

* The p95 is the empirical quantile over every run (the smallest time t with at least 95 % of the runs on target
  by t, computed here from its definition), a run that never gets there counting as not reached; ranks by the
  p95 (equal within 1 s), then by the runs never on target, checked on made-up times.
* A user's unit given by path takes the place beside the scenario's own PD; the PD's times are those of the
  scenario run directly (the engines' own run of the same draw, with the mission metric computed here from the
  logged truth), a unit that crashes loses its runs, not the benchmark, and ranks last.
* The command line refuses what cannot work, in one line with exit status 2.
"""

from __future__ import annotations

import csv
import math
import subprocess
import sys

import numpy as np
import pytest

import foreign_units as fu
from scfmu.benchmark import mission as bm
from scfmu.engines import simulate
from scfmu.registry import REGISTRY
from scfmu.scenario import get


def scfmu(*args, timeout=900):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def quantile(times, q):
    """The smallest t of the runs with at least q·n runs done by t (inf: fewer than q·n runs ever get there)."""
    n = len(times)
    for t in sorted(times):
        if sum(1 for x in times if x <= t) >= q * n:
            return t
    return math.inf


def test_p95_counts_a_run_that_never_gets_there_and_ties_share_a_rank():
    rng = np.random.default_rng(3)
    base = list(3900 + 300 * rng.random(20))
    one = bm.MissionEntry("A", "m", values=base[:19] + [math.inf])       # 1 of 20 never: p95 still finite
    two = bm.MissionEntry("B", "m", values=base[:18] + [math.inf] * 2)   # 2 of 20 never: p95 not reached
    for m in (one, two):
        m.runs = m.ok = 20
        assert m.p(95) == quantile(m.values, 0.95)
        assert m.p(50) == quantile(m.values, 0.50)
    assert math.isfinite(one.p(95)) and one.p(95) == sorted(base[:19])[18] and two.p(95) == math.inf
    assert one.never == 1 and two.never == 2
    c = bm.MissionEntry("C", "m", values=[x + 0.5 for x in one.values])  # within 1 s of A: the same rank
    d = bm.MissionEntry("D", "m", values=[x + 5.0 for x in one.values])
    for m in (c, d):
        m.runs = m.ok = 20
    na = bm.MissionEntry("E", "m", status="not designed for this plant: …")
    worse = bm.MissionEntry("F", "m", values=[math.inf] * 20)               # not reached either, 20 never
    worse.runs = worse.ok = 20
    assert bm.ranks([two, d, one, c, na, worse]) == {"A": 1, "C": 1, "D": 3, "B": 4, "F": 5}


def test_the_mission_case_is_registered_for_the_attitude_family():
    case = bm.case_of("attitude")
    assert case is not None and case.scenario == "mission/tipoff" and case.metric == "t_on_target_s"
    assert bm.case_of("formation") is None
    a, b = bm.draws(case, 3), bm.draws(case, 3)
    assert a == b and len({tuple(sorted(d.items())) for d in a}) == 3       # the same draws every time, distinct
    assert set(REGISTRY.dispersions_of("mission/tipoff")) <= set(a[0]) and set(get(case.scenario).seed_params) <= set(a[0])


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bm_mission")
    unit = fu.build_c_pd(tmp, "crash", fail_time=100.0)
    r = scfmu("benchmark", unit, "--family", "attitude", "--mission", "--mission-runs", 2, "--controllers",
              "PdController", "--cases", "paper000/000-5", "--out", tmp / "out", "--workers", 2, "--quick")
    assert r.returncode == 0, r.stderr[-2000:]
    with open(tmp / "out" / "mission.csv") as f:
        rows = {row["controller"]: row for row in csv.DictReader(f)}
    return tmp, rows, (tmp / "out" / "benchmark.md").read_text()


def test_a_crashing_unit_loses_its_runs_not_the_benchmark_and_ranks_last(page):
    _, rows, md = page
    unit, pd = rows["CPdController_crash"], rows["PD, quaternion error"]
    assert unit["envelope"] == "unit" and unit["ok"] == "0" and unit["never"] == "2" and unit["rank"] == "2"
    assert "crash" in unit["failures"] or "signal" in unit["failures"].lower() or "died" in unit["failures"]
    assert pd["envelope"] == "home" and pd["ok"] == "2" and pd["never"] == "0" and pd["rank"] == "1"
    assert "## Mission: time to fine pointing" in md and "**CPdController_crash**" in md


def test_the_scenarios_own_pd_gives_the_times_of_a_direct_run(page):
    """The PD's on-target times in the column are those of mission/tipoff run directly with the same draws,
    the on-target time recomputed here from the logged mode and the pointing error of the truth."""
    _, rows, _ = page
    case = bm.case_of("attitude")
    times = []
    for d in bm.draws(case, 2):
        r = simulate(get(case.scenario).with_overrides(d), engine="auto")
        t = np.asarray(r["time"], dtype=float)
        q = np.stack([np.asarray(r[f"q_{a}"], dtype=float) for a in "wxyz"], axis=1)
        qr = np.stack([np.asarray(r[f"q_ref_{a}"], dtype=float) for a in "wxyz"], axis=1)
        err = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q * qr, axis=1)), 0, 1)))
        ok = (np.rint(np.asarray(r["mode"], dtype=float)) == 4) & (err <= 0.2)
        w = int(round(300.0 / (t[1] - t[0])))
        first = next((t[i] for i in range(len(t) - w + 1) if ok[i:i + w].all()), math.inf)
        times.append(first)
    pd = rows["PD, quaternion error"]
    assert float(pd["t_on_target_s median [s]"]) == pytest.approx(min(times), abs=0.11)
    assert float(pd["t_on_target_s p95 [s]"]) == pytest.approx(max(times), abs=0.11)


@pytest.mark.parametrize("args, says", [
    (["--mission", "--family", "formation"], "--mission: family 'formation' has no mission scenario"),
    (["--mission-runs", "3"], "--mission-runs 3: only with --mission"),
    (["--mission", "--mission-runs", "0"], "--mission-runs 0: allowed: a whole number in [1, 100000]"),
])
def test_refusals_are_one_line_with_exit_2(args, says):
    r = scfmu("benchmark", *args, timeout=120)
    assert r.returncode == 2 and says in r.stderr and "Traceback" not in r.stderr, r.stderr
