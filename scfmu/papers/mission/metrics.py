"""The metric set ``mission``: one row per run of a ``mission/*`` scenario, from its logged signals.

* ``t_<mode>_s``: the first time the manager is in SUN_ACQUISITION, DETERMINATION, FINE_POINTING, SAFE (NaN if
  never); ``t_fine_after_safe_s``: the first FINE_POINTING after the first SAFE; ``reached_fine``: 1 or 0;
* ``mode_changes``: the manager's transition count; ``mode_chatter``: transitions back into the mode left less
  than 60 s before;
* ``peak_rate_deg_s``: the largest true body rate; ``peak_rate_fine_deg_s``: in FINE_POINTING;
* ``wheel_energy_j``: the motors' positive mechanical work, ∫ Σ max(0, Ω_i dh_i/dt) dt (no regeneration);
  ``peak_wheel_momentum``: max |h_w| [N·m·s]; ``mtq_usage``: ∫ |m| dt [A·m²·s];
* ``t_on_target_s``: the first time in FINE_POINTING from which the angle to the reference stays within the
  pointing requirement ``ON_TARGET_DEG`` for ``ON_TARGET_HOLD`` seconds (NaN if never): the time to a usable
  pointing, where the FINE_POINTING law shows (the manager's hand-over time does not depend on it);
* ``fine_error_p95_deg``, ``fine_error_max_deg``: the angle between the attitude and the nadir reference over
  the samples in FINE_POINTING more than 600 s after its entry (the slew from the sun-pointing attitude left
  out); NaN if none;
* ``safe_array_power_w``: the array's orbit-averaged power in SAFE: its mean over SAFE's sunlit samples times
  the run's sunlit fraction; ``safe_power_margin_w``: that minus the safe-mode load (power-positive if > 0);
  ``net_energy_wh``: ∫ (array power − safe load) dt over the run.
The array is body-mounted on +x (the sun sensor's boresight), ``ARRAY_POWER`` at normal incidence, cosine law,
times the visible fraction of the solar disk (``scenarios.ARRAY_POWER``, ``SAFE_LOAD``: project choices)."""

from __future__ import annotations

import math

import numpy as np

from ...metrics import error_rotation_deg, to_body
from .scenarios import ARRAY_POWER, MODES, SAFE_LOAD

FINE_SETTLE = 600.0
ON_TARGET_DEG = 0.2  # the mission's pointing requirement (project choice)
ON_TARGET_HOLD = 300.0
CHATTER_WINDOW = 60.0
_ENTRY = {"t_fine_pointing_s": 4, "t_sun_acquisition_s": 2, "t_determination_s": 3, "t_safe_s": 0}
COLUMNS = [*_ENTRY, "t_on_target_s", "t_fine_after_safe_s", "reached_fine", "mode_changes", "mode_chatter", "peak_rate_deg_s",
           "peak_rate_fine_deg_s", "wheel_energy_j", "peak_wheel_momentum", "mtq_usage", "fine_error_p95_deg",
           "fine_error_max_deg", "safe_array_power_w", "safe_power_margin_w", "net_energy_wh"]
_V = [f"{s}_{a}" for s in ("w", "h_wheel", "wheel_speed", "dipole", "sun_eci") for a in "xyz"]
LOGS = ("mode", "mode_changes", "eclipse", *_V, *[f"q_{c}" for c in "wxyz"], *[f"q_ref_{c}" for c in "wxyz"])


def _stack(r, stem, comps="xyz"):
    return np.stack([np.asarray(r[f"{stem}_{c}"], dtype=float) for c in comps], axis=1)


def error_angle_deg(q: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    """The angle [deg] of the rotation from the attitude to the reference, per sample."""
    return np.linalg.norm(error_rotation_deg(q, q_ref), axis=1)


def transitions(t: np.ndarray, mode: np.ndarray) -> list[tuple[float, int, int]]:
    """(time, from, to) of every change of the logged mode."""
    idx = np.nonzero(np.diff(mode) != 0)[0] + 1
    return [(float(t[i]), int(mode[i - 1]), int(mode[i])) for i in idx]


def chatter(changes: list[tuple[float, int, int]], window: float = CHATTER_WINDOW) -> int:
    """Transitions back into the mode left less than ``window`` seconds before."""
    return sum(1 for (t0, a, b), (t1, c, d) in zip(changes, changes[1:]) if d == a and c == b and t1 - t0 < window)


def array_power(r: dict) -> np.ndarray:
    """The +x array's power [W] per sample: ARRAY_POWER · max(0, x_b · s_b) · visible fraction."""
    s_b = to_body(_stack(r, "q", "wxyz"), _stack(r, "sun_eci"))
    return ARRAY_POWER * np.clip(s_b[:, 0], 0.0, None) * np.asarray(r["eclipse"], dtype=float)


def compute(r: dict) -> dict:
    t = np.asarray(r["time"], dtype=float)
    mode = np.rint(np.asarray(r["mode"], dtype=float)).astype(int)
    out = {k: math.nan for k in COLUMNS}
    for k, m in _ENTRY.items():
        hit = np.nonzero(mode == m)[0]
        out[k] = float(t[hit[0]]) if hit.size else math.nan
    if not math.isnan(out["t_safe_s"]):
        after = np.nonzero((mode == 4) & (t > out["t_safe_s"]))[0]
        out["t_fine_after_safe_s"] = float(t[after[0]]) if after.size else math.nan
    out["reached_fine"] = float(np.any(mode == 4))
    changes = transitions(t, mode)
    out["mode_changes"] = float(np.asarray(r["mode_changes"])[-1])
    out["mode_chatter"] = float(chatter(changes))
    rate = np.degrees(np.linalg.norm(_stack(r, "w"), axis=1))
    out["peak_rate_deg_s"] = float(rate.max())
    if np.any(mode == 4):
        out["peak_rate_fine_deg_s"] = float(rate[mode == 4].max())
    h, omega = _stack(r, "h_wheel"), _stack(r, "wheel_speed")
    dt = np.diff(t)
    work = np.sum(omega[:-1] * np.diff(h, axis=0), axis=1)  # Ω · Δh per step, per axis summed
    out["wheel_energy_j"] = float(np.sum(np.clip(work, 0.0, None)))
    out["peak_wheel_momentum"] = float(np.linalg.norm(h, axis=1).max())
    out["mtq_usage"] = float(np.sum(np.linalg.norm(_stack(r, "dipole"), axis=1)[:-1] * dt))
    err_all = error_angle_deg(_stack(r, "q", "wxyz"), _stack(r, "q_ref", "wxyz"))
    out["t_on_target_s"] = on_target(t, (mode == 4) & (err_all <= ON_TARGET_DEG))
    settled = _in_fine_since(t, mode, fine_entries(t, mode))
    if settled.any():
        err = error_angle_deg(_stack(r, "q", "wxyz")[settled], _stack(r, "q_ref", "wxyz")[settled])
        out["fine_error_p95_deg"] = float(np.percentile(err, 95))
        out["fine_error_max_deg"] = float(err.max())
    p = array_power(r)
    lit = np.asarray(r["eclipse"], dtype=float) > 0.5
    safe_lit = (mode == 0) & lit
    if safe_lit.any():
        out["safe_array_power_w"] = float(p[safe_lit].mean() * lit.mean())
        out["safe_power_margin_w"] = out["safe_array_power_w"] - SAFE_LOAD
    out["net_energy_wh"] = float(np.sum((p[:-1] - SAFE_LOAD) * dt) / 3600.0)
    return out


def on_target(t: np.ndarray, ok: np.ndarray, hold: float = ON_TARGET_HOLD) -> float:
    """The first time from which ``ok`` holds for ``hold`` seconds without a break (NaN if never)."""
    if len(t) < 2:
        return math.nan
    w = int(round(hold / float(t[1] - t[0])))
    bad = np.concatenate([[0], np.cumsum(~ok)])
    i = np.nonzero((bad[w:] - bad[:-w] == 0) if w < len(bad) else np.zeros(0, dtype=bool))[0]
    return float(t[i[0]]) if i.size else math.nan


def fine_entries(t: np.ndarray, mode: np.ndarray) -> list[float]:
    """Times at which FINE_POINTING is entered (the start included when the run begins in it)."""
    return [float(t[0])] * bool(mode[0] == 4) + [c[0] for c in transitions(t, mode) if c[2] == 4]


def _in_fine_since(t, mode, entries) -> np.ndarray:
    """Samples whose current FINE_POINTING stretch began at least FINE_SETTLE before them."""
    ok = np.zeros(len(t), dtype=bool)
    starts = sorted(entries)
    for i, t0 in enumerate(starts):
        end = starts[i + 1] if i + 1 < len(starts) else math.inf
        ok |= (t >= t0 + FINE_SETTLE) & (t < end) & (mode == 4)
    return ok


def timeline(r: dict) -> list[tuple[float, str, str]]:
    """The run's mode changes as (time, from, to) with the modes' names."""
    t = np.asarray(r["time"], dtype=float)
    mode = np.rint(np.asarray(r["mode"], dtype=float)).astype(int)
    return [(tt, MODES[a], MODES[b]) for tt, a, b in transitions(t, mode)]
