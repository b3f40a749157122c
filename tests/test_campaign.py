"""Scenario declarations, the lean and native masters against the reference master, and the Dask
campaign engine (determinism across worker counts, an existing scheduler reached by address, failing
runs, resume, CLI)."""

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from scfmu import campaign
from scfmu import scenario as scenarios
from scfmu.scenario.model import Component, Scenario
from scfmu.engines import simulate

ROOT = Path(__file__).resolve().parents[1]


def short(name="default", t=3.0, **kw):
    return scenarios.get(name, stop_time=t, **kw)


# ----- scenario ----------------------------------------------------------------------------------------
def test_wiring_by_name_with_explicit_exceptions():
    s = Scenario("w", [Component("a", "A"), Component("b", "B"), Component("c", "C")], 1.0, 0.1,
                 connections={"c.u": "a.y2"}, unconnected=["dist_*", "b.opt"])
    ports = {"a": ([], ["y", "y2"]), "b": (["y", "opt", "dist_x"], ["u"]), "c": (["u", "y"], [])}
    assert s.wiring(ports) == [("b", "y", "a", "y"), ("c", "u", "a", "y2"), ("c", "y", "a", "y")]
    with pytest.raises(ValueError, match="b.opt has no source"):
        Scenario("w", s.components, 1.0, 0.1, unconnected=[]).wiring(ports)
    ports["b"][1].append("y")  # two sources of c.y
    with pytest.raises(ValueError, match="several sources"):
        s.wiring(ports)
    s2 = s.with_overrides({"a.k": 2, "input:b.opt": 1.5})
    assert s2.component("a").params == {"k": 2} and s2.inputs == {"b.opt": 1.5} and s.inputs == {}
    assert Scenario.from_dict(s2.to_dict()) == s2


def test_standard_scenarios_resolve():
    for name in scenarios.names():
        sc = scenarios.get(name)
        assert sc.n_steps > 0 and sc.log


# ----- masters -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,t", [("default", 3.0), ("paper000/000-9L", 2.0), ("wheel_fault", 20.0),
                                    ("paper001/c/dist0.01", 2.0), ("paper003/T2FSMC/W", 3.0)])
def test_lean_and_native_bit_identical_to_reference_master(name, t):
    sc = short(name, t)
    ref = simulate(sc, "reference")
    lean = simulate(sc, "lean")
    nat = simulate(sc, "native")
    assert list(ref) == list(lean) == list(nat)
    for k in ref:
        assert np.array_equal(ref[k], lean[k]), k
        assert np.array_equal(ref[k], nat[k]), k


def test_native_full_run_000_6_eulerint_matches_reference():
    """Run 000-6 over its 30 s: the container loop (no Python per step) gives the reference EULERINT."""
    sc = scenarios.get("default")
    ref = simulate(sc, "reference")["eulerint_deg_s"][-1]
    nat = simulate(sc, "native", log_every=0)
    assert len(nat["time"]) == 2 and nat["time"][-1] == 30.0
    assert nat["eulerint_deg_s"][-1] == ref
    assert 150.0 < ref < 160.0  # paper 000 order of magnitude for the quaternion PD on command L


def test_failing_runs_raise_simulation_error():
    from scfmu.engines.lean import SimulationError
    for engine in ("lean", "native", "compiled"):
        with pytest.raises((SimulationError, Exception)) as e:
            simulate(short().with_overrides({"controller.wn": -1.0}), engine)
        assert "wn" in str(e.value)


# ----- compiled engine (scfmu/engines/native_loop) ------------------------------------------------------
def need_compiled():
    from scfmu.engines import compiled
    if not compiled.available():
        pytest.fail(f"compiled loop library not found ({compiled.library_path()}): cargo build --release")


@pytest.mark.parametrize("name,t", [("default", 3.0), ("paper000/000-9L", 2.0), ("wheel_fault", 20.0),
                                    ("paper001/c/dist0.01", 2.0), ("paper003/T2FSMC/W", 3.0)])
def test_compiled_bit_identical_to_reference_master(name, t):
    need_compiled()
    sc = short(name, t)
    ref = simulate(sc, "reference")
    for kw in ({"reuse": False}, {}, {}):  # fresh instances, then instances from the pool
        got = simulate(sc, "compiled", **kw)
        assert list(got) == list(ref)
        for k in ref:
            assert np.array_equal(ref[k], got[k]), (k, kw)


def test_compiled_fmu_error_status_raises_with_the_fmus_messages():
    """A doStep error at the second step (the plant's state overflows) stops the compiled loop there:
    SimulationError at that time with the FMU's message, as on the reference and lean masters. When
    several FMUs would fail at one point, the compiled loop stops at the first failing call (its message
    is the first of the lean master's, which makes the remaining calls of the step)."""
    from scfmu.engines.lean import SimulationError
    need_compiled()
    sc = short(t=0.5).with_overrides({"controller.gain_mode": 1, "controller.kp_x": 1e160})
    errs = {}
    for engine in ("reference", "lean", "compiled"):
        with pytest.raises(SimulationError) as e:
            simulate(sc, engine)
        errs[engine] = e.value
    assert errs["compiled"].status == "fmu_error" and errs["compiled"].time == 0.01 == errs["lean"].time
    assert str(errs["compiled"]) == str(errs["lean"]) == str(errs["reference"])
    assert "plant: fmi2DoStep: step from t = 0.01 failed" in str(errs["compiled"])
    sc = short(t=0.5).with_overrides({"controller.wn": 1e80})
    with pytest.raises(SimulationError) as lean:
        simulate(sc, "lean")
    with pytest.raises(SimulationError) as comp:
        simulate(sc, "compiled")
    assert comp.value.time == lean.value.time == 0.01
    assert str(lean.value).startswith(str(comp.value) + "; ") and str(comp.value).startswith("controller: ")
    # the pool is not given the instances of a failed run, and a good run afterwards is unchanged
    assert np.array_equal(simulate(short(t=1.0), "compiled")["q_x"], simulate(short(t=1.0), "reference")["q_x"])


def test_compiled_nonfinite_logged_value_raises(monkeypatch):
    """The FMUs refuse non-finite values themselves, so one is injected: the metrics FMU's fmi2GetReal (its outputs are only logged) returns
    NaN for its first value from its 40th call on (a ctypes callback around the real function). The
    compiled loop logs it like the lean master, and the run fails with status ``nonfinite`` at the same time."""
    from ctypes import CFUNCTYPE, c_double, c_int, c_size_t, c_void_p
    from scfmu.engines import calls
    from scfmu.engines.lean import SimulationError
    need_compiled()
    real_raw = calls.raw_fn
    proto = CFUNCTYPE(c_int, c_void_p, c_void_p, c_size_t, c_void_p)
    keep = []

    def raw(slave, name):
        f = real_raw(slave, name)
        if name != "fmi2GetReal" or slave.instanceName != "metrics":
            return f
        calls = [0]

        def get(c, vr, n, v):
            st = f(c, vr, n, v)
            calls[0] += 1
            if calls[0] >= 40:
                c_double.from_address(v).value = float("nan")
            return st

        cb = proto(get)
        keep.append(cb)
        return cb

    monkeypatch.setattr(calls, "raw_fn", raw)
    errs = {}
    for engine in ("lean", "compiled"):
        with pytest.raises(SimulationError) as e:
            simulate(short(t=1.0), engine, reuse=False)
        errs[engine] = e.value
    assert errs["compiled"].status == errs["lean"].status == "nonfinite"
    assert errs["compiled"].time == errs["lean"].time and 0 < errs["compiled"].time < 1.0
    assert str(errs["compiled"]) == str(errs["lean"])


def test_compiled_instance_reuse_after_reset_gives_fresh_results():
    """Instances reset after a run and initialized again give the fresh-instance results (also after a
    run that failed, whose instances are freed)."""
    from scfmu.engines import compiled
    from scfmu.engines.lean import SimulationError
    need_compiled()
    a = short(t=2.0).with_overrides({"controller.wn": 1.7, "plant.dist_noise_std_x": 0.5}).with_seed(7)
    b = short(t=2.0).with_overrides({"controller.wn": 0.6}).with_seed(1)
    fresh_a = simulate(a, "reference")
    fresh_b = simulate(b, "reference")
    compiled._POOL.clear()
    sets = []
    for sc, ref in ((a, fresh_a), (b, fresh_b), (a, fresh_a), (None, None), (b, fresh_b)):
        if sc is None:  # a run that fails at initialization takes the pooled set, which is then freed
            with pytest.raises(SimulationError):
                simulate(short(t=2.0).with_overrides({"controller.wn": -1.0}), "compiled")
            assert sum(len(v) for v in compiled._POOL.values()) == 0
            continue
        r = simulate(sc, "compiled")
        assert all(np.array_equal(r[k], ref[k]) for k in ref)
        (pool,) = compiled._POOL.values()
        sets.append(pool[-1])
    assert sets[0] is sets[1] is sets[2] and sets[3] is not sets[0]  # the same instances, reset, until freed


def test_auto_engine_is_compiled_when_available_else_native(monkeypatch):
    """Campaigns run on "auto": the compiled engine in this checkout; without its library the native
    engine, with no error and the same row."""
    from scfmu.engines import compiled, resolve_engine
    need_compiled()
    assert resolve_engine("auto") == "compiled" and campaign.Campaign(short()).engine == "auto"
    spec = campaign.Campaign(short(t=2.0), [{"controller.wn": 1.3}], seeds=[None]).runs()[0]
    row_c, _ = campaign.run_one(spec)
    monkeypatch.setattr(compiled, "_LIB", [None])
    assert not compiled.available() and resolve_engine("auto") == "native"
    row_n, _ = campaign.run_one(spec)
    assert row_c["status"] == row_n["status"] == "ok"
    same_rows([row_c], [row_n])


# ----- campaigns ---------------------------------------------------------------------------------------
def small_campaign(t=2.0, engine="native", timeseries=None):
    sets = campaign.grid({"controller.wn": [0.5, 1.0, 2.0], "controller.zeta": [0.7, 1.0]})
    sets.append({"controller.wn": -1.0})  # invalid parameter: the FMU refuses to initialize
    sets.append({"controller.no_such_parameter": 1.0})
    return campaign.Campaign(short("default", t), sets, seeds=[3, 4], engine=engine, timeseries=timeseries,
                             ts_every=5)


def rows_of(table):
    return table.to_pylist()


def same_rows(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.keys() == y.keys()
        for k in x:
            if isinstance(x[k], float) and np.isnan(x[k]):
                assert isinstance(y[k], float) and np.isnan(y[k]), (x["run"], k)
            else:
                assert x[k] == y[k], (x["run"], k, x[k], y[k])


@pytest.fixture(scope="module")
def reference_rows(tmp_path_factory):
    out = tmp_path_factory.mktemp("camp1")
    return rows_of(campaign.run(small_campaign(), out, n_workers=1, progress=False)), out


def test_failing_run_is_a_row_with_status_and_message(reference_rows):
    rows, out = reference_rows
    assert len(rows) == 16 and [r["run"] for r in rows] == list(range(16))
    bad = [r for r in rows if r["status"] != "ok"]
    assert [r["run"] for r in bad] == [12, 13, 14, 15]
    assert bad[0]["status"] == "fmu_error" and "wn" in bad[0]["message"] and np.isnan(bad[0]["eulerint_deg_s"])
    assert bad[2]["status"] == "bad_input" and "no_such_parameter" in bad[2]["message"]
    ok = [r for r in rows if r["status"] == "ok"]
    assert all(np.isfinite(r["eulerint_deg_s"]) and r["eulerint_deg_s"] > 0 for r in ok)
    # rows agree with a direct reference-master run of the same parameters
    ref = simulate(short("default", 2.0).with_overrides({"controller.wn": 2.0, "controller.zeta": 1.0}), "reference")
    assert rows[10]["p:controller.wn"] == 2.0 and rows[10]["p:controller.zeta"] == 1.0
    assert rows[10]["eulerint_deg_s"] == ref["eulerint_deg_s"][-1]
    import json
    man = json.loads((out / "manifest.json").read_text())
    assert man["n_runs"] == 16 and man["fmus"]["PdController"]["guid"].startswith("{")
    assert man["seeds"] == [3, 4] and "dask" in man["packages"] and "pyarrow" in man["packages"]


def test_rows_identical_with_two_workers(reference_rows, tmp_path):
    rows = rows_of(campaign.run(small_campaign(), tmp_path, n_workers=2, chunk=1, progress=False))
    same_rows(reference_rows[0], rows)


def test_existing_scheduler_by_address(reference_rows, tmp_path):
    """A scheduler and a worker started here on 127.0.0.1, reached the way a real cluster is."""
    sf = tmp_path / "scheduler.json"
    env = dict(os.environ, PYTHONPATH="")  # the worker gets the package from the client (upload)
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                               "--port", "0", "--no-dashboard", "--scheduler-file", str(sf)], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)]
    try:
        for _ in range(300):
            if sf.exists() and sf.stat().st_size > 0:
                break
            time.sleep(0.1)
        import json
        address = json.loads(sf.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                                       "--nworkers", "1", "--host", "127.0.0.1", "--no-dashboard", "--no-nanny"],
                                      env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path))
        from dask.distributed import Client
        with Client(address, timeout=60) as c:
            c.wait_for_workers(1, timeout=60)
        rows = rows_of(campaign.run(small_campaign(), tmp_path / "out", scheduler=address, progress=False))
        same_rows(reference_rows[0], rows)
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


def test_resume_runs_only_what_is_missing(reference_rows, tmp_path):
    c = small_campaign(timeseries=["alpha_deg"])
    full = rows_of(campaign.run(c, tmp_path, n_workers=1, flush_every=4, chunk=2, progress=False))
    same_rows([{k: v for k, v in r.items()} for r in reference_rows[0]], full)
    parts = sorted((tmp_path / "parts").glob("rows-*.parquet"))
    assert len(parts) == 4
    # an interrupted campaign: the final table and half of the parts are gone, one time series too
    (tmp_path / "results.parquet").unlink()
    for p in parts[1:3]:  # parts lost in the middle: new parts must not overwrite the last one
        p.unlink()
    parts = [parts[0], parts[3]]
    import pyarrow.parquet as pq
    kept = sorted(r for p in parts for r in pq.read_table(p).column("run").to_pylist())
    lost_ts = kept[0]
    (tmp_path / "timeseries" / f"run-{lost_ts:06d}.parquet").unlink()
    done_before = {p.name: p.stat().st_mtime_ns for p in parts}
    resumed = rows_of(campaign.run(c, tmp_path, n_workers=1, flush_every=100, progress=False))
    same_rows(full, resumed)
    new_parts = sorted(set(p.name for p in (tmp_path / "parts").glob("rows-*.parquet")) - set(done_before))
    redone = sorted(r for n in new_parts for r in pq.read_table(tmp_path / "parts" / n).column("run").to_pylist())
    assert redone == sorted(set(range(16)) - set(kept) | {lost_ts})
    assert all((tmp_path / "parts" / n).stat().st_mtime_ns == m for n, m in done_before.items())
    ts = campaign.read_timeseries(tmp_path, lost_ts)
    assert set(ts) == {"time", "alpha_deg"} and ts["time"][-1] == 2.0
    # a different campaign in the same folder is refused
    with pytest.raises(RuntimeError, match="another campaign"):
        campaign.run(small_campaign(t=1.0), tmp_path, n_workers=1, progress=False)
    # the same campaign with rows from another FMU build is not resumed: refused, or redone with overwrite
    import json
    man = json.loads((tmp_path / "manifest.json").read_text())
    man["fmus"]["PdController"]["sha256"] = "0" * 64
    (tmp_path / "manifest.json").write_text(json.dumps(man))
    with pytest.raises(RuntimeError, match="other FMU builds.*PdController"):
        campaign.run(c, tmp_path, n_workers=1, progress=False)
    import time
    t0 = time.time_ns()
    redone = rows_of(campaign.run(c, tmp_path, n_workers=1, progress=False, overwrite=True))
    same_rows(full, redone)
    parts = list((tmp_path / "parts").glob("rows-*.parquet"))
    assert parts and all(p.stat().st_mtime_ns >= t0 for p in parts)  # every run done again
    assert json.loads((tmp_path / "manifest.json").read_text())["fmus"]["PdController"]["sha256"] != "0" * 64


def test_cli_grid_and_plots(tmp_path):
    r = subprocess.run([sys.executable, "-m", "scfmu", "campaign", "default", "--t-end", "2",
                        "--grid", "controller.wn=0.5,1,2", "--workers", "1", "--timeseries", "alpha_deg",
                        "--plot-vs", "controller.wn", "--out", str(tmp_path), "--no-progress"],
                       capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "3 of 3 runs ok" in r.stdout
    for f in ("results.parquet", "manifest.json", "hist_eulerint_deg_s.png", "eulerint_deg_s_vs_controller_wn.png",
              "envelope_alpha_deg.png"):
        assert (tmp_path / f).stat().st_size > 0, f


def test_native_instance_reuse_after_reset_gives_fresh_results():
    """A container instance reset after a run (also after a failed one) gives the fresh-instance results."""
    from scfmu.engines import native
    from scfmu.engines.lean import SimulationError
    a = short(t=2.0).with_overrides({"controller.wn": 1.7, "plant.dist_noise_std_x": 0.5}).with_seed(7)
    b = short(t=2.0).with_overrides({"controller.wn": 0.6}).with_seed(1)
    fresh_a = simulate(a, "native", reuse=False)
    fresh_b = simulate(b, "native", reuse=False)
    native._POOL.clear()
    for sc, ref in ((a, fresh_a), (b, fresh_b), (a, fresh_a)):
        r = simulate(sc, "native")
        assert all(np.array_equal(r[k], ref[k]) for k in ref)
        with pytest.raises(SimulationError):
            simulate(short(t=2.0).with_overrides({"controller.wn": -1.0}), "native")
    assert sum(len(v) for v in native._POOL.values()) >= 1


def test_second_master_libcosim_agrees_within_the_coupling_delay():
    """libcosim (Jacobi: values move after the step) against the Gauss–Seidel reference, run 000-6:
    the one-step torque delay changes EULERINT by a fraction of a percent, nothing more."""
    pytest.importorskip("libcosimpy")
    from scfmu.engines.libcosim import run_libcosim
    sc = scenarios.get("default")
    ref = simulate(sc, "native", log_every=0)
    lc = run_libcosim(sc)
    e_ref, e_lc = ref["eulerint_deg_s"][-1], lc["eulerint_deg_s"]
    assert e_lc != e_ref  # a different coupling scheme, not the same computation
    assert abs(e_lc - e_ref) / e_ref < 0.01
    assert lc["alpha_deg"] < 1e-3 and lc["wall_s"] > 0


def test_a_worker_that_dies_gives_a_worker_error_row(tmp_path, monkeypatch):
    import dask
    monkeypatch.setenv("SCFMU_CRASH_TEST_RUN", "2")  # inherited by the LocalCluster's worker processes
    c = campaign.Campaign(short(t=1.0), campaign.grid({"controller.wn": [0.5, 1.0, 2.0, 3.0]}), seeds=[None])
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        rows = rows_of(campaign.run(c, tmp_path, n_workers=1, chunk=2, progress=False))
    assert [r["status"] for r in rows] == ["ok", "ok", "worker_error", "ok"]
    assert rows[2]["p:controller.wn"] == 2.0 and np.isnan(rows[2]["eulerint_deg_s"])


@pytest.mark.parametrize("name,t,overrides,seed", [("default", 3.0, {"controller.wn": 1.3}, None),
                                                   ("paper002/FOPID", 1.5, {"controller.kp": 4.0}, None),
                                                   ("paper001/c/dist0.01", 2.0, {}, None),
                                                   ("paper003/T2FSMC/W", 3.0, {}, 5)])
def test_campaign_metrics_equal_those_of_a_full_log_reference_run(name, t, overrides, seed):
    """A campaign run logs only the signals its metric set reads; its metric columns equal, to the bit,
    the metrics computed from every logged signal of the same scenario on the reference master."""
    from scfmu import metrics as run_metrics

    base = short(name, t)
    spec = campaign.Campaign(base, [overrides], seeds=[seed]).runs()[0]
    seen = []
    real_simulate = campaign.runs.simulate

    def spy(sc, *a, **kw):  # a campaign run hands simulate its plan (the scenario resolved once)
        seen.append(dict(getattr(sc, "scenario", sc).log))
        return real_simulate(sc, *a, **kw)

    campaign.runs.simulate = spy
    try:
        row, ts = campaign.run_one(spec)
    finally:
        campaign.runs.simulate = real_simulate
    assert row["status"] == "ok", row["message"]
    assert ts is None
    need = run_metrics.logs_needed(base.metrics)
    assert need is not None and set(seen[0]) == set(base.log) & set(need) and len(seen[0]) <= len(base.log)
    full = base.with_overrides(overrides)
    if seed is not None:
        full = full.with_seed(seed)
    ref = simulate(full, "reference")
    assert set(ref) == {"time", *base.log}  # every signal logged
    want = run_metrics.compute(base.metrics, ref)
    cols = run_metrics.columns(base.metrics)
    assert cols
    for k in cols:
        a, b = row[k], float(want.get(k, np.nan))
        assert np.array(a).view(np.int64) == np.array(b).view(np.int64) or (np.isnan(a) and np.isnan(b)), (k, a, b)


def test_a_local_cluster_leaves_port_8787_alone(tmp_path):
    """Another Dask on the machine (a second campaign, a notebook's cluster) holds the usual dashboard port:
    the local cluster takes a free port instead and Dask prints no port warning into the run's messages."""
    import socket
    import warnings
    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen(1)
    except OSError:
        holder.close()
        pytest.skip("port 8787 is taken by something else already")
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            rows = rows_of(campaign.run(small_campaign(t=1.0), tmp_path, n_workers=1, progress=False))
    finally:
        holder.close()
    assert len(rows) == 16  # the campaign ran
    assert not [w for w in seen if "8787" in str(w.message)], [str(w.message) for w in seen]
