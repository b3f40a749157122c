"""Metrics of one run, computed from its logged signals; one function per ``Scenario.metrics`` name.

Every function returns the common columns (NaN where a scenario has no such quantity):

* ``eulerint_deg_s``: EULERINT, ∫ α dt of the Euler-axis error angle [deg·s] (AttitudeMetrics);
* ``ise``, ``isf``: integral of squared error and of squared control (AttitudeMetrics; formation: ∑‖e‖²Δ
  and ∑‖F‖²Δ, left rectangle on the communication grid);
* ``settling_s``: 2 % settling time of the main error signal (α, or the slowest axis) [s], NaN if not
  settled by the end;
* ``effort_abs``, ``effort_sq``: ∫ Σ|u_i| dt and ∫ ‖u‖² dt;
* ``final_error``: main error at the end (α [deg], or ‖position error‖ [m]);

plus scenario-specific columns (per-axis settling, final angle errors, peak control).
"""

from __future__ import annotations

import math

import numpy as np

from .metrics import overshoot_percent, settling_time

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
        out[f"dist_est_end_{a}"] = _last(r, f"dist_est_{a}")
        st.append(s)
    out["settling_s"] = max(st) if not any(math.isnan(x) for x in st) else math.nan
    out["final_error"] = float(np.linalg.norm(e[:, -1]))
    out["peak_force"] = float(np.max(np.abs(f)))
    return out


def paper003(r: dict) -> dict:
    """Paper 003 loops: attitude columns plus steady-state error per Euler angle, torque extremes, GA cost."""
    from .paper003 import metrics
    return metrics(r)


def single_axis(r: dict) -> dict:
    """Single-axis step response (paper 002): needs ``theta`` [rad] and the ``theta_ref`` [rad] input logged
    at every communication step. ``mae_deg``, ``late_max_deg`` and ``cost`` are the PSO cost terms of
    ``scfmu.paper002.cost_from_series`` (MAE over the samples of [t0, t_end), max error for t >= 10 s)."""
    from .paper002 import cost_from_series
    t, th = r["time"], r["theta"]
    ref = float(r["theta_ref"][-1])
    out = _nan_row()
    out.update(cost_from_series(t, th, math.degrees(ref)))
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


FUNCTIONS = {"attitude": attitude, "attitude_nometrics": attitude_nometrics, "formation": formation,
             "single_axis": single_axis, "paper003": paper003}


def compute(name: str, r: dict) -> dict:
    if not name:
        return _nan_row()
    return FUNCTIONS[name](r)


def columns(name: str) -> list[str]:
    """The metric columns a function returns (for the schema of failed-run rows)."""
    extra = {
        "attitude": [f"{k}_{a}{u}" for a in ("roll", "pitch", "yaw")
                     for k, u in (("settling", "_s"), ("overshoot", "_pct"), ("final_error", "_deg"))] + ["peak_torque"],
        "attitude_nometrics": [f"{k}_{a}{u}" for a in ("roll", "pitch", "yaw")
                               for k, u in (("settling", "_s"), ("overshoot", "_pct"), ("final_error", "_deg"))] + ["peak_torque"],
        "formation": [f"{k}_{a}{u}" for a in "xyz" for k, u in (("settling", "_s"), ("overshoot", "_pct"),
                                                               ("final_error", "_m"), ("dist_est_end", ""))] + ["peak_force"],
        "single_axis": ["mae_deg", "late_max_deg", "cost", "overshoot_pct", "peak_torque"],
    }.get(name, [])
    if name == "paper003":
        from .paper003 import EXTRA_COLUMNS
        extra = columns("attitude")[len(COMMON):] + list(EXTRA_COLUMNS)
    return [*COMMON, *extra]
