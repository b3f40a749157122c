"""The engineering section of the benchmark page (attitude family): effort, saturation and pointing tables
with an effort-vs-performance scatter per scenario, the robustness Monte Carlo's percentiles and the
stability margins with Bode plots; also ``engineering.csv``, ``robustness.csv`` and ``margins.csv``. The
numbers come from :mod:`.engineering` (``Entry.means`` and the result of :func:`.engineering.studies`).
"""

from __future__ import annotations

import csv
import html
import math
from pathlib import Path

import numpy as np

from .engineering import COLS, MC_COLS, PRIMARY_NAMES, _slug


# ----- figures ------------------------------------------------------------------------------------------
def _fmt(v, pct=False) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–" if not (isinstance(v, float) and v == math.inf) else "∞"
    return f"{v:.4g}"


def _scatter(out: Path, case, entries, unit_label) -> str | None:
    es = [e for e in entries if e.case == case.label and not e.status
          and math.isfinite(e.means.get("effort_abs", math.nan)) and math.isfinite(e.means.get(case.primary, math.nan))]
    if not es:
        return None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    groups: dict = {}  # controllers at the same point (to 4 significant digits) share one label
    for e in es:
        me = e.controller == unit_label
        x, y = e.means["effort_abs"], e.means[case.primary]
        ax.scatter(x, y, s=90 if me else 35, marker="*" if me else "o", edgecolors="k" if me else "none", zorder=3)
        groups.setdefault((f"{x:.4g}", f"{y:.4g}"), [x, y, []])[2].append(e.controller)
    for x, y, names in groups.values():
        ax.annotate(" = ".join(names), (x, y), fontsize=7, xytext=(4, 3), textcoords="offset points",
                    fontweight="bold" if unit_label in names else "normal")
    ax.set_xlabel("control effort ∫Σ|u| dt [N·m·s]")
    ax.set_ylabel(PRIMARY_NAMES.get(case.primary, case.primary) + " (lower is better)")
    if max(e.means["effort_abs"] for e in es) > 20 * max(1e-300, min(e.means["effort_abs"] for e in es)):
        ax.set_xscale("log")
    ax.set_title(f"Effort vs performance: {case.label}" + (f"\nunit under test: {unit_label}" if unit_label else ""),
                 fontsize=9)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    name = f"figures/effort_{_slug(case.label)}.png"
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    return name


def _bode(out: Path, label: str, margins: dict, unit_label) -> str | None:
    rows = [(ctrl, m) for (lab, ctrl), m in margins.items() if lab == label and isinstance(m, list)]
    if not rows:
        return None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(2, 3, figsize=(12, 6), sharex="col")
    for ctrl, ms in rows:
        me = ctrl == unit_label
        for j, m in enumerate(ms):
            w, L = np.asarray(m["omega"]), np.asarray(m["loop"])
            ok = np.isfinite(L)
            axs[0, j].semilogx(w[ok], 20 * np.log10(np.abs(L[ok])), lw=2.0 if me else 0.9, label=ctrl)
            axs[1, j].semilogx(w[ok], np.degrees(np.unwrap(np.angle(L[ok]))), lw=2.0 if me else 0.9)
    for j, a in enumerate("xyz"):
        axs[0, j].axhline(0, color="k", lw=0.6)
        axs[1, j].axhline(-180, color="k", lw=0.6)
        axs[0, j].set_title(f"axis {a}: loop L(e^jωT) broken at torque_cmd_{a}", fontsize=9)
        axs[0, j].set_ylabel("|L| [dB]")
        axs[1, j].set_ylabel("phase of L [deg]")
        axs[1, j].set_xlabel("frequency ω [rad/s]")
        for k in range(2):
            axs[k, j].grid(True, which="both", alpha=0.3)
    axs[0, 0].legend(fontsize=6)
    fig.suptitle(f"Bode plots of the per-axis loop transfer: {label}" + (f" (unit under test: {unit_label})" if unit_label else ""),
                 fontsize=10)
    fig.tight_layout()
    name = f"figures/bode_{_slug(label)}.png"
    fig.savefig(out / name, dpi=100)
    plt.close(fig)
    return name


class _Page:
    """Markdown lines and HTML fragments of one section, written side by side."""

    def __init__(self):
        self.md: list[str] = []
        self.h: list[str] = []

    def heading(self, level: int, text: str) -> None:
        self.md.extend([f"{'#' * level} {text}", ""])
        self.h.append(f"<h{level}>{html.escape(text)}</h{level}>")

    def para(self, text: str) -> None:
        self.md.extend([text, ""])
        self.h.append(f"<p>{html.escape(text)}</p>")

    def figure(self, fig: str | None, alt_md: str, alt_html: str) -> None:
        if fig:
            self.md.extend([f"![{alt_md}]({fig})", ""])
            self.h.append(f"<p><img src='{fig}' alt='{alt_html}' style='max-width:100%'></p>")

    def table(self, head, rows, bold) -> None:
        md, h = self.md, self.h
        md.extend(["| " + " | ".join(head) + " |", "|" + "---|" * len(head)])
        h.append("<table border=1 cellspacing=0 cellpadding=3><tr>" + "".join(f"<th>{html.escape(x)}</th>" for x in head) + "</tr>")
        for r, b in zip(rows, bold):
            md.append("| " + " | ".join((f"**{x}**" if b and i == 0 else str(x)).replace("|", "/") for i, x in enumerate(r)) + " |")
            h.append(f"<tr{' style=font-weight:bold' if b else ''}>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in r) + "</tr>")
        md.append("")
        h.append("</table>")


def append_to_page(out: Path, cases, entries, rk: dict, unit_label, res: dict | None) -> None:
    """Appends the section "Effort, saturation, pointing, robustness and margins" to ``benchmark.md`` and
    ``index.html`` and writes ``engineering.csv``, ``robustness.csv`` and ``margins.csv``."""
    out = Path(out)
    res = res or {"mc": {}, "margins": {}, "mc_cases": [], "margin_cases": [], "mc_runs": 0}
    p = _Page()
    p.heading(2, "Effort, saturation, pointing, robustness and stability margins")
    _pointing(p, out, cases, entries, rk, unit_label)
    _robustness(p, out, res, unit_label)
    _margins(p, out, res, unit_label)
    with open(out / "benchmark.md", "a", encoding="utf-8") as f:
        f.write("\n" + "\n".join(p.md) + "\n")
    page = (out / "index.html").read_text(encoding="utf-8")
    page = page.replace("</body>", "\n".join(p.h) + "</body>", 1)
    (out / "index.html").write_text(page, encoding="utf-8")


def _pointing(p: _Page, out: Path, cases, entries, rk: dict, unit_label) -> None:
    p.para("Effort: ∫Σ|u_i| dt of the applied torque [N·m·s]. Time in saturation: share of the run in which any "
           "axis of the commanded torque is at or beyond the actuator's torque limit (wheels: or a wheel at its "
           "momentum limit). Pointing errors of the small-rotation error vector e(t) of the body against the "
           "reference [deg], over the pointing phase (last third of the run) cut into 4 windows: APE = max ‖e‖; "
           "MPE = ‖mean e‖; RPE = max over windows of max ‖e − window mean‖; PDE = max ‖difference of "
           "consecutive window means‖; jitter = RMS of e − window mean. Values are means over the runs of a "
           "scenario that succeeded, computed from the logged response.")
    with open(out / "engineering.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "controller", "rank", *[k for k, _ in COLS]])
        for case in cases:
            es = [e for e in entries if e.case == case.label]
            if not any(math.isfinite(e.means.get("ape_deg", math.nan)) for e in es):
                continue
            ev = next((getattr(e, "eval_text", "") for e in es if getattr(e, "eval_text", "")), "")
            p.heading(3, case.label)
            p.para(f"Primary metric {case.primary}; {ev}.")
            rows, bold = [], []
            for e in es:
                if e.status:
                    continue
                rank = rk.get(case.label, {}).get(e.controller, "–")
                rows.append([e.controller, rank, _fmt(e.means.get(case.primary, math.nan)),
                             *[_fmt(e.means.get(k, math.nan)) for k, _ in COLS]])
                bold.append(e.controller == unit_label)
                w.writerow([case.label, e.controller, rank, *[e.means.get(k, math.nan) for k, _ in COLS]])
            p.table(["controller", "rank", case.primary, *[n for _, n in COLS]], rows, bold)
            p.figure(_scatter(out, case, entries, unit_label), f"effort vs performance, {case.label}",
                     "effort vs performance")


def _robustness(p: _Page, out: Path, res: dict, unit_label) -> None:
    p.heading(3, "Robustness Monte Carlo")
    if "seconds" in res:
        p.para(f"Monte Carlo and margins: {res['seconds']:.0f} s of wall time (the margins run on the workers "
               f"beside the Monte Carlo).")
    p.para(f"{res['mc_runs']} seeded runs per controller (seed 0; the same draws for every controller) on "
           f"{', '.join(res['mc_cases']) or 'no scenario'}: principal inertias ±20 % (uniform) with principal "
           f"axes turned up to 10° (products of inertia; every draw positive definite and meeting the triangle "
           f"inequalities), actuator misalignment N(0, 0.5°) per axis, actuator scale factor 1 ± 5 % (uniform), "
           f"initial attitude + N(0, 2°) per 3-2-1 angle, initial rate + N(0, 0.1 °/s) per axis, disturbance "
           f"torques × U(0.5, 2). Pass: the run succeeded and settled (2 % band) before its end. Percentiles: "
           f"NumPy linear interpolation over the runs that succeeded.")
    with open(out / "robustness.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "controller", "runs", "pass_fraction", *[f"{k}_{s}" for k in MC_COLS for s in ("median", "p95", "p99")]])
        for lab in res["mc_cases"]:
            items = [(ctrl, v) for (l2, ctrl), v in res["mc"].items() if l2 == lab]
            if not items:
                continue
            prim = items[0][1]["primary_name"]
            p.heading(4, lab)
            names = {**dict(COLS), "primary": prim, "settling_s": "settling [s]"}
            head = ["controller", "pass", *[f"{names.get(k, k)} median / p95 / p99" for k in MC_COLS]]
            rows, bold = [], []
            for ctrl, v in items:
                rows.append([ctrl, f"{100 * v['pass']:.0f} % of {v['runs']}",
                             *[" / ".join(_fmt(v[k][s]) for s in ("median", "p95", "p99")) for k in MC_COLS]])
                bold.append(ctrl == unit_label)
                w.writerow([lab, ctrl, v["runs"], v["pass"], *[v[k][s] for k in MC_COLS for s in ("median", "p95", "p99")]])
            p.table(head, rows, bold)


def _margins(p: _Page, out: Path, res: dict, unit_label) -> None:
    p.heading(3, "Stability margins")
    p.para("Per axis, loop broken at the plant's torque input (the other two axes closed), at the state of every "
           "unit at the end of the scenario's nominal run; the discrete loop at its sample time T (the "
           "communication step, or the flight computer's period when the torque reaching the plant is held "
           "longer), identified from pulse responses through FMU state save/restore; margins by python-control "
           "on its frequency response. GM: gain margin [dB] (∞: no phase crossover below the Nyquist frequency), "
           "PM: phase margin [deg] at the crossover ω_c [rad/s], DM = PM/ω_c: delay margin [s].")
    with open(out / "margins.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "controller", "axis", "sample_time_s", "gm_db", "gm_reduction_db", "pm_deg",
                    "crossover_rad_s", "delay_margin_s", "note"])
        for lab in res["margin_cases"]:
            items = [(ctrl, v) for (l2, ctrl), v in res["margins"].items() if l2 == lab]
            if not items:
                continue
            p.heading(4, lab)
            head = ["controller", "T [s]", *[f"{a}: GM [dB] / PM [deg] / ω_c [rad/s] / DM [s]" for a in "xyz"], "note"]
            rows, bold = [], []
            for ctrl, v in items:
                if isinstance(v, str):
                    rows.append([ctrl, "–", "–", "–", "–", "not linearised: " + v])
                    w.writerow([lab, ctrl, "", "", "", "", "", "", "", "not linearised: " + v])
                else:
                    rows.append([ctrl, _fmt(v[0]["sample_time"]),
                                 *[" / ".join(_fmt(m[k]) for k in ("gm_db", "pm_deg", "wc", "dm_s")) for m in v],
                                 "; ".join(dict.fromkeys(m["note"] for m in v if m["note"]))])
                    for m in v:
                        w.writerow([lab, ctrl, m["axis"], m["sample_time"], m["gm_db"], m["gm_low_db"], m["pm_deg"],
                                    m["wc"], m["dm_s"], m["note"]])
                bold.append(ctrl == unit_label)
            p.table(head, rows, bold)
            p.figure(_bode(out, lab, res["margins"], unit_label), f"Bode plots, {lab}", "Bode plots")
