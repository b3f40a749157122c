"""The ``Mekf``'s coarse re-initialisation (inputs ``q_coarse``, ``init_request``; parameter ``sigma_att_coarse``)
through the packaged FMU (issue 44).

Independent truth and sensors written here in numpy (seeded): a rotation with a time-varying rate integrated on
a fine grid, a 100 Hz gyro (rate + random-walk bias drawn from N(0, sigma_b0^2) + angle random walk, the noise
densities of ``scripts/mekf_consistency.py``) and a 5 Hz star tracker (5 / 41 arcsec). Each run is re-initialised
once, at 10.1 s (between two star-tracker samples), from a coarse attitude 5 deg off the truth about a random
axis: per axis the variance (5 deg)^2 / 3 = (0.0504 rad)^2, what the default sigma_att_coarse = 0.05 rad claims.

* At the re-initialisation sample p_att = sigma_att_coarse^2 exactly and the attitude error is 5 deg.
* From the re-initialisation on, the Monte Carlo passes the consistency checks of
  ``scripts/mekf_consistency.py`` (``check``: time-averaged NEES per error component in the 95 % band of
  chi2(N)/N, NIS per degree of freedom in its chi2 band, bias within 3 sigma at the end, attitude-error spread
  within 20 % of the filter's sigma), and the first star-tracker update brings the error to the star tracker's
  level. The same runs with sigma_att_coarse = 0.005 rad (ten times overconfident) fail them (the test can fail).
* A zero q_coarse with the request high is refused with the input's name.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from scfmu.fmu import Fmu

ROOT = Path(__file__).resolve().parents[4]  # the repository (this file: src/models/estimation/tests/)
_spec = importlib.util.spec_from_file_location("mekf_consistency", ROOT / "scripts" / "mekf_consistency.py")
mc_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mc_mod)

AX, QN = "xyz", ("w", "x", "y", "z")
T, N, K_RE, ST_EVERY, RUNS = 0.01, 2000, 1010, 20, 50
OUT = [*(f"q_est_{a}" for a in QN), *(f"bias_est_{a}" for a in AX), *(f"p_att_{a}" for a in AX),
       *(f"p_bias_{a}" for a in AX), "nis"]  # then nis_dim (an Integer)
IN = [*(f"w_meas_{a}" for a in AX), *(f"q_meas_{a}" for a in QN), "init_request", *(f"q_coarse_{a}" for a in QN)]


def quat_exp(th):
    """exp of half the rotation vector th: the unit quaternion of the rotation th."""
    a = np.linalg.norm(th)
    return np.concatenate([[math.cos(a / 2)], th * (math.sin(a / 2) / a if a > 0 else 0.5)])


def quat_mul(p, q):
    pw, pv, qw, qv = p[0], p[1:], q[0], q[1:]
    return np.concatenate([[pw * qw - pv @ qv], pw * qv + qw * pv + np.cross(pv, qv)])


def rate(t):
    return np.array([0.02 * math.sin(0.1 * t), -0.01, 0.015 * math.cos(0.07 * t)])


def truth() -> np.ndarray:
    """q(t_k), k = 0..N-1: q' = q (x) (0, w/2), 20 exponential midpoint sub-steps per sample."""
    q = quat_exp(np.array([0.3, -0.2, 0.5]))
    out = np.empty((N, 4))
    for k in range(N):
        out[k] = q
        for j in range(20):
            q = quat_mul(q, quat_exp(rate((k + (j + 0.5) / 20) * T) * (T / 20)))
        q /= np.linalg.norm(q)
    return out


Q_TRUE = truth()


def run(seed: int, sigmas: tuple, k_request: int = K_RE) -> tuple[list[np.ndarray], np.ndarray]:
    """One seeded run of a Mekf per value of sigma_att_coarse in ``sigmas`` on the same sensors: the outputs
    (N, len(OUT) + 1: nis_dim last) of each at every sample and the true gyro bias (N, 3)."""
    rng = np.random.default_rng([44, seed])
    bias = rng.normal(0.0, mc_mod.SIGMA_B0, 3)
    axis = rng.normal(size=3)
    q_coarse = quat_mul(Q_TRUE[K_RE], quat_exp(axis / np.linalg.norm(axis) * math.radians(5.0)))
    fs = [Fmu("Mekf", {**mc_mod.filter_params(1.0), "sigma_att_coarse": s}) for s in sigmas]
    outs, b_true = [np.empty((N, len(OUT) + 1)) for _ in fs], np.empty((N, 3))
    try:
        q_st = Q_TRUE[0]
        for k in range(N):
            b_true[k] = bias
            w = rate(k * T) + bias + rng.normal(0.0, math.sqrt(mc_mod.ARW_PSD / T), 3)
            bias = bias + rng.normal(0.0, math.sqrt(mc_mod.RRW_PSD * T), 3)
            if k % ST_EVERY == 0:
                nse = rng.normal(0.0, 1.0, 3) * [mc_mod.ST_CROSS, mc_mod.ST_CROSS, mc_mod.ST_ABOUT]
                q_st = quat_mul(Q_TRUE[k], quat_exp(nse))
            values = [*w, *q_st, 1.0 if k == k_request else 0.0, *q_coarse]
            for f, o in zip(fs, outs):
                f.set_reals(IN, values)
                o[k] = [*f.get_reals(OUT), f.get("nis_dim")]  # the sample of t_k with the inputs of t_k
                f.do_step(k * T, T)
    finally:
        for f in fs:
            f.close()
    return outs, b_true


def study(sigmas: tuple, k_request: int = K_RE) -> list[dict]:
    """The runs stacked from the re-initialisation sample on, in the form of ``mc_mod.check``, one per filter."""
    per = [[] for _ in sigmas]
    for seed in range(1, RUNS + 1):
        outs, b_true = run(seed, sigmas, k_request)
        for acc, o in zip(per, outs):
            q_est = o[:, 0:4]
            e = mc_mod.rotation_vector(mc_mod.quat_mul(q_est * np.array([1, -1, -1, -1]), Q_TRUE))
            acc.append({"e_att": e[K_RE:], "e_bias": (o[:, 4:7] - b_true)[K_RE:], "p_att": o[K_RE:, 7:10],
                        "p_bias": o[K_RE:, 10:13], "nis": o[K_RE:, 13], "dim": o[K_RE:, 14]})
    t = np.arange(K_RE, N) * T
    return [{"time": t, "mekf": {k: np.stack([r[k] for r in acc]) for k in acc[0]}} for acc in per]


@pytest.fixture(scope="module")
def studies():
    return dict(zip(("default", "overconfident"), study((0.05, 0.005))))


def test_reinitialization_sample_has_the_coarse_covariance_and_attitude(studies):
    d = studies["default"]["mekf"]
    # p_att at the re-initialisation sample is sigma_att_coarse^2, bit for bit, in every run
    assert np.all(d["p_att"][:, 0, :] == 0.05 * 0.05), d["p_att"][:, 0, :]
    err0 = np.linalg.norm(d["e_att"][:, 0, :], axis=1)
    assert np.allclose(err0, math.radians(5.0), rtol=0, atol=1e-12), err0
    assert np.all(d["dim"][:, 0] == 0)
    print(f"\nre-initialisation sample: p_att = {d['p_att'][0, 0, 0]!r} = 0.05^2 in all {RUNS} runs; "
          f"attitude error {np.degrees(err0).min():.9f}..{np.degrees(err0).max():.9f} deg")


def test_converges_and_stays_consistent_after_a_5_deg_coarse_attitude(studies):
    mc = studies["default"]
    r = mc_mod.check(mc, "mekf")
    line = mc_mod.summary("coarse re-init", "mekf", r)
    # the first star-tracker update (10 samples after the re-initialisation) ends the 5 deg error
    after = np.linalg.norm(mc["mekf"]["e_att"][:, ST_EVERY - (K_RE % ST_EVERY):, :], axis=2)
    sigma = np.sqrt(mc["mekf"]["p_att"][:, ST_EVERY - (K_RE % ST_EVERY):, :].sum(axis=2))
    print(f"\n{line}\nafter the first update: error <= {after.max():.3e} rad, at most {(after / sigma).max():.2f} "
          f"filter sigmas; final error <= {after[:, -1].max():.3e} rad")
    assert r["nees_ok"] and r["nis_ok"] and r["bias_ok"] and r["std_ok"], line
    assert after.max() < 1e-3 and (after / sigma).max() < 5.0


def test_an_overconfident_coarse_sigma_fails_the_same_checks(studies):
    r = mc_mod.check(studies["overconfident"], "mekf")
    line = mc_mod.summary("coarse re-init, sigma_att_coarse x0.1", "mekf", r)
    print("\n" + line)
    assert not r["nees_ok"] and not r["nis_ok"] and not r["ok"], line


def test_a_zero_coarse_attitude_with_the_request_high_is_refused_by_name():
    f = Fmu("Mekf", {}, logging_on=True)
    try:
        f.set_reals(["init_request", *(f"q_coarse_{a}" for a in QN)], [0.0, 0.0, 0.0, 0.0, 0.0])
        f.do_step(0.0, T)  # not read with the request low
        f.set_reals(["init_request"], [1.0])
        with pytest.raises(Exception):
            f.do_step(T, T)
        text = " ".join(m[2] for m in f.messages)
        assert "input q_coarse has norm 0" in text, text
    finally:
        f.close()
