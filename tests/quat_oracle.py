"""Independent quaternion helpers for the tests (README conventions: scalar-first Hamilton
quaternions, 321 = yaw about z, then pitch, then roll), written with numpy only so that they do not
share code with the FMUs they check."""

import math

import numpy as np


def qmul(a, b):
    aw, av = a[0], np.asarray(a[1:])
    bw, bv = b[0], np.asarray(b[1:])
    return np.concatenate([[aw * bw - av @ bv], aw * bv + bw * av + np.cross(av, bv)])


def qconj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def q321(roll, pitch, yaw):
    def el(axis, a):
        q = np.zeros(4)
        q[0] = math.cos(a / 2)
        q[axis] = math.sin(a / 2)
        return q
    return qmul(qmul(el(3, yaw), el(2, pitch)), el(1, roll))


def estimate_error(r: dict) -> np.ndarray:
    """Angle [rad] of the rotation from the true attitude (``q_*``) to the estimated one (``q_est_*``) of a
    run's logged signals, sample by sample."""
    qt = np.stack([r[f"q_{a}"] for a in "wxyz"], axis=1)
    qe = np.stack([r[f"q_est_{a}"] for a in "wxyz"], axis=1)
    dot = np.abs(np.sum(qt * qe, axis=1)) / np.linalg.norm(qt, axis=1) / np.linalg.norm(qe, axis=1)
    return 2 * np.arccos(np.clip(dot, -1.0, 1.0))
