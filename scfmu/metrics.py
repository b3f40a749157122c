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
