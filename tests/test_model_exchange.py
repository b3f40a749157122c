"""Model Exchange in FMI 2.0 and FMI 3.0 (one test per behaviour, parametrized over the version where both
have it): which units offer it, that they validate, that fmpy's own ME master (CVODE) integrates the plants
to the closed form and to the Co-Simulation result (and FMI 3.0 to the FMI 2.0 result), that time events
and the quaternion projection work, that a static law gives its Co-Simulation outputs, that FMU states keep
the ME states, that the paper 000 slew with the plant (and the static laws) run as Model Exchange under
SciPy's solve_ivp in the reference master gives the Co-Simulation EULERINT, and that bad Model Exchange
calls are refused with the status the standard prescribes and a message naming the function. FMI 3.0: the
states, derivatives and dependency lists equal the FMI 2.0 description's (an independent writer of the same
declarations), and its ME state machine."""

from __future__ import annotations

import ctypes
import math
import xml.etree.ElementTree as ET
import zipfile
from ctypes import POINTER, byref, c_double, c_int
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model, FMU3Slave, fmi3Boolean, fmi3Float64, fmi3Int32
from fmpy.validation import validate_fmu

from test_fmi_bad_input import ERROR, OK, TIME_VR, f64, status, vrs  # the raw-call helpers

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
               "Type2FuzzySmcController", "FeedbackLinearizingController", "SunSafeController", "AttitudeCommand",
               "RelativePositionCommand"}
# sampled laws (a sample time) and the sensors (sampled noise): Co-Simulation only
CS_ONLY = {"PidController", "FopidController", "Gyro", "StarTracker", "SunSensor", "Magnetometer", "SampleHold", "Mekf"}
N_STATES = {**PLANTS, **STATEFUL}
VERSIONS = ["fmi2", "fmi3"]
ROOT = Path(__file__).resolve().parents[1]
MODELS = sorted(p.stem for p in (ROOT / "modelDescription" / "fmi3").glob("*.xml"))


def path(model: str) -> str:
    return str(fmu_path(model))


def fmu_of(version: str, model: str) -> str:
    p = fmu_path(model) if version == "fmi2" else fmu_path(model).parent / "fmi3" / f"{model}.fmu"
    assert p.exists(), f"{p} missing: run scripts/build_fmus.sh"
    return str(p)


def fmu3(model: str) -> str:
    return fmu_of("fmi3", model)


def fmu2(model: str) -> str:
    return fmu_of("fmi2", model)


def dedup_last(r):
    """fmpy's ME result holds two rows at an event time (before and after); keep the last of each."""
    t = r["time"]
    keep = np.append(t[1:] != t[:-1], True)
    return r[keep]


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("model", sorted(set(N_STATES) | STATIC_LAWS | CS_ONLY))
def test_interfaces_are_the_declared_ones_and_every_fmu_validates(model, version):
    md = read_model_description(fmu_of(version, model))
    assert md.coSimulation is not None
    states = [v for v in md.modelVariables if v.derivative is not None]
    if model in CS_ONLY:
        assert md.modelExchange is None and not states and not md.derivatives
        assert not md.numberOfContinuousStates
    else:
        assert md.modelExchange is not None and md.modelExchange.modelIdentifier == model
        assert len(states) == N_STATES.get(model, 0)
        # each derivative names its state; <Derivatives> lists exactly the derivatives
        assert [u.variable for u in md.derivatives] == states
        for d in states:
            assert d.name == f"der({d.derivative.name})" and d.derivative.causality == "local"
            assert d.derivative.variability == "continuous"
    assert validate_fmu(fmu_of(version, model)) == []


@pytest.mark.parametrize("version", VERSIONS)
def test_a_co_simulation_only_unit_refuses_model_exchange_with_a_message(version):
    p = fmu_of(version, "PidController")
    md, msgs = read_model_description(p), []
    fmu = (FMU2Model if version == "fmi2" else FMU3Model)(guid=md.guid, unzipDirectory=extract(p),
                                                          modelIdentifier="PidController", instanceName="pid")
    if version == "fmi2":
        cb = recording_callbacks(msgs)  # kept alive while the library may call it
        with pytest.raises(Exception):
            fmu.instantiate(callbacks=cb)
        says = ("supports only Co-Simulation",)
    else:
        with pytest.raises(Exception):
            fmu.instantiate(logMessage=lambda env, st, cat, m: msgs.append((st, cat.decode(), m.decode())))
        says = ("fmi3InstantiateModelExchange", "provides Co-Simulation only")
    assert any(all(w in m[2] for w in says) for m in msgs), msgs
    fmu.freeLibrary()


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


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("model", sorted(PLANT_CASES))
def test_model_exchange_under_cvode_matches_co_simulation(model, version):
    """The same model run as ME under fmpy's CVODE and as CS with its adaptive Dormand-Prince at a tight
    tolerance: two independent integrators of the same equations (the AttitudePlant case crosses a fault time
    event). FMI 3.0 ME also equals FMI 2.0 ME under the same solver settings to 1e-12."""
    sv, outs, stop, dt = PLANT_CASES[model]
    kw = dict(fmi_type="ModelExchange", solver="CVode", stop_time=stop, output_interval=dt, relative_tolerance=1e-11,
              start_values=sv, output=outs)
    me = dedup_last(simulate_fmu(fmu_of(version, model), **kw))
    cs = simulate_fmu(fmu_of(version, model), fmi_type="CoSimulation", stop_time=stop, output_interval=dt,
                      relative_tolerance=1e-12, start_values=dict(sv, integrator=2), output=outs)
    assert np.array_equal(me["time"], cs["time"])
    for k in outs:
        scale = max(1.0, float(np.max(np.abs(cs[k]))))
        assert np.max(np.abs(me[k] - cs[k])) < 1e-7 * scale, k
    if version == "fmi3":
        r2 = dedup_last(simulate_fmu(fmu2(model), **kw))
        assert np.array_equal(me["time"], r2["time"])
        for k in outs:
            scale = max(1.0, float(np.max(np.abs(r2[k]))))
            assert np.max(np.abs(me[k] - r2[k])) <= 1e-12 * scale, k


@pytest.mark.parametrize("version", VERSIONS)
def test_time_events_are_reported_and_the_fault_switches_exactly_at_its_time(version):
    f = Fmu("AttitudePlant", params={"fault_time": 2.5, "torque_cmd_x": 1.0, "fault_bias_x": 0.5}, interface="me",
            path=fmu_of(version, "AttitudePlant"))
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


@pytest.mark.parametrize("version", VERSIONS)
def test_a_static_law_as_model_exchange_gives_its_co_simulation_outputs(version):
    ins = {"q_w": 0.9, "q_x": 0.1, "q_y": -0.3, "q_z": 0.2, "w_x": 0.01, "w_y": -0.02, "w_z": 0.03,
           "q_ref_w": 1.0, "q_ref_x": 0.0, "q_ref_y": 0.0, "q_ref_z": 0.0}
    norm = math.sqrt(sum(ins[k] ** 2 for k in ("q_w", "q_x", "q_y", "q_z")))
    for k in ("q_w", "q_x", "q_y", "q_z"):
        ins[k] /= norm
    out = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]
    res = []
    for interface in ("cs", "me"):
        f = Fmu("PdController", interface=interface, path=fmu_of(version, "PdController"))
        try:
            if version == "fmi3" and interface == "me":  # in Continuous-Time Mode with no states
                assert f.slave.getNumberOfContinuousStates() == 0 and f.slave.getNumberOfEventIndicators() == 0
                assert status(f.slave.fmi3GetContinuousStateDerivatives, f.slave.component, None, 0) == OK
                f.slave.setTime(1.5)
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


@pytest.mark.parametrize("version", VERSIONS)
def test_a_command_step_is_a_time_event(version):
    r = simulate_fmu(fmu_of(version, "AttitudeCommand"), fmi_type="ModelExchange", stop_time=5.0, output_interval=1.0,
                     start_values={"step_time": 2.5, "ref_euler321_yaw": 0.5}, output=["yaw_ref"])
    t = r["time"]
    assert 2.5 in t  # the event is a row of the result
    assert np.all(r["yaw_ref"][t < 2.5] == 0.0)
    assert r["yaw_ref"][-1] == 0.5 and r["yaw_ref"][np.flatnonzero(t == 2.5)[-1]] == 0.5
    if version == "fmi3":  # every output equals FMI 2.0's
        kw = dict(fmi_type="ModelExchange", stop_time=5.0, output_interval=1.0)
        r3, r2 = simulate_fmu(fmu3("AttitudeCommand"), **kw), simulate_fmu(fmu2("AttitudeCommand"), **kw)
        assert r3.dtype.names == r2.dtype.names
        for n in r2.dtype.names:
            assert np.array_equal(r3[n], r2[n]), n


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


@pytest.mark.parametrize("version", VERSIONS)
def test_an_fmu_state_keeps_the_model_exchange_states_and_refuses_a_co_simulation_instance(version):
    p = fmu_of(version, "SingleAxisPlant")
    me = Fmu("SingleAxisPlant", params={"u": 0.4}, interface="me", path=p)
    cs = Fmu("SingleAxisPlant", params={"u": 0.4}, path=p)
    try:
        me.do_step(0.0, 1.0)
        s = me.slave.getFMUState()
        a = me.get("theta")
        me.do_step(1.0, 1.0)
        me.slave.setFMUState(s)
        assert me.get("theta") == a
        blob = me.slave.serializeFMUState(s)
        with pytest.raises(Exception):
            cs.slave.deserializeFMUState(blob)  # refused already here: an accepted state can always be set
        taken = "FMU state was taken from a Model Exchange instance"
        assert any("erializeFMU" in m[2] and taken in m[2] for m in cs.messages), cs.messages
    finally:
        me.close()
        cs.close()


# ----- FMI 3.0 only: its description against the FMI 2.0 one, the ME state machine through ctypes --------

def me_models() -> list[str]:
    """The units with FMI 2.0 Model Exchange, read from their FMI 2.0 descriptions."""
    return [m for m in MODELS if read_model_description(fmu2(m)).modelExchange is not None]


ME_MODELS = me_models()


def test_the_model_exchange_units_are_the_fmi2_ones():
    # written out (the table at the top): at least these have ME
    assert {"AttitudePlant", "SingleAxisPlant", "RelativeOrbitPlant", "PdController", "AttitudeCommand"} <= set(ME_MODELS)
    assert len(ME_MODELS) >= 12
    for m in MODELS:
        assert (read_model_description(fmu3(m)).modelExchange is not None) == (m in ME_MODELS), m


def interface_attributes(path: str) -> dict:
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return {e.tag: dict(e.attrib) for e in root if e.tag in ("ModelExchange", "CoSimulation")}


def names(unknowns):
    return [u.variable.name for u in unknowns]


def deps(u):
    return None if u.dependencies is None else sorted(v.name for v in u.dependencies)


@pytest.mark.parametrize("model", ME_MODELS)
def test_fmi3_model_exchange_validates_and_matches_the_fmi2_description(model):
    assert validate_fmu(fmu3(model)) == []
    md3, md2 = read_model_description(fmu3(model)), read_model_description(fmu2(model))
    me3, me2 = md3.modelExchange, md2.modelExchange
    assert me3.modelIdentifier == me2.modelIdentifier == model
    assert me3.needsCompletedIntegratorStep is (not me2.completedIntegratorStepNotNeeded) is True
    # the capability flags, read from the XML itself (FMI 3.0 spells them differently from FMI 2.0)
    x3, x2 = interface_attributes(fmu3(model)), interface_attributes(fmu2(model))
    flags3 = ("canGetAndSetFMUState", "canSerializeFMUState", "providesDirectionalDerivatives")
    flags2 = ("canGetAndSetFMUstate", "canSerializeFMUstate", "providesDirectionalDerivative")
    assert [x3["ModelExchange"][f] for f in flags3] == [x2["ModelExchange"][f] for f in flags2] == ["true"] * 3
    assert [x3["ModelExchange"][f] for f in flags3] == [x3["CoSimulation"][f] for f in flags3]
    assert x3["ModelExchange"]["needsCompletedIntegratorStep"] == "true"
    # same states and derivatives (names, value references, order), the derivative naming its state
    assert md3.numberOfContinuousStates == md2.numberOfContinuousStates == len(md2.derivatives)
    assert names(md3.derivatives) == names(md2.derivatives)
    for u3, u2 in zip(md3.derivatives, md2.derivatives):
        d3, d2 = u3.variable, u2.variable
        assert (d3.valueReference, d3.causality, d3.variability) == (d2.valueReference, "local", "continuous")
        assert d3.derivative.name == d2.derivative.name and d3.derivative.valueReference == d2.derivative.valueReference
        assert d3.derivative.type == "Float64" and d3.derivative.initial == "calculated"
        assert deps(u3) == deps(u2), d3.name
    # the same dependency lists, translated from indices to value references
    assert names(md3.outputs) == names(md2.outputs)
    for u3, u2 in zip(md3.outputs, md2.outputs):
        assert deps(u3) == deps(u2), u3.variable.name
    assert names(md3.initialUnknowns) == names(md2.initialUnknowns)
    for u3, u2 in zip(md3.initialUnknowns, md2.initialUnknowns):
        assert deps(u3) == deps(u2), u3.variable.name


@pytest.mark.parametrize("model", sorted(set(MODELS) - set(ME_MODELS)))
def test_co_simulation_only_units_have_no_model_exchange_in_fmi3(model):
    md3 = read_model_description(fmu3(model))
    assert md3.modelExchange is None and md3.numberOfContinuousStates == 0 and not md3.derivatives


class Me3:
    """One FMI 3.0 instance (Model Exchange unless `cs`) with a recording logger."""

    def __init__(self, tmp: Path, model: str = "AttitudePlant", cs: bool = False, name: str = "me"):
        path = fmu3(model)
        self.md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.n = self.md.numberOfContinuousStates
        self.messages: list[tuple[int, str, str]] = []
        # one extracted copy per model: instances of one library share its FMU-state table
        d = tmp / model
        if not d.exists():
            extract(path, unzipdir=str(d))
        d = str(d)
        cls = FMU3Slave if cs else FMU3Model
        self.s = cls(guid=self.md.guid, unzipDirectory=d, modelIdentifier=model, instanceName=name)

        def log(env, st, category, message):
            self.messages.append((st, category.decode(), message.decode()))

        self.error = None
        try:
            self.s.instantiate(logMessage=log)
        except Exception as e:  # fmpy raises when the instance pointer is NULL
            self.error = e
        self.c = self.s.component

    def last(self) -> str:
        return self.messages[-1][2] if self.messages else ""

    def init(self, **values):
        self.s.enterInitializationMode(startTime=0.0)
        if values:
            self.s.setFloat64([self.vr[k] for k in values], list(values.values()))
        self.s.exitInitializationMode()

    def to_continuous_time(self, **values):
        self.init(**values)
        self.s.updateDiscreteStates()
        self.s.enterContinuousTimeMode()

    def close(self):
        if self.c:
            self.s.fmi3FreeInstance(self.c)
        self.s.freeLibrary()


@pytest.fixture
def me(tmp_path):
    f = Me3(tmp_path)
    yield f
    f.close()


def test_states_and_derivatives_by_value_reference_and_the_state_machine(me):
    tau, iz = 0.2, 700.0
    assert me.s.getNumberOfContinuousStates() == 18 and me.s.getNumberOfEventIndicators() == 0
    me.init(torque_cmd_z=tau)
    # Event Mode after initialization: time events are reported by fmi3UpdateDiscreteStates
    need, term, nominals, values, defined, _ = me.s.updateDiscreteStates()
    assert (need, term, nominals, defined) == (False, False, False, False)
    me.s.enterContinuousTimeMode()
    n = me.n
    x, dx, nom = (c_double * n)(), (c_double * n)(), (c_double * n)()
    me.s.getContinuousStates(x, n)
    me.s.getNominalsOfContinuousStates(nom, n)
    assert list(nom) == [1.0] * n
    order = [u.variable.derivative.name for u in me.md.derivatives]
    k = order.index("state_w_z")
    me.s.setTime(2.0)
    x[k] = tau / iz * 2.0
    me.s.setContinuousStates(x, n)
    me.s.getContinuousStateDerivatives(dx, n)
    assert dx[k] == pytest.approx(tau / iz, abs=1e-15)
    got = me.s.getFloat64([me.vr["state_w_z"], me.vr["der(state_w_z)"], me.vr["w_z"], TIME_VR])
    assert got == pytest.approx([tau / iz * 2.0, tau / iz, tau / iz * 2.0, 2.0], abs=1e-15)
    # a state set by value reference in Continuous-Time Mode (FMI 3.0 allows it) is the state
    me.s.setFloat64([me.vr["state_w_x"]], [0.125])
    assert me.s.getFloat64([me.vr["w_x"]]) == [0.125]
    enter, terminate = me.s.completedIntegratorStep()
    assert not terminate
    me.s.enterEventMode()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    assert status(me.s.fmi3Terminate, me.c) == OK
    me.s.getContinuousStates(x, n)  # still readable in Terminated
    assert x[k] == pytest.approx(tau / iz * 2.0)


def test_fmu_state_round_trip_in_continuous_time_mode(me):
    me.to_continuous_time(torque_cmd_z=0.2, init_w_x=0.01)
    n = me.n
    x, dx0, dx1 = (c_double * n)(), (c_double * n)(), (c_double * n)()
    me.s.setTime(1.0)
    me.s.getContinuousStates(x, n)
    me.s.getContinuousStateDerivatives(dx0, n)
    state = me.s.getFMUState()
    blob = me.s.serializeFMUState(state)
    me.s.completedIntegratorStep()
    me.s.enterEventMode()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    me.s.setTime(3.0)
    x2 = (c_double * n)(*[v + 0.01 for v in x])
    me.s.setContinuousStates(x2, n)
    restored = me.s.deserializeFMUState(blob)
    me.s.setFMUState(restored)
    assert me.s.getFloat64([TIME_VR]) == [1.0]
    me.s.getContinuousStateDerivatives(dx1, n)
    assert list(dx1) == list(dx0)
    me.s.setTime(1.5)  # after the restore the solver may go on from the restored time
    me.s.freeFMUState(state)
    me.s.freeFMUState(restored)


def err(f: Me3, fn, *args, contains: str = "") -> str:
    st = status(fn, f.c, *args)
    assert st == ERROR, (fn.__name__ if hasattr(fn, "__name__") else fn, st, f.last())
    msg = f.last()
    assert contains in msg, msg
    return msg


def test_wrong_call_order_is_refused_and_terminates(me):
    n = me.n
    x = (c_double * n)()
    msg = err(me, me.s.fmi3SetContinuousStates, x, n, contains="fmi3SetContinuousStates")
    assert "not allowed in state Instantiated" in msg
    # fmi3Error -> Terminated: initialization is refused until fmi3Reset
    assert status(me.s.fmi3EnterInitializationMode, me.c, fmi3Boolean(False), 0.0, 0.0, fmi3Boolean(False), 0.0) == ERROR
    assert "Terminated" in me.last()
    assert status(me.s.fmi3Reset, me.c) == OK
    me.s.enterInitializationMode(startTime=0.0)
    err(me, me.s.fmi3EnterContinuousTimeMode, contains="fmi3EnterContinuousTimeMode: not allowed in state Initialization Mode")
    me.s.fmi3Reset(me.c)
    me.init()
    # Event Mode: no time, no states, no integrator step, no second fmi3EnterEventMode
    for fn, args in [(me.s.fmi3SetTime, (1.0,)), (me.s.fmi3SetContinuousStates, (x, n)),
                     (me.s.fmi3CompletedIntegratorStep, (fmi3Boolean(True), byref(fmi3Boolean()), byref(fmi3Boolean()))),
                     (me.s.fmi3EnterEventMode, ())]:
        err(me, fn, *args, contains="not allowed in state Event Mode")
        assert status(me.s.fmi3Reset, me.c) == OK
        me.init()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    bs = [fmi3Boolean() for _ in range(5)]
    t = fmi3Float64()
    err(me, me.s.fmi3UpdateDiscreteStates, *[byref(b) for b in bs], byref(t),
        contains="fmi3UpdateDiscreteStates: not allowed in state Continuous-Time Mode")


def test_wrong_lengths_nan_states_and_infinite_time_are_refused(me):
    me.to_continuous_time()
    n = me.n
    x = (c_double * (n + 1))()
    for fn, arr in [(me.s.fmi3GetContinuousStates, "continuousStates[]"), (me.s.fmi3SetContinuousStates, "continuousStates[]"),
                    (me.s.fmi3GetContinuousStateDerivatives, "derivatives[]"), (me.s.fmi3GetNominalsOfContinuousStates, "nominals[]")]:
        msg = err(me, fn, x, n - 1, contains=f"{arr} has {n - 1} elements, but AttitudePlant has {n} continuous states")
        assert msg.startswith("me: fmi3"), msg
        me.s.fmi3Reset(me.c)
        me.to_continuous_time()
    err(me, me.s.fmi3GetEventIndicators, x, 1, contains="numberOfEventIndicators = 0")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    assert status(me.s.fmi3GetEventIndicators, me.c, None, 0) == OK
    err(me, me.s.fmi3GetContinuousStates, None, n, contains="continuousStates[] is NULL")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    me.s.getContinuousStates(x, n)
    x[5] = float("nan")
    err(me, me.s.fmi3SetContinuousStates, x, n, contains="continuousStates[5] (state_att_6) = NaN is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetTime, math.inf, contains="fmi3SetTime: time inf is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["state_w_x"]), 1, f64(math.nan), 1, contains="state_w_x is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3CompletedIntegratorStep, fmi3Boolean(True), None, byref(fmi3Boolean()), contains="enterEventMode is NULL")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3GetNumberOfContinuousStates, None, contains="nContinuousStates is NULL")


def test_what_cannot_be_set_in_continuous_time_mode(me):
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["inertia_xx"]), 1, f64(900.0), 1,
        contains="inertia_xx cannot be set in Continuous-Time Mode")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    i = (fmi3Int32 * 1)(1)
    err(me, me.s.fmi3SetInt32, vrs(me.vr["gg_enable"]), 1, i, 1, contains="fmi3SetInt32: Int32 variables are discrete")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["der(state_w_x)"]), 1, f64(1.0), 1, contains="der(state_w_x) is a state derivative")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(TIME_VR), 1, f64(1.0), 1, contains="it is set with fmi3SetTime")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    me.s.setFloat64([me.vr["torque_cmd_x"]], [0.5])  # a continuous input: fine


def test_do_step_on_a_model_exchange_instance_and_me_calls_on_a_co_simulation_instance(tmp_path):
    me, cs = Me3(tmp_path, name="me"), Me3(tmp_path, cs=True, name="cs")
    try:
        me.to_continuous_time()
        ev, term, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        err(me, me.s.fmi3DoStep, 0.0, 0.1, fmi3Boolean(True), byref(ev), byref(term), byref(early), byref(last),
            contains="fmi3DoStep: Co-Simulation function, but this instance was created by fmi3InstantiateModelExchange")
        cs.init()
        x = (c_double * 18)()
        err(cs, cs.s.fmi3GetContinuousStates, x, 18,
            contains="fmi3GetContinuousStates: Model Exchange function, but this instance was created by fmi3InstantiateCoSimulation")
        # a Model Exchange FMU state cannot be set into a Co-Simulation instance
        me.s.fmi3Reset(me.c)
        me.to_continuous_time()
        state = me.s.getFMUState()
        cs.s.fmi3Reset(cs.c)
        cs.init()
        err(cs, cs.s.fmi3SetFMUState, state, contains="fmi3SetFMUState: FMU state was taken from a Model Exchange instance")
        me.s.freeFMUState(state)
        # and a Co-Simulation one not into a Model Exchange instance
        cs.s.fmi3Reset(cs.c)
        cs.init()
        state = cs.s.getFMUState()
        err(me, me.s.fmi3SetFMUState, state, contains="taken from a Co-Simulation instance")
        cs.s.freeFMUState(state)
    finally:
        me.close()
        cs.close()


def test_co_simulation_keeps_refusing_event_mode(tmp_path):
    cs = Me3(tmp_path, cs=True)
    try:
        cs.init()
        err(cs, cs.s.fmi3EnterEventMode, contains="hasEventMode = false")
        cs.s.fmi3Reset(cs.c)
        cs.init()
        bs = [fmi3Boolean() for _ in range(5)]
        t = fmi3Float64()
        err(cs, cs.s.fmi3UpdateDiscreteStates, *[byref(b) for b in bs], byref(t), contains="has no Event Mode")
    finally:
        cs.close()


def test_directional_derivatives_of_state_derivatives_follow_the_rigid_body(me):
    """providesDirectionalDerivatives = true in <ModelExchange>: the Jacobian entries a stiff solver asks
    for, against the rigid body by hand. At q = (cos(a/2), 0, 0, sin(a/2)), w = (0, 0, w_z) with J diagonal:
    d(w_z')/d(tau_z) = 1/I_z, d(q_w')/d(w_z) = -q_z/2, d(q_z')/d(w_z) = q_w/2, d(w_x')/d(w_y) = (I_y - I_z) w_z / I_x."""
    ix, iy, iz = 1000.0, 500.0, 700.0
    a, wz = 0.7, 0.03
    me.to_continuous_time()
    n = me.n
    x = (c_double * n)()
    me.s.getContinuousStates(x, n)
    order = [u.variable.derivative.name for u in me.md.derivatives]
    x[order.index("state_att_1")], x[order.index("state_att_4")] = math.cos(a / 2), math.sin(a / 2)
    x[order.index("state_w_z")] = wz
    me.s.setTime(1.0)
    me.s.setContinuousStates(x, n)
    v = me.vr
    d = me.s.getDirectionalDerivative([v["der(state_w_z)"]], [v["torque_cmd_z"]], [1.0])
    assert d[0] == pytest.approx(1 / iz, rel=1e-9)
    d = me.s.getDirectionalDerivative([v["der(state_att_1)"], v["der(state_att_4)"], v["der(state_w_x)"]], [v["state_w_z"]], [1.0])
    assert d[:2] == pytest.approx([-math.sin(a / 2) / 2, math.cos(a / 2) / 2], rel=1e-8)
    assert abs(d[2]) < 1e-12
    d = me.s.getDirectionalDerivative([v["der(state_w_x)"]], [v["state_w_y"]], [1.0])
    assert d[0] == pytest.approx((iy - iz) * wz / ix, rel=1e-7)
    # outputs with respect to states: w_z is the state itself
    assert me.s.getDirectionalDerivative([v["w_z"]], [v["state_w_z"]], [2.0]) == pytest.approx([2.0], rel=1e-9)
    err(me, me.s.fmi3GetDirectionalDerivative, vrs(v["state_w_z"]), 1, vrs(v["state_w_x"]), 1, f64(1.0), 1, f64(0.0), 1,
        contains="is neither a Real output nor a state derivative")
