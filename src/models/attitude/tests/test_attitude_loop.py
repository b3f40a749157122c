"""The first closed loop (AttitudeCommand + PdController + AttitudePlant + AttitudeMetrics in fmpy)
against an independent scipy implementation of the same equations, torque-free conservation laws,
and bit-identical continuation from saved FMU states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu

I_P000 = np.diag([1000.0, 500.0, 700.0])
LARGE = (math.radians(40.0), math.radians(-40.0), math.radians(-60.0))


# ----- independent reference (written from the paper's equations, not from the Rust code) -------------------

def qmul(a, b):
    aw, av = a[0], a[1:]
    bw, bv = b[0], b[1:]
    return np.concatenate([[aw * bw - av @ bv], aw * bv + bw * av + np.cross(av, bv)])


def q321(r, p, y):
    cr, sr = math.cos(r / 2), math.sin(r / 2)
    cp, sp = math.cos(p / 2), math.sin(p / 2)
    cy, sy = math.cos(y / 2), math.sin(y / 2)
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


def conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def rigid_body_rhs(inertia, torque):
    inv = np.linalg.inv(inertia)

    def f(_t, x):
        q, w = x[:4], x[4:]
        qdot = 0.5 * qmul(q, np.concatenate([[0.0], w]))
        wdot = inv @ (torque - np.cross(w, inertia @ w))
        return np.concatenate([qdot, wdot])
    return f


def reference_pd_loop(t_end, dt, command, wn=1.0, zeta=1.0):
    """Sampled-data loop exactly as the master runs it: torque computed at t_k from the state at
    t_k, held over [t_k, t_k + dt] (zero-order hold); each interval integrated by DOP853 with
    rtol = atol = 1e-12."""
    diag = np.diag(I_P000)
    k, kd = wn ** 2 * diag, -2.0 * zeta * wn * diag
    q_ref = q321(*command)
    x = np.array([1.0, 0, 0, 0, 0, 0, 0])
    n = int(round(t_end / dt))
    qs = [x[:4].copy()]
    for i in range(n):
        qe = qmul(conj(x[:4]), q_ref)
        e = 2.0 * qe[0] * qe[1:]
        tau = k * e + kd * x[4:]
        sol = solve_ivp(rigid_body_rhs(I_P000, tau), (i * dt, (i + 1) * dt), x, method="DOP853", rtol=1e-12, atol=1e-12)
        x = sol.y[:, -1]
        x[:4] /= np.linalg.norm(x[:4])
        qs.append(x[:4].copy())
    return np.array(qs)


def angle_between(qa, qb):
    """Rotation angle between attitude quaternions (rows)."""
    dots = np.abs(np.sum(qa * qb, axis=1)).clip(max=1.0)
    return 2.0 * np.arccos(dots)


def pd_loop(t_end, dt):
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": LARGE[0], "ref_euler321_pitch": LARGE[1], "ref_euler321_yaw": LARGE[2]})
    ctrl = Fmu("PdController")
    plant = Fmu("AttitudePlant")
    metrics = Fmu("AttitudeMetrics")
    return CoSimulation([cmd, ctrl, plant, metrics]), plant, metrics


def test_closed_loop_matches_scipy_reference():
    t_end, dt = 60.0, 0.01
    sim, plant, metrics = pd_loop(t_end, dt)
    try:
        r = sim.run(t_end, dt, {f"q_{c}": (plant, f"q_{c}") for c in "wxyz"} | {"alpha": (metrics, "alpha_deg"), "eulerint": (metrics, "eulerint_deg_s")})
    finally:
        sim.close()
    q_fmu = np.column_stack([r["q_w"], r["q_x"], r["q_y"], r["q_z"]])
    q_ref = reference_pd_loop(t_end, dt, LARGE)
    err = angle_between(q_fmu, q_ref)
    print(f"\nclosed loop vs scipy DOP853 (ZOH, dt = {dt} s, 60 s): max attitude difference {err.max():.3e} rad")
    assert err.max() < 1e-6
    # EULERINT from the reference trajectory with the same left-rectangle rule
    alpha_ref = np.degrees(2 * np.arctan2(np.linalg.norm([qmul(conj(q), q321(*LARGE))[1:] for q in q_ref], axis=1),
                                          np.abs([qmul(conj(q), q321(*LARGE))[0] for q in q_ref])))
    eulerint_ref = np.sum(alpha_ref[:-1]) * dt
    print(f"EULERINT over 60 s: FMU {r['eulerint'][-1]:.9f} deg s, reference {eulerint_ref:.9f} deg s")
    assert abs(r["eulerint"][-1] - eulerint_ref) < 1e-6 * eulerint_ref
    assert r["alpha"][-1] < 1e-6, "the loop converges to the command"


def test_torque_free_tumbling_conserves_momentum_and_energy():
    inertia = np.array([[1000.0, 30.0, -20.0], [30.0, 500.0, 10.0], [-20.0, 10.0, 700.0]])
    w0 = (0.05, -0.07, 0.06)
    p = Fmu("AttitudePlant", {"inertia_xx": 1000.0, "inertia_yy": 500.0, "inertia_zz": 700.0, "inertia_xy": 30.0,
                              "inertia_xz": -20.0, "inertia_yz": 10.0, "init_w_x": w0[0], "init_w_y": w0[1], "init_w_z": w0[2],
                              "init_euler321_roll": 0.3, "init_euler321_pitch": -0.2, "init_euler321_yaw": 1.0})
    try:
        sim = CoSimulation([p], unconnected={"torque_cmd_x", "torque_cmd_y", "torque_cmd_z"})
        r = sim.run(100.0, 0.01, {n: (p, n) for n in ["w_x", "w_y", "w_z", "h_total_ref_x", "h_total_ref_y", "h_total_ref_z"]})
    finally:
        p.close()
    w = np.column_stack([r["w_x"], r["w_y"], r["w_z"]])
    energy = 0.5 * np.einsum("ij,jk,ik->i", w, inertia, w)
    h = np.column_stack([r["h_total_ref_x"], r["h_total_ref_y"], r["h_total_ref_z"]])
    e_drift = np.max(np.abs(energy - energy[0])) / energy[0]
    h_drift = np.max(np.linalg.norm(h - h[0], axis=1)) / np.linalg.norm(h[0])
    print(f"\ntorque-free 100 s, RK4 0.01 s: energy drift {e_drift:.2e}, momentum drift {h_drift:.2e} (relative)")
    assert np.linalg.norm(w[-1] - w[0]) > 1e-3, "the body really tumbles (rates change in the body frame)"
    assert e_drift < 1e-9
    assert h_drift < 1e-9


def _snapshot(fmus):
    return [f.slave.getFMUstate() for f in fmus]


def test_restored_states_continue_bit_identically():
    sim, plant, metrics = pd_loop(10.0, 0.01)
    fmus = sim.fmus
    log = {f"q_{c}": (plant, f"q_{c}") for c in "wxyz"} | {"w_x": (plant, "w_x"), "eulerint": (metrics, "eulerint_deg_s")}
    try:
        sim.run(2.0, 0.01, log)
        states = _snapshot(fmus)
        blobs = [f.slave.serializeFMUstate(s) for f, s in zip(fmus, states)]
        first = sim.run(5.0, 0.01, log, t0=2.0)
        for f, s in zip(fmus, states):
            f.slave.setFMUstate(s)
        second = sim.run(5.0, 0.01, log, t0=2.0)
        for k in log:
            assert np.array_equal(first[k], second[k]), f"{k} differs after fmi2SetFMUstate"
        # the serialized bytes restore into fresh, uninitialized instances of the same FMUs
        fresh = [Fmu(f.model, initialize=False) for f in fmus]
        try:
            for f, blob in zip(fresh, blobs):
                f.slave.setFMUstate(f.slave.deSerializeFMUstate(blob))
            sim2 = CoSimulation(fresh)
            p2, m2 = fresh[2], fresh[3]
            third = sim2.run(5.0, 0.01, {f"q_{c}": (p2, f"q_{c}") for c in "wxyz"} | {"w_x": (p2, "w_x"), "eulerint": (m2, "eulerint_deg_s")}, t0=2.0)
            for k in log:
                assert np.array_equal(first[k], third[k]), f"{k} differs after deserialization"
        finally:
            for f in fresh:
                f.close()
        for f, s in zip(fmus, states):
            f.slave.freeFMUstate(s)
    finally:
        sim.close()


def test_same_inputs_give_bit_identical_runs():
    a = pd_loop(5.0, 0.01)
    b = pd_loop(5.0, 0.01)
    try:
        ra = a[0].run(5.0, 0.01, {"q_x": (a[1], "q_x"), "tau": (a[1], "torque_applied_y")})
        rb = b[0].run(5.0, 0.01, {"q_x": (b[1], "q_x"), "tau": (b[1], "torque_applied_y")})
        assert np.array_equal(ra["q_x"], rb["q_x"]) and np.array_equal(ra["tau"], rb["tau"])
    finally:
        a[0].close()
        b[0].close()


@pytest.mark.parametrize("dt", [0.01, 0.05])
def test_controller_torque_is_the_paper_law(dt):
    """PD torque at t = 0 from rest: T = k e^Q with e^Q = 2 q_E,w q_E,v (closed form)."""
    sim, plant, _ = pd_loop(dt, dt)
    ctrl = sim.fmus[1]
    try:
        sim.propagate()
        qe = qmul(conj(np.array([1.0, 0, 0, 0])), q321(*LARGE))
        expected = np.diag(I_P000) * 2 * qe[0] * qe[1:]
        got = np.array(ctrl.get_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]))
        assert np.allclose(got, expected, rtol=1e-14, atol=1e-12)
    finally:
        sim.close()


def test_directional_derivatives_match_the_closed_form():
    """fmi2GetDirectionalDerivative: ∂T/∂w = k_d (diagonal) for the PD law; the plant's state outputs
    do not depend on its inputs, its applied torque does with slope 1 below the limit, 0 above it."""
    ctrl = Fmu("PdController")
    plant = Fmu("AttitudePlant", {"u_max_y": 1.0})
    try:
        vr = lambda f, n: f.var(n).valueReference  # noqa: E731
        d = ctrl.slave.getDirectionalDerivative([vr(ctrl, "torque_cmd_x"), vr(ctrl, "torque_cmd_y"), vr(ctrl, "torque_cmd_z")],
                                                [vr(ctrl, "w_y")], [1.0])
        assert np.allclose(d, [0.0, -1000.0, 0.0], rtol=1e-8, atol=1e-6)
        plant.set("torque_cmd_x", 0.5)
        plant.set("torque_cmd_y", 3.0)  # saturated at 1
        unknowns = [vr(plant, n) for n in ["q_x", "w_x", "torque_applied_x", "torque_applied_y"]]
        d = plant.slave.getDirectionalDerivative(unknowns, [vr(plant, "torque_cmd_x"), vr(plant, "torque_cmd_y")], [1.0, 1.0])
        assert np.allclose(d, [0.0, 0.0, 1.0, 0.0], atol=1e-9)
    finally:
        ctrl.close()
        plant.close()
