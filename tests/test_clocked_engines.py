"""Issue 48 item 2: our engines run FMI 3.0 clocked units on their clocks (clocked Co-Simulation and a
Scheduled Execution scheduler) and give the sampled run's outputs.

Oracles: the same scenario on the reference master (fmpy's high-level calls, every unit sampling inside
doStep: our FMI 2.0 units, or a foreign clocked C unit run with eventModeUsed = false), written to CSV; the
sampled, clocked and scheduled runs must write the same CSV byte for byte. The foreign unit's law in NumPy
(tests/foreign_clocked.py), and the schedule's closed form (tick k of a clock at t_start + shift +
k·interval: the counts of activations). Errors: the one-line refusals of the command line and the API, and
a partition activated off its tick."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

import foreign_clocked
from scfmu import run_cmd
from scfmu.engines import SimulationError, simulate
from scfmu.engines.clocked import ClockedMaster, clock_notice, clock_problem
from scfmu.engines.scheduler import Scheduler
from scfmu.fmu import described, fmu_dir
from scfmu.scenario import get
from scfmu.scenario.plan import PlanError, build_plan

FMI3 = fmu_dir() / "fmi3"
KP, KD = 14.965939284399212, 20.0  # paper 002's PID gains (ki = 0)


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


@pytest.fixture(scope="module")
def c3(tmp_path_factory):
    d = tmp_path_factory.mktemp("c3clocked")
    return foreign_clocked.build(d), foreign_clocked.build(d, scheduled=False)


def foreign_loop(fmu, step=0.001, delay=0.004, stop=1.0):
    """paper 002's single-axis loop with the foreign clocked PD (100 Hz, command delivered ``delay`` later) in
    the controller's place and the FMI 3.0 plant when there is one."""
    sc = get("paper002/PID", stop_time=stop, step=step).with_models({"controller": str(fmu)})
    sc = sc.with_overrides({"controller.period": 0.01, "controller.delay": delay, "controller.kp": KP,
                            "controller.kd": KD})
    return in_fmi3(sc, {"plant"})


@pytest.mark.parametrize("step,delay", [(0.001, 0.004), (0.02, 0.004), (0.005, 0.0)])
def test_a_foreign_clocked_unit_gives_its_sampled_run_three_ways(c3, step, delay, tmp_path):
    """A 100 Hz PD on a 1 kHz, a 50 Hz (samples between grid points) and a 200 Hz grid, with and without a
    delivery delay: sampled (the unit's own sampling, on fmpy's calls and on the lean master), clocked and
    scheduled write the same CSV; on the 1 kHz grid u is the law in NumPy from the logged theta, exactly."""
    sc = foreign_loop(c3[0], step, delay)
    ref_res = simulate(sc, "reference")
    ref = csv_bytes(ref_res, tmp_path / "ref.csv")
    plan = build_plan(sc)
    assert [(c.name, c.vr, c.priority, c.clocked) for c in plan.unit("controller").clocks] == [
        ("sample_clock", 100, 0, ["error"]), ("delivery_clock", 101, 1, ["u"])]
    for clocks in ("sampled", "clocked", "scheduled"):
        assert csv_bytes(simulate(plan, "lean", clocks=clocks), tmp_path / f"{clocks}.csv") == ref, clocks
    assert abs(ref_res["theta"][-1]) > 0.05  # the loop moved
    if step == 0.001:
        u = foreign_clocked.pd_oracle(ref_res["time"], ref_res["theta"], sc.inputs["controller.theta_ref"], 0.01,
                                      delay, KP, KD)
        assert np.array_equal(u, ref_res["u"])


def test_the_scheduler_activates_every_tick_once_in_time_and_priority_order(c3):
    plan = build_plan(foreign_loop(c3[0], 0.02, 0.0))
    with Scheduler(plan, log_activations=True) as se:
        se.run()
        log, acts, pre, timing = list(se.activation_log), dict(se.activations), dict(se.preemption), se.timing
    assert [(c.name, i, s) for c, i, s in timing["controller"]] == [("sample_clock", 0.01, 0.0),
                                                                    ("delivery_clock", 0.01, 0.0)]
    assert acts == {("controller", "sample_clock"): 101, ("controller", "delivery_clock"): 101}
    assert log[:4] == [(0.0, "controller", "sample_clock"), (0.0, "controller", "delivery_clock"),
                       (0.01, "controller", "sample_clock"), (0.01, "controller", "delivery_clock")]
    assert [t for t, _u, _c in log] == sorted(t for t, _u, _c in log)
    # the unit brackets each partition with lockPreemption / unlockPreemption: one pair per activation
    assert pre == {"locks": 202, "unlocks": 202, "depth": 0, "max_depth": 1, "errors": []}


def test_a_partition_activated_off_its_tick_fails_the_run_with_the_units_message(c3):
    plan = build_plan(foreign_loop(c3[0], 0.02, 0.004, stop=0.1))
    why = {ClockedMaster: "nextEventTime 0.004, but the clocks' next tick is 0.005",  # (the master's check)
           Scheduler: "fmi3ActivateModelPartition: clock 101 does not tick at t = 0.0050"}  # (the unit's)
    for master in (ClockedMaster, Scheduler):
        with master(plan) as m:
            c, interval, shift = m.timing["controller"][1]
            m.timing["controller"][1] = (c, interval, shift + 0.001)  # the master's schedule 1 ms late
            with pytest.raises(SimulationError, match=why[master]):
                m.run()


def test_scheduled_needs_the_interface_clocked_does_not(c3):
    plan = build_plan(foreign_loop(c3[1], 0.02, 0.004, stop=0.1))
    assert clock_problem(plan, "clocked") is None
    assert clock_problem(plan, "scheduled") == ("--clocks scheduled: controller (C3SampledPd_cs.fmu) has clocks but no "
                                                "<ScheduledExecution> interface")
    with pytest.raises(PlanError, match="no <ScheduledExecution>"):
        simulate(plan, clocks="scheduled")
    assert bits_equal(simulate(plan, clocks="clocked"), simulate(plan, "reference"))


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


def test_cli_runs_on_the_clocks_and_refuses_another_engine(c3, tmp_path, capsys):
    args = ["paper002/PID", "--t-end", "0.05", "--fmu", f"controller={c3[0]}", "--set", f"controller.kp={KP}",
            "--set", f"controller.kd={KD}", "--set", "controller.delay=0.004", "--no-plot"]
    assert run_cmd.main(args + ["--clocks", "clocked", "--engine", "native"]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "scfmu run: --clocks clocked runs on the lean engine (its clocked master), not --engine native")
    for clocks in ("sampled", "scheduled"):
        assert run_cmd.main(args + ["--clocks", clocks, "--out", str(tmp_path / clocks)]) == 0
    out = capsys.readouterr()
    assert "on the lean engine (units on their clocks: scheduled)" in out.out
    assert "controller=C3SampledPd.fmu (FMI 3.0 Scheduled Execution)" in out.out
    assert ("--clocks scheduled: no clocks in plant (FMI 2.0): they step with doStep on the scenario's grid as in a "
            "sampled run") in out.err.splitlines()
    a = (tmp_path / "sampled" / "paper002_PID.csv").read_bytes()
    assert a == (tmp_path / "scheduled" / "paper002_PID.csv").read_bytes()
    manifest = json.loads((tmp_path / "scheduled" / "paper002_PID.manifest.json").read_text())
    assert (manifest["engine"], manifest["clocks"]) == ("lean", "scheduled")
