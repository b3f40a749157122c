"""Inputs that are not yet consistent in Initialization Mode (issue 45 item 7).

OMSimulator initialises a subsystem by giving every connected input its connector's default 0 and reading
the units' outputs before the values flow. A controller then sees the quaternion [0, 0, 0, 0]; it used to
answer fmi2GetReal with fmi2Error ("input quaternion q has norm 0"), and OMSimulator ended the run in
Initialization Mode. The rule now (scfmu's FMI layer, every unit): in Initialization Mode outputs that the
inputs set so far do not allow keep their previous values and the call returns a warning that names the
reason; once the instance has left Initialization Mode the same inputs are refused with an error.
"""

from __future__ import annotations

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from me_master import MeLoop
from scfmu import scenario as scenarios
from scfmu.fmu import fmu_dir, fmu_path, models, recording_callbacks, unpacked

WARNING, ERROR = 1, 3


def _slave(path, messages):
    md, d = unpacked(path)
    if md.fmiVersion.startswith("3"):
        u = FMU3Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="u")
        u.instantiate(loggingOn=True, logMessage=_log3(messages))
    else:
        u = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="u")
        u.instantiate(callbacks=recording_callbacks(messages), loggingOn=True)
    return md, u


def _log3(messages):
    def log(env, status, category, message):
        messages.append((status, category.decode() if category else "", message.decode() if message else ""))
    return log


def _set_inputs_zero_and_read(md, u):
    reals = [v for v in md.modelVariables if v.type in ("Real", "Float64")]
    ins = [v.valueReference for v in reals if v.causality == "input"]
    outs = [v.valueReference for v in reals if v.causality == "output"]
    v3 = md.fmiVersion.startswith("3")
    if ins:
        (u.setFloat64 if v3 else u.setReal)(ins, [0.0] * len(ins))
    return outs, (lambda: (u.getFloat64 if v3 else u.getReal)(outs))


def _units():
    out = []
    for m in models():
        out.append(pytest.param(fmu_path(m), id=f"fmi2-{m}"))
        p3 = fmu_dir() / "fmi3" / f"{m}.fmu"
        if p3.is_file():
            out.append(pytest.param(p3, id=f"fmi3-{m}"))
    return out


@pytest.mark.parametrize("path", _units())
def test_every_unit_reads_its_outputs_with_zero_inputs_in_initialization_mode(path):
    """Every unit, FMI 2.0 and 3.0: in Initialization Mode, with every Real input 0 (the connector default),
    reading every output returns OK or a warning with finite values, never an error; a warning names why."""
    messages = []
    md, u = _slave(str(path), messages)
    if md.coSimulation is None:
        pytest.skip("no Co-Simulation interface")
    try:
        v3 = md.fmiVersion.startswith("3")
        if v3:
            u.enterInitializationMode(startTime=0.0)
        else:
            u.setupExperiment(startTime=0.0)
            u.enterInitializationMode()
        outs, read = _set_inputs_zero_and_read(md, u)
        if not outs:
            pytest.skip("no Real outputs")
        values = read()  # fmpy raises for a status worse than a warning
        assert np.all(np.isfinite(values))
        worse = [m for m in messages if m[0] >= ERROR]
        assert not worse, worse
        for status, _, text in messages:
            if status == WARNING:
                assert "Initialization Mode" in text and "inputs set so far" in text, text
    finally:
        u.freeInstance()


def _pd_in_initialization(messages):
    """A PdController (FMI 2.0 CS) in Initialization Mode with the quaternion input [0, 0, 0, 0]; (unit,
    value references by name)."""
    md, u = _slave(str(fmu_path("PdController")), messages)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    u.setupExperiment(startTime=0.0)
    u.enterInitializationMode()
    u.setReal([vr[k] for k in ("q_w", "q_x", "q_y", "q_z")], [0.0] * 4)
    return u, vr


def test_a_controller_warns_in_initialization_and_refuses_after_it():
    messages = []
    u, vr = _pd_in_initialization(messages)
    torque = [vr[k] for k in ("torque_cmd_x", "torque_cmd_y", "torque_cmd_z")]
    try:
        assert u.getReal(torque) == [0.0, 0.0, 0.0]  # the start values, kept
        assert messages[-1][0] == WARNING and "fmi2GetReal" in messages[-1][2] and "norm 0" in messages[-1][2]
        u.exitInitializationMode()  # still inconsistent: a warning, the instance leaves initialization
        assert messages[-1][0] == WARNING and "fmi2ExitInitializationMode" in messages[-1][2]
        with pytest.raises(FMICallException):  # out of Initialization Mode: refused
            u.getReal(torque)
        assert messages[-1][0] == ERROR and "norm 0" in messages[-1][2]
    finally:
        u.freeInstance()


def test_consistent_inputs_after_a_warning_compute_the_outputs():
    """After the warning, the inputs the loop then sets are used: the torque equals a PD law's."""
    messages = []
    u, vr = _pd_in_initialization(messages)
    try:
        u.getReal([vr["torque_cmd_x"]])
        c, s = np.cos(0.05), np.sin(0.05)  # 0.1 rad about x
        u.setReal([vr[k] for k in ("q_w", "q_x", "q_y", "q_z")], [c, s, 0.0, 0.0])
        u.exitInitializationMode()
        tx = u.getReal([vr["torque_cmd_x"]])[0]
        assert messages[-1][0] == WARNING  # the one from the first read; nothing since
        assert tx < 0 and np.isfinite(tx)  # a restoring torque about x
    finally:
        u.freeInstance()


def test_a_loop_initialised_with_connector_defaults_runs_as_one_initialised_in_order():
    """The whole default loop initialised the OMSimulator way (connected inputs 0, outputs read first) runs
    to the end bit for bit like the same loop initialised in order; the controller warned on the way."""
    sc = scenarios.get("default", stop_time=0.5)
    logs: dict = {}
    log = [("plant", k) for k in ("q_w", "q_x", "q_y", "q_z", "w_x")]
    ordered, defaults = MeLoop(sc), MeLoop(sc, connector_defaults=True,
                                           callbacks=lambda n: recording_callbacks(logs.setdefault(n, [])))
    try:
        a = np.array(ordered.run(0.5, 1e-3, "rk4", log=log))
        b = np.array(defaults.run(0.5, 1e-3, "rk4", log=log))
    finally:
        ordered.close()
        defaults.close()
    assert np.array_equal(a, b)
    assert np.ptp(a[:, 1:]) > 0.01  # the loop moves
    warned = [m for m in logs["controller"] if m[0] == WARNING]
    assert warned and "Initialization Mode" in warned[0][2], logs["controller"]
    assert not [m for ms in logs.values() for m in ms if m[0] >= ERROR]

