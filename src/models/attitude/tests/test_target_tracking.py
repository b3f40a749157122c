"""AttitudeCommand's inertial-target reference (reference 3) and the reference's angular acceleration
`w_ref_dot`, and PdController's full tracking law (rate_feedforward = 2), through the FMUs:

* w_ref_dot of the nadir reference against a central difference of w_ref along an eccentric Keplerian orbit
  (the closed-form Kepler solution, written here);
* PdController's torque against a NumPy implementation of the tracking law
  T = k e + k_d w_e + J (A_e w_ref_dot − w × A_e w_ref) + w × J w;
* the closed loop with AttitudePlant (ideal torques) on eccentric-orbit nadir pointing (e = 0.1): with
  rate_feedforward = 1 the pitch error follows the linear error dynamics driven by the reference's acceleration,
  th'' + 2 zeta wn th' + wn^2 th = −w_ref_dot_y, and with 2 it stays at least 10x smaller."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from quat_oracle import qconj, qmul
from scfmu.fmu import Fmu
from scfmu.metrics import attitude_matrix  # A(q), v_B = A v_R (numpy, tested against SciPy)

MU = 3.986004418e14
A_SMA, ECC = 8.0e6, 0.1  # perigee 7200 km
INC, RAAN, ARGP = math.radians(51.6), math.radians(30.0), math.radians(40.0)
N_MEAN = math.sqrt(MU / A_SMA ** 3)
J = np.array([1000.0, 500.0, 700.0])


def rot3(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def rot1(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


PQW = rot3(RAAN) @ rot1(INC) @ rot3(ARGP)  # perifocal → inertial


def kepler(t):
    """Position and velocity at time t after perigee: M = n t, Kepler's equation by Newton, then the perifocal
    r = a (cos E − e, sqrt(1 − e²) sin E), v = sqrt(mu a)/|r| (−sin E, sqrt(1 − e²) cos E)."""
    m = N_MEAN * t
    ea = m
    for _ in range(30):
        ea -= (ea - ECC * math.sin(ea) - m) / (1 - ECC * math.cos(ea))
    b = math.sqrt(1 - ECC ** 2)
    r = A_SMA * np.array([math.cos(ea) - ECC, b * math.sin(ea), 0.0])
    v = math.sqrt(MU * A_SMA) / np.linalg.norm(r) * np.array([-math.sin(ea), b * math.cos(ea), 0.0])
    return PQW @ r, PQW @ v


def command_at(cmd, t):
    r, v = kepler(t)
    cmd.set_reals([f"{s}_{c}" for s in ("r", "v") for c in "xyz"], [*r, *v])
    names = [f"q_ref_{c}" for c in "wxyz"] + [f"w_ref_{c}" for c in "xyz"] + [f"w_ref_dot_{c}" for c in "xyz"]
    x = np.array(cmd.get_reals(names))
    return x[:4], x[4:7], x[7:]


def test_nadir_w_ref_dot_is_the_derivative_of_w_ref_along_an_eccentric_orbit():
    cmd = Fmu("AttitudeCommand", {"reference": 1})
    try:
        h, worst, peak = 0.5, 0.0, 0.0
        for t in np.linspace(0.0, 2 * math.pi / N_MEAN, 61):
            _, _, wd = command_at(cmd, t)
            fd = (command_at(cmd, t + h)[1] - command_at(cmd, t - h)[1]) / (2 * h)
            worst, peak = max(worst, np.max(np.abs(fd - wd))), max(peak, abs(wd[1]))
            assert wd[0] == wd[2] == 0.0
    finally:
        cmd.close()
    print(f"\nnadir, a = 8000 km, e = 0.1: max |w_ref_dot| = {peak:.4e} rad/s2 (2 e n^2 = {2 * ECC * N_MEAN ** 2:.4e}); "
          f"max |central difference of w_ref (h = 0.5 s) - w_ref_dot| = {worst:.2e} rad/s2")
    # the central difference's truncation error h^2/6 |w'''| is about 1e-14 rad/s2 here
    assert worst < 1e-6 * peak
    assert peak == pytest.approx(2 * ECC * N_MEAN ** 2, rel=0.15)


def test_target_reference_points_the_axis_at_the_fixed_direction():
    u = np.array([0.3, -0.8, 0.2])
    axis = np.array([0.0, 0.6, -0.8])
    p = {"reference": 3, **{f"target_eci_{c}": 4 * u[i] for i, c in enumerate("xyz")},
         **{f"sun_axis_{c}": axis[i] for i, c in enumerate("xyz")}}
    cmd = Fmu("AttitudeCommand", p)
    try:
        q, w, wd = command_at(cmd, 100.0)  # r, v are not read with reference 3
    finally:
        cmd.close()
    a = attitude_matrix(q)
    assert a @ (u / np.linalg.norm(u)) == pytest.approx(axis, abs=1e-14)
    # secondary_axis (default body x) in the plane of the target and the inertial z, on z's side
    x_r = a.T @ np.array([1.0, 0, 0])
    assert abs(x_r @ np.cross(u, [0, 0, 1.0])) < 1e-14 and x_r[2] > 0
    assert list(w) == list(wd) == [0.0] * 3
    with pytest.raises(Exception, match="target_eci"):
        Fmu("AttitudeCommand", {"reference": 3, "target_eci_x": 0.0})


def test_full_tracking_law_is_the_formula():
    rng = np.random.default_rng(45)
    pd = Fmu("PdController", {"wn": 0.3, "zeta": 0.7, "rate_feedforward": 2})
    pd1 = Fmu("PdController", {"wn": 0.3, "zeta": 0.7, "rate_feedforward": 1})
    k, kd = 0.09 * J, -2 * 0.7 * 0.3 * J
    names = ([f"q_{c}" for c in "wxyz"] + [f"w_{c}" for c in "xyz"] + [f"q_ref_{c}" for c in "wxyz"]
             + [f"w_ref_{c}" for c in "xyz"] + [f"w_ref_dot_{c}" for c in "xyz"])
    worst = 0.0
    try:
        for _ in range(30):
            q, qr = rng.normal(size=4), rng.normal(size=4)
            q, qr = q / np.linalg.norm(q), qr / np.linalg.norm(qr)
            w, wr, wrd = rng.normal(size=3) * 0.05, rng.normal(size=3) * 0.01, rng.normal(size=3) * 1e-3
            qe = qmul(qconj(q), qr)
            e = 2 * qe[0] * qe[1:]
            ae = attitude_matrix(q) @ attitude_matrix(qr).T
            t1 = k * e + kd * (w - ae @ wr)
            t2 = t1 + J * (ae @ wrd - np.cross(w, ae @ wr)) + np.cross(w, J * w)
            for unit, expected in ((pd, t2), (pd1, t1)):
                unit.set_reals(names, [*q, *w, *qr, *wr, *wrd])
                worst = max(worst, np.max(np.abs(np.array(unit.get_reals(
                    ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"])) - expected)))
    finally:
        pd.close()
        pd1.close()
    print(f"\nPdController rate_feedforward 2 (and 1) against the NumPy law, 30 random states: max difference "
          f"{worst:.2e} N.m")
    assert worst < 1e-11


def nadir_loop(mode, t_end, dt, wn=0.1, zeta=0.9):
    """AttitudeCommand (nadir, r and v from the Kepler solution) → PdController → AttitudePlant (ideal torques),
    starting on the reference at perigee with the reference's rate; returns t and the signed pitch error
    2 q_err,y of q_err = q_ref* ⊗ q (the body relative to the commanded frame, small angles)."""
    cmd = Fmu("AttitudeCommand", {"reference": 1})
    q0, w0, _ = command_at(cmd, 0.0)
    a0 = attitude_matrix(q0)
    start = {"init_euler321_roll": math.atan2(a0[1, 2], a0[2, 2]), "init_euler321_pitch": -math.asin(a0[0, 2]),
             "init_euler321_yaw": math.atan2(a0[0, 1], a0[0, 0]), **{f"init_w_{c}": w0[i] for i, c in enumerate("xyz")}}
    plant = Fmu("AttitudePlant", {"actuator_mode": 0, **start})
    pd = Fmu("PdController", {"wn": wn, "zeta": zeta, "rate_feedforward": mode})
    names = ([f"q_{c}" for c in "wxyz"] + [f"w_{c}" for c in "xyz"] + [f"q_ref_{c}" for c in "wxyz"]
             + [f"w_ref_{c}" for c in "xyz"] + [f"w_ref_dot_{c}" for c in "xyz"])
    rows = []
    try:
        for i in range(int(round(t_end / dt))):
            t = i * dt
            q, w = plant.get_reals([f"q_{c}" for c in "wxyz"]), plant.get_reals([f"w_{c}" for c in "xyz"])
            qr, wr, wrd = command_at(cmd, t)
            qe = qmul(qconj(qr), q)
            rows.append((t, 2 * qe[2] * np.sign(qe[0]), 2 * np.linalg.norm(qe[1:])))
            pd.set_reals(names, [*q, *w, *qr, *wr, *wrd])
            plant.set_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"],
                            pd.get_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]))
            for unit in (plant, cmd, pd):
                unit.do_step(t, dt)
    finally:
        for unit in (plant, cmd, pd):
            unit.close()
    return np.array(rows)


def linear_pitch_error(t, wn=0.1, zeta=0.9):
    """th'' + 2 zeta wn th' + wn^2 th = −w_ref_dot_y(t), th(0) = th'(0) = 0, with w_ref_dot_y from differencing the
    closed-form LVLH rate −|h|/|r(t)|^2 of the Kepler solution (independent of the FMU)."""
    hmag = math.sqrt(MU * A_SMA * (1 - ECC ** 2))

    def wy(tt):
        return -hmag / np.linalg.norm(kepler(tt)[0]) ** 2

    def rhs(tt, x):
        acc = (wy(tt + 0.5) - wy(tt - 0.5)) / 1.0
        return [x[1], -acc - 2 * zeta * wn * x[1] - wn ** 2 * x[0]]
    sol = solve_ivp(rhs, (t[0], t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-16, max_step=5.0)
    return sol.y[0]


def test_full_tracking_law_removes_the_error_of_an_accelerating_reference():
    t_end, dt = 1800.0, 0.5  # perigee to past the largest |w_ref_dot| (eccentric anomaly 90 deg near t = 1250 s)
    r1, r2 = nadir_loop(1, t_end, dt), nadir_loop(2, t_end, dt)
    model = linear_pitch_error(r1[:, 0])
    steady = r1[:, 0] >= 200.0
    e1, e2 = np.max(r1[steady, 2]), np.max(r2[steady, 2])
    fit = np.max(np.abs(r1[:, 1] - model)) / np.max(np.abs(model))
    print(f"\neccentric nadir (a = 8000 km, e = 0.1, wn = 0.1, zeta = 0.9, dt = {dt} s, {t_end:.0f} s from perigee): "
          f"max pointing error after 200 s: rate_feedforward 1 {e1:.3e} rad, 2 {e2:.3e} rad (ratio {e1 / e2:.0f}); "
          f"pitch error of 1 vs the linear error dynamics: max difference {fit:.2%} of its peak "
          f"{np.max(np.abs(model)):.3e} rad")
    assert e1 >= 10 * e2
    assert fit < 0.03
