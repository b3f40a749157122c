"""Report section of paper 003: GA-tuned sliding mode (GA-SMC) against sliding mode with an interval
type-2 fuzzy gain schedule (T2F-SMC), LEO satellite with reaction wheels and magnetorquers.

``build(ctx)`` runs on the campaign engine (``ctx.campaign``):

* the five cases 003-N, -C, -S, -W (one run each) and the 003-U Monte Carlo (100 runs; seeds 1…100)
  for both controllers with the committed GA values (``paper003/data/tuned.json``);
* sensitivity sweeps of the project-choice readings that could flip the verdicts: the type-2 fuzzy
  system (gain-change strength κ, the footprint of uncertainty σ_lo/σ_up, the rule-table orientation,
  the input scales e_scale/edot_scale), the disturbance magnitude of 003-C/S/W and the boundary layer Φ
  of both controllers; each swept setting re-runs 003-N, C, S, W and the first ``n_mc_sweep`` 003-U
  seeds (controllers keep their tuned gains: no re-tuning per setting);

and returns claims C003-1 and C003-2 with tables, figures, verdicts and the region of each sweep where
the claim holds. ``ctx.quick``: the same runs and horizon, 8 Monte Carlo runs, 4 per swept setting, fewer values.

Verdict rule (:func:`verdict`): confirmed when the claim holds with today's readings and in every swept
setting, not confirmed when it holds nowhere, "depends on a reading" otherwise. The claims are judged
by :func:`claim1` and :func:`claim2` on a summary table ``{(controller, case): {"ise", "isf", "sse"}}``
(controller "SMC" or "T2FSMC", case "N" … "U"; sse = mean over the three Euler angles of the
steady-state error in deg; for U the Monte Carlo means).

The running (campaigns of controller settings, their summaries), the swept readings and the figures are in
``report_runs.py``; this file holds the claims, their rules and ``build`` (one helper per part of the section).
"""

from __future__ import annotations

import math
import time

import numpy as np

from . import model as p3
from ...report import common, rules
from ...campaign import read_timeseries
from ...report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED, Claim, Figure, PaperSection, Sensitivity, Table
from .report_runs import (CASE_NAME, CASES, CTRL, DET, LABEL, _fmt, _plot_overview, _plot_sweep,
                          _settings_campaign, _summarise, _sweeps)


# ----- the claims as functions of a summary table ----------------------------------------------------
def claim1(summary: dict) -> tuple[bool, dict]:
    """C003-1: T2F-SMC has the smaller steady-state error and the smaller ISE in every case.
    Returns (holds, {case: (ise_lower, sse_lower)}) over the cases present in ``summary``."""
    per = {}
    for case in CASES:
        if ("SMC", case) not in summary or ("T2FSMC", case) not in summary:
            continue
        a, b = summary[("SMC", case)], summary[("T2FSMC", case)]
        per[case] = (b["ise"] < a["ise"], b["sse"] < a["sse"])
    return bool(per) and all(i and s for i, s in per.values()), per


ISF_BODY = {"N": "SMC", "C": "SMC", "S": "SMC", "W": "T2FSMC", "U": "T2FSMC"}


def examined(flips: list) -> list[str]:
    """Every swept reading (name, results per value), the ones that move the verdict marked."""
    return [f"{p} (moves the verdict)" if len(set(h)) > 1 else f"{p} (verdict unchanged)" for p, h in flips]


def isf_winners(summary: dict) -> dict:
    """{case: controller with the lower ISF} ("tie" when equal)."""
    out = {}
    for case in CASES:
        if ("SMC", case) not in summary or ("T2FSMC", case) not in summary:
            continue
        a, b = summary[("SMC", case)]["isf"], summary[("T2FSMC", case)]["isf"]
        out[case] = "SMC" if a < b else "T2FSMC" if b < a else "tie"
    return out


def claim2(summary: dict) -> tuple[bool, bool, dict]:
    """C003-2 in its two readings: (body, abstract, winners). Body: GA-SMC has the lower ISF in N, C, S
    and T2F-SMC in W and U; abstract ("better in all situations"): T2F-SMC has the lower ISF everywhere."""
    w = isf_winners(summary)
    body = bool(w) and all(w[c] == ISF_BODY[c] for c in w)
    abstract = bool(w) and all(v == "T2FSMC" for v in w.values())
    return body, abstract, w


def verdict(at_default: bool, in_sweeps: list[bool]) -> str:
    """Confirmed if the claim holds with today's readings and in every swept setting; not confirmed if
    it holds in none; depends on a reading otherwise."""
    allv = [bool(at_default), *map(bool, in_sweeps)]
    if all(allv):
        return CONFIRMED
    if not any(allv):
        return NOT_CONFIRMED
    return DEPENDS


def holds_where(values: list, holds: list[bool], default) -> str:
    """Plain-text region of a sweep where a claim holds."""
    fmt = lambda v: (f"{v:g}" if isinstance(v, float) else str(v)) + (" (default)" if v == default else "")
    yes = [fmt(v) for v, h in zip(values, holds) if h]
    if len(yes) == len(values):
        return "everywhere tried"
    if not yes:
        return "nowhere tried"
    no = [fmt(v) for v, h in zip(values, holds) if not h]
    return f"holds at {', '.join(yes)}; fails at {', '.join(no)}"


# ----- the section ------------------------------------------------------------------------------------
def _main_runs(ctx, t_end: float, n_mc: int, n_mc_sweep: int) -> tuple[dict, dict, dict, dict]:
    """The main runs: N, C, S, W with time series and the 003-U Monte Carlo, per controller. Returns
    (summary, sweep_base, ts, mc_rows); sweep_base has the 003-U means of the first n_mc_sweep seeds."""
    main, mc_rows = {}, {}
    ts = {}
    for c in CTRL:
        camp, index = _settings_campaign(c, [("tuned", {}, 1.0)], t_end, 0, timeseries=[], ts_every=10)
        rows = p3.rows(ctx.campaign(camp, f"paper003/{c}_cases"))
        s = _summarise(rows, index, 1)[0]
        for case in DET:
            main[(c, case)] = s[case]
        for r, (_, case, _) in zip(rows, index):
            if r["status"] == "ok":
                ts[(c, case)] = read_timeseries(ctx.runs_dir(f"paper003/{c}_cases"), r["run"])
        mc = p3.rows(ctx.campaign(p3.mc_campaign(c, range(1, n_mc + 1), t_end=t_end), f"paper003/{c}_mc"))
        mc_rows[c] = mc
        main[(c, "U")] = _summarise(mc, [(0, "U", s) for s in range(1, n_mc + 1)], 1)[0]["U"]
        # the sweeps compare on the first n_mc_sweep seeds: the same runs as the main Monte Carlo's first rows
        main[(c, "U_sweep")] = _summarise(mc[:n_mc_sweep], [(0, "U", s) for s in range(1, n_mc_sweep + 1)], 1)[0]["U"]
    summary = {k: v for k, v in main.items() if k[1] != "U_sweep"}
    sweep_base = {**{k: v for k, v in main.items() if k[1] in DET},
                  **{(c, "U"): main[(c, "U_sweep")] for c in CTRL}}
    return summary, sweep_base, ts, mc_rows


def _main_figures(ctx, summary: dict, ts: dict, mc_rows: dict, t_end: float, n_mc: int) -> tuple[list, Figure]:
    """The scenario figures (one per deterministic case, the 003-U Monte Carlo) and the overview figure."""
    figs = ctx.figures_dir
    figures = []
    for case in DET:
        if all((c, case) in ts for c in CTRL):
            p3.plot_scenario({LABEL[c]: ts[(c, case)] for c in CTRL}, f"003-{case}", figs / f"003_{case}.png")
            figures.append(Figure(_rel(f"003_{case}.png"), f"{CASE_NAME[case]}: Euler angles, applied torques, "
                                  f"wheel momentum and external torque, GA-SMC (solid) and T2F-SMC (dashed), "
                                  f"{t_end:g} s."))
    p3.plot_monte_carlo({LABEL[c]: mc_rows[c] for c in CTRL}, figs / "003_U.png")
    figures.append(Figure(_rel("003_U.png"), f"003-U: ISE and ISF over {n_mc} runs with inertia scaled uniformly in "
                                             f"[0.8, 1.2] per axis (seeds 1…{n_mc}), and the GA cost J."))
    _plot_overview(summary, figs / "003_overview.png")
    overview = Figure(_rel("003_overview.png"), "ISE, ISF and steady-state error of both controllers in every "
                                                "scenario (003-U: Monte Carlo mean).")
    return figures, overview


def _rel(name: str) -> str:
    return f"figures/{name}"


def _result_tables(summary: dict, ts: dict, n_mc: int) -> tuple[Table, Table, Table, Table]:
    """(results per scenario and controller, its deterministic part for the docs, the 003-U Monte Carlo
    table, the applied-torque extremes)."""
    res_rows = []
    for case in CASES:
        for c in CTRL:
            d = summary[(c, case)]
            res_rows.append([f"003-{case}", LABEL[c], d["sse_roll_deg"], d["sse_pitch_deg"], d["sse_yaw_deg"],
                             d["sse"], d["ise"], d["isf"]])
    t_results = Table(f"Steady-state error per Euler angle (deg, mean |error| over the last 10 % of the run), ISE "
                      f"(rad² s) and ISF (N² m² s); 003-U: means over {n_mc} runs.",
                      ["scenario", "controller", "sse roll", "sse pitch", "sse yaw", "sse mean", "ISE", "ISF"], res_rows)
    doc_results = Table("Steady-state error per Euler angle (deg), ISE (rad² s) and ISF (N² m² s) of the deterministic "
                        "scenarios", t_results.columns, [r for r in res_rows if r[0] != "003-U"])
    mc_tab = Table(f"003-U Monte Carlo ({n_mc} runs): mean and standard deviation.",
                   ["controller", "ISE mean", "ISE std", "ISF mean", "ISF std", "runs ok", "failed"],
                   [[LABEL[c], summary[(c, "U")]["ise"], summary[(c, "U")].get("ise_std", math.nan),
                     summary[(c, "U")]["isf"], summary[(c, "U")].get("isf_std", math.nan), summary[(c, "U")]["n"],
                     summary[(c, "U")]["failed"]] for c in CTRL])
    torque_rows = []
    for case in DET:
        for c in CTRL:
            tq = [r for r in [ts.get((c, case))] if r is not None]
            if tq:
                torque_rows.append([f"003-{case}", LABEL[c]] + [float(f(tq[0][f"torque_applied_{a}"]))
                                                                for a in p3.AX for f in (np.max, np.min)])
    t_torque = Table("Applied torque extremes per axis (N m), from the logged series (every 10th sample).",
                     ["scenario", "controller", "max x", "min x", "max y", "min y", "max z", "min z"], torque_rows)
    return t_results, doc_results, mc_tab, t_torque


def _sweep_summaries(ctx, k: int, sw: dict, sweep_base: dict, t_end: float, n_mc_sweep: int) -> list[dict]:
    """Runs one swept reading (the default reuses the main runs) and returns one summary per value."""
    values = sw["values"]
    cases = sw.get("cases", DET)
    with_mc = sw.get("mc", True)
    summaries = []
    todo = {c: [] for c in CTRL}  # settings to run per controller (the default reuses the main runs)
    for v in values:
        covs = sw["ctrl"](v)
        for c, cov in zip(CTRL, covs):
            if v != sw["default"] and (cov or sw["dist"](v) != 1.0):
                todo[c].append((v, cov, sw["dist"](v)))
    ran = {}
    for c in CTRL:
        if not todo[c]:
            continue
        camp, index = _settings_campaign(c, todo[c], t_end, n_mc_sweep if with_mc else 0, cases=cases,
                                         log_every=10)
        rows = p3.rows(ctx.campaign(camp, f"paper003/sweep{k}_{c}"))
        for (v, _, _), s in zip(todo[c], _summarise(rows, index, len(todo[c]))):
            ran[(c, repr(v))] = s
    for v in values:
        s = dict(sweep_base)
        for c in CTRL:
            for case, d in ran.get((c, repr(v)), {}).items():
                s[(c, case)] = d
        summaries.append(s)
    return summaries


def _sweep_table(sw: dict, summaries: list[dict], h1: list, h2: list) -> Table:
    """Per swept value: where T2F-SMC is lower on ISE and on steady-state error, the lower ISF, the claims."""
    trows = []
    for v, s, a, (b, ab) in zip(sw["values"], summaries, h1, h2):
        _, per = claim1(s)
        w = isf_winners(s)
        trows.append([_fmt(v) + (" (default)" if v == sw["default"] else ""),
                      " ".join(f"{cs}{'+' if per[cs][0] else '-'}" for cs in per),
                      " ".join(f"{cs}{'+' if per[cs][1] else '-'}" for cs in per),
                      "yes" if a else "no",
                      " ".join(f"{cs}:{LABEL.get(w[cs], w[cs])}" for cs in w),
                      "yes" if b else "no", "yes" if ab else "no"])
    return Table(f"{sw['name']}: '+' = T2F-SMC lower on ISE / on steady-state error in that scenario; lower ISF per "
                 f"scenario; whether each claim holds.",
                 ["value", "ISE (T2F lower)", "sse (T2F lower)", "C003-1 holds", "lower ISF",
                  "C003-2 body holds", "C003-2 abstract holds"], trows, digits=4)


def _sensitivity(ctx, tuned: dict, sweep_base: dict, t_end: float, n_mc_sweep: int) -> dict:
    """Every swept reading, run and judged: the Sensitivity entries of both claims, the claims' results
    in the non-default settings, the flips per reading, and the settings where a half of a claim holds."""
    acc = {key: [] for key in ("sens1", "sens2", "holds1", "holds2_body", "holds2_abs", "flips1", "flips2",
                               "ise_half", "sse_half", "ise_isf_both")}
    for k, sw in enumerate(_sweeps(tuned, bool(ctx.quick))):
        values = sw["values"]
        summaries = _sweep_summaries(ctx, k, sw, sweep_base, t_end, n_mc_sweep)
        h1 = [claim1(s)[0] for s in summaries]
        for v, sm in zip(values, summaries):
            if v == sw["default"]:
                continue
            per = claim1(sm)[1]
            label = f"{sw['name']} = {_fmt(v)}"
            if all(i for i, _ in per.values()):
                acc["ise_half"].append(label)
            if all(x for _, x in per.values()):
                acc["sse_half"].append(label)
            if all(i for i, _ in per.values()) and claim2(sm)[1]:
                acc["ise_isf_both"].append(label)
        h2 = [claim2(s)[:2] for s in summaries]
        fname = f"003_sweep_{k}.png"
        _plot_sweep(sw["name"], sw["unit"], values, summaries, ctx.figures_dir / fname)
        fig = Figure(_rel(fname), f"Sensitivity of paper 003 to {sw['name']}: T2F-SMC / GA-SMC ratios of ISE, ISF "
                                  f"and steady-state error per scenario (003-U: first {n_mc_sweep} seeds).")
        tab = _sweep_table(sw, summaries, h1, h2)
        dflt = sw["default"]
        acc["sens1"].append(Sensitivity(sw["name"], values, dflt, holds_where(values, h1, dflt), fig, tab))
        acc["sens2"].append(Sensitivity(sw["name"], values, dflt,
                                        f"body reading: {holds_where(values, [b for b, _ in h2], dflt)}; abstract "
                                        f"reading: {holds_where(values, [a for _, a in h2], dflt)}", fig, tab))
        acc["flips1"].append((sw["name"], h1))
        acc["flips2"].append((sw["name"], [tuple(x) for x in h2]))  # either reading flipping counts
        acc["holds1"] += [h for v, h in zip(values, h1) if v != dflt]
        acc["holds2_body"] += [b for v, (b, _) in zip(values, h2) if v != dflt]
        acc["holds2_abs"] += [a for v, (_, a) in zip(values, h2) if v != dflt]
    return acc


def _claim_1(summary: dict, sweep_base: dict, acc: dict, tables: list, overview: Figure, t_end: float,
             n_mc: int, n_mc_sweep: int) -> Claim:
    """C003-1: T2F-SMC lower on ISE and steady-state error in every scenario."""
    c1_default, c1_per = claim1(summary)
    c1_sweep_base, _ = claim1(sweep_base)
    sweep_holds1, ise_half, sse_half = acc["holds1"], acc["ise_half"], acc["sse_half"]
    v1 = verdict(c1_default, sweep_holds1)
    n_sw = len(sweep_holds1)
    fails_ise = [f"003-{c}" for c, (i, _) in c1_per.items() if not i]
    fails_sse = [f"003-{c}" for c, (_, s) in c1_per.items() if not s]
    ev1 = (f"Both controllers ran the five scenarios with the committed GA values ({t_end:g} s; 003-U {n_mc} runs). "
           f"T2F-SMC has the lower ISE in {len(c1_per) - len(fails_ise)} of {len(c1_per)} scenarios"
           + (f" (not in {', '.join(fails_ise)})" if fails_ise else "")
           + f" and the lower steady-state error (mean over the three Euler angles) in "
           f"{len(c1_per) - len(fails_sse)} of {len(c1_per)}" + (f" (not in {', '.join(fails_sse)})" if fails_sse else "")
           + f": with today's readings the claim {'holds' if c1_default else 'does not hold'}. "
           f"Across {len(sweep_holds1)} swept settings of the project-choice readings it holds in "
           f"{sum(sweep_holds1)}. Taken apart, the ISE half holds in {len(ise_half)} of {n_sw} swept settings (fails in "
           f"{n_sw - len(ise_half)}) and the steady-state half in {len(sse_half)} of {n_sw}"
           + (f" ({_lst(sse_half)})" if sse_half else "") + "." + ("" if c1_sweep_base == c1_default else
                                      f" (On the first {n_mc_sweep} 003-U seeds used by the sweeps the default "
                                      f"{'holds' if c1_sweep_base else 'does not hold'}.)"))
    return Claim("C003-1", "The type-2 fuzzy SMC has the smaller steady-state error and the smaller ISE in every "
                           "scenario (nominal, constant, sinusoidal and white-noise disturbance, inertia uncertainty).",
                 v1, ev1, tables=tables, figures=[overview],
                 sensitive_to=examined(acc["flips1"]),
                 sensitivity=acc["sens1"])


def _lst(xs: list) -> str:
    return "; ".join(xs) if xs else "none"


def _claim_2(summary: dict, acc: dict, overview: Figure) -> Claim:
    """C003-2: which controller has the lower ISF per scenario, in the body's and the abstract's reading."""
    c2_body, c2_abs, c2_w = claim2(summary)
    sweep_holds2_body, sweep_holds2_abs = acc["holds2_body"], acc["holds2_abs"]
    v2 = verdict(c2_body, sweep_holds2_body)
    win_txt = ", ".join(f"003-{c}: {LABEL.get(w, w)}" for c, w in c2_w.items())
    ev2 = (f"Lower ISF per scenario in our runs: {win_txt}. The paper's body says GA-SMC is lower in 003-N, C, S and "
           f"T2F-SMC in 003-W and U: this reading {'holds' if c2_body else 'does not hold'} with today's readings and "
           f"in {sum(sweep_holds2_body)} of {len(sweep_holds2_body)} swept settings. The abstract's reading "
           f"(T2F-SMC better in all situations, i.e. lower ISF everywhere) {'holds' if c2_abs else 'does not hold'} "
           f"with today's readings and in {sum(sweep_holds2_abs)} of {len(sweep_holds2_abs)} swept settings. "
           f"The verdict is on the body's statement. Settings where T2F-SMC is lower on both ISE and ISF in every "
           f"scenario (the abstract's 'better', leaving the steady-state error aside): {_lst(acc['ise_isf_both'])}. "
           f"The ISF differences are small (a few per cent at most, see the table), so which controller has the "
           f"lower ISF moves with most readings.")
    isf_tab = Table("ISF (N² m² s) per scenario and the lower one (003-U: Monte Carlo mean).",
                    ["scenario", "GA-SMC", "T2F-SMC", "lower", "body says", "abstract says"],
                    [[f"003-{c}", summary[("SMC", c)]["isf"], summary[("T2FSMC", c)]["isf"], LABEL.get(w, w),
                      LABEL[ISF_BODY[c]], "T2F-SMC"] for c, w in c2_w.items()], digits=5)
    return Claim("C003-2", "On ISF, GA-SMC is better in the nominal, constant- and sinusoidal-disturbance scenarios; "
                           "the type-2 fuzzy SMC is better with uncertainty and with white noise (the body's "
                           "statement). The abstract instead says the type-2 fuzzy SMC is better in all situations.",
                 v2, ev2, tables=[isf_tab], figures=[overview],
                 sensitive_to=examined(acc["flips2"]),
                 sensitivity=acc["sens2"])


def _setup_and_notes(tuned: dict, t_end: float, n_mc: int, n_mc_sweep: int, quick: bool) -> tuple[str, str]:
    setup = (f"AttitudePlant with the paper 003 inertia, three reaction wheels with magnetorquer dumping and gravity "
             f"gradient on a 700 km / 98° orbit; command roll 20°, pitch −15°, yaw 0° from rest; Δ = 0.01 s, "
             f"{t_end:g} s. SlidingModeController (k = {tuned['SMC'].get('k_switch', 0.005):.4g} N m) and "
             f"Type2FuzzySmcController (" + ", ".join(f"{k} = {v:.4g}" for k, v in tuned["T2FSMC"].items())
             + f") from paper003/data/tuned.json. Disturbances 5e-4 N m (constant, sinusoid 0.1 rad/s, white noise "
             f"with 0.1 s hold, seed 1); 003-U {n_mc} runs. Sweeps: {n_mc_sweep} 003-U seeds per setting, logged "
             f"every 0.1 s; campaign engine (native container loop)." + (" Quick mode." if quick else ""))
    notes = ("Paper 003's equations and disturbance values are lost: the sliding-mode law, the type-2 fuzzy gain "
             "schedule (sets, footprint σ_lo/σ_up, rule-table orientation, κ range), the boundary layer Φ = 0.005 rad/s, "
             "the disturbance magnitudes, the command and the run length are project choices; the sweeps show which "
             "of them move the verdicts. Controllers are not re-tuned inside the sweeps. The steady-state error is "
             "the mean |wrapped error| over the last 10 % of the logged samples (every sample in the main runs, every "
             "10th in the sweeps)." + (" Quick mode: the same runs and horizon, 8 Monte Carlo runs, 4 per swept "
                                       "setting, fewer sweep values." if quick else ""))
    return setup, notes


def build(ctx) -> PaperSection:
    t_start = time.time()
    quick = bool(ctx.quick)
    t_end = p3.T_END   # quick mode runs fewer cases, never a shorter horizon ("steady state" must mean the same)
    n_mc = 8 if quick else 100
    n_mc_sweep = 4 if quick else 20
    tuned = p3.tuned_params()
    summary, sweep_base, ts, mc_rows = _main_runs(ctx, t_end, n_mc, n_mc_sweep)
    figures, overview = _main_figures(ctx, summary, ts, mc_rows, t_end, n_mc)
    t_results, doc_results, mc_tab, t_torque = _result_tables(summary, ts, n_mc)
    acc = _sensitivity(ctx, tuned, sweep_base, t_end, n_mc_sweep)
    claim_1 = _claim_1(summary, sweep_base, acc, [t_results, mc_tab], overview, t_end, n_mc, n_mc_sweep)
    claim_2 = _claim_2(summary, acc, overview)
    setup, notes = _setup_and_notes(tuned, t_end, n_mc, n_mc_sweep, quick)
    return PaperSection("003", "Sliding mode (GA-tuned) vs sliding mode with an interval type-2 fuzzy gain, LEO "
                               "satellite with reaction wheels and magnetorquers (title lost)",
                        setup, [claim_1, claim_2], figures=figures, tables=[t_torque], notes=notes,
                        runtime_s=round(time.time() - t_start, 1), numbers=number_rows(summary),
                        doc_tables={"results": doc_results})


# Named readings of the ISF's scale (none is documented by the paper; each is shown, labelled, never counted):
# the torque read in another unit multiplies ISF by the square of the factor.
ISF_UNIT_READINGS = {"N·cm": 1e2, "mN·m": 1e3}


def number_rows(summary: dict | None = None) -> list:
    """Paper 003's one surviving number, ISF = 1.0611 for the GA-tuned SMC in the nominal case, beside ours
    (``summary[(controller, case)]["isf"]`` in N²·m²·s). Our value under today's set-up is the independent row;
    the torque-unit readings of ``ISF_UNIT_READINGS`` are extra rows labelled "chosen among readings" (a unit
    picked after seeing the paper's number is no evidence), with the torque scale that would match."""
    from ...report.types import CHOSEN, NOT_CHECKABLE, NumberRow
    rep = common.reported("scfmu.papers.paper003")
    out = []
    for n in rep["numbers"]:
        paper = float(n["value"])
        ours = (summary or {}).get((n["controller"], n["case"]), {}).get("isf")
        if ours is None or not rules.finite(ours):
            out.append(NumberRow("003", n["label"], "N²·m²·s", paper, None, NOT_CHECKABLE, paper_text=n["value"],
                                 note="our run is missing"))
            continue
        scale = math.sqrt(paper / ours)
        v = rules.number_verdict(ours, paper, rules.printed_precision(n["value"]))
        out.append(NumberRow("003", n["label"], "N²·m²·s", paper, ours, v, paper_text=f"{n['value']} (no unit)",
                             note=(f"{n['text']}; ours over our horizon and command, ISF = ∫‖τ‖² dt of the applied "
                                   f"torque: {paper / ours:.4g}× smaller, i.e. a torque scale {scale:.3g}× apart"),
                                 precision=rules.printed_precision(n["value"])))
        for unit, f in ISF_UNIT_READINGS.items():
            o = ours * f * f
            out.append(NumberRow("003", f"{n['label']}, torque read in {unit}", f"({unit})²·s", paper, o,
                                 rules.number_verdict(o, paper, rules.printed_precision(n["value"])), basis=CHOSEN,
                                 paper_text=n["value"], precision=rules.printed_precision(n["value"]),
                                 note=f"reading: the paper's torques in {unit} (ISF × {f * f:g}); no unit is printed, "
                                      f"so this is a reading picked by comparing, not evidence"))
    if not out:
        out.append(NumberRow("003", "any reported number (steady-state error, ISE, ISF per scenario)", "–", None,
                             None, NOT_CHECKABLE, note=rep["source"], paper_text="none survives"))
    return out
