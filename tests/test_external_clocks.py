"""External masters on the clocked FMI 3.0 units (issue 48 item 2): fmpy 0.3.32 as the importer, with its own
loader and its own ctypes binding (none of scfmu's FMU code is used here).

What is measured, and against what:
* fmpy's ``FMU3Slave`` instantiated with ``eventModeUsed = true`` drives every clock of every clocked unit
  (``fmi3SetClock`` at the clock's ticks, ``fmi3UpdateDiscreteStates``, ``fmi3EnterStepMode``, ``fmi3DoStep``,
  ``fmi3EnterEventMode``), and its ``FMU3ScheduledExecution`` calls ``fmi3ActivateModelPartition`` at the same
  ticks: the outputs read at every communication point have the same IEEE-754 bits as the unit's FMI 2.0 FMU
  stepped by fmpy's ``FMU2Slave`` (the sampled run, which has no clocks at all);
* the intervals and shifts ``fmi3GetIntervalDecimal`` / ``fmi3GetShiftDecimal`` give in Initialization Mode
  against the units' documented sampling (a PID at 1 ms, a gyro at 10 ms, a star tracker at 0.2 s delivering
  0.1 s later) and the qualifiers the standard prescribes (section 2.2.9: ``fmi3IntervalChanged`` at the first
  call, ``fmi3IntervalUnchanged`` after); the ``nextEventTime`` of each update against the next tick;
* what ``fmpy.simulate_fmu`` itself does with a clocked unit: by default (no event mode) it runs it, and the
  results equal the FMI 2.0 FMU's; with ``use_event_mode=True`` it never sets a clock; with
  ``fmi_type='ScheduledExecution'`` it refuses before loading anything (docs/tools.md gives the table).
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import (FMU3ScheduledExecution, FMU3Slave, fmi3Float64, fmi3IntervalChanged, fmi3IntervalQualifier,
                       fmi3IntervalUnchanged, fmi3ValueReference)

from scfmu.fmu import fmu_dir

# the units the issue names, with inputs that move and the sampling their documentation gives:
# (parameters, {input: function of t}, [(interval, shift) per clock, in clock order])
AXIS = (0.48, -0.6, 0.64)


def _quat(t):
    a = 0.05 * t + 0.3 * math.sin(0.7 * t)
    return {"q_w": math.cos(a / 2), **{f"q_{c}": math.sin(a / 2) * e for c, e in zip("xyz", AXIS)}}


CASES = {
    "PidController": ({}, lambda t: {"theta": 0.3 * math.sin(4 * math.pi * t), "theta_ref": 0.1},
                      [(0.001, 0.0)]),
    "Gyro": ({}, lambda t: {f"w_{c}": 0.01 * math.sin((i + 1) * t) for i, c in enumerate("xyz")}, [(0.01, 0.0)]),
    "StarTracker": ({}, _quat, [(0.2, 0.0), (0.2, 0.1)]),
    "SampleHold": ({"sample_period": 0.1, "delay": 0.05},
                   lambda t: {f"u_{i}": math.sin(i * t) for i in range(1, 9)}, [(0.1, 0.0), (0.1, 0.05)]),
}
# moving inputs for other clocked units (the rest keep their start values)
INPUTS = {
    "FopidController": CASES["PidController"][1],
    "BDot": lambda t: {"b_meas_x": 3e-5 * math.cos(0.3 * t), "b_meas_y": 3e-5 * math.sin(0.3 * t), "b_meas_z": 1e-5},
    "Magnetometer": lambda t: {**_quat(t), "b_eci_x": 2e-5, "b_eci_y": -1e-5, "b_eci_z": 3e-5},
    "SunSensor": lambda t: {**_quat(t), "sun_eci_x": 0.0, "sun_eci_y": 0.0, "sun_eci_z": 1.0},
    "Mekf": lambda t: {**{f"w_meas_{c}": 0.01 * math.sin((i + 1) * t) for i, c in enumerate("xyz")},
                       **{k.replace("q_", "q_meas_"): v for k, v in _quat(t).items()}, "st_valid": 1.0},
}
PARAMS = {"SunSensor": {"environment_inputs": 1}}  # the sun direction from the input, not its own ephemeris
MIN_STEPS, MAX_STEPS = 200, 600


def fmi3(model: str) -> Path:
    return fmu_dir() / "fmi3" / f"{model}.fmu"


def clocked_models() -> list[str]:
    """The models whose FMI 3.0 description declares a clock, read from the archives with ElementTree."""
    out = []
    for p in sorted((fmu_dir() / "fmi3").glob("*.fmu")):
        with zipfile.ZipFile(p) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
        if root.find("ModelVariables/Clock") is not None:
            out.append(p.stem)
    return out


def test_the_sampled_units_are_clocked():
    """The ten sampled units of the issue declare clocks (else every test below would test nothing)."""
    assert set(clocked_models()) >= {"PidController", "FopidController", "SampleHold", "Gyro", "Magnetometer",
                                     "StarTracker", "SunSensor", "Mekf", "BDot", "ModeManager"}, clocked_models()


class Log(list):
    """fmpy's log callback (fmi3LogMessageCallback) keeping the messages."""

    def __call__(self, env, status, category, message):
        self.append(message.decode(errors="replace") if isinstance(message, bytes) else str(message))


def _open(model: str, fmi: int, tmp: Path, kind: str = "cs"):
    """fmpy's own object for the unit (unpacked by fmpy), its model description and a log."""
    path = fmi3(model) if fmi == 3 else fmu_dir() / f"{model}.fmu"
    md = read_model_description(str(path))
    d = extract(str(path), unzipdir=str(tmp / f"{model}{fmi}{kind}"))
    if fmi == 2:
        return FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                         instanceName=model), md, Log()
    cls, iface = (FMU3Slave, md.coSimulation) if kind == "cs" else (FMU3ScheduledExecution, md.scheduledExecution)
    assert iface is not None, f"{model}: no {kind} interface in the description"
    return cls(guid=md.guid, unzipDirectory=d, modelIdentifier=iface.modelIdentifier, instanceName=model), md, Log()


def _vars(md, names):
    by = {v.name: v for v in md.modelVariables}
    return [by[n] for n in names]


def _set(s, fmi, variables, values):
    for v, x in zip(variables, values):
        if v.type in ("Real", "Float64"):
            (s.setReal if fmi == 2 else s.setFloat64)([v.valueReference], [float(x)])
        elif v.type in ("Integer", "Int32"):
            (s.setInteger if fmi == 2 else s.setInt32)([v.valueReference], [int(x)])
        else:
            s.setBoolean([v.valueReference], [bool(x)])


def _get(s, fmi, variables):
    out = []
    for v in variables:
        if v.type in ("Real", "Float64"):
            out += (s.getReal if fmi == 2 else s.getFloat64)([v.valueReference])
        elif v.type in ("Integer", "Int32"):
            out += (s.getInteger if fmi == 2 else s.getInt32)([v.valueReference])
        else:
            out += [float(b) for b in s.getBoolean([v.valueReference])]
    return out


def outputs_of(md) -> list[str]:
    return [v.name for v in md.modelVariables if v.causality == "output" and v.type != "Clock"]


def clocks_of(md):
    return sorted((v for v in md.modelVariables if v.type == "Clock"), key=lambda v: v.valueReference)


def _timing(s, clocks):
    """(intervals, shifts, qualifiers of two calls) by fmi3GetIntervalDecimal / fmi3GetShiftDecimal."""
    n = len(clocks)
    vrs = (fmi3ValueReference * n)(*[c.valueReference for c in clocks])
    iv, sh = (fmi3Float64 * n)(), (fmi3Float64 * n)()
    q1, q2 = (fmi3IntervalQualifier * n)(), (fmi3IntervalQualifier * n)()
    s.getIntervalDecimal(vrs, iv, q1)
    s.getIntervalDecimal(vrs, (fmi3Float64 * n)(), q2)
    s.getShiftDecimal(vrs, sh)
    return list(iv), list(sh), list(q1), list(q2)


def grid(model: str, timing) -> tuple[float, int]:
    """The communication step (the smallest positive interval or shift: every tick lies on its grid) and the
    number of steps: MIN_STEPS, or three periods of the slowest clock if longer, at most MAX_STEPS."""
    iv, sh = timing[:2]
    h = min(x for x in iv + sh if x > 0)
    for x in iv + sh:
        assert abs(x / h - round(x / h)) < 1e-9, f"{model}: tick times {iv}, {sh} are not on one grid"
    return h, min(MAX_STEPS, max(MIN_STEPS, int(round(3 * max(iv) / h)) + 1))


def due(t: float, iv: float, sh: float) -> bool:
    k = round((t - sh) / iv)
    return k >= 0 and abs(t - (sh + k * iv)) <= 1e-9 * max(1.0, abs(t))


def next_tick(t: float, timing) -> float:
    return min(sh + (math.floor((t - sh) / iv + 1e-9) + 1) * iv if t >= sh - 1e-12 else sh
               for iv, sh in zip(*timing[:2]))


def sampled_run(model, tmp, params, inputs, h, n):
    """Today's sampled run: the FMI 2.0 FMU, fmpy's FMU2Slave: at t = k h set the inputs, read the outputs,
    step."""
    s, md, _ = _open(model, 2, tmp)
    s.instantiate()
    _set(s, 2, _vars(md, params), params.values())
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    _set(s, 2, _vars(md, inputs(0.0)), inputs(0.0).values())
    s.exitInitializationMode()
    outs = _vars(md, outputs_of(md))
    rows = []
    for k in range(n):
        u = inputs(k * h)
        _set(s, 2, _vars(md, u), u.values())
        rows.append(_get(s, 2, outs))
        s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
    s.terminate()
    s.freeInstance()
    return np.array(rows)


def clocked_cs_run(model, tmp, params, inputs, timing_only=False):
    """The clocked Co-Simulation run through fmpy's FMU3Slave with eventModeUsed = true. Returns (timing,
    step, rows, the nextEventTime of every update, the log)."""
    s, md, log = _open(model, 3, tmp)
    s.instantiate(eventModeUsed=True, logMessage=log)
    _set(s, 3, _vars(md, params), params.values())
    clocks = clocks_of(md)
    s.enterInitializationMode(startTime=0.0)
    _set(s, 3, _vars(md, inputs(0.0)), inputs(0.0).values())
    timing = _timing(s, clocks)
    s.exitInitializationMode()  # to Event Mode
    if timing_only:
        s.terminate()
        s.freeInstance()
        return timing, None, None, None, log
    h, n = grid(model, timing)
    outs = _vars(md, outputs_of(md))
    rows, nexts = [], []
    for k in range(n):
        t = k * h
        u = inputs(t)
        _set(s, 3, _vars(md, u), u.values())
        active = [c.valueReference for c, iv, sh in zip(clocks, *timing[:2]) if due(t, iv, sh)]
        if active:
            s.setClock(active, [True] * len(active))
        need, terminate, _, _, defined, t_next = s.updateDiscreteStates()
        assert not need and not terminate and defined, (model, t)
        nexts.append(t_next)
        rows.append(_get(s, 3, outs))
        s.enterStepMode()
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        s.enterEventMode()
    s.terminate()
    s.freeInstance()
    return timing, h, np.array(rows), nexts, log


def se_run(model, tmp, params, inputs, h, n):
    """Scheduled Execution through fmpy's FMU3ScheduledExecution: at each tick (in time order, a lower
    priority number first at the same instant) set the inputs, activate the partitions due, read the
    outputs. Returns (rows, the activations (t, clock name), the log)."""
    s, md, log = _open(model, 3, tmp, "se")
    s.instantiate(logMessage=log)
    _set(s, 3, _vars(md, params), params.values())
    clocks = clocks_of(md)
    s.enterInitializationMode(startTime=0.0)
    _set(s, 3, _vars(md, inputs(0.0)), inputs(0.0).values())
    timing = _timing(s, clocks)
    s.exitInitializationMode()  # to Clock Activation Mode
    outs = _vars(md, outputs_of(md))
    rows, acts = [], []
    for k in range(n):
        t = k * h
        u = inputs(t)
        _set(s, 3, _vars(md, u), u.values())
        for c, iv, sh in sorted(zip(clocks, *timing[:2]), key=lambda x: int(x[0].priority or x[0].valueReference)):
            if due(t, iv, sh):
                s.activateModelPartition(c.valueReference, t)
                acts.append((t, c.name))
        rows.append(_get(s, 3, outs))
    s.terminate()
    s.freeInstance()
    return np.array(rows), acts, log


def _case(model):
    params, inputs, _ = CASES.get(model, (PARAMS.get(model, {}), INPUTS.get(model, lambda t: {}), None))
    return params, inputs


def _same(model, names, a, b, what):
    bad = [n for j, n in enumerate(names) if not np.array_equal(a[:, j], b[:, j])]
    assert not bad, f"{model}: {what} differs from the sampled FMI 2.0 run in {bad}"


@pytest.mark.parametrize("model", list(CASES))
def test_intervals_and_shifts_are_the_documented_sampling(model, tmp_path):
    timing, *_ = clocked_cs_run(model, tmp_path, CASES[model][0], CASES[model][1], timing_only=True)
    iv, sh, q1, q2 = timing
    assert list(zip(iv, sh)) == CASES[model][2]
    assert q1 == [fmi3IntervalChanged] * len(iv) and q2 == [fmi3IntervalUnchanged] * len(iv)


@pytest.mark.parametrize("model", clocked_models())
def test_fmpy_clocked_co_simulation_equals_the_sampled_run(model, tmp_path):
    params, inputs = _case(model)
    timing, h, rows, nexts, log = clocked_cs_run(model, tmp_path, params, inputs)
    ref = sampled_run(model, tmp_path, params, inputs, h, len(rows))
    md = read_model_description(str(fmi3(model)))
    _same(model, outputs_of(md), rows, ref, "fmpy's clocked Co-Simulation")
    want = [next_tick(k * h, timing) for k in range(len(rows))]
    np.testing.assert_allclose(nexts, want, rtol=1e-12, atol=1e-12, err_msg=f"{model}: nextEventTime")
    assert rows.shape[0] >= MIN_STEPS and not any("rror" in m for m in log), log
    assert any(np.ptp(rows[:, j]) > 0 for j in range(rows.shape[1])), f"{model}: every output is constant"


@pytest.mark.parametrize("model", clocked_models())
def test_fmpy_scheduled_execution_equals_the_sampled_run(model, tmp_path):
    params, inputs = _case(model)
    timing, *_ = clocked_cs_run(model, tmp_path, params, inputs, timing_only=True)
    h, n = grid(model, timing)
    rows, acts, log = se_run(model, tmp_path, params, inputs, h, n)
    ref = sampled_run(model, tmp_path, params, inputs, h, n)
    md = read_model_description(str(fmi3(model)))
    _same(model, outputs_of(md), rows, ref, "fmpy's Scheduled Execution")
    assert len(acts) >= n and not any("rror" in m for m in log), log


def test_star_tracker_activations_in_scheduled_execution(tmp_path):
    """The schedule of the star tracker (0.2 s, delivered 0.1 s later): the sample partition at 0, 0.2, 0.4,
    ..., the delivery partition at 0.1, 0.3, ...: fmi3ActivateModelPartition refuses any other time."""
    params, inputs, _ = CASES["StarTracker"]
    _, acts, _ = se_run("StarTracker", tmp_path, params, inputs, 0.1, 11)
    assert [(round(t, 12), c) for t, c in acts] == [(round(0.1 * k, 12), "sample_clock" if k % 2 == 0 else
                                                     "delivery_clock") for k in range(11)]
    s, md, log = _open("StarTracker", 3, tmp_path / "x", "se")
    s.instantiate(logMessage=log)
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    sample = clocks_of(md)[0]
    with pytest.raises(Exception):
        s.activateModelPartition(sample.valueReference, 0.1)  # not a tick of the sample clock
    assert any("sample_clock" in m for m in log), log
    s.freeInstance()


# ----- what fmpy.simulate_fmu does with a clocked unit (docs/tools.md) ------------------------------------------

def test_simulate_fmu_without_event_mode_runs_the_unit_sampled():
    """fmpy's default FMI 3.0 Co-Simulation (eventModeUsed = false): the unit runs sampled inside doStep,
    the same results as the FMI 2.0 FMU."""
    a = simulate_fmu(str(fmi3("Gyro")), stop_time=1.0, output_interval=0.01)
    b = simulate_fmu(str(fmu_dir() / "Gyro.fmu"), stop_time=1.0, output_interval=0.01)
    for n in b.dtype.names:
        np.testing.assert_array_equal(a[n], b[n], err_msg=n)
    assert np.ptp(a["w_meas_x"]) > 0


def test_simulate_fmu_with_event_mode_never_sets_a_clock():
    """fmpy's use_event_mode=True: fmpy updates the discrete states after initialization and then steps, but
    it calls fmi3SetClock nowhere, so the tick at the start time is never activated and the unit refuses
    the step that would pass it (fmi3Error, a message naming the clock)."""
    log = Log()
    with pytest.raises(Exception) as e:
        simulate_fmu(str(fmi3("Gyro")), stop_time=1.0, output_interval=0.01, use_event_mode=True, logger=log)
    assert "doStep" in str(e.value) or "DoStep" in str(e.value) or any("sample_clock" in m for m in log), \
        (str(e.value), log)


def test_simulate_fmu_refuses_scheduled_execution():
    """fmpy 0.3.32's simulate_fmu simulates Model Exchange and Co-Simulation only: fmi_type
    'ScheduledExecution' is refused before the FMU is loaded (its FMU3ScheduledExecution class is there for a
    master of one's own, as above)."""
    with pytest.raises(Exception, match='fmi_type must be one of "ModelExchange" or "CoSimulation"'):
        simulate_fmu(str(fmi3("Gyro")), fmi_type="ScheduledExecution", stop_time=1.0)


def test_scheduled_execution_of_an_unclocked_unit_is_refused(tmp_path):
    """A unit without clocks has no <ScheduledExecution>: fmi3InstantiateScheduledExecution gives NULL."""
    path = fmi3("PdController")
    md = read_model_description(str(path))
    assert md.scheduledExecution is None
    s = FMU3ScheduledExecution(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp_path / "pd")),
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName="pd")
    log = Log()
    with pytest.raises(Exception, match="Failed to instantiate"):
        s.instantiate(logMessage=log)
    assert any("InstantiateScheduledExecution" in m for m in log), log


# ----- terminals: what an external tool reads of terminalsAndIcons.xml ------------------------------------------

def _terminal_files() -> dict:
    out = {}
    for p in sorted((fmu_dir() / "fmi3").glob("*.fmu")):
        with zipfile.ZipFile(p) as z:
            if "terminalsAndIcons/terminalsAndIcons.xml" in z.namelist():
                out[p.stem] = (z.read("terminalsAndIcons/terminalsAndIcons.xml"), z.read("modelDescription.xml"))
    return out


def test_fmpy_has_no_terminals_reader_only_the_schema():
    """fmpy 0.3.32 reads no terminalsAndIcons.xml (read_model_description and validate_fmu ignore it); it ships
    the standard's schema for it, which is what an fmpy user can check a file against."""
    import fmpy
    root = Path(fmpy.__file__).parent
    assert (root / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd").is_file()
    assert not [p.name for p in root.glob("*.py") if "terminalsAndIcons" in p.read_text(errors="replace")]


@pytest.mark.skipif(not _terminal_files(), reason="no FMU carries terminalsAndIcons/terminalsAndIcons.xml yet")
def test_terminals_pass_the_schema_fmpy_ships():
    """Every terminalsAndIcons.xml in our FMI 3.0 FMUs is valid against fmpy's copy of the standard's schema,
    and every terminal member names a variable of the unit's description."""
    import fmpy
    from lxml import etree
    xsd = etree.XMLSchema(file=str(Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd"))
    for model, (text, md) in _terminal_files().items():
        doc = etree.fromstring(text)
        assert xsd.validate(doc), (model, [e.message for e in xsd.error_log][:3])
        names = {e.get("name") for e in ET.fromstring(md).find("ModelVariables")}
        members = [m.get("variableName") for m in doc.iter("TerminalMemberVariable")]
        assert members and set(members) <= names, (model, set(members) - names)
    text = next(iter(_terminal_files().values()))[0]  # the check fails on a broken file (a required attribute gone)
    assert not xsd.validate(etree.fromstring(text.replace(b' matchingRule="', b' matching="', 1)))


# ----- the schedule figure's script (docs/fmi3.md) ---------------------------------------------------------------

def test_schedule_script_logs_the_ticks_of_a_real_scheduled_execution_run(tmp_path):
    """scripts/schedule_figure.py over 0.25 s: the PID activated every 1 ms (251 times from 0 to 0.25 s), the
    gyro every 10 ms (26), the star tracker's sample at 0 and 0.2 s and its delivery at 0.1 s, in time order;
    the figure is written."""
    import csv
    import subprocess
    import sys
    root = Path(__file__).resolve().parents[1]
    r = subprocess.run([sys.executable, str(root / "scripts" / "schedule_figure.py"), "--t-end", "0.25", "--out",
                        str(tmp_path / "s.png"), "--log", str(tmp_path / "s.csv")], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    rows = list(csv.DictReader(open(tmp_path / "s.csv")))
    by = {}
    for row in rows:
        by.setdefault((row["unit"], row["clock"]), []).append(float(row["time_s"]))
    assert len(by[("pid", "sample_clock")]) == 251 and len(by[("gyro", "sample_clock")]) == 26
    np.testing.assert_allclose(by[("pid", "sample_clock")], np.arange(251) * 0.001, rtol=0, atol=1e-12)
    assert by[("star_tracker", "sample_clock")] == pytest.approx([0.0, 0.2])
    assert by[("star_tracker", "delivery_clock")] == pytest.approx([0.1])
    times = [float(row["time_s"]) for row in rows]
    assert times == sorted(times)
    assert (tmp_path / "s.png").stat().st_size > 10_000
