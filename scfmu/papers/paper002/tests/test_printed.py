"""Paper 002 as printed: the readings' mechanics against independent references (numpy Grünwald–Letnikov, the
degree reading as a gain scale) and the candidate sets."""

import math

import numpy as np
import pytest

from scfmu.fmu import Fmu
from scfmu.papers.paper002 import model as p2
from scfmu.papers.paper002 import printed as P
from scfmu.report import common
from scfmu.report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED


@pytest.mark.parametrize("model,mu", [("FopidController", 0.6), ("FopidController", 1.3), ("PidController", 1.0)])
def test_derivative_on_measurement_is_history_before_start(model, mu):
    """With a constant reference and history_before_start = 1, K_D D^μ e = −K_D D^μ θ where θ is extended by
    θ_0 into the past (numpy GL with scipy binomial weights, S_∞ = 0 for μ > 0)."""
    h, n, ref = 0.001, 400, 0.5
    k = np.arange(n)
    theta = 0.2 * np.sin(3.0 * k * h) + 0.1 * (k * h) ** 2 + 0.05           # θ_0 = 0.05 ≠ 0
    params = {"kp": 0.0, "ki": 0.0, "kd": 1.7, "step": h, "history_before_start": 1}
    if model == "FopidController":
        params["mu"] = mu
    f = Fmu(model, params)
    try:
        u = []
        for i in range(n):
            f.set_reals(["theta", "theta_ref"], [theta[i], ref])
            u.append(f.get_reals(["u"])[0])
            f.do_step(i * h, h)
    finally:
        f.close()
    w = p2.gl_weights(mu, n)
    s = np.cumsum(w)
    want = np.array([-1.7 * h ** -mu * (np.dot(w[: i + 1], theta[i::-1]) - theta[0] * s[i]) for i in range(n)])
    err = np.max(np.abs(np.array(u) - want)) / np.max(np.abs(want))
    print(f"{model} μ = {mu}: max relative |u − numpy| = {err:.2e}")
    assert err < 1e-9


def test_degree_reading_scales_every_gain_but_not_the_orders():
    ov = P.overrides("FOPID", {"kp": 2.0, "ki": 0.1, "kd": 16.18, "lambda": 0.77, "mu": 0.16}, ("deg", "none", "on error"))
    f = 180.0 / math.pi
    assert ov["controller.kp"] == 2.0 * f and ov["controller.ki"] == 0.1 * f and ov["controller.kd"] == 16.18 * f
    assert ov["controller.lambda"] == 0.77 and ov["controller.mu"] == 0.16 and ov["plant.torque_limit"] >= 1e30
    ov = P.overrides("PD", {"kp": 0.6, "kd": 1.44}, ("rad", "10 N·m", "on measurement"))
    assert ov == {"controller.kp": 0.6, "controller.kd": 1.44, "plant.torque_limit": 10.0,
                  "controller.history_before_start": 1}


def test_every_printed_candidate_runs():
    rep = common.reported("scfmu.papers.paper002")
    sets = P.gain_sets(rep)
    for g in rep["gains"]:
        got = {s_[g["gain"]] for s_ in sets[g["controller"]]}
        assert got == {float(x) for x in g["candidates"]}, g
    assert {k: len(v) for k, v in sets.items()} == {"PD": 3, "FOPD": 11, "PID": 19, "FOPID": 10}
    assert len(P.readings()) == 12 and P.DEFAULT in P.readings()


def test_claim_verdict_names_the_readings():
    r = P.readings()
    every = {x: {"C": (4, 4)} for x in r}
    assert P.claim_verdict(every, "C")[0] == CONFIRMED
    none = {x: {"C": (0, 4)} for x in r}
    assert P.claim_verdict(none, "C")[0] == NOT_CONFIRMED
    mixed = {**none, r[0]: {"C": (4, 4)}, r[1]: {"C": (1, 4)}}
    v, ev, some = P.claim_verdict(mixed, "C")
    assert v == DEPENDS and ev == [P.name(r[0])] and some == [P.name(r[1])]


def test_shares_count_candidate_combinations():
    """Synthetic results: FOPD better than PD for one of two FOPD sets, FOPID better than PID everywhere."""
    from scfmu.papers.paper002 import report as r2

    def m(x):
        return {"mae_deg": x, "settling_s": x, "overshoot_pct": x}
    res = {"PD": [m(2.0)], "PID": [m(3.0), m(3.0)], "FOPD": [m(1.0), m(5.0)], "FOPID": [m(1.0)]}
    results = {c: {rd: v for rd in P.readings()} for c, v in res.items()}
    s = P.shares(results, r2.pair_rule, r2.phase_rule, r2.PAIRS)[P.DEFAULT]
    assert s["FOPD vs PD"] == (1, 2) and s["FOPID vs PID"] == (2, 2)
    assert s["C002-1"] == (2, 4) and s["C002-2"] == (2, 4)        # PD (2) not worse than PID (3)
    t = P.table({rd: s for rd in P.readings()}, results)
    assert t.rows[0][1:5] == ["1 / 2", "2 / 2", "2 / 4", "2 / 4"]
