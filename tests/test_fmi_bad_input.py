"""Bad input never crashes the host: each case calls the FMU's C functions (through fmpy's ctypes
bindings) with a wrong argument or in a wrong state, asserts the status the FMI 2.0 standard
prescribes and a logger message naming the function, then checks that the Python process and,
where FMI allows, the instance are still usable."""

from __future__ import annotations

import ctypes
import math
from ctypes import byref, c_char, c_int, c_size_t, c_void_p

import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Real, fmi2ValueReference

from scfmu.fmu import Fmu

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4


def status(fn, *args) -> int:
    """Status of a raw FMI call (fmpy raises for status > warning)."""
    try:
        r = fn(*args)
        return int(r) if r is not None else OK
    except FMICallException as e:
        return e.status


def vrs(*v):
    return (fmi2ValueReference * len(v))(*v)


def reals(*v):
    return (fmi2Real * len(v))(*v)


def last(f: Fmu) -> str:
    return f.messages[-1][2] if f.messages else ""


def usable(f: Fmu) -> None:
    """The instance still answers: outputs readable and one step possible."""
    out = f.outputs()[0]
    assert math.isfinite(f.get(out))
    f.do_step(f.time, 0.01)


@pytest.fixture
def plant():
    f = Fmu("AttitudePlant", {"init_w_x": 0.01})
    yield f
    f.close()


@pytest.fixture
def ctrl():
    f = Fmu("PdController")
    yield f
    f.close()


@pytest.fixture
def fresh():
    """Instantiated, not initialized."""
    f = Fmu("AttitudePlant", initialize=False)
    yield f
    f.close()


def vr(f: Fmu, name: str) -> int:
    return f.var(name).valueReference


# ----- arrays and value references ------------------------------------------------------------

def test_get_real_null_vr_array(plant):
    assert status(plant.slave.fmi2GetReal, plant.slave.component, None, 1, reals(0.0)) == ERROR
    assert "fmi2GetReal" in last(plant) and "vr[]" in last(plant)
    usable(plant)


def test_get_real_null_value_array(plant):
    assert status(plant.slave.fmi2GetReal, plant.slave.component, vrs(vr(plant, "q_w")), 1, None) == ERROR
    assert "value[]" in last(plant)
    usable(plant)


def test_set_real_null_vr_array(plant):
    assert status(plant.slave.fmi2SetReal, plant.slave.component, None, 2, reals(1.0, 2.0)) == ERROR
    usable(plant)


def test_set_real_null_value_array(plant):
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(0), 1, None) == ERROR
    usable(plant)


def test_zero_length_with_null_arrays_is_fine(plant):
    assert status(plant.slave.fmi2GetReal, plant.slave.component, None, 0, None) == OK
    assert status(plant.slave.fmi2SetReal, plant.slave.component, None, 0, None) == OK


def test_impossible_length(plant):
    n = 1 << 62
    assert status(plant.slave.fmi2GetReal, plant.slave.component, vrs(0), n, reals(0.0)) == ERROR
    assert "impossible" in last(plant)
    usable(plant)


def test_unknown_value_reference_get(plant):
    assert status(plant.slave.fmi2GetReal, plant.slave.component, vrs(9999), 1, reals(0.0)) == ERROR
    assert "unknown Real value reference 9999" in last(plant)
    usable(plant)


def test_unknown_value_reference_set(plant):
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(9999), 1, reals(1.0)) == ERROR
    usable(plant)


def test_type_mismatch_integer_on_real(plant):
    v = (c_int * 1)()
    assert status(plant.slave.fmi2GetInteger, plant.slave.component, vrs(vr(plant, "q_w")), 1, v) == ERROR
    assert "is q_w (Real), not Integer" in last(plant)
    usable(plant)


def test_string_access_has_no_variables(plant):
    v = (ctypes.c_char_p * 1)()
    assert status(plant.slave.fmi2GetString, plant.slave.component, vrs(0), 1, v) == ERROR
    usable(plant)


# ----- non-finite and illegal values ----------------------------------------------------------------

@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_input_refused_and_value_kept(plant, bad):
    plant.set("torque_cmd_x", 2.0)
    r = vr(plant, "torque_cmd_x")
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(r), 1, reals(bad)) == ERROR
    assert "not finite" in last(plant)
    assert plant.get("torque_applied_x") == 2.0, "refused call must not change the input"
    usable(plant)


def test_refused_set_is_atomic(plant):
    a, b = vr(plant, "torque_cmd_x"), vr(plant, "torque_cmd_y")
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(a, b), 2, reals(5.0, math.nan)) == ERROR
    assert plant.get("torque_applied_x") == 0.0, "first value of a refused call must not be applied"


def test_set_output_refused(plant):
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(vr(plant, "q_w")), 1, reals(0.5)) == ERROR
    assert "output" in last(plant)
    usable(plant)


def test_set_fixed_parameter_after_initialization_refused(plant):
    assert status(plant.slave.fmi2SetReal, plant.slave.component, vrs(vr(plant, "inertia_xx")), 1, reals(10.0)) == ERROR
    assert "fixed" in last(plant)
    usable(plant)


def test_set_calculated_parameter_refused(ctrl):
    assert status(ctrl.slave.fmi2SetReal, ctrl.slave.component, vrs(vr(ctrl, "k_x")), 1, reals(1.0)) == ERROR
    assert "calculated parameter" in last(ctrl)


def test_invalid_parameter_gives_error_at_exit_and_can_be_fixed(fresh):
    s = fresh.slave
    s.setupExperiment()
    s.enterInitializationMode()
    fresh.set("inertia_xy", 5000.0)  # not positive definite with diag(1000, 500, 700)
    assert status(s.fmi2ExitInitializationMode, s.component) == ERROR
    assert "fmi2ExitInitializationMode" in last(fresh) and "positive definite" in last(fresh)
    fresh.set("inertia_xy", 10.0)
    assert status(s.fmi2ExitInitializationMode, s.component) == OK
    usable(fresh)


def test_unknown_enumeration_value(fresh):
    s = fresh.slave
    s.setupExperiment()
    s.enterInitializationMode()
    fresh.set("integrator", 7)
    assert status(s.fmi2ExitInitializationMode, s.component) == ERROR
    assert "integrator = 7" in last(fresh)


def test_negative_limit_parameter(fresh):
    s = fresh.slave
    s.setupExperiment()
    s.enterInitializationMode()
    fresh.set("u_max_x", -1.0)
    assert status(s.fmi2ExitInitializationMode, s.component) == ERROR
    assert "u_max_x" in last(fresh)


def test_controller_with_unconnected_quaternion(ctrl):
    ctrl.set_reals(["q_w", "q_x", "q_y", "q_z"], [0.0, 0.0, 0.0, 0.0])
    assert status(ctrl.slave.fmi2GetReal, ctrl.slave.component, vrs(vr(ctrl, "torque_cmd_x")), 1, reals(0.0)) == ERROR
    assert "norm" in last(ctrl)
    ctrl.set("q_w", 1.0)
    assert ctrl.get("torque_cmd_x") == 0.0


# ----- stepping ------------------------------------------------------------------------------

@pytest.mark.parametrize("h", [0.0, -0.01, math.nan, math.inf])
def test_bad_step_size(plant, h):
    assert status(plant.slave.fmi2DoStep, plant.slave.component, 0.0, h, 1) == ERROR
    assert "communicationStepSize" in last(plant)
    usable(plant)


def test_communication_point_mismatch(plant):
    assert status(plant.slave.fmi2DoStep, plant.slave.component, 5.0, 0.01, 1) == ERROR
    assert "does not match the FMU time" in last(plant)
    usable(plant)


def test_step_beyond_stop_time():
    f = Fmu("AttitudePlant", stop_time=0.05)
    try:
        assert status(f.slave.fmi2DoStep, f.slave.component, 0.0, 0.1, 1) == ERROR
        assert "stopTime" in last(f)
        f.do_step(0.0, 0.05)
    finally:
        f.close()


# ----- state machine ---------------------------------------------------------------------------

def test_do_step_before_initialization(fresh):
    assert status(fresh.slave.fmi2DoStep, fresh.slave.component, 0.0, 0.01, 1) == ERROR
    assert "fmi2DoStep" in last(fresh) and "Instantiated" in last(fresh)


def test_get_real_before_initialization(fresh):
    assert status(fresh.slave.fmi2GetReal, fresh.slave.component, vrs(vr(fresh, "q_w")), 1, reals(0.0)) == ERROR


def test_exit_without_enter(fresh):
    assert status(fresh.slave.fmi2ExitInitializationMode, fresh.slave.component) == ERROR
    fresh.slave.enterInitializationMode()
    fresh.slave.exitInitializationMode()
    usable(fresh)


def test_enter_twice(fresh):
    fresh.slave.enterInitializationMode()
    assert status(fresh.slave.fmi2EnterInitializationMode, fresh.slave.component) == ERROR
    fresh.slave.exitInitializationMode()
    usable(fresh)


def test_setup_experiment_after_initialization(plant):
    assert status(plant.slave.fmi2SetupExperiment, plant.slave.component, 0, 0.0, 0.0, 0, 0.0) == ERROR
    usable(plant)


def test_non_finite_start_time(fresh):
    assert status(fresh.slave.fmi2SetupExperiment, fresh.slave.component, 0, 0.0, math.nan, 0, 0.0) == ERROR


def test_step_after_terminate_then_reset(plant):
    plant.slave.terminate()
    assert status(plant.slave.fmi2DoStep, plant.slave.component, plant.time, 0.01, 1) == ERROR
    assert "Terminated" in last(plant)
    plant.slave.reset()
    plant.slave.setupExperiment(startTime=0.0)
    plant.slave.enterInitializationMode()
    plant.slave.exitInitializationMode()
    plant.time = 0.0
    usable(plant)


def test_unsupported_functions(plant):
    s = plant.slave
    order = (c_int * 1)(1)
    assert status(s.fmi2SetRealInputDerivatives, s.component, vrs(0), 1, order, reals(1.0)) == ERROR
    assert "canInterpolateInputs" in last(plant)
    assert status(s.fmi2GetRealOutputDerivatives, s.component, vrs(10), 1, order, reals(0.0)) == ERROR
    assert status(s.fmi2CancelStep, s.component) == ERROR
    usable(plant)


def test_status_queries(plant):
    plant.do_step(0.0, 0.25)
    s = plant.slave
    v = fmi2Real()
    assert status(s.fmi2GetRealStatus, s.component, 2, byref(v)) == OK  # fmi2LastSuccessfulTime
    assert v.value == 0.25
    i = c_int()
    assert status(s.fmi2GetStatus, s.component, 0, byref(i)) == DISCARD
    assert status(s.fmi2GetBooleanStatus, s.component, 3, byref(i)) == OK and i.value == 0


def test_debug_logging_categories(plant):
    s = plant.slave
    cats = (ctypes.c_char_p * 1)(b"noSuchCategory")
    assert status(s.fmi2SetDebugLogging, s.component, 1, 1, cats) == ERROR
    assert "unknown log category" in last(plant)
    assert status(s.fmi2SetDebugLogging, s.component, 1, 2, None) == ERROR
    cats = (ctypes.c_char_p * 1)(b"logCalls")
    assert status(s.fmi2SetDebugLogging, s.component, 1, 1, cats) == OK
    plant.do_step(0.0, 0.01)
    assert any("fmi2DoStep(" in m[2] for m in plant.messages), "logCalls traces the call"


# ----- FMU state -----------------------------------------------------------------------------

def test_get_fmu_state_null_pointer(plant):
    assert status(plant.slave.fmi2GetFMUstate, plant.slave.component, None) == ERROR
    usable(plant)


def test_set_fmu_state_garbage_pointer(plant):
    junk = ctypes.create_string_buffer(64)
    assert status(plant.slave.fmi2SetFMUstate, plant.slave.component, ctypes.cast(junk, c_void_p)) == ERROR
    assert "not created by this FMU" in last(plant)
    usable(plant)


def test_deserialize_corrupted_bytes(plant):
    st = plant.slave.getFMUstate()
    data = bytearray(plant.slave.serializeFMUstate(st))
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(FMICallException) as e:
        plant.slave.deSerializeFMUstate(bytes(data))
    assert e.value.status == ERROR and "corrupted" in last(plant)
    with pytest.raises(FMICallException):
        plant.slave.deSerializeFMUstate(b"not a state at all")
    plant.slave.freeFMUstate(st)
    usable(plant)


def test_serialize_with_wrong_size(plant):
    st = plant.slave.getFMUstate()
    size = c_size_t()
    plant.slave.fmi2SerializedFMUstateSize(plant.slave.component, st, byref(size))
    buf = (c_char * (size.value + 8))()
    assert status(plant.slave.fmi2SerializeFMUstate, plant.slave.component, st, buf, size.value + 8) == ERROR
    plant.slave.freeFMUstate(st)
    usable(plant)


# ----- instances -----------------------------------------------------------------------------

def _slave(model="AttitudePlant", guid=None):
    f = Fmu(model, initialize=False)
    return f, f.slave


@pytest.mark.parametrize("case", ["wrong_guid", "bad_fmu_type", "null_name", "empty_name", "null_guid", "null_callbacks"])
def test_instantiate_refusals(case):
    f = Fmu("AttitudePlant", initialize=False)  # keeps the library loaded
    try:
        s = f.slave
        name, kind, guid = b"x", 1, f.md.guid.encode()
        cb = byref(f.callbacks)
        if case == "wrong_guid":
            guid = b"{00000000-0000-0000-0000-000000000000}"
        elif case == "bad_fmu_type":  # AttitudePlant offers both fmi2ModelExchange (0) and fmi2CoSimulation (1)
            kind = 2
        elif case == "null_name":
            name = None
        elif case == "empty_name":
            name = b""
        elif case == "null_guid":
            guid = None
        elif case == "null_callbacks":
            cb = None
        n_before = len(f.messages)
        c = s.fmi2Instantiate(name, kind, guid, b"file:///tmp", cb, 0, 0)
        assert not c, "instantiation must fail"
        if case != "null_callbacks":
            assert len(f.messages) > n_before and "fmi2Instantiate" in f.messages[-1][2]
        if case == "wrong_guid":
            assert "does not match AttitudePlant's GUID" in f.messages[-1][2]
        if case == "bad_fmu_type":
            assert "fmuType 2 is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)" in f.messages[-1][2]
        f.slave.setupExperiment()  # the existing instance is unaffected
    finally:
        f.close()


def test_null_and_freed_component_pointers():
    f = Fmu("AttitudePlant")
    g = Fmu("AttitudePlant", path=None)
    try:
        s = f.slave
        assert status(s.fmi2DoStep, None, 0.0, 0.01, 1) == ERROR
        assert status(s.fmi2GetReal, None, vrs(10), 1, reals(0.0)) == ERROR
        s.fmi2FreeInstance(None)  # no-op, no crash
        # a second instance in the same loaded library, freed by hand, then used
        c2 = s.fmi2Instantiate(b"second", 1, f.md.guid.encode(), b"", byref(f.callbacks), 0, 0)
        assert c2
        s.fmi2FreeInstance(c2)
        assert status(s.fmi2DoStep, c2, 0.0, 0.01, 1) == ERROR
        s.fmi2FreeInstance(c2)  # double free: ignored
        usable(f)
    finally:
        g.close()
        f.close()


def test_non_finite_output_is_an_error_not_a_value():
    f = Fmu("PdController", {"gain_mode": 1, "kd_x": -1e308})
    try:
        f.set("w_x", 10.0)  # torque = -1e309: overflows to -inf
        r = vr(f, "torque_cmd_x")
        assert status(f.slave.fmi2GetReal, f.slave.component, vrs(r), 1, reals(0.0)) == ERROR
        assert "torque_cmd_x is -inf" in last(f)
        assert status(f.slave.fmi2DoStep, f.slave.component, 0.0, 0.01, 1) == ERROR, "error state: no stepping"
        f.slave.reset()  # recovers
    finally:
        f.close()
