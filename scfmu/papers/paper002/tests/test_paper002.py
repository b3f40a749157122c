"""Paper 002: PidController / FopidController FMUs against independent references (scipy binomials,
numpy difference equations), the PSO driver on a problem with a known minimum, bad parameters and the
FMU state round trip."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu, fmu_path
from scfmu.papers.paper002 import tuning as p2t
from scfmu.papers.paper002.model import Scenario, gl_weights, pso_minimize, reference_loop, run_case

H = 0.001


def drive(model: str, params: dict, theta: np.ndarray, theta_ref: float = 0.0) -> np.ndarray:
    """Open loop: feed θ_n, read u_n, doStep (Δ = step) for every sample."""
    f = Fmu(model, params)
    try:
        h = params.get("step", H)
        u = np.empty(len(theta))
        for n, th in enumerate(theta):
            f.set_reals(["theta", "theta_ref"], [th, theta_ref])
            u[n] = f.get("u")
            f.do_step(n * h, h)
        return u
    finally:
        f.close()


@pytest.mark.parametrize("model", ["PidController", "FopidController"])
def test_fmu_validates(model):
    assert validate_fmu(str(fmu_path(model))) == []


@pytest.mark.parametrize("alpha", [0.35, 1.0, 1.7, 2.0, 0.0])
def test_gl_weights_match_scipy_binomials(alpha):
    """Impulse e_0 = 1, e_k = 0 through K_D D^μ only: u_n = h^{-μ} w_n = h^{-μ} (-1)^n binom(μ, n)."""
    n = 300
    theta = np.zeros(n)
    theta[0] = -1.0  # e = θ_ref − θ = 1 at n = 0
    u = drive("FopidController", {"kp": 0.0, "ki": 0.0, "kd": 1.0, "mu": alpha}, theta)
    w = gl_weights(alpha, n) * H ** (-alpha)
    err = np.max(np.abs(u - w) / np.maximum(np.abs(w), 1e-300 + np.abs(w).max() * 1e-15))
    print(f"mu = {alpha}: max relative |u_n − h^-mu (−1)^n binom(mu, n)| = {err:.2e}")
    assert err < 1e-12


def test_fopid_unit_orders_equal_pid_through_fmus():
    rng = np.random.default_rng(5)
    theta = np.cumsum(rng.normal(0, 0.01, 20_000))
    for extra in ({}, {"history_before_start": 1}, {"gl_memory": 500}):
        common = {"kp": 2.0, "ki": 0.7, "kd": 8.0, **extra}
        a = drive("PidController", common, theta, 0.5)
        b = drive("FopidController", {**common, "lambda": 1.0, "mu": 1.0}, theta, 0.5)
        d = np.max(np.abs(a - b))
        print(f"{extra}: max |u_PID − u_FOPID(1, 1)| over 20000 steps = {d:.2e}")
        assert d <= 1e-12


@pytest.mark.parametrize("controller,gains,extra", [
    ("PID", {"kp": 2.0, "ki": 0.1, "kd": 8.0}, {}),
    ("PID", {"kp": 3.0, "ki": 0.5, "kd": 5.0}, {"history_before_start": 1}),
    ("FOPID", {"kp": 2.0, "ki": 0.4, "kd": 6.0, "lambda": 0.8, "mu": 0.9}, {}),
    ("FOPID", {"kp": 2.0, "ki": 0.4, "kd": 6.0, "lambda": 1.3, "mu": 0.6}, {"gl_memory": 700, "history_before_start": 1}),
])
def test_closed_loop_matches_numpy_difference_equations(controller, gains, extra):
    """Linear, unsaturated plant (T_sat = 1e30, M_d = 0): the FMU loop equals the numpy recursion
    (Euler plant, direct GL sums with scipy binomial weights)."""
    sc = Scenario(t_end=4.0, theta_ref_deg=10.0, plant={"torque_limit": 1e30, "md_amp": 0.0, "md_const": 0.0}, **extra)
    a = run_case(controller, gains, sc, record=True)
    b = reference_loop(controller, gains, sc)
    d_th = np.max(np.abs(a["theta"] - b["theta"]))
    d_u = np.max(np.abs(a["u"] - b["u"]) / (1.0 + np.abs(b["u"])))
    print(f"{controller} {extra}: max |θ_FMU − θ_numpy| = {d_th:.2e} rad, max rel |Δu| = {d_u:.2e}")
    assert np.all(np.isfinite(a["theta"])) and np.ptp(a["theta"]) > 0.05
    assert d_th < 1e-11 and d_u < 1e-10


@pytest.mark.parametrize("controller,model,gains", [
    ("FOPID", "FopidController", {"kp": 5.0, "ki": 1.0, "kd": 10.0, "lambda": 0.9, "mu": 1.1}),
    ("PID", "PidController", {"kp": 5.0, "ki": 1.0, "kd": 10.0}),
])
def test_project_master_gives_the_same_loop(controller, model, gains):
    """scfmu.master.CoSimulation (wired by port name, theta_ref set once) equals the direct loop."""
    sc = Scenario(t_end=2.0)
    ctrl = Fmu(model, {**gains, "step": H})
    plant = Fmu("SingleAxisPlant", {"integrator": 1, "max_internal_step": H})
    ctrl.set("theta_ref", math.radians(sc.theta_ref_deg))
    sim = CoSimulation([ctrl, plant], unconnected={"theta_ref"})
    try:
        out = sim.run(sc.t_end, H, {"theta": (plant, "theta"), "u": (ctrl, "u")})
    finally:
        sim.close()
    ref = run_case(controller, gains, sc, record=True)
    assert np.array_equal(out["theta"], ref["theta"]) and np.array_equal(out["u"], ref["u"])


def test_nominal_loop_with_saturation_and_disturbance_matches_numpy():
    sc = Scenario(t_end=3.0)
    a = run_case("FOPID", {"kp": 5.0, "ki": 1.0, "kd": 10.0, "lambda": 0.9, "mu": 1.1}, sc, record=True)
    b = reference_loop("FOPID", {"kp": 5.0, "ki": 1.0, "kd": 10.0, "lambda": 0.9, "mu": 1.1}, sc)
    assert np.max(np.abs(a["applied_torque"])) == 1.0  # saturation active
    assert np.max(np.abs(a["theta"] - b["theta"])) < 1e-11


def test_pso_finds_known_minimum_and_is_reproducible():
    """Shifted, scaled quadratic plus a Rastrigin-like ripple, minimum 0 at x* inside the box."""
    x_star = np.array([3.0, 12.5, 0.4, 1.6])
    r1 = pso_minimize(_test_cost, [0, 0, 0, 0], [20, 20, 2, 2], n_particles=30, max_iter=300, seed=7, progress=False)
    r2 = pso_minimize(_test_cost, [0, 0, 0, 0], [20, 20, 2, 2], n_particles=30, max_iter=300, seed=7, workers=2,
                      progress=False)
    print(f"PSO: x = {np.round(r1['x'], 6)}, cost = {r1['cost']:.2e}, {r1['iterations']} iterations")
    assert np.allclose(r1["x"], x_star, atol=1e-3) and r1["cost"] < 1e-5
    assert r1["x"] == r2["x"] and r1["history"] == r2["history"]  # same seed, any worker count
    assert r1["iterations"] < 300  # the stall rule stopped it


def _test_cost(x):
    x_star = np.array([3.0, 12.5, 0.4, 1.6])
    z = (np.asarray(x) - x_star) / np.array([20, 20, 2, 2])
    return float(np.sum(100 * z**2) + 0.1 * np.sum(1 - np.cos(40 * np.pi * z)))


@pytest.mark.parametrize("model,params,name", [
    ("FopidController", {"lambda": 2.5}, "lambda"),
    ("FopidController", {"mu": -0.1}, "mu"),
    ("FopidController", {"gl_memory": -1}, "gl_memory"),
    ("PidController", {"gl_memory": -5}, "gl_memory"),
    ("PidController", {"step": 0.0}, "step"),
    ("FopidController", {"history_before_start": 2}, "history_before_start"),
    ("PidController", {"kd": math.nan}, "kd"),
])
def test_bad_parameters_are_fmi_errors_with_message(model, params, name):
    f = Fmu(model, initialize=False)
    try:
        f.slave.setupExperiment(startTime=0.0)
        f.slave.enterInitializationMode()
        with pytest.raises(Exception):  # refused when set (non-finite) or at exitInitializationMode
            for k, v in params.items():
                f.set(k, v)
            f.slave.exitInitializationMode()
        assert any(name in m[2] for m in f.messages), f.messages
    finally:
        f.close()


@pytest.mark.parametrize("model", ["PidController", "FopidController"])
def test_step_not_a_multiple_of_the_sample_time_is_an_error(model):
    """A step of k sample times is k samples with the inputs held (0.002 s = 2 samples of 0.001 s);
    a step that is no integer multiple is refused with a message naming the sample time."""
    f = Fmu(model, {"step": 0.001})
    try:
        f.do_step(0.0, 0.001)
        f.do_step(0.001, 0.002)
        with pytest.raises(Exception):
            f.do_step(0.003, 0.0015)
        assert any("integer multiple" in m[2] and "step = 0.001" in m[2] for m in f.messages), f.messages
    finally:
        f.close()


@pytest.mark.parametrize("model,extra", [("FopidController", {"lambda": 0.7, "mu": 1.3}), ("PidController", {})])
def test_state_serialize_restore_continues_bit_identically(model, extra):
    """Serialize after 3000 steps (history crosses several FFT block levels), continue 3000 steps; a
    fresh instance deserialized from the bytes gives bit-identical outputs."""
    params = {"kp": 2.0, "ki": 0.5, "kd": 4.0, **extra}
    theta = np.sin(np.arange(6000) * 0.003) * 0.3
    a = Fmu(model, params)
    b = Fmu(model, params)
    try:
        for n in range(3000):
            a.set_reals(["theta", "theta_ref"], [theta[n], 0.2])
            a.do_step(n * H, H)
        blob = a.slave.serializeFMUstate(a.slave.getFMUstate())
        b.slave.setFMUstate(b.slave.deSerializeFMUstate(blob))
        ua, ub = [], []
        for n in range(3000, 6000):
            for f, out in ((a, ua), (b, ub)):
                f.set_reals(["theta", "theta_ref"], [theta[n], 0.2])
                out.append(f.get("u"))
                f.do_step(n * H, H)
        assert np.array_equal(np.array(ua).view(np.int64), np.array(ub).view(np.int64))
    finally:
        a.close()
        b.close()


def test_tuner_and_sweeps_quick(tmp_path):
    gains = tmp_path / "gains.json"
    r = subprocess.run([sys.executable, "-m", "scfmu", "paper", "002", "tune", "--quick", "--out", gains,
                        "--controllers", "PD,PID,FOPD,FOPID"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    r = subprocess.run([sys.executable, "-m", "scfmu", "paper", "002", "sweeps", "--quick", "--digits", "--gains", gains,
                        "--out", tmp_path / "sweeps"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    for run in ("002-1_step_responses", "002-2_phase_plane", "002-3", "002-4", "002-5", "002-6", "002-7"):
        assert (tmp_path / "sweeps" / f"{run}.csv").exists() and (tmp_path / "sweeps" / f"{run}.png").exists()
    assert "002-6" in r.stdout and (tmp_path / "sweeps" / "summary.csv").exists()
    rows = (tmp_path / "sweeps" / "002-7.csv").read_text().splitlines()
    assert rows[0].startswith("inertia_kg_m2,wheel_gain,mae_deg_PD") and rows[1].startswith("7.7,1.0,")
    assert rows[-1].startswith("9.9,5.0,")


def test_declared_scenario_equals_the_tuner_loop():
    """The declared scenario paper002/FOPID (tuned gains, wired by port name, run on the lean master)
    is the tuner's direct two-FMU loop, bit for bit."""
    import json

    from scfmu.papers.paper002 import model as p2
    from scfmu import scenario as scenarios
    from scfmu.engines import simulate

    gains = json.loads(p2.GAINS_FILE.read_text())["controllers"]["FOPID"]["gains"]
    ref = p2.run_case("FOPID", gains, p2.Scenario(), record=True)
    got = simulate(scenarios.get("paper002/FOPID"), engine="lean")
    assert np.array_equal(got["theta"], ref["theta"])
    assert np.array_equal(got["u"], ref["u"])


# ----- the tuner on the campaign engine ----------------------------------------------------------------
ENGINE_GAINS = {"kp": 5.0, "ki": 1.0, "kd": 10.0, "lambda": 0.9, "mu": 1.1}


@pytest.mark.parametrize("controller", ["PD", "PID", "FOPD", "FOPID"])
def test_engine_cost_equals_direct_loop_and_numpy(controller):
    """One gain set, 11 s (so the t >= 10 s penalty window is in play): the cost of the campaign run
    (native path, scenario paper002/<controller> + gain overrides) equals the cost of the direct two-FMU
    loop of the old tuner to round-off (the engine sees θ_ref through radians → degrees) and the cost of
    the independent numpy difference equations to 1e-9."""

    sc = Scenario(t_end=11.0)
    row = p2t.engine_cost(controller, ENGINE_GAINS, sc)
    direct = run_case(controller, ENGINE_GAINS, sc)
    numpy_ref = reference_loop(controller, ENGINE_GAINS, sc)
    print(f"{controller}: engine {row['cost']!r}, direct loop {direct['cost']!r}, numpy {numpy_ref['cost']!r}")
    assert row["status"] == "ok"
    assert abs(row["cost"] - direct["cost"]) <= 1e-12 * direct["cost"]
    assert abs(row["mae_deg"] - numpy_ref["mae_deg"]) < 1e-9
    assert abs(row["late_max_deg"] - numpy_ref["late_max_deg"]) < 1e-9
    assert (row["cost"] > 1000) == (numpy_ref["cost"] > 1000)
    assert p2t.row_cost({"status": "nonfinite", "cost": float("nan")}) == 1e6 + 1000


def test_engine_tuner_same_for_any_worker_count_and_resumes(tmp_path):
    """Tiny swarms (3 particles, 3 iterations, PD and FOPD in lockstep, 11 s runs): in this process and
    on a 2-worker Dask cluster the swarms follow the same trajectory; a tuning interrupted after its
    second iteration and resumed from its checkpoint ends identically; the reported best cost is the
    direct loop's cost of the reported gains."""
    from scfmu import campaign

    sc = Scenario(t_end=11.0)
    kw = dict(n_particles=3, max_iter=3, seed=2, progress=False)
    serial = p2t.tune(["PD", "FOPD"], sc, **kw)
    client, cluster = campaign._client(None, 2)
    try:
        dask = p2t.tune(["PD", "FOPD"], sc, client=client, **kw)
    finally:
        client.close()
        cluster.close()

    class Kill(Exception):
        pass

    def kill_after_two(swarms, info):
        if min(s.it for s in swarms.values()) == 2:
            raise Kill

    ck = tmp_path / "ck.json"
    with pytest.raises(Kill):
        p2t.tune(["PD", "FOPD"], sc, checkpoint=ck, on_round=kill_after_two, **kw)
    # a checkpoint from another FMU build is not resumed: the swarms start again at iteration 0
    import json
    saved = ck.read_text()
    st = json.loads(saved)
    st["setup"]["fmus"]["PidController"] = "0" * 64
    ck.write_text(json.dumps(st))
    starts = []

    def note_first_round(swarms, info):
        starts.append(min(s.it for s in swarms.values()))
        raise Kill

    with pytest.raises(Kill):
        p2t.tune(["PD", "FOPD"], sc, checkpoint=ck, on_round=note_first_round, **kw)
    assert starts == [1]  # after its first iteration, not the third
    ck.write_text(saved)
    resumed = p2t.tune(["PD", "FOPD"], sc, checkpoint=ck, **kw)
    for c in ("PD", "FOPD"):
        print(c, serial[c]["history"], serial[c]["gains"])
        assert serial[c]["seed"] == {"PD": 2, "FOPD": 4}[c]
        for other in (dask, resumed):
            assert other[c]["history"] == serial[c]["history"] and other[c]["x"] == serial[c]["x"]
        assert serial[c]["iterations"] == 3 and serial[c]["stop"] == "max_iter"
        direct = run_case(c, serial[c]["gains"], sc)["cost"]
        assert abs(serial[c]["cost"] - direct) <= 1e-12 * direct


@pytest.mark.parametrize("controller,gains,sc", [
    ("PD", {"kp": 5.0, "kd": 10.0}, Scenario(t_end=2.0)),
    ("PID", {"kp": 3.0, "ki": 0.5, "kd": 5.0}, Scenario(t_end=2.0, history_before_start=1,
                                                        plant={"inertia_scale": 1.2, "wheel_gain": 2.0})),
    ("FOPD", {"kp": 5.0, "kd": 10.0, "mu": 0.8}, Scenario(t_end=2.0, theta_ref_deg=10.0)),
    ("FOPID", {"kp": 5.0, "ki": 1.0, "kd": 10.0, "lambda": 0.9, "mu": 1.1}, Scenario(t_end=2.0, gl_memory=300)),
])
def test_run_case_is_the_reference_master_run_of_the_loop_scenario(controller, gains, sc):
    """run_case (the loop scenario on the native engine) equals, bit for bit, the reference master's run
    of the same scenario (fmpy high-level calls, the tests' oracle), plant and memory options included."""
    from scfmu.engines import simulate
    from scfmu.papers.paper002 import model as p2

    a = run_case(controller, gains, sc, record=True)
    ref = simulate(p2.loop_scenario(controller, gains, sc), "reference")
    for k in ("theta", "omega", "u", "applied_torque"):
        assert np.array_equal(a[k].view(np.int64), ref[k].view(np.int64)), k
    assert np.array_equal(a["t"], ref["time"])
    assert a["cost"] == p2.cost_terms(ref["theta"], sc)["cost"]
