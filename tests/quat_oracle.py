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
