"""Verdict rules shared by the paper sections: small pure functions on lists of numbers, so that every
verdict of the report is decided by a rule that can be read (and is unit-tested) rather than by eye.

Conventions: "lower is better" for every error or cost metric; a comparison ``better(a, b, rel)``
counts a as better than b only when it is lower by more than ``rel`` of |b| (ties and differences
below that margin are "no material difference").
"""

from __future__ import annotations

import math
from typing import Iterable, Sequence

from .types import (CONFIRMED, DEPENDS, NOT_CHECKABLE, NOT_CONFIRMED, NOT_REPRODUCED, NUMBER_VERDICTS, REPRODUCED,
                    SAME_ORDERING)

REL_TOL = 0.05   # "reproduced": within 5 % of the paper's value (or within its printed precision, if larger)


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


def combine_evidence(nominal: bool, readings: dict, chosen=()) -> tuple[str, list[str]]:
    """``combine`` over the evidence only: readings named in ``chosen`` (set-ups "chosen among readings" after
    comparing with the paper, never evidence) are left out of the verdict. Returns (verdict, the chosen
    readings under which the claim holds while the evidence gives "not confirmed"): a claim whose only
    support is a chosen reading reads "not confirmed (holds only under a chosen reading: …)"
    (``Claim.chosen_support``). The same rule for every paper."""
    chosen = set(chosen)
    evidence = {k: v for k, v in readings.items() if k not in chosen}
    v = combine(nominal, evidence)
    support = [k for k, h in readings.items() if k in chosen and h] if v == NOT_CONFIRMED else []
    return v, support


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


# ----- the papers' reported numbers beside ours -----------------------------------------------------------
def rel_diff(ours, paper) -> float:
    """(ours − paper)/|paper| (NaN when either is missing or non-finite, or the paper's value is 0)."""
    if not (finite(ours) and finite(paper)) or paper == 0:
        return math.nan
    return (ours - paper) / abs(paper)


def printed_precision(text: str) -> float:
    """Half a unit of the last printed digit of a decimal number as printed ("0.01" → 0.005, "156.1" →
    0.05, "2954" → 0.5); the precision a value printed that way stands for. Leading "≈", "~" and signs
    are ignored; NaN when the text holds no number."""
    t = str(text).strip().lstrip("≈~<>=± ").replace("−", "-").lstrip("+-")
    num = ""
    for ch in t:
        if ch.isdigit() or ch == ".":
            num += ch
        else:
            break
    if not num or not any(c.isdigit() for c in num):
        return math.nan
    decimals = len(num.split(".")[1]) if "." in num else 0
    return 0.5 * 10.0 ** (-decimals)


def precision_within_requirement(printed: float, paper: float, requirement: float | None, meets: bool) -> float:
    """The printed-precision half-width of one row, never wider than the paper's own stated requirement: when
    the paper states that the value meets ``requirement`` (an upper bound, ``meets``), the window may not
    reach above it; when it states that it fails, not below it. (5 % of the paper's value stays the floor,
    ``within``.)"""
    p = printed if finite(printed) else 0.0
    if requirement is None or not finite(requirement):
        return p
    room = (requirement - paper) if meets else (paper - requirement)
    return max(0.0, min(p, room))


def within(ours, paper, rel: float = REL_TOL, precision: float = 0.0) -> bool:
    """|ours − paper| ≤ max(rel·|paper|, precision) (False when either is missing)."""
    if not (finite(ours) and finite(paper)):
        return False
    prec = precision if finite(precision) else 0.0
    return abs(ours - paper) <= max(rel * abs(paper), prec) + 1e-12 * abs(paper)


def same_ordering(i: int, ours: Sequence, paper: Sequence, tie: float = 0.005) -> bool:
    """Item i sits among the others as the paper has it: for every other item j with both values, the sign
    of ours[i] − ours[j] equals that of paper[i] − paper[j], where differences within ``tie`` (relative to
    the larger magnitude) count as a tie (sign 0). False when item i lacks a value or has no partner."""
    if len(ours) != len(paper):
        raise ValueError("same_ordering: lengths differ")

    def sign(a, b):
        if abs(a - b) <= tie * max(abs(a), abs(b)):
            return 0
        return 1 if a > b else -1

    if not (finite(ours[i]) and finite(paper[i])):
        return False
    pairs = [j for j in range(len(ours)) if j != i and finite(ours[j]) and finite(paper[j])]
    return bool(pairs) and all(sign(ours[i], ours[j]) == sign(paper[i], paper[j]) for j in pairs)


def number_verdict(ours, paper, precision: float = 0.0, ordering: bool | None = None, rel: float = REL_TOL) -> str:
    """The verdict of one reported number: not checkable when either value is missing; reproduced when
    ``within(ours, paper, rel, precision)``; otherwise "same ordering only" when ``ordering`` is True (the
    item ranks among the paper's other numbers as in the paper), else not reproduced."""
    if not (finite(ours) and finite(paper)):
        return NOT_CHECKABLE
    if within(ours, paper, rel, precision):
        return REPRODUCED
    return SAME_ORDERING if ordering else NOT_REPRODUCED


def bound_verdict(ours, bound, above: bool = True) -> str:
    """A number the paper states as a bound ("more than 50 times"): reproduced when ours is beyond it."""
    if not (finite(ours) and finite(bound)):
        return NOT_CHECKABLE
    return REPRODUCED if ((ours > bound) if above else (ours < bound)) else NOT_REPRODUCED


def nearest(ours, candidates: Sequence[float]) -> tuple[float, float]:
    """(candidate closest to ours, its relative difference) among the paper's candidate readings of a damaged
    number; (NaN, NaN) when there is nothing to compare."""
    c = [x for x in candidates if finite(x)]
    if not c or not finite(ours):
        return math.nan, math.nan
    best = min(c, key=lambda x: abs(ours - x))
    return best, rel_diff(ours, best)


def tally(verdicts: Iterable[str]) -> dict:
    """{number verdict: count} in the order of NUMBER_VERDICTS (zeros included)."""
    v = list(verdicts)
    return {k: sum(1 for x in v if x == k) for k in NUMBER_VERDICTS}


def combine_faithful(nominal: bool, readings: dict) -> tuple[str, list[str], list[str]]:
    """Like ``combine`` for readings ``{name: (holds, moves_away)}``, where ``moves_away`` says that the
    reading moves our values of the paper's own reported numbers further from them. Such a reading is never
    support (nor a counter-example): it is left out of the verdict and listed. Returns (verdict, names of
    readings that support the claim, names of readings under which it holds only by moving away from the
    paper)."""
    support = [n for n, (h, away) in readings.items() if h and not away]
    away = [n for n, (h, a) in readings.items() if h and a]
    vals = [bool(nominal)] + [bool(h) for h, a in readings.values() if not a]
    if all(vals):
        v = CONFIRMED
    elif not any(vals):
        v = NOT_CONFIRMED
    else:
        v = DEPENDS
    return v, support, away
