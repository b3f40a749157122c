"""Issue 48 item 2: our engines run FMI 3.0 clocked units on their clocks (clocked Co-Simulation and a
Scheduled Execution scheduler) and give the sampled run's outputs.

Oracle: the same scenario with the FMI 2.0 units on the reference master (fmpy's high-level calls, the
units sampling inside doStep), written to CSV; the sampled FMI 3.0 run, the clocked run and the scheduled
run must write the same CSV byte for byte. The schedule is checked against the closed form (tick k of a
clock at t_start + shift + k·interval: the counts of activations). Errors: the one-line refusals of the
command line and the API."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from scfmu import run_cmd
from scfmu.engines import simulate
from scfmu.engines.clocked import ClockedMaster, clock_notice, clock_problem
from scfmu.engines.scheduler import Scheduler
from scfmu.fmu import described, fmu_dir
from scfmu.scenario import get
from scfmu.scenario.plan import PlanError, build_plan

FMI3 = fmu_dir() / "fmi3"


def has_clocks(model: str) -> bool:
    p = FMI3 / f"{model}.fmu"
    return p.exists() and any(v.type == "Clock" for v in described(p).modelVariables)


needs_clocks = pytest.mark.skipif(not has_clocks("PidController"),
                                  reason="the FMI 3.0 FMUs have no clocks yet (SCFMU_FMU_DIR: a build with clocks)")


def in_fmi3(sc, instances=None):
    """The scenario with its units (or ``instances``) as FMI 3.0 FMUs, parameters kept (same names)."""
    s = copy.deepcopy(sc)
    for c in s.components:
        if (instances is None or c.name in instances) and (FMI3 / f"{c.model}.fmu").exists():
            c.model = str(FMI3 / f"{c.model}.fmu")
    return s


def csv_bytes(res, path) -> bytes:
    res.to_csv(path)
    return path.read_bytes()


def bits_equal(a: dict, b: dict) -> bool:
    return list(a) == list(b) and all(np.array_equal(np.asarray(a[k]).view(np.uint64), np.asarray(b[k]).view(np.uint64))
                                      for k in a)


def pid_loop():
    return get("paper002/PID", stop_time=1.0)


def adcs_loop():
    """ModeManager + Mekf + StarTracker (with latency: a shifted delivery clock) + gyro, sun sensor,
    magnetometer, BDot: the tip-off mission for 30 s."""
    sc = get("mission/tipoff", stop_time=30.0)
    sc = sc.with_overrides({"star_tracker.latency": 0.1, "star_tracker.sample_period": 0.2})
    return sc


def sensing_loop():
    """Gyro 100 Hz, star tracker 5 Hz with 0.1 s latency, Mekf 100 Hz, a 10 Hz hold with 0.05 s delay, on a
    0.05 s grid: the gyro's and the Mekf's ticks fall between grid points."""
    sc = get("sensing+estimation/default", stop_time=3.0, step=0.05)
    return sc.with_overrides({"star_tracker.latency": 0.1})


@needs_clocks
@pytest.mark.parametrize("build", [pid_loop, adcs_loop, sensing_loop])
def test_sampled_clocked_and_scheduled_runs_write_the_same_csv(build, tmp_path):
    sc = build()
    ref = csv_bytes(simulate(sc, "reference"), tmp_path / "ref.csv")  # FMI 2.0, sampled, fmpy's calls
    s3 = in_fmi3(sc)
    plan = build_plan(s3)
    assert [u.name for u in plan.units if u.clocks], "no clocked unit in the scenario"
    for clocks in ("sampled", "clocked", "scheduled"):
        got = csv_bytes(simulate(plan, "lean", clocks=clocks), tmp_path / f"{clocks}.csv")
        assert got == ref, f"{build.__name__}: the {clocks} run differs from the sampled FMI 2.0 run"


def expected_ticks(t_end: float, interval: float, shift: float) -> int:
    """Ticks t = shift + k·interval in [0, t_end] (the grid tolerance at the end)."""
    return math.floor((t_end - shift) / interval + 1e-9) + 1


@needs_clocks
def test_every_tick_runs_once_in_time_order_and_preemption_nests():
    sc = in_fmi3(sensing_loop())
    plan = build_plan(sc)
    with ClockedMaster(plan, log_activations=True) as cm:
        a = cm.run()
        timing = cm.timing
        clocked_acts = dict(cm.activations)
    with Scheduler(plan, log_activations=True) as se:
        b = se.run()
        log = list(se.activation_log)
        acts, pre = dict(se.activations), dict(se.preemption)
    assert bits_equal(a, b)
    assert clocked_acts == acts
    for unit, clocks in timing.items():
        for c, interval, shift in clocks:
            assert acts[(unit, c.name)] == expected_ticks(sc.stop_time, interval, shift), (unit, c.name)
    hold = {c.name: (i, s) for c, i, s in timing["hold"]}
    assert hold["delivery_clock"] == (0.1, 0.05) and hold["sample_clock"] == (0.1, 0.0)
    times = [t for t, _u, _c in log]
    assert times == sorted(times)
    assert pre["errors"] == [] and pre["depth"] == 0 and pre["locks"] == pre["unlocks"]
    assert pre["locks"] == 0 or pre["max_depth"] == 1


@needs_clocks
def test_units_without_clocks_are_named_in_one_line_and_step_as_today():
    plan = build_plan(in_fmi3(pid_loop()))
    note = clock_notice(plan, "clocked")
    assert note == ("--clocks clocked: no clocks in plant: they step with doStep on the scenario's grid as in a "
                    "sampled run")
    mixed = build_plan(in_fmi3(pid_loop(), {"controller"}))  # an FMI 2.0 plant beside the clocked controller
    assert "plant (FMI 2.0)" in clock_notice(mixed, "scheduled")
    assert bits_equal(simulate(mixed, "lean", clocks="scheduled"), simulate(pid_loop(), "lean"))


def test_clocks_on_fmi2_units_are_refused_in_one_line(capsys):
    plan = build_plan(pid_loop())
    assert clock_problem(plan, "sampled") is None
    why = clock_problem(plan, "clocked")
    assert why.startswith("--clocks clocked: every unit is FMI 2.0, which has no clocks")
    with pytest.raises(PlanError, match="every unit is FMI 2.0"):
        simulate(plan, clocks="scheduled")
    with pytest.raises(ValueError, match="runs on the lean engine"):
        simulate(plan, "native", clocks="clocked")
    with pytest.raises(ValueError, match="expected 'sampled'"):
        simulate(plan, clocks="sometimes")
    assert run_cmd.main(["paper002/PID", "--t-end", "0.01", "--clocks", "clocked", "--no-plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["scfmu run: " + why]


@needs_clocks
def test_cli_runs_on_the_clocks_and_refuses_another_engine(tmp_path, capsys):
    pid = str(FMI3 / "PidController.fmu")
    args = ["paper002/PID", "--t-end", "0.05", "--fmu", f"controller={pid}", "--set", "controller.kp=15",
            "--set", "controller.step=0.001", "--no-plot"]
    assert run_cmd.main(args + ["--clocks", "clocked", "--engine", "native"]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "scfmu run: --clocks clocked runs on the lean engine (its clocked master), not --engine native")
    for clocks in ("sampled", "scheduled"):
        assert run_cmd.main(args + ["--clocks", clocks, "--engine", "lean", "--out", str(tmp_path / clocks)]) == 0
    out = capsys.readouterr()
    assert "units on their clocks: scheduled" in out.out
    assert "--clocks scheduled: no clocks in plant (FMI 2.0)" in out.err
    a = (tmp_path / "sampled" / "paper002_PID.csv").read_bytes()
    assert a == (tmp_path / "scheduled" / "paper002_PID.csv").read_bytes()
