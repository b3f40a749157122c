"""Metrics of one run, computed from its logged signals, and the metric sets of the registry.

Signal helpers: :func:`settling_time`, :func:`overshoot_percent`, :func:`steady_state_error`.

A *metric set* is a named function ``logged signals -> row of metrics`` (``Scenario.metrics`` names one;
the name crosses process boundaries and is resolved in :mod:`scfmu.registry`). The built-in sets below
return the common columns (NaN where a scenario has no such quantity):

* ``eulerint_deg_s``: EULERINT, integral of the Euler-axis error angle [deg·s] (AttitudeMetrics);
* ``ise``, ``isf``: integral of squared error and of squared control (AttitudeMetrics; formation: sums of
  squared position error and force times Δ, left rectangle on the communication grid);
* ``settling_s``: 2 % settling time of the main error signal (α, or the slowest axis) [s], NaN if not
  settled by the end;
* ``effort_abs``, ``effort_sq``: integrals of Σ|u_i| and of ‖u‖²;
* ``final_error``: main error at the end (α [deg], or ‖position error‖ [m], or the angle error [deg]);

plus set-specific columns (per-axis settling, final angle errors, peak control). Paper plug-ins register
their own sets (e.g. ``paper003``, ``paper002``) with ``REGISTRY.metrics``.
"""

from __future__ import annotations

import math

import numpy as np

from .registry import REGISTRY


def settling_time(t: np.ndarray, y: np.ndarray, y_ref: float, band: float = 0.02) -> float:
    """Earliest t after which |y - y_ref| <= band * |y_ref - y(0)| until the end (nan if never)."""
    tol = band * abs(y_ref - y[0])
    if tol == 0.0:
        return 0.0
    outside = np.nonzero(np.abs(y - y_ref) > tol)[0]
    if outside.size == 0:
        return float(t[0])
    last = outside[-1]
    return float(t[last + 1]) if last + 1 < len(t) else float("nan")


def overshoot_percent(y: np.ndarray, y_ref: float) -> float:
    """max (y - y_ref) sign(y_ref - y(0)) / |y_ref - y(0)| * 100, floored at 0."""
    span = y_ref - y[0]
    if span == 0.0:
        return 0.0
    return float(max(0.0, np.max((y - y_ref) * np.sign(span)) / abs(span) * 100.0))


def steady_state_error(y: np.ndarray, y_ref, fraction: float = 0.1) -> float:
    """Mean |y_ref - y| over the last `fraction` of the run."""
    n = max(1, int(round(len(y) * fraction)))
    return float(np.mean(np.abs(np.asarray(y_ref) - y)[-n:]))


COMMON = ("eulerint_deg_s", "ise", "isf", "settling_s", "effort_abs", "effort_sq", "final_error")


def _nan_row(extra=()) -> dict:
    return {k: math.nan for k in (*COMMON, *extra)}


def _last(r, k):
    return float(r[k][-1]) if k in r else math.nan


def attitude(r: dict) -> dict:
    """Attitude loops with an AttitudeMetrics instance (keys eulerint_deg_s, alpha_deg, ise, isf, effort_*)
    and the plant's 321 angles with the command's references."""
    t = r["time"]
    out = {
        "eulerint_deg_s": _last(r, "eulerint_deg_s"),
        "ise": _last(r, "ise"),
        "isf": _last(r, "isf"),
        "settling_s": settling_time(t, r["alpha_deg"], 0.0) if "alpha_deg" in r else math.nan,
        "effort_abs": _last(r, "effort_abs"),
        "effort_sq": _last(r, "effort_sq"),
        "final_error": _last(r, "alpha_deg"),
    }
    out.update(_angles(r))
    return out


def _angles(r: dict) -> dict:
    out = {}
    t = r["time"]
    for ax in ("roll", "pitch", "yaw"):
        if ax in r and f"{ax}_ref" in r:
            ref = float(r[f"{ax}_ref"][-1])
            out[f"settling_{ax}_s"] = settling_time(t, r[ax], ref)
            out[f"overshoot_{ax}_pct"] = overshoot_percent(r[ax], ref)
            out[f"final_error_{ax}_deg"] = math.degrees(float(r[ax][-1]) - ref)
    torques = [r[f"torque_applied_{a}"] for a in "xyz" if f"torque_applied_{a}" in r]
    if torques:
        out["peak_torque"] = float(np.max(np.abs(np.stack(torques))))
    return out


def attitude_nometrics(r: dict) -> dict:
    """Attitude loops without an AttitudeMetrics instance: effort from the applied torques (left
    rectangle), settling as the slowest of the three 321 angles."""
    out = _nan_row()
    ang = _angles(r)
    out.update(ang)
    t = r["time"]
    dt = np.diff(t)
    tq = np.stack([r[f"torque_applied_{a}"] for a in "xyz"])
    out["effort_abs"] = float(np.sum(np.abs(tq[:, :-1]) * dt))
    out["effort_sq"] = float(np.sum(tq[:, :-1] ** 2 * dt))
    out["isf"] = out["effort_sq"]
    st = [ang.get(f"settling_{a}_s", math.nan) for a in ("roll", "pitch", "yaw")]
    out["settling_s"] = max(st) if not any(math.isnan(x) for x in st) else math.nan
    errs = [ang.get(f"final_error_{a}_deg", math.nan) for a in ("roll", "pitch", "yaw")]
    out["final_error"] = float(np.sqrt(np.sum(np.square(errs))))
    return out


def formation(r: dict) -> dict:
    """Relative-position loops (paper 001): position error e = pos_ref - pos, force F."""
    t = r["time"]
    dt = np.diff(t)
    e = np.stack([r[f"pos_ref_{a}"] - r[f"pos_{a}"] for a in "xyz"])
    f = np.stack([r[f"force_{a}"] for a in "xyz"])
    out = _nan_row()
    out["ise"] = float(np.sum(np.sum(e[:, :-1] ** 2, axis=0) * dt))
    out["isf"] = float(np.sum(np.sum(f[:, :-1] ** 2, axis=0) * dt))
    out["effort_abs"] = float(np.sum(np.abs(f[:, :-1]) * dt))
    out["effort_sq"] = out["isf"]
    st = []
    for i, a in enumerate("xyz"):
        ref = float(r[f"pos_ref_{a}"][-1])
        s = settling_time(t, r[f"pos_{a}"], ref)
        out[f"settling_{a}_s"] = s
        out[f"overshoot_{a}_pct"] = overshoot_percent(r[f"pos_{a}"], ref)
        out[f"final_error_{a}_m"] = float(e[i, -1])
        out[f"sse_{a}_m"] = steady_state_error(r[f"pos_{a}"], ref)
        out[f"peak_force_{a}"] = float(np.max(np.abs(f[i])))
        out[f"effort_abs_{a}"] = float(np.sum(np.abs(f[i, :-1]) * dt))
        out[f"dist_est_end_{a}"] = _last(r, f"dist_est_{a}")
        st.append(s)
    out["settling_s"] = max(st) if not any(math.isnan(x) for x in st) else math.nan
    out["final_error"] = float(np.linalg.norm(e[:, -1]))
    out["peak_force"] = float(np.max(np.abs(f)))
    return out


def single_axis(r: dict) -> dict:
    """Single-axis step response: needs ``theta`` [rad] and the ``theta_ref`` [rad] input logged at every
    communication step; settling, overshoot, final error [deg], effort from ``applied_torque``."""
    t, th = r["time"], r["theta"]
    ref = float(r["theta_ref"][-1])
    out = _nan_row()
    out["settling_s"] = settling_time(t, th, ref)
    out["overshoot_pct"] = overshoot_percent(th, ref)
    out["final_error"] = math.degrees(ref - float(th[-1]))
    if "applied_torque" in r:
        dt = np.diff(t)
        tq = np.asarray(r["applied_torque"])[:-1]
        out["effort_abs"] = float(np.sum(np.abs(tq) * dt))
        out["effort_sq"] = float(np.sum(tq**2 * dt))
        out["peak_torque"] = float(np.max(np.abs(r["applied_torque"])))
    return out


_ANGLE_COLS = [f"{k}_{a}{u}" for a in ("roll", "pitch", "yaw")
               for k, u in (("settling", "_s"), ("overshoot", "_pct"), ("final_error", "_deg"))] + ["peak_torque"]
EXTRA = {
    "attitude": _ANGLE_COLS,
    "attitude_nometrics": _ANGLE_COLS,
    "formation": [f"{k}_{a}{u}" for a in "xyz" for k, u in (("settling", "_s"), ("overshoot", "_pct"),
                                                           ("final_error", "_m"), ("sse", "_m"), ("peak_force", ""),
                                                           ("effort_abs", ""), ("dist_est_end", ""))] + ["peak_force"],
    "single_axis": ["overshoot_pct", "peak_torque"],
}
_ATT_LOGS = ("alpha_deg", "eulerint_deg_s", "ise", "isf", "effort_abs", "effort_sq", "roll", "pitch", "yaw",
             "roll_ref", "pitch_ref", "yaw_ref", "torque_applied_x", "torque_applied_y", "torque_applied_z")
LOGS = {
    "attitude": _ATT_LOGS,
    "attitude_nometrics": _ATT_LOGS[6:],
    "formation": tuple(f"{v}_{a}" for v in ("pos", "pos_ref", "force", "dist_est") for a in "xyz"),
    "single_axis": ("theta", "theta_ref", "applied_torque"),
}
for _name, _fn in (("attitude", attitude), ("attitude_nometrics", attitude_nometrics), ("formation", formation),
                   ("single_axis", single_axis)):
    REGISTRY.metrics(_name, _fn, [*COMMON, *EXTRA[_name]], LOGS[_name])


def metric_set(name: str):
    """The registered metric set ``name`` (built-in, or from a plug-in)."""
    return REGISTRY.metric_set(name)


def compute(name: str, r: dict) -> dict:
    """The metrics of one run's logged signals ``r`` by metric-set name ("" gives the common columns as NaN)."""
    if not name:
        return _nan_row()
    return REGISTRY.metric_set(name).compute(r)


def columns(name: str) -> list[str]:
    """The metric columns a set returns (for the schema of failed-run rows)."""
    if not name:
        return list(COMMON)
    return list(REGISTRY.metric_set(name).columns)


def logs_needed(name: str) -> tuple | None:
    """The log keys a metric set reads (None: unknown, keep every logged signal)."""
    if not name:
        return ()
    return REGISTRY.metric_set(name).logs


# ----- attitude matrix -------------------------------------------------------------------------------------
# The project's convention (README "Conventions", src/math/attitude.rs): scalar-first Hamilton quaternions
# q = [w, x, y, z] of the body frame B relative to the reference (inertial) frame R.


def attitude_matrix(q) -> np.ndarray:
    """A(q), the attitude matrix (direction cosine matrix) of scalar-first unit quaternions q = [w, x, y, z]:
    v_B = A(q) v_R maps a vector's reference-frame (inertial) components into body components, the *passive*
    reading, A(q) = (w² − |q_v|²) I + 2 q_v q_vᵀ − 2 w [q_v×] (the plant's ``attitude_matrix`` in
    src/math/attitude.rs); A(p ⊗ q) = A(q) A(p). It is the transpose of the *active* rotation matrix of the same
    quaternion: scipy's ``Rotation.from_quat([x, y, z, w]).as_matrix().T`` (scipy is scalar-last).
    ``q``: shape (..., 4), one quaternion or many (not normalised here); returns shape (..., 3, 3)."""
    q = np.asarray(q, dtype=float)
    one = q.ndim == 1  # one quaternion: Python floats (the same numbers, a tenth of the time in an ODE's rhs)
    w, x, y, z = q.tolist() if one else np.moveaxis(q, -1, 0)
    a = [w*w + x*x - y*y - z*z, 2*(x*y + w*z), 2*(x*z - w*y),
         2*(x*y - w*z), w*w - x*x + y*y - z*z, 2*(y*z + w*x),
         2*(x*z + w*y), 2*(y*z - w*x), w*w - x*x - y*y + z*z]
    return (np.array(a) if one else np.stack(a, axis=-1)).reshape(q.shape[:-1] + (3, 3))


def to_body(q, v) -> np.ndarray:
    """A(q) v: the body components of vectors given in the reference frame (see :func:`attitude_matrix`), sample
    by sample. ``q``: shape (..., 4), ``v``: shape (..., 3) (broadcast); returns shape (..., 3). scipy:
    ``Rotation.from_quat([x, y, z, w]).apply(v, inverse=True)``."""
    return np.einsum("...ij,...j->...i", attitude_matrix(q), np.asarray(v, dtype=float))


# ----- pointing errors (in the spirit of the ECSS pointing error engineering handbook) ----------------------
# The error signal e(t) is a vector (here the small-rotation vector of the body relative to the reference,
# in degrees) or a scalar, sampled at times t. The *evaluation period* is [t_start, t_end] (the pointing
# phase); it is cut into consecutive windows of length ``window`` (the last, shorter remainder is dropped).
# With ē_k the mean of e over window k and ē the mean over the whole evaluation period:
#   APE   absolute pointing error      max_t ‖e(t)‖
#   MPE   mean pointing error          ‖ē‖
#   RPE   relative pointing error      max_k max_{t in k} ‖e(t) − ē_k‖      (stability within a window)
#   PDE   pointing drift error         max_k ‖ē_{k+1} − ē_k‖                (drift between consecutive windows)
#   jitter                             sqrt(mean_k mean_{t in k} ‖e(t) − ē_k‖²)   (RMS of the within-window part)
# Means are sample means over the samples of a window (equal spacing assumed); ‖·‖ is the Euclidean norm
# over the axes (the absolute value for a scalar signal).
POINTING = ("ape", "mpe", "rpe", "pde", "jitter")


def error_rotation_deg(q: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    """The small-rotation vector [deg] of the reference seen from the body, per sample: the error quaternion
    q_E = q* ⊗ q_ref (scalar-first, shape (n, 4) or (4, n)), rotation vector 2 atan2(|v|, w) v/|v| with w ≥ 0
    (shortest rotation). Returns shape (n, 3)."""
    q = np.asarray(q, dtype=float)
    r = np.asarray(q_ref, dtype=float)
    if q.shape[0] == 4 and q.ndim == 2 and q.shape[1] != 4:
        q, r = q.T, r.T
    w1, v1 = q[:, 0], -q[:, 1:]  # conjugate of q
    w2, v2 = r[:, 0], r[:, 1:]
    w = w1 * w2 - np.sum(v1 * v2, axis=1)
    v = w1[:, None] * v2 + w2[:, None] * v1 + np.cross(v1, v2)
    sign = np.where(w < 0.0, -1.0, 1.0)
    w, v = w * sign, v * sign[:, None]
    n = np.linalg.norm(v, axis=1)
    angle = 2.0 * np.arctan2(n, w)
    scale = np.where(n > 0.0, angle / np.where(n > 0.0, n, 1.0), 2.0)
    return np.degrees(v * scale[:, None])


def pointing_errors(t, e, window: float, t_start: float | None = None, t_end: float | None = None) -> dict:
    """APE, MPE, RPE, PDE and jitter (see the definitions above) of the error ``e`` (shape (n,) or (n, axes))
    sampled at ``t`` over the evaluation period [t_start, t_end] (default: the whole record) with windows of
    length ``window`` [s]. RPE and jitter need one window, PDE two (NaN otherwise)."""
    t = np.asarray(t, dtype=float)
    e = np.asarray(e, dtype=float)
    if e.ndim == 1:
        e = e[:, None]
    if not window > 0.0:
        raise ValueError(f"pointing window {window!r}: must be > 0 s")
    t0 = t[0] if t_start is None else float(t_start)
    t1 = t[-1] if t_end is None else float(t_end)
    sel = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    t, e = t[sel], e[sel]
    out = {k: math.nan for k in POINTING}
    if t.size == 0:
        return out
    out["ape"] = float(np.max(np.linalg.norm(e, axis=1)))
    out["mpe"] = float(np.linalg.norm(np.mean(e, axis=0)))
    # window index of each sample: windows [t0 + k w, t0 + (k+1) w); samples on the final boundary go to the
    # last full window (the boundary is tolerant to summed floating-point time)
    k = np.floor((t - t0) / window + 1e-9).astype(int)
    n_full = int(math.floor((t1 - t0) / window + 1e-9))
    k = np.where((k == n_full) & (np.abs(t - (t0 + n_full * window)) < 1e-9 * max(1.0, abs(t1))), n_full - 1, k)
    keep = (k >= 0) & (k < n_full)
    if n_full < 1 or not np.any(keep):
        return out
    k, e = k[keep], e[keep]
    means = np.stack([np.mean(e[k == i], axis=0) for i in range(n_full)])
    dev = np.linalg.norm(e - means[k], axis=1)
    out["rpe"] = float(np.max(dev))
    out["jitter"] = float(np.sqrt(np.mean([np.mean(dev[k == i] ** 2) for i in range(n_full)])))
    if n_full >= 2:
        out["pde"] = float(np.max(np.linalg.norm(np.diff(means, axis=0), axis=1)))
    return out


def saturation_fraction(t, u, limit, tol: float = 1e-9) -> float:
    """Fraction of the run's time [0, 1] in which any axis of the command ``u`` (shape (n, axes)) is at or beyond
    its limit ``limit`` (shape (axes,) or (n, axes)): |u_i| ≥ (1 − tol) limit_i. Each sample holds until the next
    (left rectangle, as the effort integrals)."""
    t = np.asarray(t, dtype=float)
    u = np.abs(np.asarray(u, dtype=float))
    if u.ndim == 1:
        u = u[:, None]
    lim = np.broadcast_to(np.asarray(limit, dtype=float), u.shape)
    sat = np.any(u >= (1.0 - tol) * lim, axis=1)[:-1]
    dt = np.diff(t)
    total = float(np.sum(dt))
    return float(np.sum(dt[sat]) / total) if total > 0 else math.nan
