"""FMI 2.0 Model Exchange: which units offer it, that they validate, that fmpy's own ME master (CVODE)
integrates the plants to the closed form and to the Co-Simulation result, that time events and the
quaternion projection work, that the paper 000 slew with the plant (and the static laws) run as Model
Exchange under SciPy's solve_ivp in the reference master gives the Co-Simulation EULERINT, and that bad
Model Exchange calls are refused with a message."""

from __future__ import annotations

import ctypes
import math
from ctypes import POINTER, byref, c_double, c_int

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.validation import validate_fmu

from scfmu.engines import run_reference
from scfmu.fmu import Fmu, fmu_path, recording_callbacks
from scfmu.papers.paper000.scenarios import paper000

# Written out here (the interface each model should have), not read from the code.
PLANTS = {"AttitudePlant": 18, "SingleAxisPlant": 3, "RelativeOrbitPlant": 7}
STATIC_LAWS = {"PdController", "LqrController", "PolePlacementController", "FuzzyPdController", "SlidingModeController",
               "Type2FuzzySmcController", "FeedbackLinearizingController", "AttitudeCommand", "RelativePositionCommand"}
CS_ONLY = {"PidController", "FopidController", "MracController", "AdaptiveFuzzyController", "ReferenceCorrector",
           "AttitudeMetrics", "PredictivePidController", "Gyro", "StarTracker", "SunSensor", "Magnetometer", "SampleHold"}


def path(model: str) -> str:
    return str(fmu_path(model))


def dedup_last(r):
    """fmpy's ME result holds two rows at an event time (before and after); keep the last of each."""
    t = r["time"]
    keep = np.append(t[1:] != t[:-1], True)
    return r[keep]


@pytest.mark.parametrize("model", sorted(set(PLANTS) | STATIC_LAWS | CS_ONLY))
def test_interfaces_are_the_declared_ones_and_every_fmu_validates(model):
    md = read_model_description(path(model))
    assert md.coSimulation is not None
    states = [v for v in md.modelVariables if v.derivative is not None]
    if model in CS_ONLY:
        assert md.modelExchange is None and not states
    else:
        assert md.modelExchange is not None and md.modelExchange.modelIdentifier == model
        assert len(states) == PLANTS.get(model, 0)
        # each derivative names its state; <Derivatives> lists exactly the derivatives
        assert [u.variable for u in md.derivatives] == states
        for d in states:
            assert d.name == f"der({d.derivative.name})" and d.derivative.causality == "local"
            assert d.derivative.variability == "continuous"
    assert validate_fmu(path(model)) == []


def test_a_co_simulation_only_unit_refuses_model_exchange_with_a_message():
    md = read_model_description(path("PidController"))
    msgs: list = []
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(path("PidController")), modelIdentifier="PidController",
                    instanceName="pid")
    cb = recording_callbacks(msgs)  # kept alive while the library may call it
    with pytest.raises(Exception):
        fmu.instantiate(callbacks=cb)
    assert any("supports only Co-Simulation" in m[2] for m in msgs), msgs


def test_single_axis_plant_under_cvode_follows_the_closed_form_step_response():
    # theta(t) of J theta'' = T_c, T T_c' = K u - T_c from rest: a (t^2/2 - T t + T^2 (1 - e^{-t/T})), a = K u / J
    sv = {"u": 0.5, "md_amp": 0.0, "md_const": 0.0}
    r = simulate_fmu(path("SingleAxisPlant"), fmi_type="ModelExchange", solver="CVode", stop_time=10.0,
                     output_interval=0.01, relative_tolerance=1e-10, start_values=sv, output=["theta", "omega"])
    t, tc, a = r["time"], 0.2, 0.5 / 7.7
    theta = a * (t * t / 2 - tc * t + tc * tc * (1 - np.exp(-t / tc)))
    omega = a * (t - tc * (1 - np.exp(-t / tc)))
    assert np.max(np.abs(r["theta"] - theta)) < 1e-8
    assert np.max(np.abs(r["omega"] - omega)) < 1e-9


def test_attitude_plant_under_cvode_spins_up_as_the_closed_form_under_a_constant_torque():
    # torque about the principal axis z from rest: w_z = tau t / I_z, yaw = tau t^2 / (2 I_z), no coupling
    tau, iz = 0.2, 700.0
    r = simulate_fmu(path("AttitudePlant"), fmi_type="ModelExchange", solver="CVode", stop_time=20.0,
                     output_interval=0.1, relative_tolerance=1e-10, start_values={"torque_cmd_z": tau},
                     output=["w_x", "w_z", "q_w", "q_z"])
    t = r["time"]
    assert np.max(np.abs(r["w_z"] - tau * t / iz)) < 1e-10
    assert np.max(np.abs(r["w_x"])) < 1e-14
    psi = tau * t * t / (2 * iz)
    assert np.max(np.abs(r["q_w"] - np.cos(psi / 2))) < 1e-8
    assert np.max(np.abs(r["q_z"] - np.sin(psi / 2))) < 1e-8


PLANT_CASES = {
    # tumbling rigid body with a fault at 5 s (a time event) and a wheel set with lag
    "AttitudePlant": ({"torque_cmd_x": 0.1, "torque_cmd_y": -0.05, "torque_cmd_z": 0.02, "init_w_x": 0.01,
                       "init_w_y": 0.02, "init_w_z": -0.01, "init_euler321_roll": 0.3, "fault_time": 5.0, "fault_bias_x": 0.05,
                       "inertia_xy": 20.0, "gg_enable": 1},
                      ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"], 20.0, 0.1),
    "SingleAxisPlant": ({"u": 0.3, "init_omega": 0.01}, ["theta", "omega", "wheel_torque", "applied_torque"], 50.0, 0.05),
    "RelativeOrbitPlant": ({"eccentricity": 0.1, "init_pos_x": 100.0, "init_vel_y": -0.2, "force_x": 0.5},
                           ["pos_x", "pos_y", "pos_z", "vel_x", "vel_y", "leader_true_anomaly"], 600.0, 1.0),
}


@pytest.mark.parametrize("model", sorted(PLANT_CASES))
def test_model_exchange_under_cvode_matches_co_simulation(model):
    """The same model run as ME under fmpy's CVODE and as CS with its adaptive Dormand-Prince at a tight
    tolerance: two independent integrators of the same equations."""
    sv, outs, stop, dt = PLANT_CASES[model]
    me = dedup_last(simulate_fmu(path(model), fmi_type="ModelExchange", solver="CVode", stop_time=stop,
                                 output_interval=dt, relative_tolerance=1e-11, start_values=sv, output=outs))
    cs = simulate_fmu(path(model), fmi_type="CoSimulation", stop_time=stop, output_interval=dt,
                      relative_tolerance=1e-12, start_values=dict(sv, integrator=2), output=outs)
    assert np.array_equal(me["time"], cs["time"])
    for k in outs:
        scale = max(1.0, float(np.max(np.abs(cs[k]))))
        assert np.max(np.abs(me[k] - cs[k])) < 1e-7 * scale, k


def test_time_events_are_reported_and_the_fault_switches_exactly_at_its_time():
    f = Fmu("AttitudePlant", params={"fault_time": 2.5, "torque_cmd_x": 1.0, "fault_bias_x": 0.5}, interface="me")
    try:
        assert f.next_event == 2.5
        f.do_step(0.0, 2.0)
        assert f.next_event == 2.5
        f.do_step(2.0, 1.0)  # crosses the fault: the solver stops at 2.5, the event iteration runs
        assert f.next_event is None
    finally:
        f.close()


def test_the_quaternion_stays_unit_under_a_loose_solver_by_projection_at_events():
    msgs: list = []
    md = read_model_description(path("AttitudePlant"))
    m = FMU2Model(guid=md.guid, unzipDirectory=extract(path("AttitudePlant")), modelIdentifier="AttitudePlant",
                  instanceName="p")
    cb = recording_callbacks(msgs)  # kept alive while the library may call it
    m.instantiate(callbacks=cb)
    m.setupExperiment(startTime=0.0)
    m.enterInitializationMode()
    vr = {v.name: v.valueReference for v in md.modelVariables}
    m.setReal([vr["init_w_x"], vr["init_w_y"], vr["init_w_z"]], [0.3, -0.2, 0.5])
    m.exitInitializationMode()
    m.newDiscreteStates()
    m.enterContinuousTimeMode()
    n = 18
    x, dx = (c_double * n)(), (c_double * n)()
    m.getContinuousStates(x, n)
    h, projected = 0.05, 0
    for k in range(200):  # explicit Euler: |q| grows by O(h^2 |w|^2) per step
        m.getDerivatives(dx, n)
        for i in range(n):
            x[i] += h * dx[i]
        m.setTime((k + 1) * h)
        m.setContinuousStates(x, n)
        enter, _ = m.completedIntegratorStep()
        if enter:
            m.enterEventMode()
            _, _, _, changed, _, _ = m.newDiscreteStates()
            assert changed
            m.enterContinuousTimeMode()
            m.getContinuousStates(x, n)
            projected += 1
        assert abs(math.sqrt(sum(x[i] ** 2 for i in range(4))) - 1.0) < 1e-2
    q = m.getReal([vr["q_w"], vr["q_x"], vr["q_y"], vr["q_z"]])
    assert projected > 100 and abs(math.sqrt(sum(c * c for c in q)) - 1.0) < 1e-2
    m.terminate()
    m.freeInstance()


def test_a_static_law_as_model_exchange_gives_its_co_simulation_outputs():
    ins = {"q_w": 0.9, "q_x": 0.1, "q_y": -0.3, "q_z": 0.2, "w_x": 0.01, "w_y": -0.02, "w_z": 0.03,
           "q_ref_w": 1.0, "q_ref_x": 0.0, "q_ref_y": 0.0, "q_ref_z": 0.0}
    norm = math.sqrt(sum(ins[k] ** 2 for k in ("q_w", "q_x", "q_y", "q_z")))
    for k in ("q_w", "q_x", "q_y", "q_z"):
        ins[k] /= norm
    out = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]
    res = []
    for interface in ("cs", "me"):
        f = Fmu("PdController", interface=interface)
        try:
            for k, v in ins.items():
                f.set(k, v)
            res.append(f.get_reals(out))
        finally:
            f.close()
    assert res[0] == res[1]
    # the law by hand: T = wn^2 I e + (-2 zeta wn I) w with e = 2 q_E,w q_E,v, q_E = q* (x) q_ref = q* here
    e = [2 * ins["q_w"] * -ins[k] for k in ("q_x", "q_y", "q_z")]
    inertia = (1000.0, 500.0, 700.0)
    expect = [i * ei - 2 * i * w for i, ei, w in zip(inertia, e, (ins["w_x"], ins["w_y"], ins["w_z"]))]
    assert np.allclose(res[1], expect, rtol=1e-12, atol=1e-12)


def test_a_command_step_is_a_time_event():
    r = simulate_fmu(path("AttitudeCommand"), fmi_type="ModelExchange", stop_time=5.0, output_interval=1.0,
                     start_values={"step_time": 2.5, "ref_euler321_yaw": 0.5}, output=["yaw_ref"])
    t = r["time"]
    assert 2.5 in t  # the event is a row of the result
    assert np.all(r["yaw_ref"][t < 2.5] == 0.0)
    assert r["yaw_ref"][-1] == 0.5 and r["yaw_ref"][np.flatnonzero(t == 2.5)[-1]] == 0.5


def test_paper000_slew_with_model_exchange_units_gives_the_co_simulation_eulerint():
    s = paper000("000-6", stop_time=30.0)
    cs = run_reference(s)
    me = run_reference(s, model_exchange={"plant", "controller", "command"})
    a, b = cs["eulerint_deg_s"][-1], me["eulerint_deg_s"][-1]
    assert a > 100.0  # a real slew: (40, -40, -60) deg
    assert abs(b - a) <= 1e-3 * a, (a, b)
    assert np.max(np.abs(cs["q_w"] - me["q_w"])) < 1e-6


def test_the_reference_master_refuses_model_exchange_for_a_unit_without_it():
    s = paper000("000-6", stop_time=1.0)
    with pytest.raises(ValueError, match="no Model Exchange"):
        run_reference(s, model_exchange={"metrics"})
    with pytest.raises(KeyError, match="no instance"):
        run_reference(s, model_exchange={"nosuch"})


# ----- bad Model Exchange calls, straight through ctypes ---------------------------------------------

class Raw:
    """An instance of AttitudePlant through the C functions, with the logged messages."""

    def __init__(self, fmu_type: int):
        self.md = read_model_description(path("AttitudePlant"))
        self.msgs: list = []
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(path("AttitudePlant")),
                               modelIdentifier="AttitudePlant", instanceName="raw")
        self.cb0 = recording_callbacks(self.msgs)  # kept alive while the library may call it
        self.slave.instantiate(callbacks=self.cb0)  # loads the library (a CS instance)
        self.dll = self.slave.dll
        if fmu_type == 0:  # a Model Exchange instance beside it (fmpy's freeInstance would unload the library)
            inst = self.dll.fmi2Instantiate
            inst.restype = ctypes.c_void_p
            inst.argtypes = [ctypes.c_char_p, c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p, c_int, c_int]
            self.cb = recording_callbacks(self.msgs)
            self.c = inst(b"raw", 0, self.md.guid.encode(), b"", ctypes.addressof(self.cb), 0, 0)
            assert self.c
        else:
            self.c = self.slave.component
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}

    def f(self, name, *argtypes):
        fn = self.dll[name]
        fn.argtypes = [ctypes.c_void_p, *argtypes]
        fn.restype = c_int
        return lambda *a: fn(self.c, *a)

    def init(self):
        assert self.f("fmi2SetupExperiment", c_int, c_double, c_double, c_int, c_double)(0, 0.0, 0.0, 0, 0.0) == 0
        assert self.f("fmi2EnterInitializationMode")() == 0
        assert self.f("fmi2ExitInitializationMode")() == 0

    def last(self) -> str:
        return self.msgs[-1][2] if self.msgs else ""


def test_model_exchange_calls_on_a_co_simulation_instance_are_refused():
    r = Raw(1)
    r.init()
    assert r.f("fmi2SetTime", c_double)(1.0) == 3
    assert "instantiated for Co-Simulation" in r.last()


def test_bad_model_exchange_calls_get_errors_with_reasons():
    r = Raw(0)
    r.init()
    x = (c_double * 18)()
    # wrong number of states
    assert r.f("fmi2GetContinuousStates", POINTER(c_double), ctypes.c_size_t)(x, 17) == 3
    assert "has 17 elements" in r.last() and "18 continuous states" in r.last()
    # SetContinuousStates is allowed in continuous-time mode only (this is event mode)
    assert r.f("fmi2SetContinuousStates", POINTER(c_double), ctypes.c_size_t)(x, 18) == 3
    assert "EventMode" in r.last()
    # doStep is not a Model Exchange call
    assert r.f("fmi2DoStep", c_double, c_double, c_int)(0.0, 0.1, 1) == 3
    assert r.f("fmi2EnterContinuousTimeMode")() == 0
    assert r.f("fmi2GetContinuousStates", POINTER(c_double), ctypes.c_size_t)(x, 18) == 0
    assert x[0] == 1.0  # q_w of the identity attitude
    x[3] = float("nan")
    assert r.f("fmi2SetContinuousStates", POINTER(c_double), ctypes.c_size_t)(x, 18) == 3
    assert "x[3] (state_att_4) = NaN is not finite" in r.last()
    assert r.f("fmi2SetTime", c_double)(float("inf")) == 3
    assert "not finite" in r.last()
    # states are set by fmi2SetContinuousStates, never by fmi2SetReal
    set_real = r.f("fmi2SetReal", POINTER(ctypes.c_uint), ctypes.c_size_t, POINTER(c_double))
    vr = (ctypes.c_uint * 1)(r.vr["state_att_1"])
    assert set_real(vr, 1, (c_double * 1)(0.5)) == 3
    assert "fmi2SetContinuousStates" in r.last()
    # no event indicators
    z = (c_double * 1)()
    assert r.f("fmi2GetEventIndicators", POINTER(c_double), ctypes.c_size_t)(z, 1) == 3
    assert "numberOfEventIndicators = 0" in r.last()
    # a state and its derivative read by value reference
    get_real = r.f("fmi2GetReal", POINTER(ctypes.c_uint), ctypes.c_size_t, POINTER(c_double))
    out = (c_double * 2)()
    assert get_real((ctypes.c_uint * 2)(r.vr["state_att_1"], r.vr["der(state_w_x)"]), 2, out) == 0
    assert out[0] == 1.0 and out[1] == 0.0


def test_an_fmu_state_keeps_the_model_exchange_states_and_refuses_a_co_simulation_instance():
    me = Fmu("SingleAxisPlant", params={"u": 0.4}, interface="me")
    cs = Fmu("SingleAxisPlant", params={"u": 0.4})
    try:
        me.do_step(0.0, 1.0)
        s = me.slave.getFMUState()
        a = me.get("theta")
        me.do_step(1.0, 1.0)
        me.slave.setFMUState(s)
        assert me.get("theta") == a
        blob = me.slave.serializeFMUState(s)
        cs_state = cs.slave.deserializeFMUState(blob)
        with pytest.raises(Exception):
            cs.slave.setFMUState(cs_state)
        assert any("taken from a Model Exchange instance" in m[2] for m in cs.messages)
    finally:
        me.close()
        cs.close()
