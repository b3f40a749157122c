"""Bad input on the FMI 3.0 entry points never crashes the host: each case calls the C functions through
fmpy's FMI 3.0 ctypes bindings with a wrong argument or in a wrong state and checks the status the FMI 3.0
standard prescribes (fmi3Error; the instance then is in Terminated, from which fmi3Reset recovers) and a
log message naming the function and the reason."""

from __future__ import annotations

import math
from ctypes import POINTER, byref, c_double, c_size_t, c_uint8, c_void_p, cast
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float32, fmi3Float64, fmi3Int32, fmi3ValueReference

from test_fmi_bad_input import ERROR, OK, status  # statuses and the raw-call status helper

ROOT = Path(__file__).resolve().parents[1]
TIME_VR = 2147483647


def vrs(*v):
    return (fmi3ValueReference * len(v))(*v)


def f64(*v):
    return (fmi3Float64 * len(v))(*v)


class Fmu3:
    """One FMI 3.0 instance with a recording logger."""

    def __init__(self, tmp: Path, model: str = "AttitudePlant", token: str | None = None, event_mode: bool = False):
        path = str(ROOT / "fmus" / "fmi3" / f"{model}.fmu")
        self.md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.messages: list[tuple[int, str, str]] = []
        d = extract(path, unzipdir=str(tmp / model))
        self.s = FMU3Slave(guid=token or self.md.guid, unzipDirectory=d, modelIdentifier=model, instanceName="bad")

        def log(env, st, category, message):
            self.messages.append((st, category.decode(), message.decode()))

        self.error = None
        try:
            self.s.instantiate(logMessage=log, eventModeUsed=event_mode)
        except Exception as e:  # fmpy raises when the instance pointer is NULL
            self.error = e
        self.c = self.s.component

    def last(self) -> str:
        return self.messages[-1][2] if self.messages else ""

    def init(self):
        self.s.enterInitializationMode(startTime=0.0)
        self.s.exitInitializationMode()

    def close(self):
        if self.c:
            self.s.fmi3FreeInstance(self.c)
        self.s.freeLibrary()


@pytest.fixture
def fmu(tmp_path):
    f = Fmu3(tmp_path)
    yield f
    f.close()


def step(f: Fmu3, t: float, h: float) -> int:
    ev, term, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
    return status(f.s.fmi3DoStep, f.c, t, h, fmi3Boolean(True), byref(ev), byref(term), byref(early), byref(last))


def test_null_instance_is_an_error(fmu):
    assert status(fmu.s.fmi3DoStep, None, 0.0, 0.1, fmi3Boolean(True), None, None, None, None) == ERROR
    assert status(fmu.s.fmi3GetFloat64, None, vrs(14), 1, f64(0.0), 1) == ERROR
    assert status(fmu.s.fmi3EnterInitializationMode, None, fmi3Boolean(False), 0.0, 0.0, fmi3Boolean(False), 0.0) == ERROR
    fmu.s.fmi3FreeInstance(None)  # ignored
    foreign = cast(byref(c_double(1.0)), c_void_p)
    assert status(fmu.s.fmi3Terminate, foreign) == ERROR


def test_wrong_state_errors_terminates_and_reset_recovers(fmu):
    assert step(fmu, 0.0, 0.1) == ERROR
    assert "fmi3DoStep" in fmu.last() and "not allowed in state Instantiated" in fmu.last()
    # fmi3Error -> Terminated (FMI 3.0, 2.3.1): initialization is refused until fmi3Reset
    assert status(fmu.s.fmi3EnterInitializationMode, fmu.c, fmi3Boolean(False), 0.0, 0.0, fmi3Boolean(False), 0.0) == ERROR
    assert "fmi3EnterInitializationMode" in fmu.last() and "Terminated" in fmu.last()
    assert status(fmu.s.fmi3Reset, fmu.c) == OK
    fmu.init()
    assert step(fmu, 0.0, 0.1) == OK
    assert status(fmu.s.fmi3ExitInitializationMode, fmu.c) == ERROR
    assert "fmi3ExitInitializationMode" in fmu.last() and "Step Mode" in fmu.last()


def test_nan_input_is_refused(fmu):
    fmu.init()
    assert status(fmu.s.fmi3SetFloat64, fmu.c, vrs(fmu.vr["torque_cmd_x"]), 1, f64(math.nan), 1) == ERROR
    assert "fmi3SetFloat64" in fmu.last() and "torque_cmd_x" in fmu.last() and "not finite" in fmu.last()


def test_negative_and_mismatched_steps_are_refused(fmu):
    fmu.init()
    assert step(fmu, 0.0, -0.1) == ERROR
    assert "fmi3DoStep" in fmu.last() and "communicationStepSize -0.1" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    fmu.init()
    assert step(fmu, 5.0, 0.1) == ERROR
    assert "fmi3DoStep" in fmu.last() and "currentCommunicationPoint 5" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    fmu.init()
    assert step(fmu, 0.0, math.inf) == ERROR


def test_do_step_null_out_pointers_and_last_successful_time(fmu):
    fmu.init()
    assert status(fmu.s.fmi3DoStep, fmu.c, 0.0, 0.1, fmi3Boolean(True), None, None, None, None) == ERROR
    assert "fmi3DoStep" in fmu.last() and "eventHandlingNeeded is NULL" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    fmu.init()
    ev, term, early, last = fmi3Boolean(True), fmi3Boolean(True), fmi3Boolean(True), fmi3Float64()
    assert status(fmu.s.fmi3DoStep, fmu.c, 0.0, 0.25, fmi3Boolean(False), byref(ev), byref(term), byref(early), byref(last)) == OK
    assert (ev.value, term.value, early.value, last.value) == (False, False, False, 0.25)


def test_wrong_instantiation_token(tmp_path):
    f = Fmu3(tmp_path, token="{00000000-0000-0000-0000-000000000000}")
    try:
        assert not f.c and f.error is not None
        assert f.messages and f.messages[-1][0] == ERROR
        assert "fmi3InstantiateCoSimulation" in f.last() and "instantiationToken" in f.last() and "AttitudePlant" in f.last()
    finally:
        f.close()


def test_event_mode_is_refused(tmp_path):
    f = Fmu3(tmp_path, event_mode=True)
    try:
        assert not f.c
        assert "fmi3InstantiateCoSimulation" in f.last() and "eventModeUsed" in f.last()
    finally:
        f.close()


def test_time_is_readable_not_settable(fmu):
    fmu.init()
    assert step(fmu, 0.0, 0.5) == OK
    out = f64(0.0, 0.0)
    assert status(fmu.s.fmi3GetFloat64, fmu.c, vrs(TIME_VR, fmu.vr["w_x"]), 2, out, 2) == OK
    assert out[0] == 0.5
    assert status(fmu.s.fmi3SetFloat64, fmu.c, vrs(TIME_VR), 1, f64(1.0), 1) == ERROR
    assert "fmi3SetFloat64" in fmu.last() and "independent" in fmu.last()


def test_counts_types_and_booleans(fmu):
    assert status(fmu.s.fmi3SetFloat64, fmu.c, vrs(113, 114), 2, f64(0.1), 1) == ERROR
    assert "fmi3SetFloat64" in fmu.last() and "nValues = 1" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    x = (fmi3Float32 * 1)()
    assert status(fmu.s.fmi3SetFloat32, fmu.c, vrs(113), 1, x, 1) == ERROR
    assert "fmi3SetFloat32" in fmu.last() and "no variables of type Float32" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    # no model declares a Boolean (switches are Int32): fmi3SetBoolean on one names the variable and its type
    b = (c_uint8 * 1)(2)
    assert status(fmu.s.fmi3SetBoolean, fmu.c, vrs(fmu.vr["mtq_enable"]), 1, cast(b, POINTER(fmi3Boolean)), 1) == ERROR
    assert "fmi3SetBoolean" in fmu.last() and "mtq_enable" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    assert status(fmu.s.fmi3SetBoolean, fmu.c, vrs(), 0, cast(b, POINTER(fmi3Boolean)), 0) == OK
    i = (fmi3Int32 * 1)(1)
    assert status(fmu.s.fmi3SetInt32, fmu.c, vrs(fmu.vr["mtq_enable"]), 1, i, 1) == OK
    fmu.s.fmi3EnterInitializationMode(fmu.c, fmi3Boolean(False), 0.0, 0.0, fmi3Boolean(False), 0.0)
    i[0] = 7
    assert status(fmu.s.fmi3GetInt32, fmu.c, vrs(fmu.vr["mtq_enable"]), 1, i, 1) == OK
    assert i[0] == 1


def test_unsupported_functions_error_with_reason(fmu):
    fmu.init()
    assert status(fmu.s.fmi3EnterEventMode, fmu.c) == ERROR and "hasEventMode = false" in fmu.last()
    assert status(fmu.s.fmi3EnterConfigurationMode, fmu.c) == ERROR and "fmi3EnterConfigurationMode" in fmu.last()
    fmu.s.fmi3Reset(fmu.c)
    n = c_size_t(99)
    assert status(fmu.s.fmi3GetNumberOfVariableDependencies, fmu.c, fmu.vr["w_x"], byref(n)) == OK
    # AttitudePlant: no direct feed-through from an input; with Model Exchange its outputs depend on its 18
    # continuous states, the list <Output dependencies> of the description gives too
    out = next(u for u in fmu.md.outputs if u.variable.name == "w_x")
    assert n.value == 18 == len(out.dependencies)
    assert all(v.causality == "local" and v.name.startswith("state_") for v in out.dependencies)


def test_fmu_state_round_trip(fmu):
    fmu.init()
    for k in range(3):
        fmu.s.setFloat64([fmu.vr["torque_cmd_x"]], [0.01])
        assert step(fmu, 0.1 * k, 0.1) == OK
    state = fmu.s.getFMUState()
    blob = fmu.s.serializeFMUState(state)
    assert step(fmu, 0.3, 0.1) == OK
    after = fmu.s.getFloat64([fmu.vr["w_x"], TIME_VR])
    restored = fmu.s.deserializeFMUState(blob)
    fmu.s.setFMUState(restored)
    assert fmu.s.getFloat64([TIME_VR]) == [pytest.approx(0.3)]
    assert step(fmu, fmu.s.getFloat64([TIME_VR])[0], 0.1) == OK
    assert fmu.s.getFloat64([fmu.vr["w_x"], TIME_VR]) == after
    fmu.s.freeFMUState(state)
    fmu.s.freeFMUState(restored)
    bad = bytearray(blob)
    bad[-1] ^= 0xFF
    with pytest.raises(FMICallException):
        fmu.s.deserializeFMUState(bytes(bad))
    assert "fmi3DeserializeFMUState" in fmu.last()
