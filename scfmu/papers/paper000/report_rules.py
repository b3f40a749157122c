"""Paper 000 report, the verdict rules: each claim's rule (``rule_c1`` … ``rule_c7``, collected in ``RULES``) is a
pure function of a table ``{run id: metrics row}`` returning (holds, one-line explanation), so that it can be
tested on synthetic numbers; with the verdict rule over the default and the swept settings (``verdict``) and the
readable region of a sweep where a claim holds (``holds_where``). ``report.py`` runs the study and re-exports
these names.

Verdict rule: holds at the defaults and at every point tried → confirmed; fails at the defaults and at every
point tried → not confirmed; otherwise → depends on a reading.
"""

from __future__ import annotations

import math

import numpy as np

from ...report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED
from .constants import (EFF, EFFORT_RATIO, EI, L_METHODS, L_RUNS, PD_VARIANTS, ROBUST_CASES, ROBUST_CTRL, S_RUNS,
                        TOL_IDENTICAL, TOL_ORDER, TOL_SMALL, _label)


# ----- rules: each returns (holds, one-line explanation) ---------------------------------------------------
def below(a: float, b: float) -> bool:
    """a ranks strictly below b (by more than TOL_ORDER relative)."""
    return a < (1.0 - TOL_ORDER) * b


def _rel(a, b) -> str:
    return "<" if below(a, b) else ">" if below(b, a) else "≈"


def rule_c1(m: dict) -> tuple[bool, str]:
    """C000-1: large slew with PD, EULERINT(quaternion) < EULERINT(DCM) < EULERINT(Euler)."""
    q, d, e = (m[k][EI] for k in ("000-6", "000-4", "000-2"))
    ok = below(q, d) and below(d, e)
    return ok, f"quaternion {q:.1f} {_rel(q, d)} DCM {d:.1f} {_rel(d, e)} Euler {e:.1f} deg·s"


def spread_c2(m: dict) -> float:
    """C000-2's measure: the relative spread (max − min)/min of EULERINT over the small-command runs."""
    v = [m[k][EI] for k in S_RUNS if k in m]
    return (max(v) - min(v)) / min(v)


def rule_c2(m: dict) -> tuple[bool, str]:
    """C000-2: small command, every method within TOL_SMALL of each other (relative spread of EULERINT)."""
    v = [m[k][EI] for k in S_RUNS if k in m]
    spread = spread_c2(m)
    return spread <= TOL_SMALL, f"small command: EULERINT {min(v):.2f} … {max(v):.2f} deg·s, spread {100 * spread:.1f} % " \
                                f"(rule ≤ {100 * TOL_SMALL:.0f} %)"


def agreement_c3(m: dict) -> float:
    """C000-3's equality, measured: the largest relative difference of LQR's and pole placement's EULERINT to the
    quaternion PD's (small and large command); three controllers whose gains come by three routes (Riccati
    equation, Ackermann, the PD's closed form)."""
    worst = 0.0
    for pd, others in (("000-5", ("000-7S", "000-8S")), ("000-6", ("000-7L", "000-8L"))):
        for o in others:
            worst = max(worst, abs(m[o][EI] - m[pd][EI]) / abs(m[pd][EI]))
    return worst


def rule_c3(m: dict) -> tuple[bool, str]:
    """C000-3: LQR and pole placement give the quaternion PD's EULERINT within TOL_IDENTICAL (S and L)."""
    worst = agreement_c3(m)
    return worst <= TOL_IDENTICAL, f"largest relative difference to PD {worst:.1e} (rule ≤ {TOL_IDENTICAL:.0e})"


def rule_c4(m: dict) -> tuple[bool, str]:
    """C000-4: large slew, EULERINT(adaptive fuzzy) < fuzzy < MRAC < quaternion PD."""
    a, f, r, p = (m[k][EI] for k in ("000-11L", "000-10L", "000-9L", "000-6"))
    ok = below(a, f) and below(f, r) and below(r, p)
    order = sorted([(a, "adaptive fuzzy"), (f, "fuzzy"), (r, "MRAC"), (p, "PD")])
    return ok, "order " + " < ".join(f"{n} {v:.1f}" for v, n in order) + " deg·s"


def _spearman(x, y) -> float:
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    if np.std(rx) == 0 or np.std(ry) == 0:
        return 0.0
    return float(np.corrcoef(rx, ry)[0, 1])


def rule_c5(m: dict, effort: str = EFF) -> tuple[bool, str]:
    """C000-5: (a) among the PD variants (large slew) effort rises with EULERINT (same order);
    (b) across the methods on the large slew (PD, MRAC, fuzzy, adaptive fuzzy) lower EULERINT costs more
    effort (Spearman rank correlation of EULERINT and effort < 0)."""
    ks = list(PD_VARIANTS)
    by_ei = sorted(ks, key=lambda k: m[k][EI])
    by_eff = sorted(ks, key=lambda k: m[k][effort])
    a = by_ei == by_eff
    ms = list(L_METHODS)
    rho = _spearman([m[k][EI] for k in ms], [m[k][effort] for k in ms])
    b = rho < 0
    return a and b, (f"(a) PD variants by EULERINT: {', '.join(PD_VARIANTS[k] for k in by_ei)}; by {effort}: "
                     f"{', '.join(PD_VARIANTS[k] for k in by_eff)} → {'same' if a else 'different'} order; "
                     f"(b) Spearman ρ(EULERINT, {effort}) over PD, MRAC, fuzzy, adaptive fuzzy = {rho:+.2f}")


def rule_c6(m: dict, effort: str = EFF) -> tuple[bool, str]:
    """C000-6: fuzzy and adaptive fuzzy below MRAC in EULERINT, each with effort ≤ EFFORT_RATIO × quaternion PD,
    and adaptive fuzzy the lowest EULERINT of all large-slew runs."""
    mr, pd = m["000-9L"][EI], m["000-6"][effort]
    parts, ok = [], True
    for k, n in (("000-10L", "fuzzy"), ("000-11L", "adaptive fuzzy")):
        ratio = m[k][effort] / pd
        good = below(m[k][EI], mr) and ratio <= EFFORT_RATIO
        ok &= good
        parts.append(f"{n}: EULERINT {m[k][EI]:.1f} vs MRAC {mr:.1f}, effort ratio {ratio:.2f}")
    best = min((k for k in L_RUNS if k in m), key=lambda k: m[k][EI])
    ok &= best == "000-11L" and all(below(m["000-11L"][EI], m[k][EI]) for k in L_RUNS if k in m and k != "000-11L")
    parts.append(f"lowest EULERINT: {_label(best)}")
    return ok, "; ".join(parts) + f" (rule: ratio ≤ {EFFORT_RATIO})"


def _os(row) -> float:
    return max(row.get(f"overshoot_{a}_pct", math.nan) for a in ("roll", "pitch", "yaw"))


def _ts(row) -> float:
    v = row.get("settling_s", math.nan)
    return math.inf if v is None or math.isnan(v) else v


def rule_c7(m: dict, commands=("L2",)) -> tuple[bool, str]:
    """C000-7: in each robustness case (R1 disturbance, R2 inertia ×1.2 and ×0.8; commands given, by default
    L2 = (60, 40, 40) deg, the command of the paper's robustness figures),
    adaptive fuzzy has overshoot ≤ PD's (largest of the three Euler angles) and settling time (α, 2 %
    band; not settled = ∞) ≤ PD's, and the lowest EULERINT of PD, MRAC, fuzzy and adaptive fuzzy."""
    ok, parts = True, []
    for case in ROBUST_CASES:
        for cmd in commands:
            rows = {c: m.get(f"{case}-{c}-{cmd}") for c in ROBUST_CTRL}
            if any(r is None for r in rows.values()):
                continue
            af, pd = rows["AdaptFuzzy"], rows["PD"]
            better = _os(af) <= _os(pd) + 1e-9 and _ts(af) <= _ts(pd)
            best = min(rows, key=lambda c: rows[c][EI])
            ok &= better and best == "AdaptFuzzy"
            parts.append(f"{case}-{cmd}: AF OS {_os(af):.1f} % vs PD {_os(pd):.1f} %, ts {_ts(af):.1f} vs {_ts(pd):.1f} s, "
                         f"best EULERINT {ROBUST_CTRL[best]}")
    if not parts:
        return False, "no robustness run for the command(s) " + ", ".join(commands)
    return ok, "; ".join(parts)


def c6_needed_ratio(m: dict, effort: str = EFF) -> float:
    """The smallest effort-ratio threshold for which C000-6 would hold on this table (∞ if its EULERINT parts
    fail): how much 'much more effort' has to allow."""
    mr, pd = m["000-9L"][EI], m["000-6"][effort]
    if not (below(m["000-10L"][EI], mr) and below(m["000-11L"][EI], mr)):
        return math.inf
    if not all(below(m["000-11L"][EI], m[k][EI]) for k in L_RUNS if k in m and k != "000-11L"):
        return math.inf
    return max(m["000-10L"][effort], m["000-11L"][effort]) / pd


# the claims that state an equality, with the measured agreement of the quantities they equate (``Claim.agreement``:
# at rounding level the claim holds by construction, decided from these numbers)
AGREEMENT = {"C000-3": agreement_c3}

# the claims whose rule compares one measure with a project-chosen threshold: (measure, threshold, unit factor,
# unit); the report states the measure at the defaults and at every reading, and the thresholds for which the
# verdict stands, so a reader can judge the threshold (C000-2: the paper prints no small-command values that
# could calibrate "about the same")
MEASURE = {"C000-2": (spread_c2, TOL_SMALL, 100.0, "%")}

RULES = {"C000-1": rule_c1, "C000-2": rule_c2, "C000-3": rule_c3, "C000-4": rule_c4, "C000-5": rule_c5,
         "C000-6": rule_c6, "C000-7": rule_c7}


def verdict(at_default: bool, swept: list[bool]) -> str:
    """The verdict rule of the module docstring of ``report.py`` (and above)."""
    allv = [at_default] + list(swept)
    if all(allv):
        return CONFIRMED
    if not any(allv):
        return NOT_CONFIRMED
    return DEPENDS


def _fmt_cat(v) -> str:
    return "(" + ", ".join(f"{e:.3g}" for e in v) + ")" if isinstance(v, tuple) else str(v)


def _value(v) -> str:
    """A reading's value in the evidence text (a pair of the joint grid, an integer code, a number)."""
    return _fmt_cat(v) if isinstance(v, (tuple, int, str)) else f"{v:.3g}"


def _measure_text(c: str, base: dict, measured: list) -> str:
    """The measure of a claim of ``MEASURE`` at the defaults and at every reading, and the thresholds for which
    the verdict stands: the rule holds wherever the measure is ≤ the threshold, so the verdict over the counted
    readings is confirmed for a threshold ≥ the largest counted measure and not confirmed below the smallest."""
    fn, tol, k, unit = MEASURE[c]
    at0 = fn(base)
    counted = [at0] + [x for _, x, away in measured if not away]
    parts = [f"{name}: {k * x:.1f} {unit}" + (" (moves the paper's own Table 3 numbers further away: not counted)"
                                              if away else "") for name, x, away in measured]
    lo, hi = k * min(counted), k * max(counted)
    return (f" The threshold {k * tol:.0f} {unit} is a project choice (the paper's own small-command values are not "
            f"among the numbers we have, so its own spread cannot set it): the measure is {k * at0:.1f} {unit} at the "
            f"defaults" + (f" and {'; '.join(parts)}" if parts else "")
            + f"; over the defaults and the counted readings the verdict would be confirmed for any threshold ≥ "
            f"{hi:.1f} {unit}" + (f", depend on the reading between {lo:.1f} and {hi:.1f} {unit}" if f"{hi:.1f}" != f"{lo:.1f}" else "")
            + (f" and be not confirmed below {lo:.1f} {unit}." if lo > 0 else "."))


def _at(param: str, values: list, most: int = 4) -> str:
    """"param = a, b" for the values at which a reading flips a verdict (at most ``most`` named)."""
    named = ", ".join(_value(v) for v in values[:most])
    return f"{param} = {named}" + (f" … ({len(values)} values)" if len(values) > most else "")


def holds_where(param: str, values: list, holds: list[bool], fmt=lambda v: f"{v:.3g}", categorical=False) -> str:
    """A readable region from a sweep: contiguous runs of holding values (values sorted as given), or for a
    categorical reading the set of values where it holds."""
    if not values:
        return "not swept"
    if categorical:
        if all(holds):
            return f"every value tried ({', '.join(fmt(v) for v in values)})"
        if not any(holds):
            return f"none of {', '.join(fmt(v) for v in values)}"
        return f"{param} ∈ {{{', '.join(fmt(v) for v, h in zip(values, holds) if h)}}} (of {', '.join(fmt(v) for v in values)})"
    if all(holds):
        return f"everywhere tried ({param} ∈ [{fmt(values[0])}, {fmt(values[-1])}])" if len(values) > 1 else "everywhere tried"
    if not any(holds):
        return f"nowhere in {param} ∈ [{fmt(values[0])}, {fmt(values[-1])}]" if len(values) > 1 else "nowhere tried"
    spans, start = [], None
    for i, h in enumerate(holds):
        if h and start is None:
            start = i
        if (not h or i == len(holds) - 1) and start is not None:
            end = i if h else i - 1
            spans.append(fmt(values[start]) if start == end else f"[{fmt(values[start])}, {fmt(values[end])}]")
            start = None
    return f"{param} ∈ " + " ∪ ".join(spans) + f" (of the values tried in [{fmt(values[0])}, {fmt(values[-1])}])"
