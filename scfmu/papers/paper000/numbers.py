"""Paper 000's reported numbers beside ours: Table 3 (EULERINT) and Table 4 (control effort) of the large
command, read from ``data/reported.json``.

* EULERINT: ours is the run the paper's row describes (PD with each kinematics, LQR, pole placement, the
  large-angle MRAC on the linear dynamics with quaternion kinematics, fuzzy and adaptive fuzzy on the command of the paper's figures).
  The fuzzy row was used to calibrate the fuzzy PD's T_r (``scenarios.T_R_CALIBRATED``) and is no
  independent check.
* Control effort: the paper gives only the unit (N·m·s). Every plausible definition is tried once
  (``EFFORT_DEFS``); a definition "fits" when it reproduces every row within 5 % (absolute), or every
  row's ratio to the quaternion PD's within 5 % (the same metric up to a constant factor such as another
  horizon or unit). If none fits, each row is "not reproduced — definition unknown" (or "same ordering
  only" when our ∫Σ|τ| dt ranks it as the paper does); the definition that would pass is never chosen after
  the fact.

All functions are pure functions of ``{run id: metrics row}`` and ``{run id: time series}`` tables.
"""

from __future__ import annotations

import math

import numpy as np

from ...report import common, rules
from ...report.types import NOT_REPRODUCED, SAME_ORDERING, NumberRow, Table

EI = "eulerint_deg_s"
REL = rules.REL_TOL
# the large-command MRAC under set-ups other than the paper's stated one (shown beside the row as readings)
MRAC_READINGS = {"000-9Ll": "linear kinematics too (kinematics 3, the earlier choice)",
                 "000-9Lc": "linear-coordinate MRAC on the full quaternion plant",
                 "000-9Lq": "quaternion MRAC on the quaternion plant"}


def reported() -> dict:
    return common.reported("scfmu.papers.paper000")


def _trapz(y, t) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def _tau(ts: dict) -> tuple[np.ndarray, np.ndarray]:
    return ts["time"], np.stack([ts[f"torque_applied_{a}"] for a in "xyz"])


# name → (label, unit, function(metrics row, time series) → value)
EFFORT_DEFS = {
    "effort_abs": ("∫ Σ|τ_i| dt", "N·m·s", lambda m, ts: m["effort_abs"]),
    "effort_norm": ("∫ ‖τ‖ dt", "N·m·s", lambda m, ts: _trapz(np.linalg.norm(_tau(ts)[1], axis=0), _tau(ts)[0])),
    "effort_sq": ("∫ ‖τ‖² dt", "N²·m²·s", lambda m, ts: m["effort_sq"]),
    "effort_rms": ("√(∫ ‖τ‖² dt)", "N·m·√s", lambda m, ts: math.sqrt(m["effort_sq"])),
    "peak": ("max_t,i |τ_i|", "N·m", lambda m, ts: float(np.max(np.abs(_tau(ts)[1])))),
}
PRIMARY_EFFORT = "effort_abs"


def eulerint_rows(m: dict, calibrated: set[str]) -> list[NumberRow]:
    """One row per Table 3 entry. ``calibrated``: keys of the rows used for a calibration."""
    rep = reported()
    rows = rep["rows"]
    paper = [float(r["eulerint"]) for r in rows]
    ours = [m[r["run"]][EI] if r["run"] in m else math.nan for r in rows]
    out = []
    for i, r in enumerate(rows):
        v = rules.number_verdict(ours[i], paper[i], rules.printed_precision(r["eulerint"]),
                                 rules.same_ordering(i, ours, paper))
        note = f"run {r['run']}"
        if r["key"] == "mrac":
            alt = [(k, lab) for k, lab in MRAC_READINGS.items() if k in m]
            note += ("; the paper's set-up: linear dynamics with quaternion kinematics (plant kinematics 4), MRAC in "
                     "its linear coordinates. Other set-ups (readings, not evidence): "
                     + "; ".join(f"{lab} {m[k][EI]:.1f} ({100 * rules.rel_diff(m[k][EI], paper[i]):+.1f} %)"
                                 for k, lab in alt))
        if r["key"] == "fuzzy":
            note += "; T_r calibrated to this number"
        out.append(NumberRow("000", f"Table 3 EULERINT: {r['label']}", rep["eulerint_unit"], paper[i], ours[i], v,
                             calibration=r["key"] in calibrated, note=note, paper_text=r["eulerint"],
                             precision=rules.printed_precision(r["eulerint"])))
    return out


def effort_fit(m: dict, ts: dict) -> dict:
    """For every definition: our values per row, and whether it fits absolutely or up to a factor."""
    rep = reported()
    rows = rep["rows"]
    paper = np.array([float(r["effort"]) for r in rows])
    i_ref = next(i for i, r in enumerate(rows) if r["key"] == "pd_quat")
    out = {}
    for name, (label, unit, f) in EFFORT_DEFS.items():
        ours = np.array([f(m[r["run"]], ts[r["run"]]) if r["run"] in m and r["run"] in ts else math.nan
                         for r in rows])
        abs_ok = [rules.within(o, p, REL) for o, p in zip(ours, paper)]
        ratio = ours / ours[i_ref]
        pratio = paper / paper[i_ref]
        fac_ok = [rules.within(o, p, REL) for o, p in zip(ratio, pratio)]
        out[name] = {"label": label, "unit": unit, "ours": ours.tolist(), "abs_ok": abs_ok, "fac_ok": fac_ok,
                     "fits_abs": all(abs_ok), "fits_factor": all(fac_ok),
                     "factor": float(paper[i_ref] / ours[i_ref]) if ours[i_ref] else math.nan}
    return out


def effort_rows(m: dict, ts: dict) -> tuple[list[NumberRow], Table, str]:
    """Table 4 rows, the table of every definition tried, and one sentence on which (if any) fits."""
    rep = reported()
    rows = rep["rows"]
    paper = [float(r["effort"]) for r in rows]
    fit = effort_fit(m, ts)
    fits = [n for n, d in fit.items() if d["fits_abs"] or d["fits_factor"]]
    out = []
    if fits:
        name = fits[0]
        d = fit[name]
        ours = d["ours"] if d["fits_abs"] else [x * d["factor"] for x in d["ours"]]
        for i, r in enumerate(rows):
            v = rules.number_verdict(ours[i], paper[i], rules.printed_precision(r["effort"]),
                                     rules.same_ordering(i, ours, paper))
            out.append(NumberRow("000", f"Table 4 control effort: {r['label']}", rep["effort_unit"], paper[i], ours[i],
                                 v, note=f"run {r['run']}; definition {d['label']}"
                                 + ("" if d["fits_abs"] else f" × {d['factor']:.3g}"), paper_text=r["effort"],
                                 precision=rules.printed_precision(r["effort"])))
        text = f"The definition {fit[name]['label']} fits every row" + ("" if fit[name]["fits_abs"] else
                                                                          " up to a constant factor") + "."
    else:
        ours = fit[PRIMARY_EFFORT]["ours"]
        for i, r in enumerate(rows):
            v = SAME_ORDERING if rules.same_ordering(i, ours, paper) else NOT_REPRODUCED
            out.append(NumberRow("000", f"Table 4 control effort: {r['label']}", rep["effort_unit"], paper[i], ours[i],
                                 v, note=f"run {r['run']}; definition unknown (none of {len(fit)} tried fits); ours "
                                 f"is {fit[PRIMARY_EFFORT]['label']}", paper_text=r["effort"]))
        best = max(fit, key=lambda n: max(sum(fit[n]["abs_ok"]), sum(fit[n]["fac_ok"])))
        text = (f"Not reproduced — definition unknown: none of the {len(fit)} definitions tried "
                f"({', '.join(d['label'] for d in fit.values())}) reproduces Table 4, neither absolutely nor up to a "
                f"constant factor (the best, {fit[best]['label']}, matches {max(sum(fit[best]['abs_ok']), sum(fit[best]['fac_ok']))} "
                f"of {len(rows)} rows within 5 %).")
    cols = ["row", "paper (N·m·s)", "paper / PD quaternion"]
    i_ref = next(i for i, r in enumerate(rows) if r["key"] == "pd_quat")
    trows = []
    for i, r in enumerate(rows):
        line = [r["label"], paper[i], paper[i] / paper[i_ref]]
        for n, d in fit.items():
            line += [d["ours"][i], d["ours"][i] / d["ours"][i_ref]]
        trows.append(line)
    for n, d in fit.items():
        cols += [f"{d['label']} [{d['unit']}]", f"{d['label']} / PD quaternion"]
    table = Table("Control effort: the paper's Table 4 and every definition tried (large command, runs of Table 3; "
                  "a definition fits when all rows agree within 5 %, absolutely or as ratios to the quaternion PD)",
                  cols, trows, digits=4)
    return out, table, text


def paper_misses(m: dict, runs) -> float:
    """The largest relative miss |ours − paper|/paper of Table 3 EULERINT over the given runs that have a
    reported value (0 when none has): how far a set of runs is from the paper's own numbers."""
    by_run = {}
    for r in reported()["rows"]:
        by_run[r["run"]] = float(r["eulerint"])
    by_run.setdefault("000-10L", by_run.get("000-10L2"))   # L and L2 are mirror images (same EULERINT)
    by_run.setdefault("000-11L", by_run.get("000-11L2"))
    miss = 0.0
    for k in runs:
        p = by_run.get(k)
        if p and k in m and rules.finite(m[k].get(EI)):
            miss = max(miss, abs(m[k][EI] - p) / p)
    return miss


def moves_away(base: dict, changed: dict) -> bool:
    """A reading that replaces the runs ``changed`` ({run id: row}) moves the paper's own numbers further
    away when the largest miss over those runs grows and ends outside the 5 % of "reproduced"."""
    runs = list(changed)
    before = paper_misses(base, runs)
    after = paper_misses({**base, **changed}, runs)
    return after > before + 1e-9 and after > REL


def metrics_table(base: dict) -> Table:
    """Every run of the paper 000 table at the default parameters (the report's table and the docs page's)."""
    from . import scenarios
    rows = []
    for r in scenarios.paper000_runs():
        m = base[r.run_id]
        os_ = max(m.get(f"overshoot_{a}_pct", math.nan) for a in ("roll", "pitch", "yaw"))
        rows.append([r.run_id, r.label, scenarios.KIN_NAMES[r.kinematics], r.command, m[EI], m["effort_abs"],
                     m["effort_sq"], m["settling_s"], os_])
    return Table("Paper 000 runs at default parameters (Δ = 0.01 s, 30 s, RK4 0.01 s, inertia diag(1000, 500, 700) "
                 "kg·m²); settling on α with a 2 % band (nan = not settled), overshoot = largest of the three angles",
                 ["run", "controller", "plant kinematics", "command", "EULERINT [deg·s]", "∫Σ|τ| [N·m·s]",
                  "∫‖τ‖² [N²·m²·s]", "settling [s]", "overshoot [%]"], rows)


SHARED_READINGS = ("AdaptiveFuzzyController λ-range scale s", "AdaptiveFuzzyController.gamma", "MracController.gamma")


def readings_table(sws_full: list, sws_quick: list, all_rows: dict, base: dict) -> Table:
    """The docs page's table of the adaptive laws' readings (λ-range scale s, γ): EULERINT and effort of the
    large-command run at each value both builds run (the quick grid is part of the full one), and the largest
    relative change of EULERINT over every run the sweep replaces (large command, R1, R2 ×1.2 and ×0.8)."""
    quick = {sw["param"]: set(sw["values"]) for sw in sws_quick}
    rows = []
    for sw in sws_full:
        if sw["param"] not in SHARED_READINGS or sw["param"] not in all_rows:
            continue
        rr = all_rows[sw["param"]]
        main = sw["runs"][0]
        for i, v in enumerate(sw["values"]):
            if v not in quick.get(sw["param"], ()):
                continue
            ch = [abs(rr[r][i][EI] - base[r][EI]) / abs(base[r][EI]) for r in sw["runs"]
                  if rr[r][i]["status"] == "ok" and r in base]
            rows.append([sw["param"], float(v), main, rr[main][i][EI], rr[main][i]["effort_abs"],
                         100.0 * max(ch) if ch else math.nan])
    return Table("The adaptive laws' readings at the points both builds run: EULERINT and effort ∫Σ|τ| dt of the "
                 "large-command run, and the largest change of EULERINT against the defaults over every run the "
                 "reading replaces (large command, R1, R2 ×1.2 and ×0.8)",
                 ["reading", "value", "run", "EULERINT (deg·s)", "effort (N·m·s)", "largest EULERINT change (%)"],
                 rows)
