"""Paper 002 report, tables and figures: the nominal-step and sweep tables; the step responses and phase planes
of the nominal runs (002-1, 002-2), the MAE along the sweeps (002-3 … 002-6) and per damaged-digit candidate
(002-7). ``report.py`` runs the campaigns and decides the claims; each plot function saves one PNG and returns
its path relative to the report. The controller names and pairs are defined here (``report.py`` imports them).
"""

from __future__ import annotations

import numpy as np

from ...report import common
from ...report.types import Table

NAMES = ("PD", "PID", "FOPD", "FOPID")
PAIRS = (("PD", "FOPD"), ("PID", "FOPID"))


def plot_steps(ctx, ts_nom: dict, theta_ref: float) -> str:
    """θ(t) and ω(t) of the two pairs for the nominal step (run 002-1)."""
    plt = common.plt()
    p_s, rel_s = common.figure(ctx, "002_step_responses.png")
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for col, pair in enumerate(PAIRS):
        for c in pair:
            r = ts_nom[c]
            ls = "-" if c.startswith("FO") else "--"
            ax[0, col].plot(r["time"], np.degrees(r["theta"]), ls, label=c)
            ax[1, col].plot(r["time"], np.degrees(r["omega"]), ls, label=c)
        ax[0, col].axhline(theta_ref, color="k", lw=0.6, ls=":", label="θ_ref")
        ax[0, col].set_ylabel("θ (deg)")
        ax[1, col].set_ylabel("ω (deg/s)")
        ax[1, col].set_xlabel("time (s)")
        ax[0, col].set_title(f"{pair[0]} vs {pair[1]}")
        for a_ in ax[:, col]:
            a_.legend(fontsize=8)
            a_.grid(alpha=0.3)
    fig.suptitle("Paper 002 run 002-1: step responses to θ_ref = 30 deg (tuned gains)", fontsize=10)
    common.save(fig, p_s)
    return rel_s


def plot_phase(ctx, ts_nom: dict, theta_ref: float) -> str:
    """Phase planes (pointing error vs rate) of the two pairs (run 002-2)."""
    plt = common.plt()
    p_p, rel_p = common.figure(ctx, "002_phase_plane.png")
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    for col, pair in enumerate(PAIRS):
        for c in pair:
            r = ts_nom[c]
            ax[col].plot(np.degrees(r["theta"]) - theta_ref, np.degrees(r["omega"]), "-" if c.startswith("FO") else "--",
                         label=c)
        ax[col].set_xlabel("pointing error θ − θ_ref (deg)")
        ax[col].set_ylabel("rate ω (deg/s)")
        ax[col].set_title(f"phase plane: {pair[0]} vs {pair[1]}")
        ax[col].legend(fontsize=8)
        ax[col].grid(alpha=0.3)
    fig.suptitle("Paper 002 run 002-2: phase planes (the end point (0, 0) is on target)", fontsize=10)
    common.save(fig, p_p)
    return rel_p


def plot_sweeps(ctx, pl: dict, sweeps: dict, mae_of, sweep_label: dict, t_end: float) -> str:
    """MAE of the four controllers along each sweep (runs 002-3 … 002-6)."""
    plt = common.plt()
    p_w, rel_w = common.figure(ctx, "002_sweeps.png")
    fig, axs = plt.subplots(2, 2, figsize=(11, 7.5))
    for a_, kind in zip(axs.flat, sweep_label):
        m = mae_of(sweeps[kind])
        for c in NAMES:
            a_.plot(pl[kind], m[c], marker="o", ls="-" if c.startswith("FO") else "--", label=c)
        a_.set_xlabel(sweep_label[kind])
        a_.set_ylabel("MAE (deg)")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=8)
    fig.suptitle(f"Paper 002 runs 002-3 … 002-6: mean absolute pointing error over [0, {t_end:g}) s, gains fixed",
                 fontsize=10)
    common.save(fig, p_w)
    return rel_w


def plot_digits(ctx, res: dict, digit_i: list, dlabels: list) -> str:
    """Nominal MAE of PID, FOPD and FOPID relative to PD per damaged-digit candidate (run 002-7)."""
    plt = common.plt()
    p_d, rel_d = common.figure(ctx, "002_digits.png")
    fig, ax = plt.subplots(figsize=(9, 4.2))
    xs = np.arange(len(digit_i))
    for k_, c in enumerate(NAMES[1:]):
        rel = [100.0 * (res[c][i]["mae_deg"] / res["PD"][i]["mae_deg"] - 1.0) for i in digit_i]
        ax.bar(xs + (k_ - 1) * 0.25, rel, 0.25, label=f"{c} vs PD", color=f"C{k_ + 1}")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xticks(xs, [lab.replace(" ", "\n") for lab in dlabels], fontsize=8)
    ax.set_xlabel("candidate reading of the damaged digits: inertia J (kg·m²), wheel gain K (-)")
    ax.set_ylabel("MAE relative to PD (%)")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    ax.set_title("Paper 002 run 002-7: MAE relative to PD per candidate (below 0: better than PD)", fontsize=10)
    common.save(fig, p_d)
    return rel_d


def nominal_table(nom: dict, t_end: float) -> Table:
    """MAE, settling, overshoot and late error of the four controllers on the nominal step."""
    return Table(f"Nominal step (θ_ref = 30 deg, t_end = {t_end:g} s): MAE, 2 % settling, overshoot",
                 ["controller", "MAE (deg)", "settling (s)", "overshoot (%)", "max |e| after 10 s (deg)"],
                 [[c, nom[c]["mae_deg"], nom[c]["settling_s"], nom[c]["overshoot_pct"], nom[c]["late_max_deg"]]
                  for c in NAMES], digits=5)


def sweep_table(pl: dict, m: dict, kind: str, label: str) -> Table:
    """MAE of the four controllers (``m``: {controller: MAE per point}) along one sweep."""
    return Table(f"MAE (deg) against {label}", [label, *NAMES],
                 [[x, *(m[c][j] for c in NAMES)] for j, x in enumerate(pl[kind])], digits=5)


def tuning_table(path=None) -> Table:
    """The committed PSO tuning (paper002/data/gains.json, written by ``scfmu paper 002 tune``): the gains, cost,
    iterations and runs of each swarm and the totals; the same in quick and full builds (it runs nothing)."""
    import json
    from .model import GAINS_FILE
    d = json.loads((path or GAINS_FILE).read_text(encoding="utf-8"))
    ctl, s = d["controllers"], d["setup"]
    rows = []
    for c in NAMES:
        r, g = ctl[c], ctl[c]["gains"]
        per_run = r["run_seconds"] / r["evaluations"]
        rows.append([c, *(f"{g[k]:.6g}" if k in g else "–" for k in ("kp", "ki", "kd", "lambda", "mu")),
                     f"{r['cost']:.8g}", r["iterations"], r["evaluations"], f"{per_run:.2f}",
                     "stall" if r["stall_rule_fired"] else r["stop"]])
    runs = sum(r["evaluations"] for r in ctl.values())
    run_s = sum(r["run_seconds"] for r in ctl.values())
    gap = max(abs(r["cost"] - r["cost_direct_loop"]) for r in ctl.values())
    rows.append(["all four", "", "", "", "", "", "", "", runs, f"{run_s / runs:.2f}",
                 f"{d['total_seconds']:.0f} s wall, {run_s:.0f} s of runs"])
    return Table(f"The committed PSO tuning (finished {d['finished_utc'][:10]}): {s['particles']} particles, at most "
                 f"{s['max_iterations']} iterations, stall rule {s['stall']}, one Dask LocalCluster ({d['machine']}); "
                 f"cost = MAE (deg) on the nominal {s['theta_ref_deg']:g}° step, {s['t_end_s']:g} s, "
                 f"h = {s['step_s']:g} s, equal to the direct two-FMU loop's to {gap:.1e}",
                 ["controller", "K_P", "K_I", "K_D", "λ", "μ", "cost = MAE (deg)", "iterations", "runs",
                  "s per run", "stop"], rows)
