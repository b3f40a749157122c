"""Units from other exporters in our scenarios: a PD controller written in C against the FMI 2.0 headers
that fmpy ships, the same law as a PythonFMU, and deliberately broken C units (tests/foreign_units.py).

* The C unit replaces PdController in the default slew on all three engines, libcosim, an SSP file, a loop
  FMU, a campaign on two Dask workers and the benchmark: its trajectories equal PdController's to round-off
  (same law, independent code and value references).
* The PythonFMU unit runs on the three engines and on a Dask worker where the host can load it (skipped
  with the reason otherwise; in CI only a host limit may skip it).
* Broken units: the pre-flight check refuses wrong ports (with --map they run), a wrong unit, a missing
  binary, Model Exchange only; a unit that crashes, hangs, returns NaN or an error status costs its runs
  only — each becomes a row with its status, the other runs complete, and the CLI exits 1 with the counts.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import pytest

import foreign_units as fu
from scfmu import campaign
from scfmu.engines import simulate
from scfmu.scenario import get
from scfmu.scenario.check import IncompatibleUnit, check, require

ENGINES = ("reference", "lean", "native")
T = 3.0


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    return fu.ForeignUnits(tmp_path_factory.mktemp("foreign"))


def scfmu(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def close(a, b):
    return np.allclose(a, b, rtol=1e-9, atol=1e-12, equal_nan=True)


def assert_same_loop(ref, mine):
    assert set(ref) == set(mine)
    for k in ref:
        assert close(ref[k], mine[k]), f"{k}: max diff {np.max(np.abs(np.asarray(ref[k]) - mine[k]))}"


@pytest.fixture(scope="module")
def reference():
    return simulate(get("default", stop_time=T), "reference")


@pytest.mark.parametrize("engine", ENGINES)
def test_c_unit_replaces_pd_on_every_engine(units, reference, engine):
    out = simulate(get("default", stop_time=T), engine, fmus={"controller": str(units.c_pd())})
    assert_same_loop(reference, out)


def test_c_unit_in_libcosim(units):
    from scfmu.engines.libcosim import run_libcosim
    a = run_libcosim(get("default", stop_time=T))
    b = run_libcosim(get("default", stop_time=T).with_models({"controller": str(units.c_pd())}))
    assert abs(a["eulerint_deg_s"] - b["eulerint_deg_s"]) <= 1e-9 * a["eulerint_deg_s"]


def test_c_unit_in_an_ssp_file_and_a_loop_fmu(units, reference, tmp_path):
    from fmpy import simulate_fmu

    from scfmu.engines import run_reference
    from scfmu.export.loops import write_loop_fmu
    from scfmu.scenario import ssp
    sc = get("default", stop_time=T).with_models({"controller": str(units.c_pd())})
    p = ssp.write_ssp(sc, tmp_path / "c.ssp")
    assert ssp.validate_ssp(p) == []
    back, paths = ssp.read_ssp(p, tmp_path / "unz")
    assert_same_loop(reference, run_reference(back, path_of=paths.__getitem__))
    loop = write_loop_fmu(sc, tmp_path / "c_loop.fmu")
    r = simulate_fmu(str(loop), stop_time=T, output_interval=0.01, output=["metrics.eulerint_deg_s"])
    assert close(r["metrics.eulerint_deg_s"], reference["eulerint_deg_s"])


def test_c_unit_in_a_campaign_on_two_workers(units, tmp_path):
    grid = campaign.grid({"controller.wn": [0.7, 1.0, 1.4]})
    c_ours = campaign.Campaign(get("default", stop_time=T), grid)
    c_theirs = campaign.Campaign(get("default", stop_time=T).with_models({"controller": str(units.c_pd())}), grid)
    assert c_theirs.isolated() and not c_ours.isolated()
    a = campaign.run(c_ours, tmp_path / "ours", n_workers=2, progress=False).to_pylist()
    b = campaign.run(c_theirs, tmp_path / "theirs", n_workers=2, progress=False).to_pylist()
    assert [r["status"] for r in b] == ["ok"] * 3
    for x, y in zip(a, b):
        for k in ("eulerint_deg_s", "ise", "isf", "effort_abs", "settling_s"):
            assert close(x[k], y[k]), k


def test_python_unit_on_every_engine_and_a_worker(units, reference, tmp_path):
    ok, why = units.python_loadable()
    if not ok:
        if os.environ.get("CI") == "true" and not fu.is_host_limit(why):
            pytest.fail(f"PythonFMU unit not loadable for a reason that is not a host limit: {why}")
        pytest.skip(f"this host cannot load a PythonFMU unit: {why}")
    p = str(units.python_pd(units=True))
    rep = check(get("default", stop_time=T).with_models({"controller": p}))
    assert rep.ok, rep.errors
    for engine in ENGINES:
        assert_same_loop(reference, simulate(get("default", stop_time=T), engine, fmus={"controller": p}))
    c = campaign.Campaign(get("default", stop_time=T).with_models({"controller": p}), [{}, {"controller.wn": 1.0}])
    rows = campaign.run(c, tmp_path / "py", n_workers=1, progress=False).to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert close(rows[0]["eulerint_deg_s"], reference["eulerint_deg_s"][-1])


def test_wrong_ports_are_refused_and_mapped(units, reference, tmp_path):
    p = str(units.c_pd("wrong_ports"))
    sc = get("default", stop_time=T).with_models({"controller": p})
    with pytest.raises(IncompatibleUnit) as e:
        require(sc)
    msg = str(e.value)  # every mismatch is named, on both sides of the unit
    for a in "xyz":
        assert f"input controller.omega_{a} has no source" in msg and f"input plant.torque_cmd_{a} has no source" in msg, msg
    mapped = sc.with_port_map({"controller.tau_x": "torque_cmd_x", "controller.tau_y": "torque_cmd_y",
                               "controller.tau_z": "torque_cmd_z", "controller.omega_x": "w_x",
                               "controller.omega_y": "w_y", "controller.omega_z": "w_z"})
    assert require(mapped).ok
    out = simulate(mapped, "native")
    assert close(out["eulerint_deg_s"], reference["eulerint_deg_s"])
    args = ["run", "default", "--t-end", T, "--fmu", f"controller={p}"]
    assert scfmu(*args).returncode == 2
    maps = [x for a in ("x", "y", "z") for x in ("--map", f"controller.tau_{a}=torque_cmd_{a}", "--map",
                                                  f"controller.omega_{a}=w_{a}")]
    r = scfmu(*args, *maps, "--out", tmp_path)
    assert r.returncode == 0, r.stderr


def test_units_and_interfaces_are_checked(units):
    base = get("default", stop_time=T)
    rep = check(base.with_models({"controller": str(units.c_pd("bad_unit"))}))
    assert any("unit 'N' does not match 'N.m'" in x for x in rep.errors), rep.errors
    rep = check(base.with_models({"controller": str(units.c_pd("no_unit"))}))
    assert rep.ok and any("no unit declared on controller.w_x" in x for x in rep.warnings), rep.warnings
    rep = check(base.with_models({"controller": str(units.c_pd("no_binary"))}))
    assert rep.errors and "no binary for this platform" in rep.errors[0]
    # a unit that declares Model Exchange only runs as Model Exchange (issue 34): this one's binary has no
    # Model Exchange functions, which the instantiation finds; asked to run as Co-Simulation, it is refused
    me_only = base.with_models({"controller": str(units.c_pd("me_only"))})
    rep = check(me_only)
    assert rep.errors and "fmi2Instantiate failed" in rep.errors[0] and "undefined symbol" in rep.errors[0], rep.errors
    me_only.component("controller").interface = "cs"
    rep = check(me_only)
    assert rep.errors and "no Co-Simulation interface" in rep.errors[0]


# a NaN torque is refused by our plant's fmi2SetReal (fmi2Error, "not finite"): fmu_error, before any NaN
# could reach a logged signal (which would give "nonfinite")
@pytest.mark.parametrize("variant, status", [("crash", "crash"), ("hang", "timeout"), ("nan", "fmu_error"),
                                             ("error", "fmu_error")])
def test_a_failing_unit_costs_its_own_runs_only(units, variant, status, tmp_path, monkeypatch):
    """One chunk of three runs on one worker: healthy, broken, healthy. The broken run becomes a row with
    its status and message; the runs after it complete. No run leaves a temporary file behind (the
    isolated child's unpacked units included, whether it crashed, hung or ended)."""
    good = campaign.Campaign(get("default", stop_time=1.0).with_models({"controller": str(units.c_pd())}),
                             timeout=30).runs()[0]
    bad = campaign.Campaign(get("default", stop_time=1.0).with_models({"controller": str(units.c_pd(variant))}),
                            timeout=4.0).runs()[0]
    specs = [dict(good, run=0), dict(bad, run=1), dict(good, run=2)]
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    rows = [r for r, _ in campaign.run_chunk(specs)]
    from scfmu.fmu.scratch import LOCK, PREFIX  # only this process's scratch folder, holding only its lock
    assert [p.name[:len(PREFIX)] for p in scratch.iterdir()] in ([], [PREFIX])
    assert [p.name for f in scratch.iterdir() for p in f.iterdir()] in ([], [LOCK])
    assert [r["status"] for r in rows] == ["ok", status, "ok"], rows[1]["message"]
    assert rows[0]["eulerint_deg_s"] == rows[2]["eulerint_deg_s"]
    want = {"crash": "SIGSEGV", "hang": "4 s", "nan": "not finite", "error": "deliberate failure"}[variant]
    assert want in rows[1]["message"], rows[1]["message"]


_ONE_RUN = """
import sys
from scfmu import campaign
from scfmu.scenario import get
spec = campaign.Campaign(get("default", stop_time=1.0).with_models({"controller": sys.argv[1]}), timeout=600).runs()[0]
print("running", flush=True)
print(campaign.run_chunk([spec])[0][0]["status"], flush=True)
"""


def test_a_crash_is_a_row_not_a_fatal_error_dump(units):
    """With Python's fault handler on (as pytest and `python -X faulthandler` have it), a unit's crash in
    an isolated run is a row with status crash and nothing else: the child drops the inherited handler, so
    no 'Fatal Python error' dump reaches the terminal and no handler re-raises the signal from user space."""
    p = subprocess.run([sys.executable, "-X", "faulthandler", "-c", _ONE_RUN, str(units.c_pd("crash"))],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and p.stdout.split() == ["running", "crash"], p.stdout + p.stderr[-2000:]
    assert "Fatal Python error" not in p.stderr, p.stderr[-2000:]


def test_an_isolated_run_dies_with_its_campaign(units, tmp_path):
    """A campaign process killed (SIGKILL) while a unit hangs in its isolated child takes the child with
    it: the child is in a session of its own (no group signal from a crashing unit reaches the campaign)
    but is tied to its parent's life, so a hanging unit cannot spin on after the campaign is gone."""
    import psutil
    p = subprocess.Popen([sys.executable, "-c", _ONE_RUN, str(units.c_pd("hang"))], stdout=subprocess.PIPE,
                         text=True, env=dict(os.environ, TMPDIR=str(tmp_path)))  # what a killed run leaves
    try:
        assert p.stdout.readline().strip() == "running"
        deadline, kids = time.monotonic() + 60, []
        while not kids and time.monotonic() < deadline:
            kids = psutil.Process(p.pid).children()
            time.sleep(0.1)
        assert len(kids) == 1, "the isolated child did not start"
        child = kids[0]
        assert os.getsid(child.pid) == child.pid != os.getsid(p.pid)  # a session of its own
        time.sleep(1.0)  # past the fail time: the unit spins in fmi2DoStep
        assert child.status() != psutil.STATUS_ZOMBIE
        p.kill()
        p.wait(10)
        gone, alive = psutil.wait_procs([child], timeout=10)
        assert not alive, "the isolated child outlived its campaign"
    finally:
        p.kill()


def test_campaign_cli_with_a_crashing_unit_exits_1_with_counts(units, tmp_path):
    r = scfmu("campaign", "default", "--t-end", "1", "--fmu", f"controller={units.c_pd('crash')}", "--grid",
              "controller.wn=0.5,1.0", "--workers", "2", "--out", tmp_path / "c", "--no-progress", "--no-plots")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "0 of 2 runs ok (crash: 2)" in r.stdout and "2 of 2 runs failed" in r.stderr
    r = scfmu("campaign", "default", "--t-end", "1", "--fmu", f"controller={units.c_pd('hang')}", "--timeout", "3",
              "--workers", "1", "--out", tmp_path / "h", "--no-progress", "--no-plots")
    assert r.returncode == 1 and "(timeout: 1)" in r.stdout, r.stdout + r.stderr


def test_campaign_check_stops_before_a_unit_that_fails_it(units, tmp_path):
    """`scfmu campaign --check` runs `scfmu check --quick` on each unit given as a file first: the crashing
    unit fails it (exit 1, the failed checks named, no run made); our PdController given as a file passes
    and its runs go. (The hand-written C unit is not check-clean: it does not guard against hostile call
    sequences, which `scfmu check` exercises.)"""
    r = scfmu("campaign", "default", "--t-end", "1", "--fmu", f"controller={units.c_pd('crash')}", "--check",
              "--workers", "1", "--out", tmp_path / "c", "--no-progress", "--no-plots")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "fails scfmu check" in r.stderr and "the campaign was not run" in r.stderr, r.stderr[-2000:]
    assert not (tmp_path / "c" / "results.parquet").exists()
    from scfmu.fmu import fmu_path
    r = scfmu("campaign", "default", "--t-end", "1", "--fmu", f"controller={fmu_path('PdController')}", "--check",
              "--workers", "1", "--out", tmp_path / "ok", "--no-progress", "--no-plots")
    assert r.returncode == 0 and "1 of 1 runs ok" in r.stdout, r.stdout + r.stderr[-2000:]


def test_benchmark_with_the_c_unit(units, tmp_path):
    r = scfmu("benchmark", units.c_pd(), "--family", "attitude", "--controllers", "PdController", "--cases",
              "default", "--out", tmp_path, timeout=900)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    md = (tmp_path / "benchmark.md").read_text()
    assert "**CPdController**" in md
    line = [x for x in md.splitlines() if x.startswith("| **CPdController**")][0]
    pd = [x for x in md.splitlines() if x.startswith("| PD, quaternion error")][0]
    assert line.split("|")[3:] == pd.split("|")[3:], (line, pd)  # pass, rank and every metric the same
    assert re.search(r"\*\*CPdController\*\*: large slew .*: rank 1 of 2", md)

