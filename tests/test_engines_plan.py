"""Issue 34: one plan for every engine; FMI 3.0 units (Co-Simulation and Model Exchange) and FMI 2.0 Model
Exchange units in every engine, campaigns and loop FMUs.

Oracles: the FMI 2.0 Co-Simulation run of the same scenario on the reference master (bit-identical where the
unit computes the same numbers; within 1e-6 relative where a Model Exchange unit is integrated by a solver
instead of the unit's own fixed-step integrator), closed forms (the Int32/Boolean counters of the foreign
FMI 3.0 unit), and SciPy's solve_ivp integrating the foreign plant's equations, written here in NumPy,
under the inputs the loop gave it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import foreign_units
from scfmu.engines import ENGINES, simulate
from scfmu.scenario import get
from scfmu.scenario.model import Component, Scenario
from scfmu.scenario.plan import PlanError, build_plan

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"
T = 3.0


def same(a: dict, b: dict) -> bool:
    return list(a) == list(b) and all(np.array_equal(a[k], b[k]) for k in a)


def worst_rel(ref: dict, got: dict) -> float:
    return max(float(np.max(np.abs(ref[k] - got[k])) / max(1e-300, np.max(np.abs(ref[k])))) for k in ref if k != "time")


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    return foreign_units.ForeignUnits(tmp_path_factory.mktemp("foreign3"))


# ----- one plan -----------------------------------------------------------------------------------------
def test_simulate_resolves_the_scenario_once(monkeypatch):
    from scfmu.scenario import plan as plan_mod
    calls = []
    real = plan_mod.resolve
    monkeypatch.setattr(plan_mod, "resolve", lambda s: calls.append(1) or real(s))
    for engine in ENGINES:
        calls.clear()
        simulate(get("default", stop_time=0.1), engine)
        assert len(calls) == 1, (engine, len(calls))


def test_the_plan_groups_links_by_destination_source_and_type(units):
    """Two instances of the foreign FMI 3.0 unit, b's Int32 and Boolean inputs fed by a's outputs and its
    Float64 rate inputs by a's torques (an arbitrary wiring): one group per (destination, source, type),
    value references of both ends those of the modelDescription."""
    sc = _counter_scenario(units, extra={"b.w_x": "a.torque_cmd_x", "b.w_y": "a.torque_cmd_y"})
    plan = build_plan(sc)
    got = [(g.dst, g.src, g.type, g.dst_names, g.src_vrs, g.dst_vrs) for g in plan.groups]
    assert got == [("b", "a", "Real", ["w_x", "w_y"], [14, 15], [4, 5]),
                   ("b", "a", "Boolean", ["enable"], [25], [22]),
                   ("b", "a", "Integer", ["count_in"], [24], [23])]
    assert [(g.inst, g.type, g.keys) for g in plan.log] == [("b", "Integer", ["count"]), ("b", "Boolean", ["enable"])]


def test_a_connection_of_another_type_is_refused_with_the_ports_named(units):
    sc = _counter_scenario(units, extra={"b.w_x": "a.step_count"})
    with pytest.raises(PlanError, match=r"a.step_count -> b.w_x: types differ: Int32 -> Float64"):
        build_plan(sc)


# ----- FMI 3.0 Co-Simulation ------------------------------------------------------------------------------
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("inst,model", [("controller", "PdController"), ("plant", "AttitudePlant")])
def test_fmi3_unit_in_place_of_the_fmi2_one_is_bit_identical_on_every_engine(engine, inst, model):
    sc = get("default", stop_time=T)
    ref = simulate(sc, "reference", fmus={inst: str(FMUS / f"{model}.fmu")})
    got = simulate(sc, engine, fmus={inst: str(FMUS / "fmi3" / f"{model}.fmu")})
    assert ref["eulerint_deg_s"][-1] > 10.0  # a real slew
    assert same(ref, got)


@pytest.mark.parametrize("engine", ENGINES)
def test_foreign_fmi3_unit_replaces_pd_on_every_engine(units, engine):
    """The hand-written C unit (FMI 3.0 headers of fmpy) gives PdController's loop to round-off."""
    ref = simulate(get("default", stop_time=T), "reference")
    sc = get("default", stop_time=T)
    sc = sc.with_overrides(unconnected=sc.unconnected + ["controller.enable", "controller.count_in"])
    got = simulate(sc, engine, fmus={"controller": str(units.c3("C3PdController"))})
    assert set(ref) == set(got)
    for k in ref:
        assert np.allclose(ref[k], got[k], rtol=1e-9, atol=1e-12), k


def _counter_scenario(units, extra=None) -> Scenario:
    p = str(units.c3("C3PdController"))
    conn = {"b.count_in": "a.step_count", "b.enable": "a.active"}
    conn.update(extra or {})
    return Scenario("counters", [Component("a", p), Component("b", p)], stop_time=1.0, step=0.1,
                    log={"count": "b.count_echo", "enable": "b.enable_echo"}, connections=conn,
                    unconnected=["*"], auto_connect=False)


@pytest.mark.parametrize("engine", ENGINES)
def test_integer_and_boolean_connections_on_every_engine(units, engine):
    """b echoes what a's Int32 step counter and Boolean "even count" give it at the same communication point
    (Gauss–Seidel: a before b): count_k = k, enable_k = (k even)."""
    r = simulate(_counter_scenario(units), engine)
    k = np.arange(11)
    assert np.array_equal(r["count"], k)
    assert np.array_equal(r["enable"], (k % 2 == 0).astype(float))


def test_fmi3_units_in_a_loop_fmu_and_a_campaign(units, tmp_path):
    from fmpy import simulate_fmu
    from scfmu import campaign
    from scfmu.export.loops import write_loop_fmu
    sc = get("default", stop_time=T).with_models({"controller": str(FMUS / "fmi3" / "PdController.fmu"),
                                                  "plant": str(FMUS / "fmi3" / "AttitudePlant.fmu")})
    p = write_loop_fmu(sc, tmp_path / "loop3.fmu")
    ref = simulate(get("default", stop_time=T).with_models({"controller": str(FMUS / "PdController.fmu"),
                                                             "plant": str(FMUS / "AttitudePlant.fmu")}), "reference")
    r = simulate_fmu(str(p), stop_time=T, output_interval=sc.step, output=["metrics.eulerint_deg_s"])
    assert r["metrics.eulerint_deg_s"][-1] == ref["eulerint_deg_s"][-1]
    rows = campaign.run(campaign.Campaign(sc, [{}, {"controller.wn": 0.8}]), tmp_path / "c", n_workers=1,
                        progress=False).to_pydict()
    assert rows["status"] == ["ok", "ok"]
    assert rows["eulerint_deg_s"][0] == ref["eulerint_deg_s"][-1] != rows["eulerint_deg_s"][1]


# ----- Model Exchange ------------------------------------------------------------------------------------
@pytest.mark.parametrize("engine", ["reference", "lean", "compiled", "native"])
@pytest.mark.parametrize("fmi", [2, 3])
def test_paper000_slew_with_the_plant_as_model_exchange_on_every_engine(engine, fmi):
    """Run 000-6 (scenario default) over 10 s with the plant as a Model Exchange unit (tight tolerances),
    against the Co-Simulation run: every logged signal within 1e-6 of its range (measured ~1e-12)."""
    sc = get("default", stop_time=10.0)
    ref = simulate(sc, "reference")
    fm = {"plant": str(FMUS / "fmi3" / "AttitudePlant.fmu")} if fmi == 3 else None
    got = simulate(sc, engine, fmus=fm, model_exchange={"plant"})
    assert ref["eulerint_deg_s"][-1] > 100.0
    assert worst_rel(ref, got) < 1e-6


@pytest.mark.parametrize("engine", ["reference", "lean", "compiled", "native"])
def test_the_plant_as_model_exchange_under_fixed_step_rk4_chosen_per_instance(engine):
    """`Component.solver = {"method": "RK4"}`: the classic Runge–Kutta 4 at the communication step, the
    method of the Co-Simulation plant's own integrator: within 1e-6 of the Co-Simulation run (measured
    7.5e-14), on the Python engines and in the compiled loop."""
    sc = get("default", stop_time=10.0)
    ref = simulate(sc, "reference")
    me = get("default", stop_time=10.0)
    me.component("plant").interface = "me"
    me.component("plant").solver = {"method": "RK4"}
    got = simulate(me, engine)
    assert worst_rel(ref, got) < 1e-6


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_loop_fmu_with_the_plant_as_model_exchange_runs_in_fmpy(fmi, tmp_path):
    """A loop FMU whose plant is a Model Exchange unit (ours, FMI 2.0 or 3.0, nested in fmpy's container as its
    Co-Simulation face: scfmu/engines/me_cs) passes fmpy's validation, and fmpy.simulate_fmu of the single
    file gives the Co-Simulation scenario's trajectory within 1e-6 of its range (measured ~1e-12)."""
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from scfmu.export.loops import write_loop_fmu
    fm = {"plant": str(FMUS / "fmi3" / "AttitudePlant.fmu")} if fmi == 3 else {}
    sc = get("default", stop_time=T).with_models(fm)
    sc.component("plant").interface = "me"
    p = write_loop_fmu(sc, tmp_path / "loop_me.fmu")
    assert validate_fmu(str(p)) == []
    ref = simulate(get("default", stop_time=T), "reference")
    keys = [k for k in ref if k != "time"]
    r = simulate_fmu(str(p), stop_time=T, output_interval=sc.step, output=[sc.log[k] for k in keys])
    assert len(r) == len(ref["time"]) and np.allclose(r["time"], ref["time"], rtol=0, atol=1e-9)
    got = {k: r[sc.log[k]] for k in keys}
    assert ref["eulerint_deg_s"][-1] > 10.0
    assert worst_rel({k: ref[k] for k in keys}, got) < 1e-6


def test_native_model_exchange_instances_reused_after_reset_give_fresh_results():
    """The native engine resets and reuses a container's instance; through the Co-Simulation face the Model
    Exchange unit is reset too: a second run is bit-identical to the first, a run with another parameter
    matches the lean engine's (measured 7e-15)."""
    runs = [simulate(get("default", stop_time=2.0).with_overrides(ov), "native", model_exchange={"plant"})
            for ov in ({}, {}, {"controller.wn": 2.0})]
    assert same(runs[0], runs[1])
    lean = simulate(get("default", stop_time=2.0).with_overrides({"controller.wn": 2.0}), "lean",
                    model_exchange={"plant"})
    assert not same(runs[0], runs[2]) and worst_rel(lean, runs[2]) < 1e-9

def test_model_exchange_in_the_native_engine_needs_the_wrapper_library(monkeypatch, tmp_path):
    """Without the built wrapper library the native engine refuses an ME unit in one line saying how to build it."""
    from scfmu.engines import cs_face, native
    monkeypatch.setattr(cs_face, "wrapper_library", lambda: None)
    monkeypatch.setattr(native, "CACHE", tmp_path)
    with pytest.raises(PlanError, match=r"^plant: a Model Exchange unit runs in fmpy's container FMU through "
                                        r"scfmu's Co-Simulation wrapper, which is not built: run `cargo build"):
        simulate(get("default", stop_time=0.1), "native", model_exchange={"plant"})


def _axis_scenario(units, stop=3.0, **params) -> Scenario:
    """paper002's PD loop with the foreign Model-Exchange-only body in place of SingleAxisPlant."""
    sc = get("paper002/PD", stop_time=stop).with_models({"plant": str(units.c3("C3AxisBody"))})
    sc = sc.with_overrides({f"plant.{k}": v for k, v in params.items()})
    sc.log.update({"crossings": "plant.crossings", "t_cross": "plant.t_cross"})
    return sc


def _axis_oracle(r: dict, inertia=7.7, limit=1.0, mark=0.1, kick_time=-1.0, kick_domega=0.0):
    """theta, omega of the body integrated by solve_ivp (RK45 via DOP853, tight) from the loop's own held
    commands u_k, and the first time theta crosses `mark` (dense output)."""
    t, u = r["time"], r["u"]
    x = np.array([0.0, 0.0])
    th, crossings = [x[0]], []
    for k in range(len(t) - 1):
        uk = min(max(u[k], -limit), limit)
        spans = [(t[k], t[k + 1])]
        if t[k] < kick_time < t[k + 1]:
            spans = [(t[k], kick_time), (kick_time, t[k + 1])]
        for a, b in spans:
            s = solve_ivp(lambda _t, y: [y[1], uk / inertia], (a, b), x, method="DOP853", rtol=1e-12, atol=1e-14,
                          dense_output=True)
            y1 = s.y[:, -1]
            if (x[0] > mark) != (y1[0] > mark):
                from scipy.optimize import brentq
                crossings.append(brentq(lambda tt: s.sol(tt)[0] - mark, a, b, xtol=1e-14))
            x = y1.copy()
            if b == kick_time:
                x[1] += kick_domega
        th.append(x[0])
    return np.array(th), crossings


@pytest.mark.parametrize("engine", ["reference", "lean", "compiled", "native"])
def test_foreign_model_exchange_body_with_state_and_time_events(units, engine):
    """The foreign FMI 3.0 ME-only body: its theta follows solve_ivp of its equations under the loop's
    commands, its state event (theta crossing 0.1 rad) is located to 1e-8 s, and its time event (a kick of
    omega at 1.2345 s, between communication points) is taken."""
    sc = _axis_scenario(units, kick_time=1.2345, kick_domega=0.05)
    r = simulate(sc, engine)
    th, crossings = _axis_oracle(r, kick_time=1.2345, kick_domega=0.05)
    assert len(crossings) >= 1
    assert r["crossings"][-1] == len(crossings)
    assert abs(r["t_cross"][-1] - crossings[0]) < 1e-8, (r["t_cross"][-1], crossings[0])
    assert np.max(np.abs(r["theta"] - th)) < 1e-8 * max(1.0, np.max(np.abs(th)))


def test_foreign_model_exchange_plant_in_a_campaign(units, tmp_path):
    """Three runs of the foreign ME-only plant (different inertias) in a campaign on the default engine
    (each run isolated in its own process, as for any foreign unit): every run ok, each run's theta that of
    solve_ivp under the run's own commands."""
    from scfmu import campaign
    sc = _axis_scenario(units, stop=2.0)
    c = campaign.Campaign(sc, [{"plant.inertia": i} for i in (5.0, 7.7, 12.0)], timeseries=["theta", "u"])
    rows = campaign.run(c, tmp_path / "c", n_workers=1, progress=False).to_pydict()
    assert rows["status"] == ["ok"] * 3, rows["message"]
    finals = []
    for i, inertia in enumerate((5.0, 7.7, 12.0)):
        r = campaign.read_timeseries(tmp_path / "c", i)
        th, _ = _axis_oracle(r, inertia=inertia)
        assert np.max(np.abs(r["theta"] - th)) < 1e-8
        finals.append(r["theta"][-1])
    assert len(set(finals)) == 3  # the parameter reached the unit
    # a coarser log grid (log_every): the campaign runs the ME unit on the compiled engine
    c2 = campaign.Campaign(sc, [{"plant.inertia": 7.7}], log_every=10)
    rows2 = campaign.run(c2, tmp_path / "c2", n_workers=1, progress=False).to_pydict()
    assert rows2["status"] == ["ok"], rows2["message"]


# ----- issue 34: --scheduler campaigns with FMI 3.0 and Model Exchange units --------------------------------
def _rows(table):
    return table.to_pylist()


def _same_rows(a, b):
    """Rows equal to the bit (NaN equal to NaN)."""
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.keys() == y.keys()
        for k in x:
            nan = isinstance(x[k], float) and np.isnan(x[k])
            assert (nan and isinstance(y[k], float) and np.isnan(y[k])) or (not nan and x[k] == y[k]), (x["run"], k)


def _unit_campaigns():
    """Two campaigns of run 000-6's loop: the project's FMI 3.0 PdController in place of the FMI 2.0 one (native
    engine, as `scfmu campaign --engine native`), and the plant as a Model Exchange unit (auto engine: the
    compiled loop integrates it)."""
    from scfmu import campaign
    fmi3 = get("default", stop_time=2.0).with_models({"controller": str(FMUS / "fmi3" / "PdController.fmu")})
    me = get("default", stop_time=2.0)
    me.component("plant").interface = "me"
    sets = campaign.grid({"controller.wn": [0.5, 1.0, 2.0]}) + [{"controller.wn": -1.0}]
    return {"fmi3": campaign.Campaign(fmi3, sets, seeds=[None], engine="native", timeseries=["alpha_deg"]),
            "me": campaign.Campaign(me, sets, seeds=[None], timeseries=["alpha_deg"])}


def test_scheduler_campaigns_with_fmi3_and_model_exchange_units_match_the_local_run(tmp_path):
    """The same campaigns on a local run (the package's own LocalCluster) and through `scheduler=` (what
    `scfmu campaign --scheduler` passes) to a LocalCluster started here: rows and time series bit-identical;
    the FMI 3.0 controller's rows are those of the FMI 2.0 one (same numbers by construction), and the ME
    plant's metrics are within 1e-6 of the Co-Simulation plant's (a solver instead of the plant's RK4)."""
    from dask.distributed import LocalCluster
    from scfmu import campaign
    sets = _unit_campaigns()["fmi3"].overrides
    cs = _rows(campaign.run(campaign.Campaign(get("default", stop_time=2.0), sets, seeds=[None], engine="native"),
                            tmp_path / "cs", n_workers=1, progress=False))
    local = {k: _rows(campaign.run(c, tmp_path / f"{k}_local", n_workers=1, progress=False))
             for k, c in _unit_campaigns().items()}
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0",
                      host="127.0.0.1") as cluster:
        remote = {k: _rows(campaign.run(c, tmp_path / f"{k}_sched", scheduler=cluster.scheduler_address,
                                        progress=False)) for k, c in _unit_campaigns().items()}
    for k in local:
        assert [r["status"] for r in local[k]] == ["ok", "ok", "ok", "fmu_error"], (k, local[k][-1]["message"])
        _same_rows(local[k], remote[k])
        for i in range(3):
            a = campaign.read_timeseries(tmp_path / f"{k}_local", i)
            b = campaign.read_timeseries(tmp_path / f"{k}_sched", i)
            assert a.keys() == b.keys() and all(np.array_equal(a[s], b[s]) for s in a)
    metrics = [k for k, v in cs[0].items() if isinstance(v, float) and np.isfinite(v) and not k.startswith("p:")]
    assert "eulerint_deg_s" in metrics and len(metrics) >= 4, metrics  # (settling times are NaN over 2 s)
    for a, b, m in zip(cs[:3], local["fmi3"][:3], local["me"][:3]):
        assert all(a[k] == b[k] for k in metrics), [(k, a[k], b[k]) for k in metrics if a[k] != b[k]]
        assert all(abs(a[k] - m[k]) <= 1e-6 * max(abs(a[k]), 1e-3) for k in metrics), [(k, a[k], m[k]) for k in metrics]


def test_ssp_1_0_and_libcosim_refuse_fmi3_units_with_a_message(tmp_path):
    """SSP 1.0 carries FMI 1.0/2.0 FMUs; the libcosim that libcosimpy ships crashes on FMI 3.0 units: both
    refuse them up front, naming the instance."""
    from scfmu.engines.libcosim import run_libcosim
    from scfmu.scenario.ssp import write_ssp
    sc = get("default", stop_time=0.1).with_models({"controller": str(FMUS / "fmi3" / "PdController.fmu")})
    with pytest.raises(ValueError, match="controller: FMI 3.0 units cannot be written to an SSP 1.0 file"):
        write_ssp(sc, tmp_path / "x.ssp")
    with pytest.raises(ValueError, match=r"libcosim runs FMI 1.0/2.0 units only: \[.controller.\] are FMI 3.0 \(the libcosim of libcosimpy"):
        run_libcosim(sc)


def _cli(*args, timeout=900):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def test_cli_run_and_benchmark_take_the_fmi3_controller(tmp_path):
    """The issue's first complaint: `scfmu run default --fmu controller=fmus/fmi3/PdController.fmu` was refused
    ("FMI 3.0, not FMI 2.0"); now it runs, and the benchmark ranks the FMI 3.0 unit exactly as the FMI 2.0 one."""
    p = FMUS / "fmi3" / "PdController.fmu"
    r = _cli("run", "default", "--t-end", "5", "--fmu", f"controller={p}", "--out", tmp_path / "run")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    r = _cli("benchmark", p, "--family", "attitude", "--controllers", "PdController", "--cases", "default",
             "--out", tmp_path / "b")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    md = (tmp_path / "b" / "benchmark.md").read_text()
    mine = [x for x in md.splitlines() if x.startswith("| **PdController**")][0]
    pd = [x for x in md.splitlines() if x.startswith("| PD, quaternion error")][0]
    assert mine.split("|")[3:] == pd.split("|")[3:], (mine, pd)


def test_cli_run_with_a_model_exchange_only_unit_picks_an_engine_that_runs_it(units, tmp_path):
    p = units.c3("C3AxisBody")
    r = _cli("run", "paper002/PD", "--t-end", "1", "--no-plot", "--fmu", f"plant={p}", "--out", tmp_path / "a")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "on the compiled engine" in r.stdout and "plant=C3AxisBody.fmu (FMI 3.0 Model Exchange)" in r.stdout, r.stdout
    r = _cli("run", "paper002/PD", "--t-end", "1", "--no-plot", "--engine", "native", "--fmu", f"plant={p}",
             "--out", tmp_path / "b")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]


def test_array_ports_and_other_fmi3_types_are_refused_by_the_one_rule():
    from fmpy.model_description import Dimension, ModelVariable
    from scfmu.scenario.plan import Unit, link_problem

    def unit(name, v):
        return Unit(name, "M", None, None, 3, "cs", {}, {v.name: v})
    arr = ModelVariable(name="tau", type="Float64", causality="output", valueReference=1)
    arr.dimensions = [Dimension(start="3", valueReference=None)]
    scalar = ModelVariable(name="tau", type="Float64", causality="input", valueReference=2)
    f32 = ModelVariable(name="tau", type="Float32", causality="output", valueReference=3)
    assert "a.tau is an FMI 3.0 array" in link_problem(unit("b", scalar), "tau", unit("a", arr), "tau")
    assert "only Real, Integer, Boolean connections" in link_problem(unit("b", scalar), "tau", unit("a", f32), "tau")
    assert link_problem(unit("b", scalar), "tau", unit("a", scalar), "tau") is None


def test_preflight_checks_the_fmi3_binary_folder_and_the_interface(units, tmp_path):
    import zipfile
    from scfmu.scenario.check import check
    src = units.c3("C3PdController")
    nobin = tmp_path / "C3PdController_nobin.fmu"
    with zipfile.ZipFile(src) as zi, zipfile.ZipFile(nobin, "w") as zo:
        zo.writestr("modelDescription.xml", zi.read("modelDescription.xml"))
    base = get("default", stop_time=T)
    base = base.with_overrides(unconnected=base.unconnected + ["controller.enable", "controller.count_in"])
    assert check(base.with_models({"controller": str(src)})).ok
    rep = check(base.with_models({"controller": str(nobin)}))
    assert rep.errors and "binaries/x86_64-linux/C3PdController.so missing" in rep.errors[0], rep.errors
    me = base.with_models({"controller": str(src)})
    me.component("controller").interface = "me"
    rep = check(me)
    assert rep.errors and "no Model Exchange interface (Co-Simulation only)" in rep.errors[0], rep.errors


def test_scenario_files_carry_the_interface_and_solver_of_an_instance():
    from scfmu.scenario import files
    data = files.to_data(get("default", stop_time=2.0))
    plant = [c for c in data["components"] if c["name"] == "plant"][0]
    plant["interface"], plant["solver"] = "me", {"method": "RK4"}
    sc = files.from_data(data, "mine.toml")
    assert (sc.component("plant").interface, sc.component("plant").solver) == ("me", {"method": "RK4"})
    assert build_plan(sc).model_exchange == {"plant"}
    assert worst_rel(simulate(get("default", stop_time=2.0), "reference"), simulate(sc, "compiled")) < 1e-6
    plant["interface"] = "modelexchange"
    with pytest.raises(files.ScenarioFileError, match=r"interface = 'modelexchange'; allowed: \"cs\""):
        files.from_data(data, "mine.toml")
