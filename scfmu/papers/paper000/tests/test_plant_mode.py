"""The plant mode paper 000 states for its large-angle MRAC: linear (gyroscope-free, decoupled) rigid-body
dynamics with nonlinear quaternion kinematics, ``AttitudePlant.kinematics = 4``, checked against a SciPy
solve_ivp (DOP853) integration of the stated equations, written here from the model's description:

    q̇ = ½ q ⊗ (0, ω),    I_ii ω̇_i = τ_i   (diagonal of I_true = S I S, no ω × Iω term)

and against the full quaternion plant (mode 0), from which it must differ exactly by the gyroscopic term.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from scfmu.fmu import Fmu

P = {"inertia_xx": 1000.0, "inertia_yy": 500.0, "inertia_zz": 700.0, "inertia_xy": 30.0, "inertia_xz": -20.0,
     "inertia_yz": 15.0, "inertia_scale_y": 1.2, "init_euler321_roll": 0.3, "init_euler321_pitch": -0.4,
     "init_euler321_yaw": 1.0, "init_w_x": 0.05, "init_w_y": -0.03, "init_w_z": 0.02}
DT, T_END = 0.1, 30.0


def cmd(t: float) -> list[float]:
    return [20.0 * math.sin(0.3 * t), -15.0 * math.cos(0.2 * t + 0.5), 10.0 * math.sin(0.11 * t) + 3.0]


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def q321(r, p, y):
    qx = np.array([math.cos(r / 2), math.sin(r / 2), 0, 0])
    qy = np.array([math.cos(p / 2), 0, math.sin(p / 2), 0])
    qz = np.array([math.cos(y / 2), 0, 0, math.sin(y / 2)])
    return qmul(qmul(qz, qy), qx)


def reference(gyro: bool) -> np.ndarray:
    """[q, ω] at every communication point; ``gyro`` adds the −ω × Iω term of the full rigid body."""
    i_full = np.array([[P["inertia_xx"], P["inertia_xy"], P["inertia_xz"]],
                       [P["inertia_xy"], P["inertia_yy"], P["inertia_yz"]],
                       [P["inertia_xz"], P["inertia_yz"], P["inertia_zz"]]])
    s = np.diag(np.sqrt([1.0, P["inertia_scale_y"], 1.0]))
    i_true = s @ i_full @ s
    diag = np.diag(i_true)

    def rhs(t, x, u):
        q, w = x[:4], x[4:]
        qd = 0.5 * qmul(q, np.array([0.0, *w]))
        wd = np.linalg.solve(i_true, u - np.cross(w, i_true @ w)) if gyro else u / diag
        return np.concatenate([qd, wd])

    x = np.concatenate([q321(P["init_euler321_roll"], P["init_euler321_pitch"], P["init_euler321_yaw"]),
                        [P["init_w_x"], P["init_w_y"], P["init_w_z"]]])
    out = [x.copy()]
    for k in range(int(round(T_END / DT))):
        sol = solve_ivp(rhs, (k * DT, (k + 1) * DT), x, method="DOP853", rtol=1e-12, atol=1e-14,
                        args=(np.array(cmd(k * DT)),))
        x = sol.y[:, -1]
        x[:4] /= np.linalg.norm(x[:4])
        out.append(x.copy())
    return np.array(out)


def run_fmu(kinematics: int) -> np.ndarray:
    names = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]
    f = Fmu("AttitudePlant", dict(P, kinematics=kinematics, max_internal_step=0.01))
    try:
        out = []
        for k in range(int(round(T_END / DT)) + 1):
            t = k * DT
            f.set_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"], cmd(t))
            out.append(f.get_reals(names))
            if k < round(T_END / DT):
                f.do_step(t, DT)
    finally:
        f.close()
    return np.array(out)


def _supported() -> bool:
    try:
        Fmu("AttitudePlant", {"kinematics": 4}).close()
        return True
    except Exception:
        return False


@pytest.mark.skipif(not _supported(), reason="AttitudePlant without kinematics 4 (rebuild the FMUs)")
def test_quaternion_kinematics_with_linear_dynamics_matches_scipy():
    got = run_fmu(4)
    ref = reference(gyro=False)
    eq = np.max(np.abs(got[:, :4] - ref[:, :4]))
    ew = np.max(np.abs(got[:, 4:] - ref[:, 4:]))
    print(f"kinematics 4 vs scipy DOP853 (linear dynamics, quaternion kinematics), 30 s: max|dq| {eq:.2e}, "
          f"max|dw| {ew:.2e} rad/s")
    assert eq < 1e-7 and ew < 1e-10
    # it is not the full rigid body: the gyroscopic term (and the off-diagonal inertia) make a visible difference
    full = reference(gyro=True)
    d_full = np.max(np.abs(got[:, 4:] - full[:, 4:]))
    print(f"kinematics 4 vs the full rigid body (scipy): max|dw| {d_full:.2e} rad/s")
    assert d_full > 1e-3
    # and mode 0 is the full rigid body, so the two modes bracket the statement
    assert np.max(np.abs(run_fmu(0)[:, 4:] - full[:, 4:])) < 1e-8
