"""Paper 003 controllers (SlidingModeController, Type2FuzzySmcController) through the packaged FMUs,
against independent references: pyit2fls (interval Gaussian memberships, Karnik–Mendel type reduction),
a numpy evaluation of the sliding variable, the sliding-mode reaching and boundary-layer properties on
AttitudePlant, the equivalent control's ds/dt = 0 on a perfect model (finite differences of the logged
s), wheel-momentum boundedness with magnetorquer dumping, and fmi2Error on bad parameters."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from fmpy.validation import validate_fmu
from pyit2fls import KM_algorithm, gauss_uncert_std_lmf, gauss_uncert_std_umf

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu
from scfmu.fmu import fmu_path

from scfmu.papers.paper003 import commands as paper003
from quat_oracle import q321, qconj, qmul  # independent helpers shared by the tests

MODELS = ["SlidingModeController", "Type2FuzzySmcController"]
AX = "xyz"
INERTIA = np.array([[4.0, 0.05, -0.03], [0.05, 5.0, 0.02], [-0.03, 0.02, 3.5]])
PLANT003 = paper003.PLANT
CMD = paper003.COMMAND


def set_inputs(ctrl: Fmu, q, w, q_ref, w_ref=(0.0, 0.0, 0.0), h=(0.0, 0.0, 0.0)):
    names = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z",
             "w_ref_x", "w_ref_y", "w_ref_z", "h_wheel_x", "h_wheel_y", "h_wheel_z"]
    ctrl.set_reals(names, [*q, *w, *q_ref, *w_ref, *h])


def vec(f: Fmu, name: str) -> np.ndarray:
    return np.array(f.get_reals([f"{name}_{a}" for a in AX]))


def error_signals(q, w, q_ref, lam):
    """q_e,v, q̇_e,v and s for ω_ref = 0 (numpy, from the definitions)."""
    qe = qmul(qconj(q_ref), q)
    if qe[0] < 0:
        qe = -qe
    qv = qe[1:]
    w = np.asarray(w)
    qv_dot = 0.5 * (qe[0] * w + np.cross(qv, w))
    return qv, qv_dot, w + lam * qv


def it2_oracle(e_bar, edot_bar, sigma_lo, sigma_up, transpose=False):
    """(y_l, y_r) from pyit2fls: memberships gauss_uncert_std_{lmf,umf}, product firing, KM_algorithm."""
    table = np.array([[1, 1, 0], [0, -1, 0], [0, 1, 1]], dtype=float)
    if transpose:
        table = table.T
    c = [-1.0, 0.0, 1.0]
    x_e, x_d = np.array([e_bar]), np.array([edot_bar])
    rows = []
    for i in range(3):
        for j in range(3):
            p_i, p_j = [c[i], sigma_lo, sigma_up, 1.0], [c[j], sigma_lo, sigma_up, 1.0]
            lo = gauss_uncert_std_lmf(x_e, p_i)[0] * gauss_uncert_std_lmf(x_d, p_j)[0]
            up = gauss_uncert_std_umf(x_e, p_i)[0] * gauss_uncert_std_umf(x_d, p_j)[0]
            rows.append([table[i, j], table[i, j], lo, up])
    rows = np.array(rows)
    rows = rows[np.argsort(rows[:, 0], kind="stable")]
    return KM_algorithm(rows)


def closed_loop(controller, ctrl_params=None, plant_params=None, t_end=60.0, dt=0.01, log_ctrl=(), log_plant=()):
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": CMD[0], "ref_euler321_pitch": CMD[1], "ref_euler321_yaw": CMD[2]})
    ctrl = Fmu(controller, ctrl_params or {})
    plant = Fmu("AttitudePlant", {**PLANT003, **(plant_params or {})})
    met = Fmu("AttitudeMetrics")
    sim = CoSimulation([cmd, ctrl, plant, met])
    log = {n: (ctrl, n) for n in log_ctrl}
    log.update({n: (plant, n) for n in log_plant})
    try:
        return sim.run(t_end, dt, log)
    finally:
        sim.close()


# ----- packaging ----------------------------------------------------------------------------------
@pytest.mark.parametrize("model", MODELS)
def test_fmu_validates_and_has_the_common_ports(model):
    assert validate_fmu(str(fmu_path(model))) == []
    f = Fmu(model)
    try:
        ins, outs = set(f.inputs()), set(f.outputs())
        for p in ["q_w", "q_x", "w_x", "q_ref_z", "w_ref_y", "h_wheel_x", "h_wheel_y", "h_wheel_z"]:
            assert p in ins
        assert {"torque_cmd_x", "s_x", "q_err_y", "k_gain_z", "torque_eq_x"} <= outs
        assert [f.var(f"h_wheel_{a}").valueReference for a in AX] == [14, 15, 16]
        assert [f.var(f"inertia_{a}").valueReference for a in ("xx", "yy", "zz")] == [100, 101, 102]
    finally:
        f.close()


# ----- the law, one evaluation --------------------------------------------------------------------
@pytest.mark.parametrize("model", MODELS)
def test_torque_matches_the_law_written_in_numpy(model):
    """T = ω×(Îω + h) − Î(λ q̇_e,v) − K sat(s/Φ) for ω_ref = 0, with Î the full nominal inertia."""
    rng = np.random.default_rng(3)
    f = Fmu(model, {"lambda": 0.3, "k_switch": 0.01, "boundary_layer": 0.02})
    try:
        for _ in range(20):
            q = q321(*rng.uniform(-0.6, 0.6, 3))
            q_ref = q321(*rng.uniform(-0.6, 0.6, 3))
            w = rng.uniform(-0.05, 0.05, 3)
            h = rng.uniform(-0.3, 0.3, 3)
            set_inputs(f, q, w, q_ref, h=h)
            qv, qv_dot, s = error_signals(q, w, q_ref, 0.3)
            k = vec(f, "k_gain")
            if model == "SlidingModeController":
                assert np.all(k == 0.01)
            t_eq = np.cross(w, INERTIA @ w + h) - INERTIA @ (0.3 * qv_dot)
            expect = t_eq - k * np.clip(s / 0.02, -1, 1)
            np.testing.assert_allclose(vec(f, "s"), s, rtol=0, atol=1e-14)
            np.testing.assert_allclose(vec(f, "q_err"), qv, rtol=0, atol=1e-14)
            np.testing.assert_allclose(vec(f, "torque_cmd"), expect, rtol=0, atol=1e-14)
    finally:
        f.close()


@pytest.mark.parametrize("transpose", [0, 1])
def test_km_endpoints_agree_with_pyit2fls_on_a_grid(transpose):
    """Through the FMU: y_l, y_r per axis vs pyit2fls's KM_algorithm on the same firing intervals; the gain
    is k (1 + κ y), y = (y_l + y_r)/2."""
    e_scale, edot_scale, k, kappa = 0.05, 0.01, 0.004, 0.7
    f = Fmu("Type2FuzzySmcController", {"e_scale": e_scale, "edot_scale": edot_scale, "k_switch": k, "kappa": kappa,
                                        "table_transpose": transpose, "sigma_lo": 0.3, "sigma_up": 0.5})
    rng = np.random.default_rng(7)
    try:
        n = 0
        for _ in range(60):
            # errors from well inside to beyond the normalisation range
            q = q321(*rng.uniform(-0.15, 0.15, 3))
            w = rng.uniform(-0.03, 0.03, 3)
            set_inputs(f, q, w, [1.0, 0.0, 0.0, 0.0])
            qv, qv_dot, _ = error_signals(q, w, np.array([1.0, 0, 0, 0]), 0.2)
            yl, yr = vec(f, "fuzzy_y_l"), vec(f, "fuzzy_y_r")
            for i in range(3):
                e = float(np.clip(qv[i] / e_scale, -1, 1))
                d = float(np.clip(qv_dot[i] / edot_scale, -1, 1))
                ol, orr = it2_oracle(e, d, 0.3, 0.5, bool(transpose))
                assert yl[i] == pytest.approx(ol, abs=1e-12) and yr[i] == pytest.approx(orr, abs=1e-12), (e, d)
                assert yl[i] <= vec(f, "fuzzy_y")[i] <= yr[i]
                n += 1
            np.testing.assert_allclose(vec(f, "k_gain"), k * (1 + kappa * (yl + yr) / 2), rtol=1e-14)
        assert n == 180
    finally:
        f.close()


def test_equal_widths_reduce_to_the_type1_weighted_average():
    f = Fmu("Type2FuzzySmcController", {"sigma_lo": 0.4, "sigma_up": 0.4})
    table = np.array([[1, 1, 0], [0, -1, 0], [0, 1, 1]], dtype=float)
    rng = np.random.default_rng(11)
    try:
        for _ in range(20):
            q = q321(*rng.uniform(-0.08, 0.08, 3))
            w = rng.uniform(-0.01, 0.01, 3)
            set_inputs(f, q, w, [1.0, 0.0, 0.0, 0.0])
            qv, qv_dot, _ = error_signals(q, w, np.array([1.0, 0, 0, 0]), 0.2)
            y = vec(f, "fuzzy_y")
            for i in range(3):
                e, d = np.clip(qv[i] / 0.05, -1, 1), np.clip(qv_dot[i] / 0.01, -1, 1)
                me = np.exp(-(e - np.array([-1, 0, 1])) ** 2 / (2 * 0.16))
                md = np.exp(-(d - np.array([-1, 0, 1])) ** 2 / (2 * 0.16))
                fire = np.outer(me, md)
                assert y[i] == pytest.approx((fire * table).sum() / fire.sum(), abs=1e-13)
    finally:
        f.close()


# ----- closed loop on AttitudePlant --------------------------------------------------------------
@pytest.mark.parametrize("model", MODELS)
def test_reaches_the_surface_and_stays_in_the_boundary_layer(model):
    """Nominal paper 003 plant (wheels, magnetorquers, gravity gradient): |s| ≤ Φ on every axis after a
    finite reaching time and up to t_end; the attitude then converges (roll 20°, pitch −15°)."""
    phi = 0.005
    r = closed_loop(model, {"k_switch": 0.01, "boundary_layer": phi}, t_end=80.0, log_ctrl=[f"s_{a}" for a in AX],
                    log_plant=["roll", "pitch", "yaw"])
    s = np.column_stack([r[f"s_{a}"] for a in AX])
    inside = np.all(np.abs(s) <= phi * (1 + 1e-6), axis=1)
    assert not inside[0], "starts off the surface (|s(0)| = λ |q_e,v(0)| > Φ)"
    t_reach = r["time"][np.argmax(inside)]
    assert inside.any() and np.all(inside[r["time"] >= t_reach]), "once inside the boundary layer it stays"
    assert t_reach < 20.0, t_reach
    assert abs(math.degrees(r["roll"][-1]) - 20.0) < 0.05 and abs(math.degrees(r["pitch"][-1]) + 15.0) < 0.05


def test_equivalent_control_alone_keeps_s_constant_on_a_perfect_model():
    """k = 0 (T = T_eq), perfect model: plant inertia = controller inertia, ideal torque actuators (no
    limits), no gravity gradient, no disturbance, wheel momentum wired (h_w = 0 in mode 0), an initial
    tumble so that T_eq is not zero. ds/dt from central differences of the logged s is ≈ 0 while
    s(0) ≠ 0 (s is frozen at its initial value); with k > 0 it is of order k/I."""
    tumble = {"init_w_x": 0.02, "init_w_y": -0.01, "init_w_z": 0.015}
    r = closed_loop("SlidingModeController", {"k_switch": 0.0},
                    {"actuator_mode": 0, "mtq_enable": 0, "gg_enable": 0, **tumble}, t_end=30.0,
                    log_ctrl=[f"s_{a}" for a in AX], log_plant=["roll", "pitch"])
    t = r["time"]
    s = np.column_stack([r[f"s_{a}"] for a in AX])
    sdot = np.gradient(s, t, axis=0)
    assert np.linalg.norm(s[0]) > 0.02
    # the loop holds T over each 0.01 s step, so ds/dt is not exactly 0 but O(Δ): measured ≈ 1e-6 rad/s²,
    # against k/I ≈ 2.5e-3 rad/s² for the default switching gain
    assert np.max(np.abs(sdot)) < 5e-6, np.max(np.abs(sdot))
    assert np.max(np.abs(s - s[0])) < 5e-5
    # and the body does move under a non-zero torque
    assert abs(r["roll"][-1] - r["roll"][0]) > math.radians(5.0)


def test_magnetorquer_dumping_keeps_wheel_momentum_bounded_over_one_orbit():
    """One orbit (about 5930 s at 700 km) holding the commanded attitude with gravity gradient on and an
    initial wheel momentum h0 = (0.15, -0.15, 0.15) N m s. Without external torque other than the
    gravity gradient and the magnetorquers, the part of the total momentum along the orbit normal
    cannot be dumped (a dipole field lies close to the plane of a near-polar orbit), the rest can:
    with magnetorquers |h_w| never exceeds |h0| by more than the gravity-gradient drift of the run
    without them, and ends well below |h0|; without them |h_w| stays near |h0| (nothing removes it)."""
    h0 = {"init_h_wheel_x": 0.15, "init_h_wheel_y": -0.15, "init_h_wheel_z": 0.15}
    t_end, dt = 5940.0, 0.1
    runs = {}
    for mtq in (1, 0):
        r = closed_loop("SlidingModeController", {"k_switch": 0.01}, {**h0, "mtq_enable": mtq, "max_internal_step": 0.05},
                        t_end=t_end, dt=dt, log_plant=[f"h_wheel_{a}" for a in AX])
        runs[mtq] = np.linalg.norm(np.column_stack([r[f"h_wheel_{a}"] for a in AX]), axis=1)
    h_on, h_off = runs[1], runs[0]
    n0 = math.sqrt(3) * 0.15
    drift = np.max(np.abs(h_off - h_off[0]))
    assert np.max(h_on) <= h_on[0] + drift + 0.01, (np.max(h_on), h_on[0], drift)
    assert h_on[-1] < 0.8 * n0, h_on[-1]
    assert h_off[-1] > 0.9 * n0 - drift, h_off[-1]


# ----- bad parameters -------------------------------------------------------------------------------
@pytest.mark.parametrize("model,params,word", [
    ("SlidingModeController", {"boundary_layer": 0.0}, "boundary_layer"),
    ("SlidingModeController", {"lambda": -0.2}, "lambda"),
    ("SlidingModeController", {"k_switch": -1.0}, "k_switch"),
    ("SlidingModeController", {"inertia_xy": 10.0}, "inertia"),
    ("Type2FuzzySmcController", {"sigma_lo": 0.6, "sigma_up": 0.5}, "sigma_up"),
    ("Type2FuzzySmcController", {"kappa": 1.5}, "kappa"),
    ("Type2FuzzySmcController", {"e_scale": 0.0}, "e_scale"),
    ("Type2FuzzySmcController", {"table_transpose": 2}, "table_transpose"),
])
def test_bad_parameters_give_fmi2error_with_a_message(model, params, word):
    f = Fmu(model, initialize=False)
    try:
        f.slave.setupExperiment(startTime=0.0)
        f.slave.enterInitializationMode()
        with pytest.raises(Exception):
            for k, v in params.items():
                f.set(k, v)
            f.slave.exitInitializationMode()
        assert any(word in m[2] for m in f.messages), f.messages
    finally:
        f.close()


def test_unconnected_quaternion_fails_loudly():
    f = Fmu("SlidingModeController")
    try:
        with pytest.raises(Exception):
            set_inputs(f, [0.0, 0.0, 0.0, 0.0], [0, 0, 0], [1.0, 0, 0, 0])
            f.get("torque_cmd_x")
            f.do_step(0.0, 0.01)
        assert any("q has norm" in m[2] for m in f.messages), f.messages
    finally:
        f.close()


# ----- the experiment script ------------------------------------------------------------------------
def test_declared_scenario_on_the_engine_equals_the_reference_path():
    """The GA fitness of one candidate and the scenario metrics, computed by the campaign engine on the
    declared scenario (native container loop, Dask worker), equal the loop written out with the reference
    master (scfmu.papers.paper003.commands.simulate_reference: its own FMU set-up, name matching each step): the same
    Gauss–Seidel scheme, so bit for bit. Candidate T2F-SMC with non-default fuzzy coefficients in 003-S."""
    from scfmu import campaign
    from scfmu.papers.paper003 import model as p3
    cand = {"k_switch": 0.004, "e_scale": 0.1, "edot_scale": 0.02, "kappa": 0.7}
    t = 4.0
    ref, _ = paper003.simulate_reference(paper003.Case("Type2FuzzySmcController", cand, p3.DISTURBANCES["S"], t_end=t))
    # the GA path: final ISE/ISF only (one container call for the whole run), on a Dask worker
    ga = p3.ga_campaign("T2FSMC", {"k_switch": 0.004}, ["e_scale", "edot_scale", "kappa"], [(0.1, 0.02, 0.7)], t)
    ga.scenario = ga.scenario.with_overrides(p3.prefixed("plant", p3.DISTURBANCES["S"]))
    row, _ = campaign.run_one(ga.runs()[0])
    assert row["status"] == "ok", row["message"]
    assert row["cost"] == ref["cost"] and row["ise"] == ref["ise"] and row["isf"] == ref["isf"]
    # the scenario path: every sample logged, steady-state error and torque extremes too
    c = p3.scenario_campaign("T2FSMC", "S", cand, t)
    row, _ = campaign.run_one(c.runs()[0])
    for k in ("cost", "ise", "isf", "sse_roll_deg", "sse_pitch_deg", "sse_yaw_deg", "tmax_x", "tmin_z"):
        assert row[k] == ref[k], k
    assert ref["isf"] > 0 and ref["sse_roll_deg"] > 0


def test_monte_carlo_on_the_engine_is_bit_reproducible_and_independent_of_workers(tmp_path):
    """003-U through the campaign engine: the same seed list gives identical rows with 1 and 2 Dask
    workers, and each row equals the reference-path run of the plant scaled by that seed."""
    from scfmu import campaign
    from scfmu.papers.paper003 import model as p3
    seeds = [1, 2, 3]
    c = p3.mc_campaign("T2FSMC", seeds, {}, t_end=3.0)
    t1 = campaign.run(c, tmp_path / "w1", n_workers=1, progress=False)
    t2 = campaign.run(c, tmp_path / "w2", n_workers=2, chunk=1, progress=False)
    rows, rows2 = p3.rows(t1), p3.rows(t2)
    assert len(rows) == len(rows2) == 3
    for x, y in zip(rows, rows2):  # bit-identical, NaN where both are NaN (e.g. settling in 3 s)
        assert x.keys() == y.keys()
        for k in x:
            assert x[k] == y[k] or (isinstance(x[k], float) and math.isnan(x[k]) and math.isnan(y[k])), k
    assert [r["status"] for r in rows] == ["ok"] * 3
    assert len({r["ise"] for r in rows}) == 3, "different seeds, different plants"
    for s, r in zip(seeds, rows):
        ref, _ = paper003.simulate_reference(paper003.Case("Type2FuzzySmcController", {},
                                                          paper003.uncertainty_scales(s), t_end=3.0))
        assert r["ise"] == ref["ise"] and r["isf"] == ref["isf"]
        assert r["p:plant.inertia_scale_y"] == paper003.uncertainty_scales(s)["inertia_scale_y"]
    scales = paper003.uncertainty_scales(5)
    assert all(0.8 <= v <= 1.2 for v in scales.values()) and scales == paper003.uncertainty_scales(5)


def _script(args, timeout=300):
    import subprocess
    r = subprocess.run([sys.executable, "-m", "scfmu", "paper", "003", *map(str, args)], capture_output=True, text=True,
                       timeout=timeout)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r.stdout


def test_quick_tuner_is_reproducible_by_seed_and_independent_of_workers(tmp_path):
    import json
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    _script(["tune", "--quick", "--seed", "3", "--workers", "1", "--out", a])
    _script(["tune", "--quick", "--seed", "3", "--workers", "2", "--out", b])
    ja, jb = json.loads(a.read_text()), json.loads(b.read_text())
    for j in (ja, jb):  # wall times and the worker count may differ; everything else must not
        j.pop("run_time_s"), j.pop("engine")
        for stage in ("GA-SMC", "T2F-SMC"):
            j[stage].pop("wall_s")
    assert ja == jb and ja["seed"] == 3 and ja["GA-SMC"]["generations_run"] == 2
    k = ja["GA-SMC"]["SlidingModeController"]["k_switch"]
    assert 1e-4 <= k <= 0.05 and ja["T2F-SMC"]["Type2FuzzySmcController"]["k_switch"] == k
    t2 = ja["T2F-SMC"]["Type2FuzzySmcController"]
    assert 0.005 <= t2["e_scale"] <= 0.5 and 0.001 <= t2["edot_scale"] <= 0.1 and 0.0 <= t2["kappa"] <= 0.9


def test_quick_scenarios_write_table_csv_and_figures(tmp_path):
    out = _script(["scenarios", "--quick", "--workers", "2", "--out", tmp_path])
    for scen in ("003-N", "003-C", "003-S", "003-W", "003-U"):
        assert scen in out
        assert (tmp_path / f"{scen}.png").stat().st_size > 10_000
    assert "lower ISE" in out and "lower ISF" in out
    rows = (tmp_path / "summary.csv").read_text().splitlines()
    assert len(rows) == 1 + 8 + 2
    assert len((tmp_path / "003-U_runs.csv").read_text().splitlines()) == 1 + 2 * 4
