"""The benchmark's robustness Monte Carlo (scfmu.benchmark.robustness): the dispersions are physically
valid (positive definite, triangle inequalities, principal moments within ±20 %), seeded, distributed as
stated (chi-square and uniform bands), reach the plant (its applied torque against the closed form
R(δ) diag(k) u with SciPy's rotation), and the percentiles are NumPy's linear interpolation."""

import math

import numpy as np
import pytest
from scipy import stats
from scipy.spatial.transform import Rotation

from scfmu.benchmark import robustness as rb
from scfmu.scenario import get

N = 2000


@pytest.fixture(scope="module")
def draws():
    sc = get("paper003/SMC/N")
    return sc, rb.dispersions(sc, N, seed=7)


def _inertia(d):
    g = lambda k: d[f"plant.inertia_{k}"]
    return np.array([[g("xx"), g("xy"), g("xz")], [g("xy"), g("yy"), g("yz")], [g("xz"), g("yz"), g("zz")]])


def test_inertia_draws_are_physical(draws):
    sc, ds = draws
    p = sc.component("plant").params
    i0 = np.array([[p["inertia_xx"], p["inertia_xy"], p["inertia_xz"]], [p["inertia_xy"], p["inertia_yy"], p["inertia_yz"]],
                   [p["inertia_xz"], p["inertia_yz"], p["inertia_zz"]]])
    lam0 = np.linalg.eigvalsh(i0)
    ratios, offdiag = [], []
    for d in ds:
        m = _inertia(d)
        lam = np.linalg.eigvalsh(m)
        assert np.all(lam > 0)  # positive definite
        assert lam[2] <= lam[0] + lam[1] + 1e-12  # triangle inequality (the largest ≤ the sum of the others)
        # the principal moments are the nominal ones scaled by 0.8 … 1.2 (sorted moments: each between the
        # smallest and largest scaled bounds of its neighbours; the ratio of the sums is a sharp check)
        ratios.append(lam.sum() / lam0.sum())
        assert 0.8 * lam0[0] - 1e-12 <= lam[0] and lam[2] <= 1.2 * lam0[2] + 1e-12
        offdiag.append(abs(m[0, 1] - i0[0, 1]) + abs(m[0, 2] - i0[0, 2]) + abs(m[1, 2] - i0[1, 2]))
    assert 0.8 <= min(ratios) and max(ratios) <= 1.2
    assert np.mean(offdiag) > 1e-3  # products of inertia are dispersed too
    # trace ratio of U(0.8, 1.2)-scaled moments: mean 1 within 4 standard errors
    se = math.sqrt(np.sum((lam0 * 0.4 / math.sqrt(12)) ** 2)) / lam0.sum() / math.sqrt(N)
    assert abs(np.mean(ratios) - 1.0) < 4 * se


def test_distributions(draws):
    sc, ds = draws
    mis = np.array([[d[f"plant.actuator_misalignment_{a}"] for a in "xyz"] for d in ds]).ravel()
    sf = np.array([[d[f"plant.actuator_scale_{a}"] for a in "xyz"] for d in ds]).ravel()
    att = np.array([[d[f"plant.init_euler321_{a}"] for a in ("roll", "pitch", "yaw")] for d in ds]).ravel()
    rate = np.array([[d[f"plant.init_w_{a}"] for a in "xyz"] for d in ds]).ravel()
    n = mis.size

    def chi2_ok(x, sigma):  # sample variance of N(0, σ²) draws inside the 99.9 % chi-square band
        s = np.sum(x**2) / sigma**2
        return stats.chi2.ppf(0.0005, n) < s < stats.chi2.ppf(0.9995, n)

    assert chi2_ok(mis, math.radians(0.5))
    assert chi2_ok(att, math.radians(2.0))
    assert chi2_ok(rate, math.radians(0.1))
    assert sf.min() >= 0.95 and sf.max() <= 1.05
    assert stats.kstest((sf - 0.95) / 0.10, "uniform").pvalue > 1e-3
    # a scenario with disturbance torques: each scaled by one factor U(0.5, 2) per run
    sc_c = get("paper003/SMC/C")
    pc = sc_c.component("plant").params
    keys = [k for k in rb.DIST_PARAMS if pc.get(k)]
    assert keys
    for d in rb.dispersions(sc_c, 50, seed=1):
        f = {d[f"plant.{k}"] / pc[k] for k in keys}
        assert len({round(x, 12) for x in f}) == 1 and 0.5 <= f.pop() <= 2.0


def test_seeded(draws):
    sc, ds = draws
    assert rb.dispersions(sc, 5, seed=7) == ds[:5]
    assert rb.dispersions(sc, 5, seed=8) != ds[:5]


def test_percentiles_closed_form():
    v = np.arange(1, 101, dtype=float)  # linear interpolation: p-th percentile of 1..100 is 1 + 0.99 p
    np.random.default_rng(0).shuffle(v)
    p = rb.percentiles(list(v) + [math.nan])
    assert p["median"] == pytest.approx(50.5) and p["p95"] == pytest.approx(95.05) and p["p99"] == pytest.approx(99.01)
    assert p["n"] == 100


def test_misalignment_and_scale_reach_the_plant():
    # one run of the plant: the applied torque is R(δ) diag(k) u (SciPy's rotation vector)
    from scfmu.fmu import Fmu
    delta = np.array([0.01, -0.02, 0.015])
    k = np.array([1.03, 0.96, 1.01])
    u = np.array([0.2, -0.1, 0.05])
    params = {**{f"actuator_misalignment_{a}": float(x) for a, x in zip("xyz", delta)},
              **{f"actuator_scale_{a}": float(x) for a, x in zip("xyz", k)}}
    f = Fmu("AttitudePlant", params)
    try:
        for a, x in zip("xyz", u):
            f.set(f"torque_cmd_{a}", float(x))
        got = np.array([f.get(f"torque_applied_{a}") for a in "xyz"])
    finally:
        f.close()
    np.testing.assert_allclose(got, Rotation.from_rotvec(delta).apply(k * u), rtol=0, atol=1e-15)
