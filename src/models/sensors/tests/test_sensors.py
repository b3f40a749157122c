"""The sensors family (issue 26) through the packaged FMUs, against independent references:

* Gyro: the Allan deviation computed by ``allantools`` shows the declared angle random walk (slope −1/2,
  value N/√τ), the bias-instability floor (flat near τ ≈ 1.9 τ_c at 0.664 B, the Gauss–Markov closed form)
  and the rate random walk (slope +1/2, K √(τ/3));
* StarTracker: error rotation per sensor axis (numpy quaternion algebra written here) has the declared
  standard deviations (χ² bounds) and zero mean;
* SampleHold: the output is the staircase of the input shifted by the delay, exactly;
* determinism: the same seed gives bit-identical outputs for any communication step, another seed others.
"""

from __future__ import annotations

import math

import allantools
import numpy as np
from scipy import stats

from scfmu.fmu import Fmu

AX = "xyz"
FLICKER = math.sqrt(2 * math.log(2) / math.pi)  # 0.664: the flicker floor per unit B (IEEE 952)


def gyro_series(params: dict, n: int, h: float) -> np.ndarray:
    """Measured rates (n × 3) of a Gyro at rest, one output per communication point t = k h."""
    f = Fmu("Gyro", params)
    vrs = [f.var(f"w_meas_{a}").valueReference for a in AX]
    out = np.empty((n, 3))
    try:
        get, step = f.slave.getReal, f.slave.doStep
        for k in range(n):
            out[k] = get(vrs)
            step(k * h, h)
    finally:
        f.close()
    return out


def gm_adev(tau, sigma, tc):
    """Allan deviation of a first-order Gauss–Markov process (stationary σ, correlation time τ_c)."""
    x = np.asarray(tau) / tc
    return sigma * np.sqrt((2 / x) * (1 - (3 - 4 * np.exp(-x) + np.exp(-2 * x)) / (2 * x)))


def slope(taus, devs, lo, hi):
    m = (taus >= lo) & (taus <= hi)
    return float(np.polyfit(np.log(taus[m]), np.log(devs[m]), 1)[0])


def test_gyro_allan_deviation_shows_angle_random_walk_and_bias_instability_floor():
    T, N, B, tc = 0.05, 1e-4, 2e-4, 10.0
    n = 80_000  # 4000 s
    y = gyro_series({"sample_period": T, "arw_psd_x": N**2, "arw_psd_y": N**2, "arw_psd_z": N**2,
                     "bias_instability_x": B, "bias_instability_y": B, "bias_instability_z": B,
                     "bias_corr_time": tc, "seed": 7}, n, T)
    sigma_b = FLICKER * B / 0.6173642831444414  # the GM std whose Allan maximum is the flicker floor
    report = []
    for i, a in enumerate(AX):
        taus, adev, err, ns = allantools.oadev(y[:, i], rate=1 / T, data_type="freq", taus="octave")
        s_arw = slope(taus, adev, T, 0.4)
        s_floor = slope(taus, adev, 1.2 * tc, 3.5 * tc)
        # floor: the value near τ = 1.9 τ_c against 0.664 B (with the ARW contribution at that τ added)
        k = int(np.argmin(np.abs(taus - 1.9 * tc)))
        floor_ref = math.sqrt((FLICKER * B) ** 2 + N**2 / taus[k])
        n_arw = float(np.exp(np.mean(np.log(adev[taus <= 0.4] * np.sqrt(taus[taus <= 0.4])))))
        # the whole curve against the closed form N²/τ + GM Allan variance: within 3.5 relative standard
        # errors, taken as sqrt(τ / L) (L = record length; about one over the root of the number of
        # independent clusters), and at least 3 %
        L = n * T
        ref = np.sqrt(N**2 / taus + gm_adev(taus, sigma_b, tc) ** 2)
        ok = taus <= L / 10
        rel = np.abs(adev[ok] / ref[ok] - 1)
        bound = 3.5 * np.sqrt(taus[ok] / L)
        report.append(f"{a}: ARW slope {s_arw:+.3f} (−0.5), N {n_arw:.4e} ({N:.1e}); floor slope {s_floor:+.3f} (0), "
                      f"ADEV({taus[k]:.1f} s) {adev[k]:.4e} vs 0.664 B (+ARW) {floor_ref:.4e}; "
                      f"max |ADEV/closed form − 1| {rel.max():.3f}")
        assert abs(s_arw + 0.5) < 0.05, report[-1]
        assert abs(n_arw / N - 1) < 0.05, report[-1]
        assert abs(s_floor) < 0.15, report[-1]
        assert abs(adev[k] / floor_ref - 1) < 0.15, report[-1]
        assert np.all(rel < np.maximum(bound, 0.03)), report[-1]
    print("\nGyro Allan deviation (allantools.oadev, 4000 s at 20 Hz, tolerances: slopes ±0.05 / ±0.15, "
          "N ±5 %, floor ±15 %):\n  " + "\n  ".join(report))


def test_gyro_allan_deviation_shows_rate_random_walk():
    T, N, K = 1.0, 1e-4, 1e-5
    n = 50_000
    y = gyro_series({"sample_period": T, "arw_psd_x": N**2, "arw_psd_y": N**2, "arw_psd_z": N**2,
                     "bias_instability_x": 0.0, "bias_instability_y": 0.0, "bias_instability_z": 0.0,
                     "rrw_psd_x": K**2, "rrw_psd_y": K**2, "rrw_psd_z": K**2, "seed": 3}, n, T)
    out, slopes, ks = [], [], []
    for i, a in enumerate(AX):
        taus, adev, _, _ = allantools.oadev(y[:, i], rate=1 / T, data_type="freq", taus="octave")
        m = (taus >= 100) & (taus <= 1600)  # K √(τ/3) ≥ 8 N/√τ here; at least 31 clusters of τ
        s = slope(taus, adev, 100, 1600)
        k_est = float(np.exp(np.mean(np.log(adev[m] / np.sqrt(taus[m] / 3)))))
        slopes.append(s)
        ks.append(k_est)
        out.append(f"{a}: RRW slope {s:+.3f} (+0.5), K {k_est:.3e} ({K:.1e})")
        assert abs(s - 0.5) < 0.15, out[-1]
        assert abs(k_est / K - 1) < 0.3, out[-1]
    # three independent axes: their mean is tighter
    out.append(f"mean slope {np.mean(slopes):+.3f}, mean K {np.mean(ks):.3e}")
    assert abs(np.mean(slopes) - 0.5) < 0.08 and abs(np.mean(ks) / K - 1) < 0.15, out
    print("\nGyro rate random walk (50 000 s at 1 Hz, slope over 100-1600 s; tolerances: slope ±0.15 per axis, "
          "±0.08 mean; K ±30 % per axis, ±15 % mean): " + "; ".join(out))


def quat_mul(p, q):
    pw, px, py, pz = p.T
    qw, qx, qy, qz = q.T
    return np.stack([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw], axis=1)


def rot(theta):
    """Rotation matrix of a rotation vector (Rodrigues), written here."""
    a = np.linalg.norm(theta)
    k = np.asarray(theta) / a
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K


def test_star_tracker_error_statistics_match_the_declared_noise_per_axis():
    sc, sa, n = 3e-5, 2.5e-4, 20_000
    mount = np.array([0.4, -0.3, 1.0])
    f = Fmu("StarTracker", {"noise_cross": sc, "noise_about": sa, "latency": 0.0, "sun_exclusion": 0.0,
                            "sample_period": 0.1, "mount_x": mount[0], "mount_y": mount[1], "mount_z": mount[2],
                            "seed": 11})
    qn = ["q_w", "q_x", "q_y", "q_z"]
    mn = ["q_meas_w", "q_meas_x", "q_meas_y", "q_meas_z"]
    t = np.arange(n) * 0.1
    # a slow tumble: q(t) = exp(ω t / 2) about a fixed axis
    ax = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    half = 0.5 * 0.01 * t
    q = np.column_stack([np.cos(half), np.outer(np.sin(half), ax)])
    qm = np.empty_like(q)
    try:
        for k in range(n):
            f.set_reals(qn, q[k])
            qm[k] = f.get_reals(mn)
            assert f.get("valid") == 1.0
            f.do_step(t[k], 0.1)
    finally:
        f.close()
    conj = q * np.array([1, -1, -1, -1])
    dq = quat_mul(conj, qm)
    th_body = 2 * dq[:, 1:] * np.sign(dq[:, :1])
    th_sensor = th_body @ rot(mount)  # R(mount)ᵀ θ_B, row-wise
    lines = []
    for i, want in enumerate((sc, sc, sa)):
        e = th_sensor[:, i]
        s2 = e.var(ddof=1)
        lo, hi = stats.chi2.ppf([0.0005, 0.9995], n - 1) / (n - 1)
        lines.append(f"sensor {AX[i]}: std {math.sqrt(s2):.4e} rad vs declared {want:.1e} "
                     f"(ratio {math.sqrt(s2) / want:.4f}, 99.9 % band [{math.sqrt(lo):.4f}, {math.sqrt(hi):.4f}]), "
                     f"mean {e.mean():+.2e}")
        assert lo <= s2 / want**2 <= hi, lines[-1]
        assert abs(e.mean()) < 3.3 * want / math.sqrt(n), lines[-1]
    print("\nStarTracker error per sensor axis (20 000 samples):\n  " + "\n  ".join(lines))


def test_sample_hold_reproduces_the_shifted_staircase_exactly():
    h, per = 0.01, 5  # T = 0.05 s
    T = h * per
    u = lambda t: math.sin(2.0 * t) + 0.3 * t
    for delay_steps in (0, 5, 10, 2, 7):  # 0, 1, 2 samples; 0.4 and 1.4 samples
        f = Fmu("SampleHold", {"sample_period": T, "delay": delay_steps * h, "initial_output": 9.0})
        ys, want = [], []
        try:
            for n in range(300):
                t = n * h
                f.set_reals(["u_1", "u_2", "u_3"], [u(t), 2 * u(t), -u(t)])
                ys.append(f.get_reals(["y_1", "y_2", "y_3"]))
                m = n - delay_steps
                w = 9.0 if m < 0 else u((m // per) * per * h)  # integer staircase on the grid
                want.append([w, 9.0 if m < 0 else 2 * w, 9.0 if m < 0 else -w])
                f.do_step(t, h)
        finally:
            f.close()
        assert np.array_equal(np.array(ys), np.array(want)), f"delay {delay_steps} steps"
    print(f"\nSampleHold: 300 steps × 5 delays (0, 1, 2, 0.4, 1.4 samples of {T} s) equal the shifted staircase bit for bit")


def test_gyro_determinism_by_seed_and_communication_step():
    p = {"sample_period": 0.1, "rrw_psd_x": 1e-10, "rrw_psd_y": 1e-10, "rrw_psd_z": 1e-10, "seed": 5}
    a = gyro_series(p, 400, 0.1)
    b = gyro_series(p, 1600, 0.025)[::4]  # the same samples read at a finer communication step
    c = gyro_series({**p, "seed": 6}, 400, 0.1)
    assert np.array_equal(a, b)
    assert not np.any(a == c)
