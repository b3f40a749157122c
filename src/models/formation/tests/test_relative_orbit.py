"""Paper 001 formation flying: RelativeOrbitPlant, RelativePositionCommand, PredictivePidController.

Independent references: inertial two-body propagation (scipy DOP853) rotated into LVLH, the Jacobi
integral, the closed-form Clohessy-Wiltshire solution, Kepler's equation, and the closed-loop
characteristic polynomial (s + c)(s^2 + K2 s + K1) with K1 = 10/(3T^2), K2 = 5/(2T) ([NPPID-Formation]
Eq. 25). Horizons and steps are shortened where the property allows; each test states its setup.
"""

from __future__ import annotations

import numpy as np
import pytest
from fmpy.validation import validate_fmu
from scipy.integrate import solve_ivp

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu, fmu_path
from scfmu.metrics import settling_time

MU = 3.986004418e14
A = 6.0e6
MODELS = ["RelativeOrbitPlant", "RelativePositionCommand", "PredictivePidController"]
CASES = [(5.0, 5.0), (25.0, 5.0), (25.0, 25.0), (25.0, 150.0)]
REF = np.array([50.0, 40.0, 60.0])
AX = "xyz"


def mean_motion(a=A):
    return np.sqrt(MU / a**3)


@pytest.mark.parametrize("model", MODELS)
def test_fmu_validates(model):
    assert validate_fmu(str(fmu_path(model))) == []


# ----------------------------------------------------------------------------------------------
# plant alone
# ----------------------------------------------------------------------------------------------

def run_plant(params, t_end, dt):
    """Plant alone (zero inputs); returns times, states (N, 6) and nu (N,)."""
    p = Fmu("RelativeOrbitPlant", params)
    names = [f"pos_{a}" for a in AX] + [f"vel_{a}" for a in AX] + ["leader_true_anomaly"]
    n = int(round(t_end / dt))
    out = np.empty((n + 1, 7))
    out[0] = p.get_reals(names)
    for k in range(n):
        p.do_step(k * dt, dt)
        out[k + 1] = p.get_reals(names)
    p.close()
    return np.arange(n + 1) * dt, out[:, :6], out[:, 6]


def leader_initial(a, e, nu0):
    """Leader position and velocity in the perifocal (inertial) frame."""
    p = a * (1 - e * e)
    r = p / (1 + e * np.cos(nu0))
    rv = r * np.array([np.cos(nu0), np.sin(nu0), 0.0])
    vv = np.sqrt(MU / p) * np.array([-np.sin(nu0), e + np.cos(nu0), 0.0])
    return rv, vv


def lvlh(rl, vl):
    """Rows: LVLH unit vectors (x radial, y along-track, z orbit normal) and the frame rate."""
    x = rl / np.linalg.norm(rl)
    h = np.cross(rl, vl)
    z = h / np.linalg.norm(h)
    y = np.cross(z, x)
    return np.array([x, y, z]), np.linalg.norm(h) / np.dot(rl, rl)


def two_body(t_eval, rl, vl, rf, vf):
    """Leader and follower propagated together in the inertial frame (DOP853, rtol 1e-13)."""
    def f(_t, s):
        out = np.empty(12)
        for i in (0, 6):
            r = s[i:i + 3]
            out[i:i + 3] = s[i + 3:i + 6]
            out[i + 3:i + 6] = -MU * r / np.linalg.norm(r) ** 3
        return out
    s0 = np.concatenate([rl, vl, rf, vf])
    sol = solve_ivp(f, (t_eval[0], t_eval[-1]), s0, method="DOP853", t_eval=t_eval, rtol=1e-13, atol=1e-9)
    assert sol.success
    return sol.y.T


@pytest.mark.parametrize("e,nu0", [(0.0, 0.0), (0.1, 0.3)])
def test_plant_matches_inertial_two_body(e, nu0):
    """1 km separation, one orbit, RK4 0.5 s: |rho_plant - rho_two_body| <= 1e-3 m."""
    rho0 = np.array([600.0, 640.0, 480.0])  # |rho0| = 1000 m
    n = mean_motion()
    rhod0 = np.array([0.1, -2 * n * 600.0, 0.2])
    period = 2 * np.pi / n
    dt = 10.0
    t_end = np.ceil(period / dt) * dt
    t, xs, nus = run_plant({"eccentricity": e, "nu0": nu0, "max_internal_step": 0.5,
                            **{f"init_pos_{a}": v for a, v in zip(AX, rho0)},
                            **{f"init_vel_{a}": v for a, v in zip(AX, rhod0)}}, t_end, dt)
    rl, vl = leader_initial(A, e, nu0)
    c, w = lvlh(rl, vl)
    rf = rl + c.T @ rho0
    vf = vl + c.T @ (rhod0 + np.cross([0, 0, w], rho0))
    s = two_body(t, rl, vl, rf, vf)
    err = 0.0
    for k in range(len(t)):
        c, w = lvlh(s[k, 0:3], s[k, 3:6])
        rho = c @ (s[k, 6:9] - s[k, 0:3])
        err = max(err, np.linalg.norm(rho - xs[k, :3]))
    print(f"e = {e}: max |rho error| over one orbit = {err:.3e} m (max |rho| = {np.max(np.linalg.norm(xs[:, :3], axis=1)):.0f} m)")
    assert err <= 1e-3


@pytest.mark.parametrize("e", [0.0, 0.1, 0.6])
def test_origin_is_equilibrium(e):
    """Spec plant test 1: rho = rho_dot = 0, F = d = 0 stays at 0 over one orbit (any e)."""
    _, xs, _ = run_plant({"eccentricity": e, "nu0": 0.7, "max_internal_step": 1.0}, 4700.0, 100.0)
    assert np.max(np.abs(xs)) == 0.0


def test_jacobi_integral():
    """Spec plant test 2: |C(t) - C(0)| < 1e-6 * 0.5 |rho_dot(0)|^2 over one orbit, RK4 h = 0.1 s."""
    n = mean_motion()
    t, xs, _ = run_plant({"init_pos_x": 100.0, "init_pos_z": 50.0, "init_vel_y": -0.2, "init_vel_z": 0.05,
                          "max_internal_step": 0.1}, 4630.0, 10.0)
    x, y, z = xs[:, 0], xs[:, 1], xs[:, 2]
    r = A
    rf = np.sqrt((r + x) ** 2 + y**2 + z**2)
    grav = -MU * (2 * r * x + x**2 + y**2 + z**2) / (rf * r * (r + rf))  # mu/rho_f - mu/R
    phi = 0.5 * n**2 * (x**2 + y**2) + grav + MU / r**2 * x
    cj = 0.5 * np.sum(xs[:, 3:] ** 2, axis=1) - phi
    drift = np.max(np.abs(cj - cj[0]))
    bound = 1e-6 * 0.5 * (0.2**2 + 0.05**2)
    print(f"Jacobi drift {drift:.3e} (bound {bound:.3e})")
    assert drift < bound


def cw_solution(t, r0, v0, n):
    """Closed-form Clohessy-Wiltshire solution (x radial, y along-track, z normal)."""
    x0, y0, z0 = r0
    vx0, vy0, vz0 = v0
    s, c = np.sin(n * t), np.cos(n * t)
    x = (4 - 3 * c) * x0 + s / n * vx0 + 2 / n * (1 - c) * vy0
    y = 6 * (s - n * t) * x0 + y0 - 2 / n * (1 - c) * vx0 + (4 * s - 3 * n * t) / n * vy0
    z = c * z0 + s / n * vz0
    return np.stack([x, y, z], axis=1)


def test_clohessy_wiltshire_drift_free():
    """Spec plant test 3: rho(0) = (10, 0, 5), rho_dot(0) = (0, -2 n 10, 0): within 0.01 m of CW for one orbit."""
    n = mean_motion()
    t, xs, _ = run_plant({"init_pos_x": 10.0, "init_pos_z": 5.0, "init_vel_y": -2 * n * 10.0,
                          "max_internal_step": 0.5}, 4630.0, 10.0)
    cw = cw_solution(t, [10.0, 0.0, 5.0], [0.0, -2 * n * 10.0, 0.0], n)
    err = np.max(np.linalg.norm(xs[:, :3] - cw, axis=1))
    print(f"max |rho - rho_CW| = {err:.3e} m")
    assert err < 0.01


def kepler_true_anomaly(m, e):
    ea = m.copy()
    for _ in range(30):
        ea -= (ea - e * np.sin(ea) - m) / (1 - e * np.cos(ea))
    return 2 * np.arctan2(np.sqrt(1 + e) * np.sin(ea / 2), np.sqrt(1 - e) * np.cos(ea / 2))


def test_true_anomaly_kepler():
    """Spec plant test 4: e = 0.1, nu(t) vs Kepler's equation (M = n t) to 1e-9 rad over one orbit (RK4 0.1 s)."""
    n = mean_motion()
    t, _, nu = run_plant({"eccentricity": 0.1, "max_internal_step": 0.1}, 4630.0, 10.0)
    ref = np.unwrap(kepler_true_anomaly(n * t, 0.1))
    err = np.max(np.abs(nu - ref))
    print(f"max |nu - nu_Kepler| = {err:.3e} rad")
    assert err < 1e-9


# ----------------------------------------------------------------------------------------------
# closed loop
# ----------------------------------------------------------------------------------------------

def closed_loop(t2, c, t_end, dt, dist=(0.0, 0.0, 0.0), ctl_extra=None, plant_extra=None, cmd_extra=None):
    cmd = Fmu("RelativePositionCommand", cmd_extra or {})
    ctl = Fmu("PredictivePidController", {"T2": t2, "c": c, **(ctl_extra or {})})
    pl = Fmu("RelativeOrbitPlant", {"max_internal_step": dt, **(plant_extra or {})})
    for a, d in zip(AX, dist):
        pl.set(f"dist_{a}", d)
    sim = CoSimulation([cmd, ctl, pl])
    log = {}
    for a in AX:
        log[f"pos_{a}"] = (pl, f"pos_{a}")
        log[f"ref_{a}"] = (cmd, f"pos_ref_{a}")
        log[f"force_{a}"] = (ctl, f"force_{a}")
        log[f"dist_est_{a}"] = (ctl, f"dist_est_{a}")
    out = sim.run(t_end, dt, log=log)
    sim.close()
    return out


def reinit(f: Fmu, params):
    """fmi2Reset and re-initialise with new parameters (same instance)."""
    f.slave.reset()
    f.slave.setupExperiment(startTime=0.0)
    f.slave.enterInitializationMode()
    for k, v in params.items():
        f.set(k, v)
    f.slave.exitInitializationMode()
    f.time = 0.0


@pytest.mark.parametrize("t2,c", CASES)
def test_closed_loop_poles(t2, c):
    """Numerical Jacobian of plant + controller about rho = ref = (50, 40, 60) m, rho_dot = 0, E = 0.

    State X = (rho, rho_dot, E). f(X) = (d rho/dt, d rho_dot/dt, dE/dt) is measured on the FMUs: the
    controller's force for (rho, rho_dot, E) (E through init_int_error_*), then the plant started at
    (rho, rho_dot) with that force held, stepped by h and 2h (fmi2Get/SetFMUstate) and differentiated
    by Richardson extrapolation (error O(h^2), h = 1e-3 s); dE/dt from the controller's integral after
    one step. Columns by central differences. Eigenvalues vs -c and (-1.25 +- 1.3307j)/T, 1e-3 relative.
    """
    ctl = Fmu("PredictivePidController", {"T2": t2, "c": c})
    pl = Fmu("RelativeOrbitPlant")
    h = 1e-3
    ctl_params = {"T2": t2, "c": c}

    def f(x):
        rho, rhod, ei = x[0:3], x[3:6], x[6:9]
        reinit(ctl, {**ctl_params, **{f"init_int_error_{a}": v for a, v in zip(AX, ei)}})
        ctl.set_reals([f"pos_ref_{a}" for a in AX], REF)
        ctl.set_reals([f"pos_{a}" for a in AX] + [f"vel_{a}" for a in AX], np.concatenate([rho, rhod]))
        force = np.array(ctl.get_reals([f"force_{a}" for a in AX]))
        ctl.do_step(0.0, h)
        edot = (np.array(ctl.get_reals([f"int_error_{a}" for a in AX])) - ei) / h
        reinit(pl, {"max_internal_step": h / 4,
                    **{f"init_pos_{a}": v for a, v in zip(AX, rho)},
                    **{f"init_vel_{a}": v for a, v in zip(AX, rhod)}})
        pl.set_reals([f"force_{a}" for a in AX], force)
        s0 = pl.slave.getFMUstate()
        names = [f"pos_{a}" for a in AX] + [f"vel_{a}" for a in AX]
        x0 = np.array(pl.get_reals(names))
        pl.do_step(0.0, h)
        d1 = np.array(pl.get_reals(names)) - x0
        pl.slave.setFMUstate(s0)
        pl.time = 0.0
        pl.do_step(0.0, 2 * h)
        d2 = np.array(pl.get_reals(names)) - x0
        pl.slave.freeFMUstate(s0)
        return np.concatenate([(4 * d1 - d2) / (2 * h), edot])

    x_eq = np.concatenate([REF, np.zeros(6)])
    deltas = np.array([1e-2] * 3 + [1e-4] * 3 + [1e-2] * 3)
    jac = np.empty((9, 9))
    for j in range(9):
        dx = np.zeros(9)
        dx[j] = deltas[j]
        jac[:, j] = (f(x_eq + dx) - f(x_eq - dx)) / (2 * deltas[j])
    ctl.close()
    pl.close()
    eig = np.linalg.eigvals(jac)
    expected = [-c] * 3 + [(-1.25 + 1.3307j) / t2] * 3 + [(-1.25 - 1.3307j) / t2] * 3
    remaining = list(eig)
    worst = 0.0
    for p in expected:
        k = int(np.argmin([abs(q - p) for q in remaining]))
        worst = max(worst, abs(remaining[k] - p) / abs(p))
        remaining.pop(k)
    # the same matching against the exact roots of (s + c)(s^2 + K2 s + K1), K1 = 10/(3T^2), K2 = 5/(2T)
    exact = list(np.roots(np.polymul([1.0, c], [1.0, 2.5 / t2, 10.0 / (3.0 * t2**2)]))) * 3
    remaining = list(eig)
    worst_exact = 0.0
    for p in exact:
        k = int(np.argmin([abs(q - p) for q in remaining]))
        worst_exact = max(worst_exact, abs(remaining[k] - p) / abs(p))
        remaining.pop(k)
    print(f"T2 = {t2}, c = {c}: eigenvalues {np.sort_complex(eig)}; worst relative error {worst:.2e} "
          f"(vs rounded 1.3307), {worst_exact:.2e} (vs exact roots)")
    assert worst < 1e-3
    assert worst_exact < 1e-6


def test_constant_disturbance_estimated_and_rejected():
    """Case a (T2 = 5 s, c = 5/s), dist = (0.01, -0.02, 0.03) N constant, Δ = RK4 step = 0.01 s, 150 s:
    dist_est -> dist within 1e-6 N, steady-state error (mean |e| over the last 10 %) < 1e-6 m.
    Also structure 1 (predictive law + observer state) gives the same limits."""
    dist = (0.01, -0.02, 0.03)
    for structure in (0, 1):
        out = closed_loop(5.0, 5.0, 150.0, 0.01, dist=dist, ctl_extra={"structure": structure})
        n10 = len(out["time"]) // 10
        for a, d, r in zip(AX, dist, REF):
            est = out[f"dist_est_{a}"][-1]
            sse = np.mean(np.abs(r - out[f"pos_{a}"][-n10:]))
            print(f"structure {structure} axis {a}: dist_est = {est:.9f} N (true {d}), steady-state error {sse:.2e} m")
            assert abs(est - d) < 1e-6
            assert sse < 1e-6
    # without the disturbance the estimate goes to 0
    out = closed_loop(5.0, 5.0, 150.0, 0.01)
    assert max(abs(out[f"dist_est_{a}"][-1]) for a in AX) < 1e-6


def test_settling_time_grows_with_T():
    """Cases a (T2 = 5) and b (T2 = 25), c = 5, Δ = 0.01 s, 250 s: 2 % settling time per axis grows with T
    (dominant poles (-1.25 +- 1.3307j)/T, so about fivefold)."""
    ts = {}
    for t2 in (5.0, 25.0):
        out = closed_loop(t2, 5.0, 250.0, 0.01)
        ts[t2] = [settling_time(out["time"], out[f"pos_{a}"], r) for a, r in zip(AX, REF)]
        print(f"T2 = {t2}: settling times {ts[t2]} s")
    for a in range(3):
        assert ts[25.0][a] > 3.0 * ts[5.0][a]


def test_control_effort_grows_with_c():
    """Cases b, c, d (T2 = 25 s; c = 5, 25, 150), Δ = RK4 step = 0.001 s (c Δ <= 0.15), first 20 s:
    peak |F_i|, the integral of |F|^2 and (only by about 3 %) the integral of sum |F_i| grow with c."""
    peak, isq, iabs = [], [], []
    for c in (5.0, 25.0, 150.0):
        out = closed_loop(25.0, c, 20.0, 0.001)
        f = np.stack([out[f"force_{a}"] for a in AX], axis=1)
        dt = 0.001
        peak.append(np.max(np.abs(f), axis=0))
        isq.append(np.sum(f[:-1] ** 2) * dt)
        iabs.append(np.sum(np.abs(f[:-1])) * dt)
        print(f"c = {c}: peak |F| {peak[-1]}, int |F|^2 dt = {isq[-1]:.4e} N^2 s, int sum|F| dt = {iabs[-1]:.4e} N s")
    for k in range(2):
        assert np.all(peak[k + 1] > peak[k])
        assert isq[k + 1] > isq[k]
        assert iabs[k + 1] > iabs[k]


def test_eccentric_leader_feed_forward():
    """e = 0.1 leader (nu wired from the plant to the controller): the feed-forward N cancels G, so the
    position follows the same linear closed loop as for e = 0 up to the O(Δ) effect of holding the force
    over a step while G moves. Case a, 60 s, Δ = RK4 step = 0.01 s and 0.005 s: difference < 1e-5 m and
    first order in Δ; a controller that assumes e = 0 on the e = 0.1 plant deviates far more."""
    diffs = []
    for dt in (0.01, 0.005):
        out0 = closed_loop(5.0, 5.0, 60.0, dt)
        out1 = closed_loop(5.0, 5.0, 60.0, dt, ctl_extra={"eccentricity": 0.1},
                           plant_extra={"eccentricity": 0.1, "nu0": 1.0})
        diffs.append(max(np.max(np.abs(out0[f"pos_{a}"] - out1[f"pos_{a}"])) for a in AX))
        if dt == 0.01:
            ref0 = out0
    out0 = ref0
    out2 = closed_loop(5.0, 5.0, 60.0, 0.01, plant_extra={"eccentricity": 0.1, "nu0": 1.0})
    mismatch = max(np.max(np.abs(out0[f"pos_{a}"] - out2[f"pos_{a}"])) for a in AX)
    print(f"max |pos(e=0.1) - pos(e=0)| = {diffs[0]:.3e} m (Δ = 0.01), {diffs[1]:.3e} m (Δ = 0.005); "
          f"controller assuming e = 0: {mismatch:.3e} m")
    assert diffs[0] < 1e-5
    assert 1.8 < diffs[0] / diffs[1] < 2.2
    assert mismatch > 20 * diffs[0]


def test_step_response_matches_linear_closed_loop():
    """Case a, structure 0, nonlinear plant, Δ = RK4 step = 0.005 s, 40 s: the position error follows
    ë + (K2 + c)ė + (K1 + cK2)e + cK1 E = 0 (E = ∫e, e(0) = ref, ė(0) = 0), solved independently with DOP853;
    max deviation <= 2e-3 * |ref| (O(Δ): force held over a step, E by the rectangle rule); the 2 % settling
    time (13.43 s for this reference) is reproduced to 0.05 s."""
    t2, c = 5.0, 5.0
    k1, k2 = 10.0 / (3.0 * t2**2), 2.5 / t2
    out = closed_loop(t2, c, 40.0, 0.005)
    t = out["time"]

    def f(_t, x):
        return [x[1], -(k2 + c) * x[1] - (k1 + c * k2) * x[0] - c * k1 * x[2], x[0]]

    sol = solve_ivp(f, (0.0, t[-1]), [1.0, 0.0, 0.0], t_eval=t, method="DOP853", rtol=1e-11, atol=1e-13)
    e_lin = sol.y[0]
    ts_lin = t[np.nonzero(np.abs(e_lin) > 0.02)[0][-1] + 1]
    for a, r in zip(AX, REF):
        dev = np.max(np.abs((r - out[f"pos_{a}"]) - r * e_lin))
        ts = settling_time(t, out[f"pos_{a}"], r)
        print(f"axis {a}: max |e - e_linear| = {dev:.3e} m, settling {ts:.3f} s (linear reference {ts_lin:.3f} s)")
        assert dev <= 2e-3 * r
        assert abs(ts - ts_lin) <= 0.05
