"""Paper 004 report, tables and figures: the terminal state of the cases, the requirement ratio per scale of the
initial attitude (table and figure) and the three cases over time. ``report.py`` runs the campaigns and decides
the claims.
"""

from __future__ import annotations

import math

import numpy as np

from . import model as P
from ...report import common
from ...report.types import Figure, Table

ANG = ("roll", "pitch", "yaw")


def plot_cases(ctx, r1: dict, r2: dict, r3: dict, S0: float) -> Figure:
    """Largest Euler angle, largest body rate and the applied x torque of cases 1, 2 and 3 over time."""
    p_m, rel_m = common.figure(ctx, "004_cases.png")
    plt = common.plt()
    fig, axs = plt.subplots(3, 1, figsize=(9, 10), sharex=True)
    for lab, r in (("004-1 healthy", r1), ("004-2 faulty", r2), ("004-3 corrected", r3)):
        t = r["time"]
        ang = np.degrees(np.max(np.abs(np.stack([r[n] for n in ANG])), axis=0))
        w = np.degrees(np.max(np.abs(np.stack([r[f"w_{a}"] for a in P.AXES])), axis=0))
        axs[0].semilogy(t, np.maximum(ang, 1e-6), label=lab)
        axs[1].semilogy(t, np.maximum(w, 1e-7), label=lab)
        axs[2].plot(t, r["torque_applied_x"], label=f"{lab}, x axis")
    axs[0].axhline(P.EULER_REQ_DEG, color="k", ls=":", label="requirement 0.1 deg")
    axs[1].axhline(P.W_REQ_DEG_S, color="k", ls=":", label="requirement 0.01 deg/s")
    axs[0].set_ylabel("max |roll, pitch, yaw| (deg)")
    axs[1].set_ylabel("max |ω_i| (deg/s)")
    axs[1].set_ylim(bottom=1e-4)
    axs[2].set_ylabel("applied torque τ_x (N·m)")
    axs[2].set_xlabel("time (s)")
    for ax in axs:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Paper 004: cases 1–3 from (yaw, pitch, roll) = ({6 * S0:g}, {-4 * S0:g}, {8 * S0:g}) deg at rest "
                 f"(calibrated start)", fontsize=10)
    common.save(fig, p_m)
    return Figure(rel_m, "Largest 321 angle and body rate (log scale, dotted: requirement) and the applied x "
                         "torque of cases 004-1, 004-2 and 004-3.")


def plot_init_scale(ctx, scales: list, term0: dict, term3: dict, S0: float) -> Figure:
    """Terminal requirement ratio of the three cases against the scale of the initial attitude."""
    p_i, rel_i = common.figure(ctx, "004_init_scale.png")
    plt = common.plt()
    s3 = sorted(k[1] for k in term3 if k[0] == "scale")
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.semilogy(scales, [term0[("scale", s, 1.0)]["ratio"] for s in scales], "o-", label="004-1 healthy")
    ax.semilogy(scales, [term0[("scale", s, P.A_FAULT)]["ratio"] for s in scales], "s--", label="004-2 faulty")
    ax.semilogy(s3, [term3[("scale", s)]["ratio"] for s in s3], "^-", label="004-3 corrected (re-optimised)")
    ax.axhline(1.0, color="k", ls=":", label="requirement (ratio 1)")
    ax.axvline(S0, color="grey", ls="--", lw=0.8, label="calibrated start")
    ax.set_xlabel("initial attitude scale (× (6, −4, 8) deg)")
    ax.set_ylabel("terminal ratio to requirement (-)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Paper 004: requirement ratio against the initial attitude", fontsize=10)
    common.save(fig, p_i)
    return Figure(rel_i, "Terminal requirement ratio (pass iff ≤ 1, log scale) of the three cases against the "
                         "scale of the initial attitude.")


def main_table(t1: dict, t2: dict, t3: dict, t3ol: dict, rep_cal: dict) -> Table:
    """The terminal state of cases 1, 2, 3 and the open-loop run 3ol against the requirement."""
    def trow(name, t, extra=""):
        return [name, t["w_end_max_deg_s"], t["euler_end_max_deg"], t["ratio"], t["peak_torque"],
                "PASS" if t["pass"] else "FAIL", extra]
    return Table("Terminal state at t_f = 20 s (requirement: max|ω_i| ≤ 0.01 deg/s and max|roll, pitch, yaw| ≤ 0.1 deg; "
                 "ratio = max of the two over its limit, pass iff ≤ 1)",
                 ["run", "max|ω_i(t_f)| (deg/s)", "max|Euler(t_f)| (deg)", "ratio to requirement", "peak |τ| (N·m)",
                  "requirement", "note"],
                 [trow("004-1 healthy", t1), trow("004-2 faulty (a = 0.1)", t2),
                  trow("004-3ol spline open loop", t3ol, f"optimiser: {rep_cal['optimiser']['status']}"),
                  trow("004-3 corrected reference", t3)], digits=4)


def init_table(pl: dict, term0: dict, term3: dict, opt: dict) -> Table:
    """The requirement ratio of each case per initial-attitude scale, with the optimiser status."""
    init_rows = []
    for s in pl["scales"]:
        a, b = term0[("scale", s, 1.0)], term0[("scale", s, P.A_FAULT)]
        c3 = term3.get(("scale", s))
        init_rows.append([s, f"({6 * s:g}, {-4 * s:g}, {8 * s:g})", a["ratio"], b["ratio"],
                          c3["ratio"] if c3 else math.nan,
                          opt[("scale", s)]["status"] if ("scale", s) in opt else "not optimised"])
    return Table("Initial attitude scaled from the default (project choice; 2.5 × is the stress run 004-X): ratio to "
                 "the requirement (pass iff ≤ 1) for each case; case 3 with a spline optimised for that start",
                 ["scale", "(yaw, pitch, roll) (deg)", "004-1 ratio", "004-2 ratio", "004-3 ratio", "optimiser"],
                 init_rows)
