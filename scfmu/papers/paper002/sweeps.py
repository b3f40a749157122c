"""Paper 002 experiments 002-1 … 002-6 (002-7 with --digits): the four tuned controllers (PD, PID,
FOPD, FOPID; gains from the package data file paper002/data/gains.json, fixed in every sweep) on SingleAxisPlant.

Nominal: J = 7.7 kg m², K = 1, T = 0.2 s, T_sat = 1 N m, M_d = 0.01 sin(0.1 t) + 0.0001 N m, θ_ref = 30°
step at t = 0, explicit Euler, h = Δ = 1 ms, t_end = 20 s, full GL memory.

  002-1  step responses θ(t), ω(t): PD vs FOPD, PID vs FOPID
  002-2  phase planes θ vs ω, same pairs
  002-3  MAE vs inertia_scale ∈ {0.80, 0.85, …, 1.20}
  002-4  MAE vs wheel time constant T ∈ {0.10, 0.15, 0.20, 0.25, 0.30, 0.40} s
  002-5  MAE vs disturbance factor (md_amp and md_const × {0, 0.5, 1, 2, 5, 10})
  002-6  MAE vs θ_ref ∈ {10, 20, 30, 40, 50}°
  002-7  (--digits) MAE for the damaged-digit candidates of the paper's plant, J ∈ {7.7, 7.9, 9.7, 9.9} kg m²
         × wheel gain K ∈ {1, 3, 5}, gains fixed (tuned at J = 7.7, K = 1); 002-7.csv has one row per
         (J, K), 002-7.png one panel of MAE vs J per K

MAE = mean |θ_ref - θ_n| in degrees over n < N = t_end/h. Writes out/paper002/<run>.csv and .png, and
out/paper002/summary.csv (run, swept value, MAE per controller), and prints the summary table.
Every run is one call of scfmu.paper002.run_case, mapped over a process pool.

Usage: scfmu paper 002 sweeps [--workers 2] [--quick] [--digits] [--gains FILE] [--out DIR]
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

from .model import CONTROLLERS, GAINS_FILE, Scenario, load_gains, run_case, step_metrics
from ...results import write_csv

NAMES = list(CONTROLLERS)
MD_AMP, MD_CONST = 0.01, 0.0001
DIGITS_J, DIGITS_K = (7.7, 7.9, 9.7, 9.9), (1.0, 3.0, 5.0)  # run 002-7


def sweeps(quick: bool, digits: bool) -> dict[str, tuple[str, list[tuple[float, Scenario]]]]:
    base = Scenario(t_end=12.0) if quick else Scenario()
    s = {
        "002-3": ("inertia_scale", [(x, replace(base, plant={"inertia_scale": x}))
                                    for x in np.round(np.arange(0.80, 1.2001, 0.05), 2)]),
        "002-4": ("wheel_time_constant_s", [(x, replace(base, plant={"wheel_time_constant": x}))
                                            for x in (0.10, 0.15, 0.20, 0.25, 0.30, 0.40)]),
        "002-5": ("disturbance_factor", [(x, replace(base, plant={"md_amp": MD_AMP * x, "md_const": MD_CONST * x}))
                                         for x in (0.0, 0.5, 1.0, 2.0, 5.0, 10.0)]),
        "002-6": ("theta_ref_deg", [(x, replace(base, theta_ref_deg=x)) for x in (10.0, 20.0, 30.0, 40.0, 50.0)]),
    }
    if digits:
        # damaged digits of the paper: inertia J and wheel gain K candidates (gains stay those tuned at
        # J = 7.7, K = 1)
        s["002-7"] = ("J_K", [((j, k), replace(base, plant={"inertia": j, "wheel_gain": k}))
                              for k in DIGITS_K for j in DIGITS_J])
    if quick:
        s = {k: (n, [pts[0], pts[-1]]) for k, (n, pts) in s.items()}
    return s


def _job(args):
    c, gains, sc, record = args
    return run_case(c, gains, sc, record=record)


def _nominal(out: Path, nominal: dict, base: Scenario, plt) -> list:
    """002-1 / 002-2: the nominal time series and phase planes (CSV + PNG) and the nominal metrics
    (002-1_nominal_metrics.csv); returns the metric rows."""
    # 002-1 / 002-2: time series and phase planes
    sig = {"time": nominal[NAMES[0]]["t"]}
    for c in NAMES:
        for k in ("theta", "omega", "u", "applied_torque"):
            sig[f"{k}_{c}"] = nominal[c][k]
    write_csv(out / "002-1_step_responses.csv", sig, every=10)
    pairs = [("PD", "FOPD"), ("PID", "FOPID")]
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for col, pair in enumerate(pairs):
        for c in pair:
            r = nominal[c]
            ax[0, col].plot(r["t"], np.degrees(r["theta"]), label=c)
            ax[1, col].plot(r["t"], np.degrees(r["omega"]), label=c)
        ax[0, col].axhline(base.theta_ref_deg, color="k", lw=0.6, ls="--", label="θ_ref")
        ax[0, col].set_ylabel("θ (deg)")
        ax[1, col].set_ylabel("ω (deg/s)")
        ax[1, col].set_xlabel("time (s)")
        ax[0, col].set_title(f"002-1: {pair[0]} vs {pair[1]}")
        for r_ in ax[:, col]:
            r_.legend()
            r_.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "002-1_step_responses.png", dpi=120)
    plt.close(fig)
    write_csv(out / "002-2_phase_plane.csv", {k: v for k, v in sig.items() if not k.startswith(("u_", "applied"))}, every=10)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    for col, pair in enumerate(pairs):
        for c in pair:
            r = nominal[c]
            ax[col].plot(np.degrees(r["theta"]), np.degrees(r["omega"]), label=c)
        ax[col].set_xlabel("θ (deg)")
        ax[col].set_ylabel("ω (deg/s)")
        ax[col].set_title(f"002-2 phase plane: {pair[0]} vs {pair[1]}")
        ax[col].legend()
        ax[col].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "002-2_phase_plane.png", dpi=120)
    plt.close(fig)

    nom_rows = []
    for c in NAMES:
        m = step_metrics(nominal[c]["t"], nominal[c]["theta"], base)
        nom_rows.append([c, nominal[c]["mae_deg"], m["overshoot_pct"], m["settling_s"], nominal[c]["late_max_deg"]])
    with open(out / "002-1_nominal_metrics.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["controller", "mae_deg", "overshoot_pct", "settling_2pct_s", "max_abs_error_after_10s_deg"])
        w.writerows(nom_rows)

    return nom_rows


def _sweep(out: Path, run: str, xname: str, rows: list, base: Scenario, plt) -> None:
    """One sweep's CSV and figure (002-7: one panel per wheel gain, MAE vs inertia)."""
    with open(out / f"{run}.csv", "w", newline="") as f:
        w = csv.writer(f)
        if run == "002-7":
            w.writerow(["inertia_kg_m2", "wheel_gain", *[f"mae_deg_{c}" for c in NAMES]])
            w.writerows([[x[0], x[1], *m] for x, *m in rows])
        else:
            w.writerow([xname, *[f"mae_deg_{c}" for c in NAMES]])
            w.writerows(rows)
    arr = np.array([r[1:] for r in rows], float)
    if run == "002-7":  # one panel per wheel gain K, MAE vs J
        ks = sorted({x[1] for x, *_ in rows})
        fig, axs = plt.subplots(1, len(ks), figsize=(4.2 * len(ks), 4.2), squeeze=False)
        for ax, k in zip(axs[0], ks):
            sel = [i for i, r in enumerate(rows) if r[0][1] == k]
            js = [rows[i][0][0] for i in sel]
            for i, c in enumerate(NAMES):
                ax.plot(js, arr[sel, i], marker="o", ls="-" if c.startswith("FO") else "--", label=c)
            ax.set_xlabel("inertia J (kg m²)")
            ax.set_ylabel("MAE (deg)")
            ax.set_title(f"002-7: wheel gain K = {k:g}")
            ax.legend()
            ax.grid(alpha=0.3)
        fig.suptitle(f"002-7: damaged-digit candidates, gains tuned at J = 7.7, K = 1 (MAE over [0, {base.t_end:g}) s)")
        fig.tight_layout()
        fig.savefig(out / f"{run}.png", dpi=120)
        plt.close(fig)
        return
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    xs = np.array([r[0] for r in rows], float)
    for i, c in enumerate(NAMES):
        ax.plot(xs, arr[:, i], marker="o", ls="-" if c.startswith("FO") else "--", label=c)
    ax.set_xlabel({"inertia_scale": "inertia scale J_true/J (-)", "wheel_time_constant_s": "wheel time constant T (s)",
                   "disturbance_factor": "disturbance factor (-)", "theta_ref_deg": "θ_ref (deg)"}[xname])
    ax.set_ylabel("MAE (deg)")
    ax.set_title(f"{run}: MAE over [0, {base.t_end:g}) s")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / f"{run}.png", dpi=120)
    plt.close(fig)



def _summary(out: Path, nom_rows: list, summary: list, base: Scenario) -> None:
    """summary.csv and the printed table."""
    with open(out / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "swept", "value", *[f"mae_deg_{c}" for c in NAMES]])
        w.writerow(["nominal", "-", "-", *[r[1] for r in nom_rows]])
        w.writerows(summary)
    print(f"nominal (t_end {base.t_end:g} s, h {base.h:g} s): controller, MAE deg, overshoot %, 2% settling s")
    for r in nom_rows:
        print(f"  {r[0]:6s} {r[1]:9.5f} {r[2]:8.3f} {r[3]:8.3f}")
    print(f"{'run':6s} {'swept':22s} {'value':>9s} " + " ".join(f"{c:>9s}" for c in NAMES) + "   best")
    for r in summary:
        best = NAMES[int(np.argmin(r[3:]))]
        print(f"{r[0]:6s} {r[1]:22s} {r[2]!s:>9.9s} " + " ".join(f"{v:9.5f}" for v in r[3:]) + f"   {best}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--quick", action="store_true", help="CI: t_end 12 s, first and last point of each sweep")
    ap.add_argument("--digits", action="store_true", help="also run 002-7 (damaged-digit candidates)")
    ap.add_argument("--gains", type=Path, default=GAINS_FILE)
    ap.add_argument("--out", type=Path, default=Path("out") / "paper002")
    a = ap.parse_args(argv)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from tqdm import tqdm

    out = a.out
    out.mkdir(parents=True, exist_ok=True)
    gains = load_gains(a.gains)
    missing = [c for c in NAMES if c not in gains]
    if missing:
        print(f"no tuned gains for {missing} in {a.gains}: run `scfmu paper 002 tune` first", file=sys.stderr)
        return 2
    base = Scenario(t_end=12.0) if a.quick else Scenario()
    t0 = time.perf_counter()
    plan = sweeps(a.quick, a.digits)
    jobs = [(c, gains[c], base, True) for c in NAMES]
    for run, (_, pts) in plan.items():
        jobs += [(c, gains[c], sc, False) for _, sc in pts for c in NAMES]
    with ProcessPoolExecutor(a.workers) as pool:
        results = list(tqdm(pool.map(_job, jobs), total=len(jobs), desc="paper 002 runs"))
    nominal = dict(zip(NAMES, results[: len(NAMES)]))
    rest = iter(results[len(NAMES):])

    summary = []
    nom_rows = _nominal(out, nominal, base, plt)
    for run, (xname, pts) in plan.items():
        rows = []
        for x, _ in pts:
            mae = [next(rest)["mae_deg"] for _ in NAMES]
            rows.append([x, *mae])
            summary.append([run, xname, f"J={x[0]:g} K={x[1]:g}" if run == "002-7" else x, *mae])
        _sweep(out, run, xname, rows, base, plt)
    _summary(out, nom_rows, summary, base)
    print(f"{len(jobs)} runs in {time.perf_counter() - t0:.1f} s ({a.workers} workers) -> {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
