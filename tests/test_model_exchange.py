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
from scfmu.scenario import Component
from scfmu.fmu import Fmu, fmu_path, recording_callbacks
from scfmu.papers.paper000.scenarios import paper000

# Written out here (the interface each model should have and its number of continuous states), not read
# from the code.
PLANTS = {"AttitudePlant": 18, "SingleAxisPlant": 3, "RelativeOrbitPlant": 7}
STATEFUL = {"MracController": 9, "AdaptiveFuzzyController": 9, "ReferenceCorrector": 13, "AttitudeMetrics": 4,
            "PredictivePidController": 6}
STATIC_LAWS = {"PdController", "LqrController", "PolePlacementController", "FuzzyPdController", "SlidingModeController",
               "Type2FuzzySmcController", "FeedbackLinearizingController", "AttitudeCommand", "RelativePositionCommand"}
# sampled laws (a sample time) and the sensors (sampled noise): Co-Simulation only
CS_ONLY = {"PidController", "FopidController", "Gyro", "StarTracker", "SunSensor", "Magnetometer", "SampleHold", "Mekf"}
N_STATES = {**PLANTS, **STATEFUL}


def path(model: str) -> str:
    return str(fmu_path(model))


def dedup_last(r):
    """fmpy's ME result holds two rows at an event time (before and after); keep the last of each."""
    t = r["time"]
    keep = np.append(t[1:] != t[:-1], True)
    return r[keep]


@pytest.mark.parametrize("model", sorted(set(N_STATES) | STATIC_LAWS | CS_ONLY))
def test_interfaces_are_the_declared_ones_and_every_fmu_validates(model):
    md = read_model_description(path(model))
    assert md.coSimulation is not None
    states = [v for v in md.modelVariables if v.derivative is not None]
    if model in CS_ONLY:
        assert md.modelExchange is None and not states
    else:
        assert md.modelExchange is not None and md.modelExchange.modelIdentifier == model
        assert len(states) == N_STATES.get(model, 0)
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


def fmu_of(version: str, model: str) -> str:
    return path(model) if version == "fmi2" else str(fmu_path(model).parent / "fmi3" / f"{model}.fmu")


@pytest.mark.parametrize("version", ["fmi2", "fmi3"])
def test_single_axis_plant_under_cvode_follows_the_closed_form_step_response(version):
    # theta(t) of J theta'' = T_c, T T_c' = K u - T_c from rest: a (t^2/2 - T t + T^2 (1 - e^{-t/T})), a = K u / J
    sv = {"u": 0.5, "md_amp": 0.0, "md_const": 0.0}
    r = simulate_fmu(fmu_of(version, "SingleAxisPlant"), fmi_type="ModelExchange", solver="CVode", stop_time=10.0,
                     output_interval=0.01, relative_tolerance=1e-10, start_values=sv, output=["theta", "omega"])
    t, tc, a = r["time"], 0.2, 0.5 / 7.7
    theta = a * (t * t / 2 - tc * t + tc * tc * (1 - np.exp(-t / tc)))
    omega = a * (t - tc * (1 - np.exp(-t / tc)))
    assert np.max(np.abs(r["theta"] - theta)) < 1e-8
    assert np.max(np.abs(r["omega"] - omega)) < 1e-9


@pytest.mark.parametrize("version", ["fmi2", "fmi3"])
def test_attitude_plant_under_cvode_spins_up_as_the_closed_form_under_a_constant_torque(version):
    # torque about the principal axis z from rest: w_z = tau t / I_z, q = (cos(th/2), 0, 0, sin(th/2)) with
    # th = tau t^2 / (2 I_z), no coupling into x and y
    tau, iz = 0.2, 700.0
    r = simulate_fmu(fmu_of(version, "AttitudePlant"), fmi_type="ModelExchange", solver="CVode", stop_time=20.0,
                     output_interval=0.1, relative_tolerance=1e-10, start_values={"torque_cmd_z": tau},
                     output=["w_x", "w_y", "w_z", "q_w", "q_x", "q_y", "q_z"])
    t = r["time"]
    assert t[-1] == pytest.approx(20.0)
    assert np.max(np.abs(r["w_z"] - tau * t / iz)) < 1e-10
    assert np.max(np.abs(r["w_x"])) < 1e-14 and np.max(np.abs(r["w_y"])) < 1e-14
    th = tau * t * t / (2 * iz)
    assert np.max(np.abs(r["q_w"] - np.cos(th / 2))) < 1e-8
    assert np.max(np.abs(r["q_z"] - np.sin(th / 2))) < 1e-8
    assert np.max(np.abs(r["q_x"])) < 1e-14 and np.max(np.abs(r["q_y"])) < 1e-14


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


@pytest.mark.parametrize("run_id", ["000-9Lq", "000-11L"])
def test_paper000_adaptive_runs_with_every_unit_as_model_exchange_give_the_co_simulation_eulerint(run_id):
    """MRAC and adaptive fuzzy (their reference model and inertia estimate as continuous states) with the
    plant, the command and the metrics (EULERINT as a state) all as ME under solve_ivp."""
    s = paper000(run_id, stop_time=30.0)
    cs = run_reference(s)
    me = run_reference(s, model_exchange={"plant", "controller", "command", "metrics"})
    a, b = cs["eulerint_deg_s"][-1], me["eulerint_deg_s"][-1]
    assert a > 50.0
    assert abs(b - a) <= 1e-3 * a, (a, b)
    # measured: 144.07748949290 vs 144.07748949241 (000-9Lq), 134.71457476 vs 134.71457420 (000-11L)
    tau = np.abs(cs["torque_applied_x"]).max()
    assert np.max(np.abs(cs["torque_applied_x"] - me["torque_applied_x"])) <= 1e-5 * tau


def test_directional_derivatives_of_the_state_derivatives_follow_the_rigid_body_jacobian():
    """fmi2GetDirectionalDerivative on an ME instance takes states as knowns and derivatives as unknowns
    (providesDirectionalDerivative): at rest with identity attitude, d(w_z')/d(torque_cmd_z) = 1/I_z,
    d(q_x')/d(w_x) = q_w / 2 = 0.5 and d(q_w')/d(w_x) = -q_x / 2 = 0."""
    md = read_model_description(path("AttitudePlant"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    m = FMU2Model(guid=md.guid, unzipDirectory=extract(path("AttitudePlant")), modelIdentifier="AttitudePlant",
                  instanceName="jac")
    m.instantiate()
    try:
        m.setupExperiment(startTime=0.0)
        m.enterInitializationMode()
        m.exitInitializationMode()
        m.newDiscreteStates()
        m.enterContinuousTimeMode()
        d = m.getDirectionalDerivative([vr["der(state_w_z)"], vr["der(state_att_2)"], vr["der(state_att_1)"]],
                                       [vr["torque_cmd_z"]], [1.0])
        assert abs(d[0] - 1 / 700.0) < 1e-9 and d[1] == 0.0 and d[2] == 0.0
        d = m.getDirectionalDerivative([vr["der(state_att_2)"], vr["der(state_att_1)"]], [vr["state_w_x"]], [1.0])
        assert abs(d[0] - 0.5) < 1e-9 and abs(d[1]) < 1e-12
    finally:
        m.terminate()
        m.freeInstance()


def test_metrics_as_model_exchange_integrate_constant_inputs_exactly():
    # q = rotation of 30 deg about z, q_ref = identity: alpha = 30 deg, yaw error = -30 deg
    c, s_ = np.cos(np.radians(15)), np.sin(np.radians(15))
    sv = {"q_w": c, "q_z": s_, "torque_applied_x": 0.3, "torque_applied_y": -0.4}
    r = simulate_fmu(path("AttitudeMetrics"), fmi_type="ModelExchange", solver="CVode", stop_time=10.0,
                     output_interval=0.5, relative_tolerance=1e-10, start_values=sv,
                     output=["eulerint_deg_s", "alpha_deg", "ise", "isf", "effort_abs"])
    t = r["time"]
    assert np.allclose(r["alpha_deg"], 30.0, rtol=1e-12)
    assert np.allclose(r["eulerint_deg_s"], 30.0 * t, rtol=1e-9, atol=1e-12)
    assert np.allclose(r["ise"], np.radians(30.0) ** 2 * t, rtol=1e-9, atol=1e-12)
    assert np.allclose(r["isf"], 0.25 * t, rtol=1e-9, atol=1e-12)
    assert np.allclose(r["effort_abs"], 0.7 * t, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("structure", [0, 1])
def test_predictive_pid_states_as_model_exchange_follow_the_closed_form(structure):
    # constant error e = (2, -1, 0.5) m, e' = 0: E(t) = e t (structure 0); dz/dt = -c K1 e (structure 1)
    sv = {"pos_ref_x": 2.0, "pos_ref_y": -1.0, "pos_ref_z": 0.5, "structure": structure, "T2": 5.0, "c": 0.5}
    r = simulate_fmu(path("PredictivePidController"), fmi_type="ModelExchange", solver="CVode", stop_time=4.0,
                     output_interval=0.5, relative_tolerance=1e-10, start_values=sv,
                     output=["int_error_x", "int_error_y", "dist_est_x", "dist_est_z"])
    t, e = r["time"], np.array([2.0, -1.0, 0.5])
    k1, k2, c, m = 10 / (3 * 25.0), 5 / (2 * 5.0), 0.5, 100.0
    d0 = -c * (k2 * e)  # d_hat(0) = -c (e' + K2 e + K1 E(0))
    if structure == 0:
        assert np.allclose(r["int_error_x"], 2.0 * t, rtol=1e-9, atol=1e-12)
        assert np.allclose(r["int_error_y"], -1.0 * t, rtol=1e-9, atol=1e-12)
        # d_hat = -c (e' + K2 e + K1 E)
        assert np.allclose(r["dist_est_x"], m * (d0[0] - c * k1 * 2.0 * t), rtol=1e-9)
    else:
        assert np.all(r["int_error_x"] == 0.0)
        # d_hat = z + c vel, z' = -c K1 e: the same line as structure 0's d_hat
        assert np.allclose(r["dist_est_x"], m * (d0[0] - c * k1 * 2.0 * t), rtol=1e-9)
        assert np.allclose(r["dist_est_z"], m * (d0[2] - c * k1 * 0.5 * t), rtol=1e-9)


def test_reference_corrector_as_model_exchange_matches_scipy_with_the_not_a_knot_spline():
    """The corrector's open-loop copy under fmpy's CVODE against SciPy: the rigid body I w' = sat(u(t)) - w x I w,
    q' = q (x) (0, w) / 2 driven by SciPy's own not-a-knot CubicSpline through the nodes (0 after the last knot,
    a time event); with e(0) = e'(0) = 0 the reference q_ref is the copy's attitude."""
    from scipy.integrate import solve_ivp
    from scipy.interpolate import CubicSpline

    inertia, limit, t_end = np.array([449.5, 264.5, 312.5]), 1.0, 10.0
    nodes = {"x": [0.0, 0.5, -0.3, 0.2, 0.4, 0.0], "y": [0.2, -0.6, 0.1, 0.0, 0.3, -0.1], "z": [0.0, 0.1, 0.3, -0.2, 0.0, 2.0]}
    sv = {"mode": 1, "spline_t_end": t_end, "effectiveness_x": 0.1, "effectiveness_y": 0.1, "effectiveness_z": 0.1,
          **{f"node_{a}_{k}": v for a in "xyz" for k, v in enumerate(nodes[a])}}
    r = dedup_last(simulate_fmu(path("ReferenceCorrector"), fmi_type="ModelExchange", solver="CVode", stop_time=15.0,
                                output_interval=0.5, relative_tolerance=1e-11, start_values=sv,
                                output=["q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z", "u_ol_z"]))
    knots = np.linspace(0.0, t_end, 6)
    spl = [CubicSpline(knots, nodes[a], bc_type="not-a-knot") for a in "xyz"]

    def f(t, y):
        q, w = y[:4], y[4:]
        u = np.clip([s(t) if t <= t_end else 0.0 for s in spl], -limit, limit)  # u_max 10 N m x effectiveness 0.1
        wd = (u - np.cross(w, inertia * w)) / inertia
        qd = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
        return np.concatenate([qd, wd])

    ref = {}
    y0 = np.array([1.0, 0, 0, 0, 0, 0, 0])
    for a, b in [(0.0, t_end), (t_end, 15.0)]:  # the torque jumps at t_end: integrate the two pieces
        sol = solve_ivp(f, (a, b), y0, method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
        y0 = sol.y[:, -1]
        for t in r["time"]:
            if a <= t <= b:
                ref[float(t)] = sol.sol(t)
    qs = np.array([ref[float(t)][:4] / np.linalg.norm(ref[float(t)][:4]) for t in r["time"]])
    assert np.max(np.abs(qs[:, 3])) > 0.01  # a real rotation (about 2 deg about z)
    for i, c in enumerate("wxyz"):
        assert np.max(np.abs(r[f"q_ref_{c}"] - qs[:, i])) < 1e-7, c
    assert r["u_ol_z"][-1] == 0.0


def test_the_reference_master_refuses_model_exchange_for_a_unit_without_it():
    s = paper000("000-6", stop_time=1.0)
    s = paper000("000-6", stop_time=1.0)
    s.components[[c.name for c in s.components].index("controller")] = Component("controller", "PidController", {})
    with pytest.raises(ValueError, match="no Model Exchange"):
        run_reference(s, model_exchange={"controller"})
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
