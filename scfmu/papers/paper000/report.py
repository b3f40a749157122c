"""Paper 000 section of the reproduction report: the runs of the paper 000 study on the campaign engine,
claims C000-1 … C000-7 with verdicts decided by the explicit rules of ``report_rules.py``, and the sensitivity of each
verdict to the readings the paper leaves open (fuzzy scales and set widths, the fuzzy reference settling
time, the adaptive-fuzzy λ ranges and scales, the adaptation gain γ, the DCM error reading, the DCM
re-orthonormalisation, the effort metric).

Verdict rule (all claims): the claim's rule is evaluated on the default runs and on every point of every
sweep of the readings it depends on (one reading changed at a time, the other controllers at their
defaults).
* holds at the defaults and at every point tried → confirmed;
* fails at the defaults and at every point tried → not confirmed;
* otherwise (it flips somewhere) → depends on a reading, and each sweep says where it holds.

``build(ctx)`` returns the ``PaperSection`` (figures: ``figures.py``); the rule functions (``rule_c1`` … ``rule_c7``,
in ``report_rules.py``, re-exported here) are pure functions of a table ``{run id: metrics row}`` so that they can
be tested on synthetic numbers.
"""

from __future__ import annotations

import math
import time

import numpy as np

from . import scenarios
from ...campaign import Campaign, read_timeseries
from ...report import common
from ...report.types import Claim, Context, PaperSection, Sensitivity, Table

from .constants import (DCM_READINGS, EFF, EFFORT_RATIO, EI, L_METHODS, L_RUNS, PD_VARIANTS, ROBUST_CASES,  # noqa: F401
                        ROBUST_CTRL, S_RUNS, TITLE, TOL_IDENTICAL, TOL_ORDER, TOL_SMALL, _label)
from . import numbers as N
from ...report import rules
from .figures import fig_effort, fig_joint, fig_ranking, fig_robust, fig_sweep
from .report_rules import (AGREEMENT, MEASURE, RULES, _at, _fmt_cat, _measure_text, _spearman, below,  # noqa: F401
                           c6_needed_ratio, holds_where, rule_c1, rule_c2, rule_c3, rule_c4, rule_c5, rule_c6,
                           rule_c7, spread_c2, _value, verdict)


# ----- sweeps -------------------------------------------------------------------------------------------------
def _lam_scale(s: float) -> dict:
    """Adaptive-fuzzy λ ranges scaled in time by √s: λ2 ∈ [0.5 s, 2 s] s⁻², λ1 ∈ [2√2 √s, 4 √s] s⁻¹
    (s = 1: today's ranges; λ1_min² = 4 λ2_max keeps the model roots real)."""
    return {"controller.lambda1_min": 2.0 * math.sqrt(2.0 * s), "controller.lambda1_max": 4.0 * math.sqrt(s),
            "controller.lambda2_min": 0.5 * s, "controller.lambda2_max": 2.0 * s}


def sweeps(quick: bool) -> list[dict]:
    """Each sweep: one project-choice reading of one controller; ``runs`` maps the base run ids it replaces
    to the scenario run id it is computed on; ``claims`` the claims whose rule it can move."""
    # quick mode: a few points of each full grid (always points of the full grid, so a quick verdict is one the
    # full build also sees), the physical set-up unchanged
    g = (lambda full, q: sorted({min(full, key=lambda v: abs(v - x)) for x in q})) if quick else (lambda full, q: full)
    geo = lambda a, b, n: [float(v) for v in np.geomspace(a, b, n)]  # noqa: E731
    lin = lambda a, b, n: [float(v) for v in np.linspace(a, b, n)]  # noqa: E731
    fuzzy_runs = ["000-10L"] + [f"{c}-FuzzyPD-L2" for c in ROBUST_CASES]
    af_runs = ["000-11L"] + [f"{c}-AdaptFuzzy-L2" for c in ROBUST_CASES]
    mrac_runs = ["000-9L"] + [f"{c}-MRAC-L2" for c in ROBUST_CASES]
    main = ["C000-4", "C000-5", "C000-6", "C000-7"]
    return [
        dict(param="PdController.dcm_error", key="controller.dcm_error", values=list(range(6)), default=0,
             runs=["000-4", "000-3"], claims=["C000-1", "C000-2", "C000-5", "C000-6"], categorical=True),
        dict(param="AttitudePlant.dcm_orthonormalize", key="plant.dcm_orthonormalize", values=[0, 1], default=0,
             runs=["000-4"], claims=["C000-1", "C000-5"], categorical=True),
        dict(param="FuzzyPdController.e_scale", key="controller.e_scale", unit="rad",
             values=g(geo(0.1, 4.0, 25), [0.25, 1.0, 3.0]), default=1.0, runs=fuzzy_runs, claims=main),
        dict(param="FuzzyPdController.edot_scale", key="controller.edot_scale", unit="rad/s",
             values=g(geo(0.05, 4.0, 25), [0.1, 0.5, 2.0]), default=0.5, runs=fuzzy_runs, claims=main),
        dict(param="FuzzyPdController.mf_half_width", key="controller.mf_half_width", unit="",
             values=g(lin(1 / 3, 1.0, 13), [1 / 3, 1.0]), default=1 / 3, runs=fuzzy_runs, claims=main),
        dict(param="FuzzyPdController.sigma (defuzz = 1)", key="controller.sigma", unit="",
             extra={"controller.defuzz": 1}, values=g(geo(0.1, 1.0, 13), [0.25, 1.0]), default=None,
             runs=fuzzy_runs, claims=main),
        dict(param="FuzzyPdController.t_r", key="controller.t_r", unit="s",
             values=g(sorted(geo(2.0, 80.0, 32) + [scenarios.T_R_UNCONSTRAINED, scenarios.T_R_CALIBRATED]),
                      [scenarios.T_R_UNCONSTRAINED, scenarios.T_R_CALIBRATED, 45.0]),
             default=scenarios.T_R_CALIBRATED, runs=fuzzy_runs, claims=main),
        dict(param="AdaptiveFuzzyController λ-range scale s", key="lam_scale", unit="",
             values=g(sorted(geo(0.5, 16.0, 24) + [1.0]), [1.0, 1.3, 4.0, 12.0]), default=1.0, runs=af_runs, claims=main),
        dict(param="AdaptiveFuzzyController.e_scale", key="controller.e_scale", unit="",
             values=g(geo(0.1, 4.0, 20), [0.25, 3.0]), default=1.0, runs=af_runs, claims=main),
        dict(param="AdaptiveFuzzyController.edot_scale", key="controller.edot_scale", unit="1/s",
             values=g(geo(0.05, 4.0, 20), [0.1, 2.0]), default=0.5, runs=af_runs, claims=main),
        dict(param="AdaptiveFuzzyController.gamma", key="controller.gamma", unit="kg·m²·s²",
             values=g([0.0] + geo(1.0, 1e5, 11), [0.0, 1000.0, 1e5]), default=1000.0, runs=af_runs, claims=main),
        dict(param="MracController.gamma", key="controller.gamma", unit="kg·m²·s²",
             values=g([0.0] + geo(1.0, 1e5, 11), [0.0, 1000.0, 1e5]), default=1000.0, runs=mrac_runs, claims=main),
    ]


JOINT = ("FuzzyPdController.t_r", "AdaptiveFuzzyController λ-range scale s")  # evaluated together, no extra runs


def _override(sw: dict, v, rid: str = "") -> dict:
    if sw["key"] == "lam_scale":
        return _lam_scale(v)
    return {**sw.get("extra", {}), sw["key"]: v}


# ----- running ----------------------------------------------------------------------------------------------------
TS_KEYS = ["alpha_deg", "roll", "pitch", "yaw", "torque_applied_x", "torque_applied_y", "torque_applied_z"]


def run_base(ctx: Context) -> tuple[dict, dict]:
    """Every run of the paper 000 table, one campaign each; robustness runs keep α(t) and the angles."""
    base, ts = {}, {}
    for r in scenarios.paper000_runs():
        keep = TS_KEYS if r.run_id.startswith("R") or r.command != "S" else None
        c = Campaign(scenarios.paper000(r.run_id), [{}], engine="native", timeseries=keep, ts_every=5)
        name = f"000/base/{r.run_id}"
        row = common.rows(ctx.campaign(c, name))[0]
        if row["status"] != "ok":
            raise RuntimeError(f"paper 000 run {r.run_id} failed: {row['message']}")
        base[r.run_id] = row
        if keep:
            ts[r.run_id] = read_timeseries(ctx.runs_dir(name), 0)
    return base, ts


def run_sweep(ctx: Context, sw: dict, idx: int) -> dict:
    """{base run id: [row per value]} for one sweep (one campaign per run id it replaces)."""
    out = {}
    for rid in sw["runs"]:
        c = Campaign(scenarios.paper000(rid), [_override(sw, v, rid) for v in sw["values"]], engine="native")
        out[rid] = common.rows(ctx.campaign(c, f"000/sweep{idx:02d}/{rid}"))
    return out


def evaluate_sweep(base: dict, sw: dict, rows: dict, claim: str) -> list[bool]:
    """The claim's rule at every value of the sweep (rows substituted into the default table); a failed run
    counts as 'does not hold'."""
    res = []
    for i in range(len(sw["values"])):
        m = dict(base)
        bad = False
        for rid, rr in rows.items():
            if rr[i]["status"] != "ok":
                bad = True
            m[rid] = rr[i]
        res.append(False if bad else RULES[claim](m)[0])
    return res


def away_sweep(base: dict, sw: dict, rows: dict) -> list[bool]:
    """At every value of the sweep: does the reading move the paper's own Table 3 numbers further away
    (``numbers.moves_away``)? Such a value is never counted as support for a claim."""
    out = []
    for i in range(len(sw["values"])):
        changed = {rid: rr[i] for rid, rr in rows.items() if rr[i]["status"] == "ok"}
        out.append(N.moves_away(base, changed))
    return out


def evaluate_joint(base: dict, swa: dict, rowsa: dict, swb: dict, rowsb: dict, claim: str) -> np.ndarray:
    """The claim's rule on the grid of two sweeps that replace different runs (holds[i, j]: value i of the first,
    value j of the second)."""
    out = np.zeros((len(swa["values"]), len(swb["values"])), bool)
    for i in range(len(swa["values"])):
        for j in range(len(swb["values"])):
            m = dict(base)
            bad = False
            for rows, k in ((rowsa, i), (rowsb, j)):
                for rid, rr in rows.items():
                    bad |= rr[k]["status"] != "ok"
                    m[rid] = rr[k]
            out[i, j] = False if bad else RULES[claim](m)[0]
    return out


def joint_where(swa, swb, h: np.ndarray) -> str:
    if h.all():
        return "every pair tried"
    if not h.any():
        return (f"no pair of {swa['param']} ∈ [{swa['values'][0]:.3g}, {swa['values'][-1]:.3g}] × {swb['param']} ∈ "
                f"[{swb['values'][0]:.3g}, {swb['values'][-1]:.3g}]")
    parts = []
    for j, vb in enumerate(swb["values"]):
        if h[:, j].any():
            parts.append(f"s = {vb:.3g}: " + holds_where("t_r", swa["values"], list(h[:, j])).split(" (of")[0])
    return f"{int(h.sum())} of {h.size} pairs; " + "; ".join(parts)


# ----- the section ------------------------------------------------------------------------------------------------
STATEMENTS = {
    "C000-1": "The kinematic representation matters: for the large slew with PD, EULERINT ranks quaternion < DCM < "
              "Euler-angle rates; quaternions are recommended.",
    "C000-2": "For small commanded angles every method gives about the same EULERINT.",
    "C000-3": "PD (quaternion), LQR and pole placement give identical EULERINT (same closed loop ωn = 1, ξ = 1).",
    "C000-4": "For the large slew, EULERINT ranks adaptive fuzzy < fuzzy < MRAC < quaternion PD (= LQR = pole placement).",
    "C000-5": "Lower EULERINT generally costs more control effort; among the three PD variants effort rises together "
              "with EULERINT.",
    "C000-6": "Fuzzy and adaptive fuzzy lower EULERINT below MRAC without much more control effort than PD; adaptive "
              "fuzzy is the best method overall.",
    "C000-7": "Under a disturbance and under inertia uncertainty, adaptive fuzzy responds better than PD (less "
              "overshoot, shorter settling) and keeps the best EULERINT.",
}
RULE_TEXT = {
    "C000-1": "holds if EULERINT(000-6 quaternion) < EULERINT(000-4 DCM) < EULERINT(000-2 Euler), large command.",
    "C000-2": f"holds if the relative spread (max − min)/min of EULERINT over the small-command runs 000-1, 000-3, "
              f"000-5, 000-7S, 000-8S, 000-9S is ≤ {100 * TOL_SMALL:.0f} %.",
    "C000-3": f"holds if LQR and pole placement match the quaternion PD's EULERINT within a relative {TOL_IDENTICAL:.0e}, "
              f"small and large command.",
    "C000-4": "holds if EULERINT(000-11L) < EULERINT(000-10L) < EULERINT(000-9L) < EULERINT(000-6).",
    "C000-5": "holds if (a) the PD variants 000-2/4/6 have the same order by effort as by EULERINT and (b) the Spearman "
              "rank correlation of EULERINT and effort over PD, MRAC, fuzzy and adaptive fuzzy (large command) is < 0; "
              "effort = ∫Σ|τ| dt (∫‖τ‖² dt shown as the other reading).",
    "C000-6": f"holds if fuzzy and adaptive fuzzy each have EULERINT below MRAC and effort ≤ {EFFORT_RATIO} × the "
              f"quaternion PD's, and adaptive fuzzy has the lowest EULERINT of all large-command runs.",
    "C000-7": "holds if, in each of R1 (10 N·m), R2 ×1.2 and R2 ×0.8 (command L2, the paper's), adaptive fuzzy has overshoot (largest "
              "of the three angles; our proxy for 'less oscillation') ≤ PD's and α settling time (2 % band, not "
              "settled = ∞) ≤ PD's, and the lowest EULERINT of PD, MRAC, fuzzy and adaptive fuzzy.",
}


def _sweeps(ctx: Context, base: dict, sws: list) -> tuple[dict, dict, list, dict, dict]:
    """Every one-reading sweep: its runs, figure, and per claim the verdict at each value (with the table
    where the reading moves the verdict) and whether the value moves the paper's own numbers away. Returns
    (per_claim, away_of, needed effort ratios, rows of each sweep, measures: per claim of ``MEASURE`` its
    measure at every value tried, (reading, measure, moves the paper's numbers away))."""
    per_claim: dict[str, list[tuple[dict, list[bool], Sensitivity]]] = {c: [] for c in RULES}
    away_of: dict[str, list[tuple[str, list, list[bool], list[bool]]]] = {c: [] for c in RULES}
    measures: dict[str, list[tuple[str, float, bool]]] = {c: [] for c in MEASURE}
    needed = [(c6_needed_ratio(base), "the defaults")]
    all_rows = {}
    for idx, sw in enumerate(sws):
        rows = run_sweep(ctx, sw, idx)
        all_rows[sw["param"]] = rows
        if "C000-6" in sw["claims"]:
            for i, v in enumerate(sw["values"]):
                if all(rr[i]["status"] == "ok" for rr in rows.values()):
                    needed.append((c6_needed_ratio({**base, **{rid: rr[i] for rid, rr in rows.items()}}),
                                   f"{sw['param']} = {_fmt_cat(v) if sw.get('categorical') else f'{v:.3g}'}"))
        holds = {c: evaluate_sweep(base, sw, rows, c) for c in sw["claims"]}
        away = away_sweep(base, sw, rows)
        for c in (c for c in sw["claims"] if c in MEASURE):
            for i, v in enumerate(sw["values"]):
                if all(rr[i]["status"] == "ok" for rr in rows.values()):
                    measures[c].append((f"{sw['param']} = {_value(v)}",
                                        MEASURE[c][0]({**base, **{rid: rr[i] for rid, rr in rows.items()}}), away[i]))
        fig = fig_sweep(ctx, base, sw, idx, rows, holds)
        plotted = [r for r in sw["runs"] if r in L_RUNS]
        fmt = _fmt_cat if sw.get("categorical") else (lambda v: f"{v:.3g}")
        for c, h in holds.items():
            cols = [sw["param"]]
            for r_ in plotted:
                cols += [f"{_label(r_)} EULERINT [deg·s]", f"{_label(r_)} ∫Σ|τ| [N·m·s]"]
            tab = Table(f"{sw['param']}: large-command runs and whether {c} holds (one reading changed, the rest at "
                        f"defaults)", cols + [f"{c} holds"],
                        [[DCM_READINGS[v] if sw["key"] == "controller.dcm_error" else _fmt_cat(v)]
                         + [x for r_ in plotted for x in (rows[r_][i][EI], rows[r_][i][EFF])]
                         + ["yes" if h[i] else "no"] for i, v in enumerate(sw["values"])])
            default = "defuzz 0 (σ unused)" if sw["default"] is None else sw["default"]
            # the table only where the reading moves the verdict (keeps the report short); the figure always
            moves = any(x != RULES[c](base)[0] for x in h)
            s = Sensitivity(sw["param"], list(sw["values"]), default,
                            holds_where(sw["param"], sw["values"], h, fmt, sw.get("categorical", False)), fig,
                            tab if moves else None)
            per_claim[c].append((sw, h, s))
            away_of[c].append((sw["param"], list(sw["values"]), list(h), away))

    return per_claim, away_of, needed, all_rows, measures


def _joint(ctx: Context, base: dict, sws: list, all_rows: dict, per_claim: dict, away_of: dict, needed: list):
    """The fuzzy PD's T_r and the adaptive-fuzzy λ-range scale evaluated together, from the same runs;
    appends to per_claim, away_of and needed, returns the figure."""
    swa, swb = (next(sw for sw in sws if sw["param"] == n) for n in JOINT)
    ra, rb = all_rows[swa["param"]], all_rows[swb["param"]]
    jh = {c: evaluate_joint(base, swa, ra, swb, rb, c) for c in ("C000-4", "C000-5", "C000-6", "C000-7")}
    jfig = fig_joint(ctx, swa, swb, jh)
    for i, va in enumerate(swa["values"]):
        for j, vb in enumerate(swb["values"]):
            m = dict(base)
            for rows, k in ((ra, i), (rb, j)):
                m.update({rid: rr[k] for rid, rr in rows.items()})
            if all(r["status"] == "ok" for r in m.values()):
                needed.append((c6_needed_ratio(m), f"T_r = {va:.3g} s with λ-range scale s = {vb:.3g}"))
    jaway = np.zeros((len(swa["values"]), len(swb["values"])), bool)
    for i in range(len(swa["values"])):
        for j in range(len(swb["values"])):
            changed = {rid: rr[i] for rid, rr in ra.items()}
            changed.update({rid: rr[j] for rid, rr in rb.items()})
            jaway[i, j] = N.moves_away(base, {k: v for k, v in changed.items() if v["status"] == "ok"})
    for c, h in jh.items():
        away_of[c].append((f"({JOINT[0]}, {JOINT[1]}) together",
                           [(va, vb) for va in swa["values"] for vb in swb["values"]], list(h.ravel()),
                           list(jaway.ravel())))
        per_claim[c].append(({"param": "joint"}, list(h.ravel()),
                             Sensitivity(f"({JOINT[0]}, {JOINT[1]}) together",
                                         [f"T_r: {len(swa['values'])} values in [{swa['values'][0]:.3g}, "
                                          f"{swa['values'][-1]:.3g}] s",
                                          f"s: {len(swb['values'])} values in [{swb['values'][0]:.3g}, "
                                          f"{swb['values'][-1]:.3g}]"],
                                         (swa["default"], swb["default"]), joint_where(swa, swb, h), jfig)))
    return jfig


def _claim(c: str, rule, base: dict, per_claim: dict, away_of: dict, needed: list,
           measures: dict | None = None) -> Claim:
    """The verdict of claim `c` with its evidence, sensitivities and the readings that flip it. Readings that move
    the paper's own Table 3 numbers further away are neither support nor counter-example
    (``rules.combine_faithful``); readings a sweep lists under ``chosen`` (values picked after comparing with the
    paper) are never evidence either, and a claim that holds only under one of them reads "not confirmed (holds
    only under a chosen reading: …)" (``rules.combine_evidence``, ``Claim.chosen_support``), the rule of every
    paper."""
    ok, why = rule(base)
    extra, sens = "", [s for _, _, s in per_claim[c]]
    swept = [x for _, h, _ in per_claim[c] for x in h]
    if c in ("C000-5", "C000-6"):  # the effort metric is a reading too
        ok_sq, why_sq = rule(base, "effort_sq")
        swept.append(ok_sq)
        extra = f" With effort = ∫‖τ‖² dt instead: {'holds' if ok_sq else 'fails'} ({why_sq})."
        sens.append(Sensitivity("effort metric", ["effort_abs", "effort_sq"], "effort_abs",
                                "both" if ok and ok_sq else "effort_abs" if ok else "effort_sq" if ok_sq else
                                "neither"))
    if c == "C000-6":
        r_min, where = min(needed, key=lambda t: t[0])
        extra += (" The EULERINT parts of the rule hold nowhere tried, so no effort threshold would help."
                  if math.isinf(r_min) else
                  f" Smallest effort ratio (max of fuzzy and adaptive fuzzy over PD) among the points where the "
                  f"EULERINT parts hold: {r_min:.2f} at {where}; the claim would need 'not much more' to allow "
                  f"that ratio.")
    if c == "C000-7":
        ok2, why2 = rule(base, ("L",))
        swept.append(ok2)
        extra = f" On command L (R1 not mirror-symmetric): {'holds' if ok2 else 'fails'} ({why2})."
        sens.append(Sensitivity("robustness command (L2 or L)", ["L2", "L"], "L2",
                                "both" if ok and ok2 else "L2" if ok else "L" if ok2 else "neither"))
    # every reading checked: (holds, moves the paper's own numbers away); the extra readings above (effort
    # metric, command) change no reported EULERINT
    readings = {f"{name} = {v_}": (bool(h_), bool(a_)) for name, vals, hs, aw in away_of[c]
                for v_, h_, a_ in zip(vals, hs, aw)}
    extra_n = len(swept) - sum(len(hs) for _, _, hs, _ in away_of[c])
    for k_, x in enumerate(swept[len(swept) - extra_n:]):
        readings[f"other reading {k_}"] = (bool(x), False)
    _v, _support, away_names = rules.combine_faithful(ok, readings)
    chosen = {f"{name} = {v_}" for (sw, _, _), (name, _, _, _) in zip(per_claim[c], away_of[c])
              for v_ in sw.get("chosen", ())}
    v, chosen_support = rules.combine_evidence(ok, {k: h for k, (h, a) in readings.items() if not a}, chosen)
    if c in MEASURE:
        extra += _measure_text(c, base, (measures or {}).get(c, []))
    away_params = sorted({name for name, vals, hs, aw in away_of[c] if any(h_ and a_ for h_, a_ in zip(hs, aw))})
    if away_params and not ok:
        extra += (" Readings under which it holds only by moving the paper's own Table 3 numbers further away "
                  f"(not counted as support): {', '.join(away_params)} ({len(away_names)} points).")
    # a reading flips the verdict when some value changes the rule's outcome; one that does so only at values
    # moving the paper's own numbers away is listed apart (combine_faithful leaves it out of the verdict)
    fl = [(s.parameter, any(x != ok and not a for x, a in zip(h, aw)), any(x != ok for x in h),
           [v_ for v_, x, a in zip(vals, h, aw) if x != ok and a])
          for (sw, h, s), (_, vals, _, aw) in zip(per_claim[c], away_of[c])]
    flips, flips_away = [p for p, f, _, _ in fl if f], [p for p, f, any_, _ in fl if any_ and not f]
    away_at = {p: vs for p, f, any_, vs in fl if any_ and not f}
    if c in ("C000-5", "C000-6") and (rule(base, "effort_sq")[0] != ok):
        flips.append("effort metric")
    if c == "C000-7" and rule(base, ("L",))[0] != ok:
        flips.append("robustness command (L2 or L)")
    evidence = (f"Rule: {RULE_TEXT[c]} At the defaults it {'holds' if ok else 'fails'}: {why}.{extra} "
                + (f"The verdict flips with: {', '.join(flips)}." if flips else "No counted reading changes it.")
                + (f" It flips only at values that move the paper's own Table 3 numbers further away (listed, "
                   f"not counted): {'; '.join(_at(p, away_at[p]) for p in flips_away)}." if flips_away else ""))
    return Claim(c, STATEMENTS[c], v, evidence, figures=[], sensitivity=sens, sensitive_to=flips + [
        f"{p} (flips it only while moving the paper's numbers away; not counted)" for p in flips_away],
        agreement=AGREEMENT[c](base) if c in AGREEMENT else None, chosen_support=chosen_support)


def _setup_and_notes(ctx: Context, base: dict, sws: list) -> tuple[str, str]:
    n_sweep = sum(len(sw["values"]) * len(sw["runs"]) for sw in sws)
    setup = (f"AttitudeCommand → controller → AttitudePlant → AttitudeMetrics, every controller swapped by FMU name; "
             f"{len(base)} runs of the paper 000 table (000-1 … 000-11 and the robustness runs R1, R2) plus "
             f"{n_sweep} sweep runs on the campaign engine (native), Δ = 0.01 s, t_end = 30 s"
             + (" (quick mode: a few points per sweep)" if ctx.quick else "") + ".")
    notes = (
        "The fuzzy PD's gain ranges are the paper's, k_p ∈ [0.28, 3] k_r and k_d ∈ [0.08, 0.15] k_r T_r. "
        "Readings: EULERINT in deg·s over [0, 30] s; effort = ∫Σ|τ| dt (the paper's formula is unknown; ∫‖τ‖² dt is "
        "evaluated too). Thresholds: rankings need a 0.5 % margin, 'about the same' ≤ 10 % spread, 'identical' ≤ 1e-6, "
        "'without much more effort' ≤ 1.5 × the quaternion PD's effort. The DCM error law has six readings "
        "(PdController parameter dcm_error, default 0 = the elements of A(q)A(q_ref)ᵀ as printed; 4 = attitude "
        "matrix read body → inertial, 5 = elements of A(q_ref)ᵀA(q)); the DCM kinematics was checked through the "
        "plant's re-orthonormalisation switch (the other form of the kinematics equation, Ȧ = A[Ω], would rotate "
        "about inertial axes and is not a consistent reading). Sweeps change one reading at a time, the other "
        "controllers at their defaults; the fuzzy PD's reference settling time T_r (which sets its damping range) "
        "and the adaptive-fuzzy λ-range scale s (λ2 range × s, λ1 range × √s: the reference model sped up by √s, "
        "roots stay real) are also evaluated together on their grid, from the same runs. "
        + ("Quick mode: 2–3 points per sweep (the regions are coarse; the verdicts are those of the full grids "
           "except where a region falls between the quick points)." if ctx.quick else
           "Full mode: 13–26 points per sweep."))
    return setup, notes


def _calibrations(eff_text: str) -> str:
    calibrations = (
        f"Calibration: the fuzzy PD's reference settling time T_r = {scenarios.T_R_CALIBRATED:g} s is fitted to the "
        f"fuzzy controller's Table 3 EULERINT (127.8 deg·s). The paper defines T_r as the model's settling time "
        f"with the actuators at most 50 % active but states no actuator limit, so the definition cannot be "
        f"evaluated (unconstrained it gives {scenarios.T_R_UNCONSTRAINED:g} s, which puts the fuzzy damping range "
        f"below the PD's own damping gain). That number is no independent check. Stated set-ups followed: MRAC "
        f"on the large command on linear dynamics with quaternion kinematics, in its linear coordinates (000-9L, "
        f"AttitudePlant.kinematics = 4; other set-ups in the row's note); PD, DCM, quaternion and MRAC on (roll, pitch, yaw) = "
        f"(40, −40, −60) deg, fuzzy, adaptive fuzzy and the robustness runs on (40, 40, 60) deg (the figures' "
        f"commands). Effort: {eff_text}")
    return calibrations


def build(ctx: Context) -> PaperSection:
    t0 = time.time()
    base, ts = run_base(ctx)
    figs = [fig_ranking(ctx, base), fig_effort(ctx, base), fig_robust(ctx, ts)]
    sws = sweeps(ctx.quick)
    per_claim, away_of, needed, all_rows, measures = _sweeps(ctx, base, sws)
    jfig = _joint(ctx, base, sws, all_rows, per_claim, away_of, needed)
    figs.append(jfig)

    claims = [_claim(c, rule, base, per_claim, away_of, needed, measures) for c, rule in RULES.items()]
    claims[0].figures = [figs[0]]
    claims[3].figures = [figs[0]]
    claims[4].figures = [figs[1]]
    claims[5].figures = [figs[1]]
    claims[6].figures = [figs[2]]
    setup, notes = _setup_and_notes(ctx, base, sws)
    nums = N.eulerint_rows(base, calibrated={"fuzzy"})
    eff_rows, eff_table, eff_text = N.effort_rows(base, ts)
    nums += eff_rows
    claims[4].evidence += f" Paper's effort numbers: {eff_text}"
    claims[4].tables.append(eff_table)
    calibrations = _calibrations(eff_text)
    mt = N.metrics_table(base)
    rt = N.readings_table(sws, sweeps(True), all_rows, base)
    return PaperSection("000", TITLE, setup, claims, figures=figs, tables=[mt, rt], notes=notes,
                        doc_tables={"runs": mt, "readings": rt},
                        runtime_s=time.time() - t0, numbers=nums, calibrations=calibrations)
