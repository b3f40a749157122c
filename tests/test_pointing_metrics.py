"""Pointing metrics (scfmu.metrics.pointing_errors, error_rotation_deg, saturation_fraction) against answers
known in closed form on synthetic signals (constant bias, ramp, sinusoid) and against SciPy's rotations; the
attitude matrix A(q) and A(q) v (scfmu.metrics.attitude_matrix, to_body) against SciPy and a closed form."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from quat_oracle import qmul
from scfmu.metrics import attitude_matrix, error_rotation_deg, pointing_errors, saturation_fraction, to_body


def test_constant_bias():
    t = np.linspace(0.0, 10.0, 1001)
    b = np.array([0.3, -0.4, 1.2])
    m = pointing_errors(t, np.tile(b, (t.size, 1)), window=1.0)
    assert m["ape"] == pytest.approx(1.3, rel=1e-12)  # |(0.3, -0.4, 1.2)| = 1.3
    assert m["mpe"] == pytest.approx(1.3, rel=1e-12)
    assert m["rpe"] == pytest.approx(0.0, abs=1e-12)
    assert m["pde"] == pytest.approx(0.0, abs=1e-12)
    assert m["jitter"] == pytest.approx(0.0, abs=1e-12)


def test_ramp():
    # e = r t sampled every dt on [0, 10) s (evaluation period [0, 10] s), windows of w = 1 s: n = 100
    # samples per window, t = k + j dt (j < n)
    r, dt, w, n = 0.2, 0.01, 1.0, 100
    t = np.arange(0, 1000) * dt
    m = pointing_errors(t, r * t, window=w, t_end=10.0)
    assert m["ape"] == pytest.approx(r * 9.99, rel=1e-12)
    assert m["mpe"] == pytest.approx(r * 9.99 / 2, rel=1e-12)
    # window mean r (k + (n-1) dt/2): largest deviation r (n-1) dt / 2
    assert m["rpe"] == pytest.approx(r * (n - 1) * dt / 2, rel=1e-9)
    assert m["pde"] == pytest.approx(r * w, rel=1e-9)  # window means one window apart
    # within-window RMS of a uniform grid of n points: r dt sqrt((n² - 1)/12) → r w / √12 for fine sampling
    assert m["jitter"] == pytest.approx(r * dt * math.sqrt((n * n - 1) / 12), rel=1e-9)
    assert m["jitter"] == pytest.approx(r * w / math.sqrt(12), rel=1e-3)
    # a window of 2.5 s: 4 full windows, the last 0.5 s dropped
    m = pointing_errors(t, r * t, window=2.5, t_end=10.0)
    assert m["pde"] == pytest.approx(r * 2.5, rel=1e-9)
    assert m["rpe"] == pytest.approx(r * 249 * dt / 2, rel=1e-9)


def test_sinusoid_and_evaluation_period():
    # A sin(2π f t), windows of whole periods: window means 0, so RPE = A, PDE ≈ 0, jitter = A/√2
    A, f = 0.05, 2.0
    t = np.linspace(0.0, 20.0, 20001)
    e = A * np.sin(2 * np.pi * f * t)
    e[t < 5.0] += 10.0  # a slew transient before the evaluation period must not count
    m = pointing_errors(t, e, window=1.0, t_start=5.0)
    assert m["ape"] == pytest.approx(A, rel=1e-6)
    assert m["rpe"] == pytest.approx(A, rel=1e-6)
    assert m["pde"] < 1e-6 * A
    assert m["jitter"] == pytest.approx(A / math.sqrt(2), rel=1e-3)
    assert m["mpe"] < 1e-6 * A


def test_error_rotation_against_scipy():
    rng = np.random.default_rng(3)
    q_ref = Rotation.random(50, random_state=rng)
    small = Rotation.from_rotvec(rng.normal(0.0, 0.2, (50, 3)))
    q = q_ref * small.inv()  # body = reference turned back by `small`: the error is `small`
    wxyz = lambda r: np.roll(r.as_quat(), 1, axis=1)  # scipy is scalar-last
    e = error_rotation_deg(wxyz(q), wxyz(q_ref))
    expect = np.degrees((q.inv() * q_ref).as_rotvec())
    np.testing.assert_allclose(e, expect, atol=1e-9)
    np.testing.assert_allclose(e, np.degrees(small.as_rotvec()), atol=1e-9)
    # the sign of a quaternion does not matter
    np.testing.assert_allclose(error_rotation_deg(-wxyz(q), wxyz(q_ref)), expect, atol=1e-9)


def test_attitude_matrix_against_scipy():
    # A(q) is passive (reference -> body components): the transpose of SciPy's active matrix of the same
    # rotation; SciPy's quaternions are scalar-last, ours scalar-first
    rot = Rotation.random(40, random_state=np.random.default_rng(7))
    xyzw = rot.as_quat()
    q = np.column_stack([xyzw[:, 3], xyzw[:, :3]])
    a = attitude_matrix(q)
    assert a.shape == (40, 3, 3)
    np.testing.assert_allclose(a, np.transpose(rot.as_matrix(), (0, 2, 1)), rtol=0, atol=1e-15)
    np.testing.assert_allclose(attitude_matrix(-q), a, rtol=0, atol=1e-15)  # q and -q: one attitude
    assert attitude_matrix(q[3]).shape == (3, 3)
    np.testing.assert_array_equal(attitude_matrix(q[3]), a[3])  # one quaternion = the same numbers as a row
    v = np.random.default_rng(8).normal(size=(40, 3))
    np.testing.assert_allclose(to_body(q, v), rot.apply(v, inverse=True), rtol=0, atol=1e-14)
    np.testing.assert_allclose(to_body(q[5], v[5]), rot[5].apply(v[5], inverse=True), rtol=0, atol=1e-14)
    np.testing.assert_allclose(to_body(q, v[0]), rot.apply(v[0], inverse=True), rtol=0, atol=1e-14)  # broadcast
    # composition of Hamilton products: A(p ⊗ q) = A(q) A(p)
    pq = np.stack([qmul(p, qq) for p, qq in zip(q[:20], q[20:])])
    np.testing.assert_allclose(attitude_matrix(pq), attitude_matrix(q[20:]) @ attitude_matrix(q[:20]), atol=1e-15)


def test_attitude_matrix_closed_form():
    # the body turned +90 deg about z from the reference: the reference x axis is body -y, reference y is body +x
    s = math.sqrt(0.5)
    q = [s, 0.0, 0.0, s]
    np.testing.assert_allclose(to_body(q, [1.0, 0.0, 0.0]), [0.0, -1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(to_body(q, [0.0, 1.0, 0.0]), [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(attitude_matrix([1.0, 0.0, 0.0, 0.0]), np.eye(3), rtol=0, atol=0)


def test_saturation_fraction():
    # |sin t| ≥ 1/2 on a third of every half period... of the time: θ in [π/6, 5π/6] → 2/3 of the time
    t = np.linspace(0.0, 20 * np.pi, 200001)
    u = np.stack([np.sin(t), np.zeros_like(t)], axis=1)
    assert saturation_fraction(t, u, [0.5, 1.0]) == pytest.approx(2 / 3, abs=1e-4)
    assert saturation_fraction(t, u, [2.0, 1.0]) == 0.0
    assert saturation_fraction(t, u, [2.0, 0.0]) == 1.0  # a zero limit: always at it


def test_bad_window():
    with pytest.raises(ValueError, match="window"):
        pointing_errors([0.0, 1.0], [0.0, 1.0], window=0.0)
