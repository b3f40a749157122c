"""Issue 34: a user's controller that comes as Model Exchange only (a continuous-time controller exported from
a modelling tool: direct feedthrough, no continuous states, no event indicators) runs in every engine, in
`scfmu run`, in campaigns and in the benchmark, FMI 3.0 and FMI 2.0.

The units are foreign, built by the tests from the FMI headers that fmpy ships (tests/foreign_units.py):
C3PdControllerME (FMI 3.0, tests/foreign/c3/c3_units.c MODEL 3) and CPdController variant "me" (FMI 2.0,
tests/foreign/c_pd/c_pd.c with MODEL_EXCHANGE=1). Both compute PdController's quaternion PD law.

Oracles and tolerances:
- the PD law in NumPy (`foreign_units.pd_law`, written independently of the units) applied to the inputs the
  unit received at each communication point gives the torque it returned (1e-12 relative);
- the same C law compiled as a Co-Simulation unit (C3PdController, CPdController "ok"): bit-identical
  trajectories. A feedthrough controller without states evaluated by the engine at the communication points
  (Model Exchange, inputs held between the points) returns exactly what the Co-Simulation build returns after
  its doStep, so nothing but the interface differs;
- the project's PdController (Rust, FMI 2.0 Co-Simulation): every logged signal within 1e-12 of its range
  (measured 5.6e-16 on every engine, both FMI versions), every campaign and benchmark metric within
  1e-12 x max(|value|, 1) in its unit (measured <= 7e-15 relative; the benchmark's final error of ~6e-10 deg
  differs by 2e-15 deg). The difference is round-off only: the C code evaluates the same law in another
  order of floating-point operations than the Rust model.
"""

from __future__ import annotations

import csv
import ctypes
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import foreign_units
from scfmu.engines import ENGINES, simulate
from scfmu.scenario import get
from scfmu.scenario.plan import build_plan

ROOT = Path(__file__).resolve().parents[1]
T = 10.0
ROUND_OFF = 1e-12  # the C law vs the Rust law: of each signal's range, of max(|metric|, 1) (module docstring)
INPUTS = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"]


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    return foreign_units.ForeignUnits(tmp_path_factory.mktemp("me_controller"))


def me_unit(units, fmi: int) -> str:
    """The Model-Exchange-only PD controller of FMI version `fmi`."""
    return str(units.c3("C3PdControllerME") if fmi == 3 else units.c_pd("me"))


def cs_twin(units, fmi: int) -> str:
    """The Co-Simulation build of the same C law."""
    return str(units.c3("C3PdController") if fmi == 3 else units.c_pd("ok"))


def worst_rel(ref: dict, got: dict) -> float:
    """The largest difference of any logged signal, relative to that signal's range in `ref`."""
    return max(float(np.max(np.abs(ref[k] - got[k])) / max(1e-300, np.ptp(ref[k]), np.max(np.abs(ref[k]))))
               for k in ref if k != "time")


def same(a: dict, b: dict) -> bool:
    return list(a) == list(b) and all(np.array_equal(a[k], b[k]) for k in a)


def _cli(*args, timeout=900):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, cwd=ROOT)


def _twin_scenario(fmi: int, stop: float = T):
    """The default scenario ready for the Co-Simulation twin (the FMI 3.0 one has Int32/Boolean inputs to leave open)."""
    sc = get("default", stop_time=stop)
    if fmi == 3:
        sc = sc.with_overrides(unconnected=sc.unconnected + ["controller.enable", "controller.count_in"])
    return sc


# ----- the units ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("fmi", [2, 3])
def test_the_units_are_model_exchange_only_without_states_or_event_indicators(units, fmi):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu
    p = me_unit(units, fmi)
    md = read_model_description(p)
    assert md.coSimulation is None and md.modelExchange is not None
    assert md.derivatives == [] and md.eventIndicators == [] and md.numberOfEventIndicators in (0, None)
    assert validate_fmu(p) == []
    names = {v.name for v in md.modelVariables}
    assert {"torque_cmd_x", "wn", "zeta", "inertia_xx"} <= names and "enable" not in names


def _law_check(set_values, get_values, vr, *, seed, wn, zeta, inertia):
    """check(mode): random unit quaternions and rates into the unit's inputs (``set_values``), its torque
    (``get_values``) against the NumPy law to 1e-12."""
    rng = np.random.default_rng(seed)

    def check(mode):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        r = rng.normal(size=4)
        r /= np.linalg.norm(r)
        w = rng.normal(size=3) * 0.1
        set_values([vr[n] for n in INPUTS], list(q) + list(w) + list(r))
        got = np.array(get_values([vr[f"torque_cmd_{a}"] for a in "xyz"]))
        want = foreign_units.pd_law(q, w, r, wn=wn, zeta=zeta, inertia=inertia)
        assert np.allclose(got, want, rtol=1e-12, atol=1e-12), (mode, got, want)
    return check


def test_fmi3_unit_follows_the_numpy_law_through_the_model_exchange_calls(units):
    """FMI 3.0 Model Exchange calls as an importer makes them (fmpy's FMU3Model): initialization, event mode,
    continuous-time mode with set time, 0 states and 0 event indicators, completed integrator step; the torque
    is the PD law of the inputs set last, in every mode; a Co-Simulation instantiation is refused."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Model, FMU3Slave
    p = me_unit(units, 3)
    md = read_model_description(p)
    d = extract(p)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    kw = dict(guid=md.guid, unzipDirectory=d, modelIdentifier=md.modelExchange.modelIdentifier)
    cs = FMU3Slave(instanceName="cs", **kw)
    with pytest.raises(Exception):
        cs.instantiate()
    cs.freeLibrary()
    m = FMU3Model(instanceName="me", **kw)
    m.instantiate()
    m.setFloat64([vr["wn"], vr["zeta"], vr["inertia_yy"]], [0.7, 0.9, 321.0])
    m.enterInitializationMode(startTime=0.0)
    check = _law_check(m.setFloat64, m.getFloat64, vr, seed=7, wn=0.7, zeta=0.9, inertia=(1000.0, 321.0, 700.0))

    check("initialization")
    m.exitInitializationMode()
    check("event")
    flags = m.updateDiscreteStates()
    assert flags[0] is False and flags[4] is False  # no new discrete states, no next time event
    m.enterContinuousTimeMode()
    assert m.getNumberOfContinuousStates() == 0 and m.getNumberOfEventIndicators() == 0
    for t in (0.1, 0.2, 0.3):
        m.setTime(t)
        check(f"continuous t={t}")
        assert m.completedIntegratorStep() == (False, False)
    m.enterEventMode()
    check("event again")
    m.terminate()
    m.freeInstance()


def test_fmi2_unit_follows_the_numpy_law_through_the_model_exchange_calls(units):
    """The same for the FMI 2.0 unit (fmpy's FMU2Model): event mode, new discrete states, continuous-time mode,
    0 states and 0 event indicators, completed integrator step; a Co-Simulation instantiation is refused."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model, FMU2Slave
    p = me_unit(units, 2)
    md = read_model_description(p)
    d = extract(p)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    kw = dict(guid=md.guid, unzipDirectory=d, modelIdentifier=md.modelExchange.modelIdentifier)
    cs = FMU2Slave(instanceName="cs", **kw)
    with pytest.raises(Exception):
        cs.instantiate()
    cs.freeLibrary()
    m = FMU2Model(instanceName="me", **kw)
    m.instantiate()
    m.setReal([vr["wn"], vr["zeta"], vr["inertia_zz"]], [1.3, 0.6, 99.0])
    m.setupExperiment(startTime=0.0)
    m.enterInitializationMode()
    check = _law_check(m.setReal, m.getReal, vr, seed=11, wn=1.3, zeta=0.6, inertia=(1000.0, 500.0, 99.0))

    check("initialization")
    m.exitInitializationMode()
    check("event")
    info = m.newDiscreteStates()
    assert not info[0] and not info[4]  # no new discrete states needed, no next time event
    m.enterContinuousTimeMode()
    m.setContinuousStates((ctypes.c_double * 1)(), 0)  # 0 states: an empty vector is accepted
    for t in (0.1, 0.2, 0.3):
        m.setTime(t)
        check(f"continuous t={t}")
        assert tuple(bool(x) for x in m.completedIntegratorStep()) == (False, False)
    m.enterEventMode()
    check("event again")
    m.terminate()
    m.freeInstance()


# ----- every engine ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def reference():
    return simulate(get("default", stop_time=T), "reference")


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("fmi", [2, 3])
def test_me_controller_on_every_engine(units, reference, engine, fmi):
    """Run 000-6 (scenario default, 10 s) with the ME-only controller in place of PdController: it runs as
    Model Exchange; its torque is the NumPy law of the inputs it got at each communication point; the run is
    bit-identical to the Co-Simulation build of the same C law and within round-off of PdController's run."""
    p = me_unit(units, fmi)
    sc = get("default", stop_time=T).with_models({"controller": p})
    assert build_plan(sc).model_exchange == {"controller"}
    sc.log.update({f"c_{n}": f"controller.{n}" for n in INPUTS})
    sc.log.update({f"c_tau_{a}": f"controller.torque_cmd_{a}" for a in "xyz"})
    got = simulate(sc, engine)
    q = np.stack([got[f"c_{n}"] for n in INPUTS[:4]], axis=1)
    w = np.stack([got[f"c_{n}"] for n in INPUTS[4:7]], axis=1)
    r = np.stack([got[f"c_{n}"] for n in INPUTS[7:]], axis=1)
    tau = np.stack([got[f"c_tau_{a}"] for a in "xyz"], axis=1)
    want = np.array([foreign_units.pd_law(*x) for x in zip(q, w, r)])
    assert np.max(np.abs(tau - want)) <= 1e-12 * np.max(np.abs(want)), np.max(np.abs(tau - want))
    assert np.ptp(q[:, 0]) > 0.1 and np.max(np.abs(tau)) > 100.0  # a real slew, real torques
    got = {k: v for k, v in got.items() if not k.startswith("c_")}
    twin = simulate(_twin_scenario(fmi), engine, fmus={"controller": cs_twin(units, fmi)})
    assert same(twin, got)
    assert reference["eulerint_deg_s"][-1] > 100.0
    assert set(reference) == set(got)
    assert worst_rel(reference, got) < ROUND_OFF


@pytest.mark.parametrize("fmi", [2, 3])
def test_scfmu_run_takes_the_me_controller(units, reference, tmp_path, fmi):
    """`scfmu run default --fmu controller=<ME-only unit>`: exit 0, and the CSV it writes is PdController's
    trajectory to round-off."""
    r = _cli("run", "default", "--t-end", T, "--no-plot", "--fmu", f"controller={me_unit(units, fmi)}",
             "--out", tmp_path / "run")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "controller=" in r.stdout and "eulerint_deg_s" in r.stdout
    with open(tmp_path / "run" / "default.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    got = {k: np.array([float(x[k]) for x in rows]) for k in rows[0]}
    assert np.allclose(got["time"], reference["time"], rtol=0, atol=1e-12)
    assert worst_rel(reference, {k: got[k] for k in reference}) < ROUND_OFF


# ----- campaign -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("fmi", [2, 3])
def test_campaign_of_three_runs_with_the_me_controller(units, tmp_path, fmi):
    """Three runs (wn = 0.8, 1, 1.5) of the ME-only controller in a campaign (default engine; a foreign unit
    runs isolated): all ok, each run's metrics those of PdController's campaign with the same wn to round-off,
    and the three runs differ (the parameter reached the unit)."""
    from scfmu import campaign
    sets = [{"controller.wn": x} for x in (0.8, 1.0, 1.5)]
    sc = get("default", stop_time=5.0)
    mine = campaign.run(campaign.Campaign(sc.with_models({"controller": me_unit(units, fmi)}), sets),
                        tmp_path / "me", n_workers=1, progress=False).to_pylist()
    pd = campaign.run(campaign.Campaign(sc, sets), tmp_path / "pd", n_workers=1, progress=False).to_pylist()
    assert [r["status"] for r in mine] == ["ok"] * 3, [r["message"] for r in mine]
    mine, pd = (sorted(x, key=lambda r: r["run"]) for x in (mine, pd))
    keys = [k for k in ("eulerint_deg_s", "ise", "isf", "effort_abs", "final_error", "peak_torque") if k in pd[0]]
    assert len(keys) == 6
    for a, b in zip(mine, pd):
        for k in keys:
            assert abs(a[k] - b[k]) <= ROUND_OFF * max(abs(b[k]), 1.0), (a["run"], k, a[k], b[k])
    assert len({r["eulerint_deg_s"] for r in mine}) == 3


# ----- benchmark ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("fmi", [2, 3])
def test_benchmark_ranks_the_me_controller_as_pd_controller(units, tmp_path, fmi):
    """`scfmu benchmark <ME-only unit> --family attitude --controllers PdController --cases default`: exit 0,
    the unit's table rows (metrics, pass, rank; robustness and margins) are PdController's, its metrics in
    results.csv equal PdController's to round-off, the two are reported as identical responses, and the page
    and the log say the unit ran as Model Exchange. The FMI 3.0 unit goes through `--check` first."""
    p = me_unit(units, fmi)
    label = Path(p).stem
    # the FMI 3.0 unit also passes `scfmu check --quick` first (--check); the FMI 2.0 one has the state machine
    # weaknesses of CPdController that tests/test_check.py reports, so it is benchmarked without --check
    r = _cli("benchmark", p, "--family", "attitude", "--controllers", "PdController", "--cases", "default",
             "--out", tmp_path / "b", *(["--check"] if fmi == 3 else []))
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    if fmi == 3:
        assert "interfaces ME" in r.stderr and "the FMU passes" in r.stderr, r.stderr[-3000:]
    how = f"run as FMI {fmi}.0 Model Exchange"
    assert how in r.stdout
    md = (tmp_path / "b" / "benchmark.md").read_text()
    assert how in md
    assert f"PD, quaternion error = {label}: identical responses" in md
    mine = [x for x in md.splitlines() if x.startswith(f"| **{label}**")]
    pd = [x for x in md.splitlines() if x.startswith("| PD, quaternion error")]
    assert len(mine) == len(pd) >= 2
    for a, b in zip(mine, pd):
        assert a.split("|")[2:] == b.split("|")[2:], (a, b)
    with open(tmp_path / "b" / "results.csv", newline="") as f:
        rows = {x["controller"]: x for x in csv.DictReader(f)}
    a, b = rows[label], rows["PD, quaternion error"]
    assert a["ok"] == b["ok"] == "1" and a["rank"] == b["rank"] == "1" and a["pass"] == b["pass"] == "True"
    assert how in a["configuration"]
    metrics = [k for k in b if "[" in k]
    assert len(metrics) >= 5
    for k in metrics:
        assert abs(float(a[k]) - float(b[k])) <= ROUND_OFF * max(abs(float(b[k])), 1.0), (k, a[k], b[k])


# ----- SSP and loop FMU -----------------------------------------------------------------------------------
def test_ssp_keeps_the_model_exchange_interface(units, tmp_path):
    """An SSP 1.0 file of the loop with the FMI 2.0 ME-only controller and the plant asked to run as Model
    Exchange (it offers both): schema-valid, both components marked implementation="ModelExchange" (the
    others left "any"), read back with their interface, and the read-back scenario on the reference master
    gives the original run to the bit (before, the plant came back as Co-Simulation)."""
    import xml.etree.ElementTree as ET
    import zipfile
    from scfmu.engines import run_reference
    from scfmu.scenario.ssp import read_ssp, validate_ssp, write_ssp
    sc = get("default", stop_time=3.0).with_models({"controller": me_unit(units, 2)})
    sc.component("plant").interface = "me"
    p = write_ssp(sc, tmp_path / "loop.ssp")
    assert validate_ssp(p) == []
    with zipfile.ZipFile(p) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    impl = {c.get("name"): c.get("implementation") for c in root.iter() if c.tag.endswith("}Component")}
    assert impl == {"command": None, "controller": "ModelExchange", "plant": "ModelExchange", "metrics": None}
    back, files = read_ssp(p, tmp_path / "x")
    assert {c.name: c.interface for c in back.components} == {"command": "", "controller": "me", "plant": "me",
                                                               "metrics": ""}
    assert build_plan(back, path_of=files.__getitem__).model_exchange == {"controller", "plant"}
    ref = simulate(sc, "reference")
    got = run_reference(back, path_of=files.__getitem__)
    assert ref["eulerint_deg_s"][-1] > 10.0
    assert all(np.array_equal(ref[k], got[k]) for k in ref)


@pytest.mark.parametrize("fmi", [2, 3])
def test_loop_fmu_with_the_me_controller_runs_in_fmpy(units, reference, tmp_path, fmi):
    """A loop FMU whose controller is the ME-only unit (nested as its Co-Simulation face) passes fmpy's
    validation, and fmpy.simulate_fmu of the single file gives PdController's loop to round-off."""
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from scfmu.export.loops import write_loop_fmu
    t = 3.0
    sc = get("default", stop_time=t).with_models({"controller": me_unit(units, fmi)})
    p = write_loop_fmu(sc, tmp_path / "loop.fmu")
    assert validate_fmu(str(p)) == []
    keys = [k for k in reference if k != "time"]
    r = simulate_fmu(str(p), stop_time=t, output_interval=sc.step, output=[sc.log[k] for k in keys])
    n = len(r)
    assert n == int(round(t / sc.step)) + 1
    ref = {k: reference[k][:n] for k in keys}
    assert worst_rel(ref, {k: r[sc.log[k]] for k in keys}) < ROUND_OFF
