"""Figures of the paper 000 report section (``scfmu.papers.paper000.report``): EULERINT ranking, effort against
EULERINT, robustness responses, one figure per sensitivity sweep and the joint T_r × λ-scale region map.
Every figure has axis labels with units, a legend where several series share axes, and a caption."""

from __future__ import annotations

import numpy as np

from .constants import EFF, EFFORT_RATIO, EI, L_RUNS, ROBUST_CASES, ROBUST_CTRL, S_RUNS, _label
from ...report import common
from ...report.types import Figure


def fig_ranking(ctx, base) -> Figure:
    plt = common.plt()
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, ids, title in ((axs[0], L_RUNS, "large command L (40, −40, −60) deg"),
                           (axs[1], S_RUNS, "small command S (4, −4, −6) deg")):
        ids = sorted(ids, key=lambda k: base[k][EI])
        vals = [base[k][EI] for k in ids]
        colors = ["tab:green" if "11" in k else "tab:olive" if "10" in k else "tab:blue" for k in ids]
        ax.barh([_label(k) for k in ids], vals, color=colors)
        for y, v in enumerate(vals):
            ax.text(v, y, f" {v:.1f}", va="center", fontsize=8)
        ax.set_xlabel("EULERINT = ∫α dt over 30 s [deg·s]")
        ax.set_title(title, fontsize=10)
        ax.set_xlim(0, max(vals) * 1.18)
    fig.suptitle("Paper 000: EULERINT of every controller (lower is better); paper's order for L: "
                 "adaptive fuzzy < fuzzy < MRAC < PD quat = LQR = pole pl. < PD DCM < PD Euler", fontsize=9)
    p = ctx.figures_dir / "000_ranking.png"
    common.save(fig, p, dpi=100)
    return Figure(f"figures/{p.name}", "EULERINT per controller, large (left) and small (right) command, default "
                                       "parameters; horizontal bars sorted from best to worst.")


def fig_effort(ctx, base) -> Figure:
    plt = common.plt()
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, unit in ((axs[0], "effort_abs", "∫Σ|τ_i| dt [N·m·s]"), (axs[1], "effort_sq", "∫‖τ‖² dt [N²·m²·s]")):
        for k in ["000-2", "000-4", "000-6", "000-9L", "000-10L", "000-11L"]:
            ax.scatter(base[k][EI], base[k][key], s=40, label=_label(k))
            ax.annotate(_label(k).split(" ", 1)[1], (base[k][EI], base[k][key]), fontsize=7,
                        xytext=(4, 4), textcoords="offset points")
        ax.set_xlabel("EULERINT [deg·s]")
        ax.set_ylabel(f"control effort {unit}")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=7)
    fig.suptitle("Paper 000, large command: control effort against EULERINT (two effort metrics; the paper's "
                 "formula is unknown)", fontsize=9)
    p = ctx.figures_dir / "000_effort_vs_eulerint.png"
    common.save(fig, p, dpi=100)
    return Figure(f"figures/{p.name}", "Control effort against EULERINT for the three PD variants, MRAC, fuzzy PD "
                                       "and adaptive fuzzy, large command; left ∫Σ|τ|, right ∫‖τ‖².")


def fig_robust(ctx, ts) -> Figure:
    plt = common.plt()
    fig, axs = plt.subplots(2, 3, figsize=(13, 6.5), sharex=True)
    for j, (case, title) in enumerate(ROBUST_CASES.items()):
        for c, lab in ROBUST_CTRL.items():
            r = ts.get(f"{case}-{c}-L")
            if r is None:
                continue
            axs[0, j].plot(r["time"], r["alpha_deg"], label=lab)
            axs[1, j].plot(r["time"], np.degrees(r["yaw"]), label=lab)
        axs[1, j].axhline(-60.0, color="k", ls=":", lw=0.8, label="command")
        axs[0, j].set_title(title + ", command L", fontsize=9)
        axs[0, j].set_ylabel("Euler-axis error α [deg]")
        axs[1, j].set_ylabel("yaw (321) [deg]")
        axs[1, j].set_xlabel("time [s]")
        axs[0, j].set_yscale("log")
        axs[0, j].set_ylim(1e-3, 100)
        for a in axs[:, j]:
            a.grid(alpha=0.3)
    axs[0, 0].legend(fontsize=8)
    axs[1, 0].legend(fontsize=8)
    fig.suptitle("Paper 000 robustness (C000-7): PD, MRAC, fuzzy and adaptive fuzzy under a constant disturbance "
                 "and ±20 % inertia", fontsize=9)
    p = ctx.figures_dir / "000_robustness.png"
    common.save(fig, p, dpi=100)
    return Figure(f"figures/{p.name}", "Responses under the 10 N·m disturbance (R1) and the inertia uncertainty (R2): "
                                       "α(t) on a log scale (top) and the yaw angle (bottom), command L.")


def fig_sweep(ctx, base, sw, idx, rows, holds: dict) -> Figure:
    plt = common.plt()
    plotted = [r for r in sw["runs"] if r in L_RUNS]
    vals = sw["values"]
    cat = sw.get("categorical", False)
    x = np.arange(len(vals)) if cat else np.asarray(vals, float)
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    ei = None
    for j, r_ in enumerate(plotted):
        e_ = [r[EI] if r["status"] == "ok" else np.nan for r in rows[r_]]
        f_ = [r[EFF] if r["status"] == "ok" else np.nan for r in rows[r_]]
        ei = e_ if ei is None else [min(a, b) for a, b in zip(ei, e_)]
        axs[0].plot(x, e_, "o-", color=f"C{j}" if j else "C0", label=f"{_label(r_)} (swept)")
        axs[1].plot(x, f_, "o-", color=f"C{j}" if j else "C0", label=f"{_label(r_)} (swept)")
    return_refs = [("000-6", "PD quat"), ("000-9L", "MRAC"), ("000-10L", "fuzzy PD"), ("000-11L", "adaptive fuzzy"),
                   ("000-2", "PD Euler")]
    for k, lab in return_refs:
        if k in plotted:
            continue
        axs[0].axhline(base[k][EI], ls=":", lw=1, color=f"C{1 + return_refs.index((k, lab))}",
                       label=f"{lab} (default)")
    axs[1].axhline(EFFORT_RATIO * base["000-6"][EFF], ls="--", color="k", lw=1,
                   label=f"{EFFORT_RATIO} × effort of PD quat")
    axs[1].axhline(base["000-6"][EFF], ls=":", color="C1", lw=1, label="PD quat (default)")
    mk = {c: ("*" if i == 0 else "^" if i == 1 else "s" if i == 2 else "D") for i, c in enumerate(holds)}
    for i, (c, h) in enumerate(holds.items()):
        xs = [xx for xx, hh in zip(x, h) if hh]
        ys = [yy for yy, hh in zip(ei, h) if hh]
        if not xs:
            continue
        axs[0].scatter(xs, np.asarray(ys) * (0.93 - 0.05 * i), marker=mk[c], s=28, color=f"C{6 + i}",
                       label=f"{c} holds here")
    for a in axs:
        if cat:
            a.set_xticks(x)
            a.set_xticklabels([str(v) if not isinstance(v, tuple) else "\n".join(f"{e:.3g}" for e in v) for v in vals],
                              fontsize=7)
        elif min(vals) > 0 and max(vals) / min(vals) > 20:
            from matplotlib import ticker
            a.set_xscale("log")
            a.xaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            a.xaxis.set_minor_formatter(ticker.NullFormatter())
        elif min(vals) == 0 and len(vals) > 2 and max(vals) / min(v for v in vals if v > 0) > 20:
            a.set_xscale("symlog", linthresh=min(v for v in vals if v > 0))
        unit = sw.get("unit", "")
        a.set_xlabel(sw["param"] + (f" [{unit}]" if unit else ""))
        if sw.get("default") is not None:
            d = vals.index(sw["default"]) if cat else sw["default"]
            a.axvline(d, color="grey", lw=0.8, ls="-.", label="today's default")
        a.grid(alpha=0.3)
    axs[0].set_ylabel("EULERINT, command L [deg·s]")
    axs[1].set_ylabel("effort ∫Σ|τ| dt, command L [N·m·s]")
    axs[0].legend(fontsize=6.5)
    axs[1].legend(fontsize=6.5)
    fig.suptitle(f"Paper 000 sensitivity: {sw['param']} (other controllers at their defaults)", fontsize=9)
    p = ctx.figures_dir / f"000_sweep{idx:02d}.png"
    common.save(fig, p, dpi=100)
    return Figure(f"figures/{p.name}", f"EULERINT (left) and effort (right) of {', '.join(map(_label, plotted))} against {sw['param']}; "
                                       f"markers below the curve show where each claim's rule holds.")


def fig_joint(ctx, swa, swb, holds: dict) -> Figure:
    plt = common.plt()
    from matplotlib import ticker
    from matplotlib.colors import ListedColormap
    fig, axs = plt.subplots(1, len(holds), figsize=(3.6 * len(holds), 3.8), sharey=True)
    axs = np.atleast_1d(axs)
    xa, xb = np.asarray(swa["values"], float), np.asarray(swb["values"], float)
    for ax, (c, h) in zip(axs, holds.items()):
        ax.pcolormesh(xb, xa, h.astype(float), cmap=ListedColormap(["#f4c7c3", "#b7e1cd"]), vmin=0, vmax=1,
                      shading="nearest")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks([t for t in (0.5, 1, 2, 4, 8, 16) if xb[0] <= t <= xb[-1]])
        ax.set_yticks([t for t in (2, 3, 5, 10, 20, 40, 80) if xa[0] <= t <= xa[-1]])
        ax.xaxis.set_major_formatter(ticker.ScalarFormatter())
        ax.yaxis.set_major_formatter(ticker.ScalarFormatter())
        ax.xaxis.set_minor_formatter(ticker.NullFormatter())
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())
        ax.plot([swb["default"]], [swa["default"]], "k*", ms=10, label="today's defaults")
        ax.set_title(f"{c}: green = holds", fontsize=9)
        ax.set_xlabel("adaptive-fuzzy λ-range scale s [-]")
    axs[0].set_ylabel("fuzzy PD reference settling time T_r [s]")
    axs[0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Paper 000: where each claim holds when T_r (fuzzy PD) and the λ ranges (adaptive fuzzy) change "
                 "together", fontsize=9)
    p = ctx.figures_dir / "000_joint_tr_lambda.png"
    common.save(fig, p, dpi=100)
    return Figure(f"figures/{p.name}", "Regions (green) where C000-4 … C000-7 hold on the grid of the fuzzy PD's T_r "
                                       "and the adaptive-fuzzy λ-range scale, other readings at their defaults.")


