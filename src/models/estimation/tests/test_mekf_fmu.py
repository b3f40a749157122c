"""The packaged ``Mekf`` FMU (FMI 2.0 and 3.0) through fmpy: its FMU state (estimate and covariance) restores
bit for bit mid-run, directly and serialized; bad inputs and parameters are refused with an error status and
a log message naming them; the documentation carries the equations, ports and parameters.

The inputs come from an independent truth written here: a constant-rate rotation q(t) = q0 ⊗ exp(ω t / 2)
with a gyro (rate + bias + white noise) and a 5 Hz star tracker (numpy draws, seeded).
"""

from __future__ import annotations

import math
import zipfile

import numpy as np
import pytest

from fmu_state_replay import replay_three_ways
from scfmu.fmu import Fmu, fmu_path

QN = ("w", "x", "y", "z")
AX = "xyz"
T = 0.01
W = np.array([0.01, -0.02, 0.015])
BIAS = np.array([2e-5, -1e-5, 3e-5])


def quat_exp(th):
    a = np.linalg.norm(th)
    return np.concatenate([[math.cos(a / 2)], th * (math.sin(a / 2) / a if a > 0 else 0.5)])


def quat_mul(p, q):
    pw, pv, qw, qv = p[0], p[1:], q[0], q[1:]
    return np.concatenate([[pw * qw - pv @ qv], pw * qv + qw * pv + np.cross(pv, qv)])


def inputs(k: int, rng_seed: int = 1):
    """(gyro rate, star-tracker quaternion) of sample k of the independent truth."""
    rng = np.random.default_rng([rng_seed, k])
    q0 = quat_exp(np.array([0.3, -0.2, 0.5]))
    w_meas = W + BIAS + rng.normal(0, 4.4e-4, 3)
    ks = (k // 20) * 20  # star tracker every 0.2 s, held in between
    rs = np.random.default_rng([rng_seed, ks, 7])
    q_st = quat_mul(quat_mul(q0, quat_exp(W * ks * T)), quat_exp(rs.normal(0, 2.5e-5, 3)))
    return w_meas, q_st


def drive(f: Fmu, k0: int, k1: int) -> np.ndarray:
    out = []
    names = [*(f"q_est_{a}" for a in QN), *(f"p_att_{a}" for a in AX), *(f"bias_est_{a}" for a in AX), "nis"]
    for k in range(k0, k1):
        w, q = inputs(k)
        f.set_reals([f"w_meas_{a}" for a in AX] + [f"q_meas_{a}" for a in QN], [*w, *q])
        f.do_step(k * T, T)
        out.append(f.get_reals(names))
    return np.array(out)


@pytest.mark.parametrize("st_latency", [0.0, 0.1])
@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_state_restore_mid_run_is_bit_identical(fmi, st_latency):
    """With st_latency = 0.1 s the state carries the delay history of 11 samples (estimates, covariances,
    transitions): restored, the delayed updates continue bit for bit."""
    path = fmu_path("Mekf") if fmi == 2 else fmu_path("Mekf").parent / "fmi3" / "Mekf.fmu"
    f = Fmu("Mekf", {"sigma_bias_init": 1e-4, "st_latency": st_latency}, path=path)
    try:
        drive(f, 0, 300)
        a, b, c, blob = replay_three_ways(f, fmi, lambda: drive(f, 300, 500))
    finally:
        f.close()
    assert np.array_equal(a, b) and np.array_equal(a, c)
    # the state carries a converged covariance: far below the initial (0.1 rad)^2, the bias near the truth
    assert a[-1, 4:7].max() < 1e-8
    assert np.all(np.abs(a[-1, 7:10] - BIAS) < 5e-5)
    print(f"\nMekf FMI {fmi}, st_latency {st_latency} s: restore after 300 steps, 200 steps bit-identical (get/set and {len(blob)}-byte "
          f"serialized); p_att {a[-1, 4:7]}, bias error {a[-1, 7:10] - BIAS}")


def test_bad_inputs_and_parameters_are_refused_with_the_reason():
    f = Fmu("Mekf", {}, logging_on=True)
    try:
        drive(f, 0, 5)
        with pytest.raises(Exception):  # the FMI layer refuses a non-finite input at fmi2SetReal
            f.set_reals(["w_meas_y"], [float("nan")])
        text = " ".join(m[2] for m in f.messages)
        assert "NaN for w_meas_y is not finite" in text, text
    finally:
        f.close()
    f = Fmu("Mekf", {}, logging_on=True)
    try:
        f.set_reals([f"q_meas_{a}" for a in QN], [0.0, 0.0, 0.0, 0.0])
        with pytest.raises(Exception):
            f.do_step(0.0, T)
        assert "q_meas has norm 0" in " ".join(m[2] for m in f.messages)
    finally:
        f.close()
    for bad in ({"st_noise_cross": 0.0}, {"arw_psd_x": -1e-9}, {"use_sun": 2}, {"st_latency": 0.105},
                {"st_latency": 11.0}, {"st_latency": 1.0, "sample_period": 1e-4}):
        with pytest.raises(Exception) as e:
            Fmu("Mekf", bad, logging_on=True)
        assert next(iter(bad)) in str(e.value), (bad, str(e.value))


def test_documentation_is_generated_from_the_declaration():
    with zipfile.ZipFile(fmu_path("Mekf")) as z:
        html = z.read("documentation/index.html").decode()
    for needed in ("Joseph", "Phi11", "nis_dim", "st_noise_cross", "arw_psd", "rad2/s3", "Lefferts"):
        assert needed in html, needed
