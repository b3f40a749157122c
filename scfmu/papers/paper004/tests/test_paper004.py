"""Paper 004 FMUs (FeedbackLinearizingController, ReferenceCorrector) and the spline optimisation,
checked against independent references: a numpy implementation of the law written from the
equations, scipy's not-a-knot CubicSpline, the closed-loop error poles -1 +- sqrt(2)/2 identified from
a logged run, the corrector's derived property (004-3 = 004-3ol), the fault limit, and fmi2Error on bad
parameters and at the singular attitude."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from scipy.interpolate import CubicSpline

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu
from scfmu.papers.paper004 import model as P
from scfmu.papers.paper004.data import data_file

NODES_JSON = data_file("nodes.json")
I = np.array(P.INERTIA)


# ---- independent numpy law (paper 004 Eqs. 1-3, written from the equations) --------------------
def skew(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def law_numpy(q, w, qr_v, qr_dot, qr_ddot, inertia, kq, kqd):
    qw, qv = q[0], np.asarray(q[1:])
    m = qw * np.eye(3) + skew(qv)
    qv_dot = 0.5 * m @ w                      # = 1/2 (q_w w + q_v x w)
    ix, iy, iz = inertia
    g1, g2, g3 = (iy - iz) / ix, (iz - ix) / iy, (ix - iy) / iz
    chi = np.array([
        -0.25 * qv[0] * w @ w + 0.5 * (g1 * qw * w[1] * w[2] - g2 * qv[2] * w[0] * w[2] + g3 * qv[1] * w[0] * w[1]),
        -0.25 * qv[1] * w @ w + 0.5 * (g1 * qv[2] * w[1] * w[2] + g2 * qw * w[0] * w[2] - g3 * qv[0] * w[0] * w[1]),
        -0.25 * qv[2] * w @ w + 0.5 * (-g1 * qv[1] * w[1] * w[2] + g2 * qv[0] * w[0] * w[2] + g3 * qw * w[0] * w[1]),
    ])
    u2 = qr_ddot - kqd * (qv_dot - qr_dot) - kq * (qv - qr_v)
    u1 = np.linalg.solve(m, 2.0 * (u2 - chi))
    return np.asarray(inertia) * u1


def test_controller_matches_numpy_law_on_random_states():
    rng = np.random.default_rng(4)
    inertia = np.array([449.5, 264.5, 312.5]) * rng.uniform(0.5, 2.0, 3)
    kq, kqd = rng.uniform(0.1, 2.0, 3), rng.uniform(0.5, 4.0, 3)
    params = {f"inertia_{a}{a}": inertia[i] for i, a in enumerate("xyz")}
    params.update({f"k_q_{a}": kq[i] for i, a in enumerate("xyz")})
    params.update({f"k_qdot_{a}": kqd[i] for i, a in enumerate("xyz")})
    c = Fmu("FeedbackLinearizingController", params)
    try:
        worst = 0.0
        for _ in range(200):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            if abs(q[0]) < 0.05:
                continue
            qr = rng.normal(size=4)
            qr /= np.linalg.norm(qr)
            w, qd, qdd = rng.normal(scale=0.2, size=3), rng.normal(scale=0.05, size=3), rng.normal(scale=0.01, size=3)
            names = ([f"q_{s}" for s in "wxyz"] + [f"w_{a}" for a in "xyz"] + [f"q_ref_{s}" for s in "wxyz"]
                     + [f"q_ref_dot_{a}" for a in "xyz"] + [f"q_ref_ddot_{a}" for a in "xyz"])
            c.set_reals(names, [*q, *w, *qr, *qd, *qdd])
            got = np.array(c.get_reals([f"torque_cmd_{a}" for a in "xyz"]))
            want = law_numpy(q, w, qr[1:], qd, qdd, inertia, kq, kqd)
            worst = max(worst, float(np.max(np.abs(got - want)) / (1.0 + np.max(np.abs(want)))))
        assert worst < 1e-12, worst
    finally:
        c.close()


def test_unsaturated_error_dynamics_have_the_design_poles():
    """Healthy, unlimited plant, constant reference (corrector mode 0): e = q_v obeys
    e'' + 2 e' + 0.5 e = 0. An AR(2) model fitted to the logged e(t_k) of all three axes gives the
    discrete poles z, and ln(z)/dt the continuous ones: -1 -+ sqrt(2)/2 = -0.2929, -1.7071 1/s."""
    dt = 0.001
    init = {"roll": 10.0, "pitch": -6.0, "yaw": 4.0}
    plant_p = P.plant_params(1.0, init)
    plant_p.update({f"u_max_{a}": 1e30 for a in "xyz"}, max_internal_step=dt, init_w_x=0.01, init_w_y=-0.02, init_w_z=0.005)
    corr = Fmu("ReferenceCorrector", P.corrector_params(0, None, 1.0, init))
    ctrl = Fmu("FeedbackLinearizingController", P.controller_params())
    plant = Fmu("AttitudePlant", plant_p)
    sim = CoSimulation([corr, ctrl, plant])
    try:
        r = sim.run(8.0, dt, {f"q_{a}": (plant, f"q_{a}") for a in "xyz"})
    finally:
        sim.close()
    rows, rhs = [], []
    for a in "xyz":
        e = r[f"q_{a}"]
        rows.append(np.column_stack([e[1:-1], e[:-2]]))
        rhs.append(e[2:])
    (a1, a2), *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)
    z = np.roots([1.0, -a1, -a2])
    poles = np.sort(np.log(z.real) / dt)
    assert np.all(np.abs(z.imag) < 1e-12)
    want = np.array([-1 - math.sqrt(0.5), -1 + math.sqrt(0.5)])
    assert np.allclose(poles, want, rtol=2e-3), poles


def test_spline_output_equals_scipy_not_a_knot():
    """u_ol through the FMU equals scipy's CubicSpline(bc_type="not-a-knot") at the node times and in
    between, and is 0 after the last node."""
    rng = np.random.default_rng(7)
    nodes = rng.uniform(-1.0, 1.0, (3, 6))
    t = np.unique(np.concatenate([np.arange(0.0, 22.0, 0.137), P.NODE_TIMES]))
    corr = Fmu("ReferenceCorrector", P.corrector_params(0, nodes, 0.1, P.INIT_DEFAULT_DEG))
    got = []
    try:
        for tk in t:
            if tk > corr.time:
                corr.do_step(corr.time, tk - corr.time)
            got.append(corr.get_reals([f"u_ol_{a}" for a in "xyz"]))
    finally:
        corr.close()
    got = np.array(got)
    ref = CubicSpline(P.NODE_TIMES, nodes.T, bc_type="not-a-knot")(t)
    ref[t > 20.0] = 0.0
    assert np.max(np.abs(got - ref)) < 1e-13
    at_nodes = got[np.searchsorted(t, P.NODE_TIMES)]
    assert np.max(np.abs(at_nodes - nodes.T)) < 1e-13


@pytest.fixture(scope="module")
def nodes():
    rep = json.loads(NODES_JSON.read_text())
    return np.array([rep["nodes_N_m"][a] for a in "xyz"]), rep


def test_committed_optimisation_is_feasible_and_within_budget(nodes):
    n, rep = nodes
    o = rep["optimiser"]
    assert o["status"] == "converged" and o["evaluations"] <= 300
    assert np.all(np.abs(n) <= 1.0 + 1e-12) and np.all(n[:, -1] == 0.0)
    r = P.run_open_loop(n, P.A_FAULT, P.INIT_DEFAULT_DEG)
    w = np.degrees(np.abs([r[f"w_{a}"][-1] for a in "xyz"]))
    e = np.degrees(np.abs([r[k][-1] for k in ("roll", "pitch", "yaw")]))
    assert w.max() <= 0.01 and e.max() <= 0.1


def test_corrected_closed_loop_reproduces_open_loop_to_round_off(nodes):
    n, _ = nodes
    ol = P.run_open_loop(n, P.A_FAULT, P.INIT_DEFAULT_DEG)
    cl = P.run_closed_loop(1, P.A_FAULT, P.INIT_DEFAULT_DEG, nodes=n)
    for k in ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]:
        assert np.max(np.abs(cl[k] - ol[k])) < 1e-13, k
    for a in "xyz":
        assert np.max(np.abs(cl[f"torque_applied_{a}"] - ol[f"torque_applied_{a}"])) < 1e-11
        # the reference output equals the plant attitude (the corrector's copy is the plant)
        assert np.max(np.abs(cl[f"q_ref_{a}"] - cl[f"q_{a}"])) < 1e-13


def test_torque_never_exceeds_the_fault_limit(nodes):
    n, _ = nodes
    for r in (P.run_closed_loop(0, P.A_FAULT, P.INIT_DEFAULT_DEG), P.run_closed_loop(1, P.A_FAULT, P.INIT_DEFAULT_DEG, nodes=n)):
        applied = np.array([r[f"torque_applied_{a}"] for a in "xyz"])
        assert np.max(np.abs(applied)) <= 1.0
    cmd = np.array([r[f"torque_cmd_{a}"] for a in "xyz"])
    assert np.max(np.abs(cmd)) <= 1.0 + 1e-9  # corrected loop commands the (clipped) open-loop torque
    r2 = P.run_closed_loop(0, P.A_FAULT, P.INIT_DEFAULT_DEG, t_end=2.0)
    assert np.max(np.abs([r2[f"torque_cmd_{a}"] for a in "xyz"])) > 1.0  # case 2 asks for more and is clipped


def _init_error(model, params):
    f = Fmu(model, initialize=False)
    try:
        f.slave.setupExperiment(startTime=0.0)
        f.slave.enterInitializationMode()
        with pytest.raises(FMICallException) as e:  # at fmi2SetReal (non-finite) or at exit
            for k, v in params.items():
                f.set(k, v)
            f.slave.exitInitializationMode()
        assert e.value.status == 3
        return " ".join(m[2] for m in f.messages)
    finally:
        f.close()


@pytest.mark.parametrize("model,params,word", [
    ("FeedbackLinearizingController", {"k_q_x": -0.5}, "k_q_x"),
    ("FeedbackLinearizingController", {"k_qdot_z": 0.0}, "k_qdot_z"),
    ("FeedbackLinearizingController", {"inertia_yy": 0.0}, "inertia_yy"),
    ("ReferenceCorrector", {"mode": 2}, "mode"),
    ("ReferenceCorrector", {"effectiveness_y": 1.5}, "effectiveness_y"),
    ("ReferenceCorrector", {"spline_t_end": -1.0}, "spline_t_end"),
    ("ReferenceCorrector", {"node_z_3": float("nan")}, "node_z_3"),
    ("ReferenceCorrector", {"max_internal_step": 0.0}, "max_internal_step"),
])
def test_bad_parameters_give_fmi2error_naming_the_parameter(model, params, word):
    assert word in _init_error(model, params)


def test_singular_attitude_gives_fmi2error_not_nan():
    c = Fmu("FeedbackLinearizingController")
    try:
        c.set_reals(["q_w", "q_x", "q_y", "q_z"], [0.0, 0.6, 0.0, 0.8])
        with pytest.raises(FMICallException) as e:
            c.get_reals(["torque_cmd_x"])
        assert e.value.status == 3
        assert any("singular" in m[2] for m in c.messages), c.messages
    finally:
        c.close()


def test_stress_case_is_reported_infeasible():
    res = P.optimise(P.INIT_STRESS_DEG, x0=np.zeros(15), budget=120)
    assert res.status.startswith("infeasible") and res.evaluations <= 120, res.status
    assert not res.terminal["pass"]


def test_case_script_quick(tmp_path):
    r = subprocess.run([sys.executable, "-m", "scfmu", "paper", "004", "cases", "--quick", "--nodes", str(NODES_JSON),
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "| 004-3 |" in r.stdout and "| 004-3ol |" in r.stdout
    assert (tmp_path / "summary.csv").exists()


def test_declared_scenario_equals_the_case_runner():
    """The declared scenario paper004/3 (corrector with the committed nodes for the calibrated start,
    controller, faulty plant, wired by port name) reproduces the case script's closed loop bit for bit on
    the lean master."""
    import json

    from scfmu.papers.paper004 import model as p4
    from scfmu import scenario as scenarios
    from scfmu.engines import simulate

    rep = json.loads(NODES_JSON.with_name("nodes_calibrated.json").read_text())
    init = p4.init_deg_scaled(p4.INIT_SCALE_CALIBRATED)
    assert rep["initial_euler321_deg"] == init
    nodes = np.array([rep["nodes_N_m"][a] for a in p4.AXES])
    ref = p4.run_closed_loop(1, p4.A_FAULT, init, nodes=nodes)
    got = simulate(scenarios.get("paper004/3"), engine="lean")
    for k in ["q_w", "q_x", "w_x", "w_y", "w_z", "torque_applied_x", "torque_applied_z"]:
        assert np.array_equal(got[k], ref[k]), k


def test_open_loop_engine_equals_the_fmpy_loop_and_restores_its_state():
    """The optimiser's plant runs (scfmu.engines.lean.OpenLoop: raw FMI calls, initial state restored
    by fmi2SetFMUstate) end, bit for bit, where run_open_loop's fmpy high-level loop on a fresh FMU ends,
    run after run."""
    rng = np.random.default_rng(4)
    t_end = 2.0
    n = int(round(t_end / P.DT))
    plant = P.open_loop_plant(P.plant_params(P.A_FAULT, P.INIT_DEFAULT_DEG))
    try:
        for _ in range(3):
            nodes = np.column_stack([rng.uniform(-1, 1, (3, P.N_NODES - 1)), np.zeros(3)])
            got = plant.run(P.spline_torque(nodes, np.arange(n) * P.DT), P.DT)
            ref = P.run_open_loop(nodes, P.A_FAULT, P.INIT_DEFAULT_DEG, t_end=t_end)
            want = np.array([ref[k][-1] for k in P.PLANT_OUT])
            assert np.array_equal(got.view(np.int64), want.view(np.int64)), (got, want)
        assert plant.runs == 3
    finally:
        plant.close()
