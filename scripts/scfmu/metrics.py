"""Metrics computed from logged signals (spec metrics-and-scenarios.md §1.2)."""

from __future__ import annotations

import numpy as np


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
