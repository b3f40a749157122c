"""SunSafeController (the safe-mode sun acquisition) through its FMU: the torque against the closed form of
the law written here from its definition (quaternion feedback on the shortest rotation to the sun,
[Wie-Weiss-Arapostathis-1989], gains K = 2 wn^2 J, C = 2 zeta wn J), and the closed loop with AttitudePlant
(ideal torques, actuator_mode 0) in a small Python loop: from 120 deg off the sun with a 1 deg/s tumble the
sun settles within the time the linear second-order closed form allows, and with the sun not valid the
angular momentum decays as exp(-2 zeta wn t)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scfmu.fmu import Fmu
from scfmu.metrics import attitude_matrix  # A(q), v_B = A v_R (numpy, tested against SciPy)

J = np.array([1000.0, 500.0, 700.0])  # the plant's and the controller's default inertia
WN, ZETA = 0.1, 0.9  # the controller's defaults
K, C = 2 * WN ** 2 * J, 2 * ZETA * WN * J
INPUTS = ["w_meas_x", "w_meas_y", "w_meas_z", "sun_meas_x", "sun_meas_y", "sun_meas_z", "sun_valid"]
TORQUE = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]


def closed_form(a, s, w, valid, spin=0.0):
    """The law by hand: e = unit(a × s) (the axis of the shortest rotation taking a onto s; for opposite
    directions unit(a × x) or unit(a × y), the longer), theta = angle(a, s). A torque along +e turns a toward s,
    so torque = K sin(theta/2) e − C (w − spin a) (= −K q_e,v − C w_e with q_e,v = −sin(theta/2) e)."""
    a, s = np.asarray(a, float) / np.linalg.norm(a), np.asarray(s, float) / np.linalg.norm(s)
    damping = -C * (np.asarray(w) - spin * a)
    if not valid:
        return damping
    theta = math.acos(np.clip(a @ s, -1.0, 1.0))
    e = np.cross(a, s)
    if np.linalg.norm(e) < 1e-9:
        ex, ey = np.cross(a, [1.0, 0, 0]), np.cross(a, [0, 1.0, 0])
        e = ex if np.linalg.norm(ex) >= np.linalg.norm(ey) else ey
    return K * math.sin(theta / 2) * e / np.linalg.norm(e) + damping


def torque(ctrl, w, s, valid):
    ctrl.set_reals(INPUTS, [*w, *s, 1.0 if valid else 0.0])
    return np.array(ctrl.get_reals(TORQUE))


def test_torque_is_the_closed_form_for_several_sun_directions():
    rng = np.random.default_rng(44)
    cases = [((0, 0, 1), (0, 0, -1)), ((1, 0, 0), (-1, 0, 0)), ((0, 0, 1), (0, 0, 3)), ((0, 0, 1), (1, 0, 0))]
    cases += [(rng.normal(size=3), rng.normal(size=3)) for _ in range(20)]
    worst = 0.0
    for spin in (0.0, 0.01):
        for a, s in cases:
            ctrl = Fmu("SunSafeController", {"sun_axis_x": a[0], "sun_axis_y": a[1], "sun_axis_z": a[2],
                                             "spin_rate": spin})
            try:
                for valid in (True, False):
                    w = rng.normal(size=3) * 0.01
                    t = torque(ctrl, w, s, valid)
                    worst = max(worst, np.max(np.abs(t - closed_form(a, s, w, valid, spin))))
                    angle = math.acos(np.clip(np.dot(a, s) / np.linalg.norm(a) / np.linalg.norm(s), -1, 1))
                    assert ctrl.get_reals(["sun_angle", "sun_seen"]) == pytest.approx([angle, float(valid)], abs=1e-12)
            finally:
                ctrl.close()
    print(f"\nSunSafeController torque vs the closed form (24 axis/sun pairs incl. 0 and 180 deg, spin 0 and "
          f"0.01 rad/s, sun valid and not): max difference {worst:.2e} N.m")
    assert worst < 1e-12
    # the 180 deg case by hand: a = z, s = −z: e = z × x = y, torque = K_y y = (0, 10, 0) N.m
    ctrl = Fmu("SunSafeController")
    try:
        assert torque(ctrl, [0, 0, 0], [0, 0, -1], True) == pytest.approx([0.0, 10.0, 0.0], abs=1e-12)
    finally:
        ctrl.close()


def test_torque_limit_keeps_the_direction_and_bad_inputs_are_refused():
    ctrl = Fmu("SunSafeController", {"torque_max": 0.5})
    try:
        w, s = [0.02, -0.01, 0.0], [1.0, 1.0, 0.0]
        full = closed_form((0, 0, 1), s, w, True)
        t = torque(ctrl, w, s, True)
        assert np.max(np.abs(t)) == pytest.approx(0.5, rel=1e-14)
        assert t == pytest.approx(full * 0.5 / np.max(np.abs(full)), abs=1e-14)
        # no direction in the measurement while it is said to be valid: an error naming the input
        with pytest.raises(Exception):
            torque(ctrl, w, [0, 0, 0], True)
        assert any("sun_meas" in m for m in ctrl.last_errors()), ctrl.last_errors()
    finally:
        ctrl.close()
    with pytest.raises(Exception, match="sun_axis"):
        Fmu("SunSafeController", {"sun_axis_x": 0.0, "sun_axis_y": 0.0, "sun_axis_z": 0.0})


def sun_loop(s_inertial, w0, t_end, dt, valid=True, params=None):
    """AttitudePlant (ideal torques, from the identity attitude) and SunSafeController fed the true rate and
    the true sun direction in body axes, A(q) s_inertial (a perfect sensor), torque held over each step."""
    plant = Fmu("AttitudePlant", {"actuator_mode": 0, **{f"init_w_{c}": w0[i] for i, c in enumerate("xyz")}})
    ctrl = Fmu("SunSafeController", params or {})
    rows = []
    try:
        for k in range(int(round(t_end / dt))):
            q = np.array(plant.get_reals(["q_w", "q_x", "q_y", "q_z"]))
            w = np.array(plant.get_reals(["w_x", "w_y", "w_z"]))
            s = attitude_matrix(q) @ s_inertial
            tau = torque(ctrl, w, s, valid)
            rows.append([k * dt, *s, *w])
            plant.set_reals(TORQUE, tau)
            plant.do_step(k * dt, dt)
            ctrl.do_step(k * dt, dt)
    finally:
        plant.close()
        ctrl.close()
    return np.array(rows)


TH0 = math.radians(120.0)
W0 = math.radians(1.0) * np.array([0.3, -0.8, 0.5]) / np.linalg.norm([0.3, -0.8, 0.5])  # a 1 deg/s tumble


def linear_settling_bound(theta0, rate0, tol):
    """Time after which the linear closed loop th'' + 2 zeta wn th' + wn^2 th = 0 (zeta < 1) stays below tol for
    any initial rate of magnitude <= rate0: the envelope of th(t) = e^(-zeta wn t) (th0 cos wd t +
    (th0' + zeta wn th0)/wd sin wd t), e^(-zeta wn t) sqrt(th0^2 + ((rate0 + zeta wn th0)/wd)^2)."""
    wd = WN * math.sqrt(1 - ZETA ** 2)
    amp = math.hypot(theta0, (rate0 + ZETA * WN * theta0) / wd)
    return math.log(amp / tol) / (ZETA * WN)


def test_sun_acquisition_from_120_degrees_settles_within_the_linear_bound():
    s_i = np.array([math.sin(TH0), 0.0, math.cos(TH0)])  # 120 deg from the default sun_axis +z
    r = sun_loop(s_i, W0, 120.0, 0.1)
    angle = np.degrees(np.arccos(np.clip(r[:, 3], -1, 1)))  # body z against the sun
    bound = linear_settling_bound(TH0, np.linalg.norm(W0), math.radians(1.0))
    above = r[angle >= 1.0, 0]
    settled = above[-1] + 0.1 if above.size else 0.0
    print(f"\nsun acquisition from 120 deg, 1 deg/s tumble (wn = {WN}, zeta = {ZETA}): below 1 deg for good from "
          f"t = {settled:.1f} s; linear closed-form bound {bound:.1f} s; final error {angle[-1]:.2e} deg")
    assert angle[0] == pytest.approx(120.0, abs=1e-9)
    assert settled <= bound
    assert angle[-1] < 0.01


def test_spin_about_the_sun_line_is_held():
    spin = math.radians(0.5)
    s_i = np.array([math.sin(TH0), 0.0, math.cos(TH0)])
    r = sun_loop(s_i, W0, 200.0, 0.1, params={"spin_rate": spin})
    angle = np.degrees(np.arccos(np.clip(r[-1, 3], -1, 1)))
    print(f"\nspin_rate 0.5 deg/s: final sun error {angle:.2e} deg, final rate {np.degrees(r[-1, 4:])} deg/s")
    assert angle < 0.01
    assert r[-1, 4:] == pytest.approx([0.0, 0.0, spin], abs=1e-3 * spin)


def test_sun_not_valid_damps_the_momentum_as_exp_minus_2_zeta_wn_t():
    # torque -C w = -2 zeta wn J w = -2 zeta wn h in body axes: the angular momentum obeys dh_I/dt = -2 zeta wn h_I,
    # |h| = |h0| exp(-2 zeta wn t) in continuous time. The torque held over each step dt gives the factor
    # (1 - c dt) per step instead of exp(-c dt), c = 2 zeta wn: a drift of about -c^2 dt t / 2 (-0.97 % at 30 s)
    dt, t_end = 0.02, 30.0
    w0 = math.radians(1.0) * np.array([0.6, -0.7, 0.4]) / np.linalg.norm([0.6, -0.7, 0.4])
    r = sun_loop(np.array([0.0, 1.0, 0.0]), w0, t_end, dt, valid=False)
    t, w = r[:, 0], r[:, 4:]
    h = np.linalg.norm(w * J, axis=1)
    expected = h[0] * np.exp(-2 * ZETA * WN * t)
    rel = np.max(np.abs(h / expected - 1))
    hold = (2 * ZETA * WN) ** 2 * dt * t[-1] / 2
    print(f"\nsun not valid, 30 s (5.4 time constants 1/(2 zeta wn)): |J w| against exp(-2 zeta wn t): "
          f"max relative difference {rel:.2e} (the hold's drift c^2 dt t/2 = {hold:.2e}); |w| from "
          f"{np.degrees(np.linalg.norm(w[0])):.3f} to {np.degrees(np.linalg.norm(w[-1])):.4f} deg/s")
    assert rel < 0.02
    assert rel == pytest.approx(hold, rel=0.05)
