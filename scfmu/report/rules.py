"""Verdict rules shared by the paper sections: small pure functions on lists of numbers, so that every
verdict of the report is decided by a rule that can be read (and is unit-tested) rather than by eye.

Conventions: "lower is better" for every error or cost metric; a comparison ``better(a, b, rel)``
counts a as better than b only when it is lower by more than ``rel`` of |b| (ties and differences
below that margin are "no material difference").
"""

from __future__ import annotations

import math
from typing import Iterable, Sequence

from .types import CONFIRMED, DEPENDS, NOT_CONFIRMED


def finite(x) -> bool:
    return isinstance(x, (int, float)) and math.isfinite(x)


def better(a: float, b: float, rel: float = 0.0) -> bool:
    """a is lower than b by more than rel·|b| (NaN/inf never better; a finite a beats a non-finite b)."""
    if not finite(a):
        return False
    if not finite(b):
        return True
    return a < b - rel * abs(b)


def count_better(a: Sequence[float], b: Sequence[float], rel: float = 0.0) -> int:
    """At how many points a[i] is better (lower) than b[i]."""
    if len(a) != len(b):
        raise ValueError("count_better: sequences of different length")
    return sum(1 for x, y in zip(a, b) if better(x, y, rel))


def at_least(k: int, n: int, frac: float) -> bool:
    """k of n points is at least the fraction frac (rounded up: 3 of 4 for 0.75)."""
    return n > 0 and k >= math.ceil(frac * n - 1e-12)


def spread(values: Iterable[float]) -> float:
    """max − min of the finite values (inf when any is non-finite, NaN when none)."""
    v = list(values)
    if not v:
        return math.nan
    if any(not finite(x) for x in v):
        return math.inf
    return max(v) - min(v)


def monotone_fraction(ys: Sequence[float], increasing: bool = True, rel: float = 0.0) -> float:
    """Fraction of consecutive pairs (y[i], y[i+1]) that move in the given direction (a pair whose
    change is within rel·|y[i]| counts as following it: flat is allowed). NaN for fewer than 2 points."""
    if len(ys) < 2:
        return math.nan
    ok = 0
    for a, b in zip(ys[:-1], ys[1:]):
        if not (finite(a) and finite(b)):
            continue
        d = b - a
        tol = rel * abs(a)
        ok += (d >= -tol) if increasing else (d <= tol)
    return ok / (len(ys) - 1)


def strictly_monotone(ys: Sequence[float], increasing: bool = True) -> bool:
    """Every consecutive pair strictly in the direction (all values finite)."""
    if len(ys) < 2 or any(not finite(y) for y in ys):
        return False
    return all((b > a) if increasing else (b < a) for a, b in zip(ys[:-1], ys[1:]))


def ratio(a: float, b: float) -> float:
    return a / b if finite(a) and finite(b) and b != 0 else math.nan


def verdict(holds: bool) -> str:
    return CONFIRMED if holds else NOT_CONFIRMED


def combine(nominal: bool, readings: dict) -> str:
    """Verdict of a claim checked under today's readings (``nominal``) and under other plausible readings
    of values the paper does not give (``readings``: name -> holds). All agree: confirmed / not
    confirmed; otherwise it depends on a reading."""
    vals = [bool(nominal), *(bool(v) for v in readings.values())]
    if all(vals):
        return CONFIRMED
    if not any(vals):
        return NOT_CONFIRMED
    return DEPENDS


def holds_where(values: Sequence, holds: Sequence[bool], name: str = "x", unit: str = "") -> str:
    """Plain-words region of ``values`` (in the order given, e.g. ascending) where ``holds`` is true:
    "everywhere tried", "nowhere tried", or contiguous runs such as "0.8 ≤ x ≤ 1.0; x = 1.2"."""
    if len(values) != len(holds):
        raise ValueError("holds_where: lengths differ")
    if not values:
        return "nothing tried"
    if all(holds):
        return f"everywhere tried ({_v(values[0], unit)} … {_v(values[-1], unit)})" if len(values) > 1 \
            else f"{name} = {_v(values[0], unit)}"
    if not any(holds):
        return "nowhere tried"
    runs, start = [], None
    for i, h in enumerate(holds):
        if h and start is None:
            start = i
        if (not h or i == len(holds) - 1) and start is not None:
            end = i if h else i - 1
            runs.append((start, end))
            start = None
    parts = []
    for a, b in runs:
        if a == b:
            parts.append(f"{name} = {_v(values[a], unit)}")
        else:
            parts.append(f"{_v(values[a], unit)} ≤ {name} ≤ {_v(values[b], unit)}")
    return "; ".join(parts)


def _v(x, unit: str) -> str:
    s = f"{x:g}" if isinstance(x, (int, float)) and not isinstance(x, bool) else str(x)
    return f"{s} {unit}".strip() if unit else s


def holds_at(labels: Sequence[str], holds: Sequence[bool]) -> str:
    """Like holds_where for unordered candidates: "everywhere tried", "nowhere tried" or the list."""
    if len(labels) != len(holds):
        raise ValueError("holds_at: lengths differ")
    if holds and all(holds):
        return "everywhere tried"
    if not any(holds):
        return "nowhere tried"
    return "at " + ", ".join(str(x) for x, h in zip(labels, holds) if h) + f" ({sum(map(bool, holds))} of {len(holds)})"
