"""Paper 000 study: PD with each kinematics option, every
controller on the large command, and the robustness runs (constant disturbance, inertia uncertainty).

Setup: AttitudePlant inertia diag(1000, 500, 700) kg m², actuator_mode 0 without limits, RK4 0.01 s,
communication step Δ = 0.01 s, t_end = 30 s; AttitudeCommand steps at t = 0 (321 angles):
S = (4, -4, -6) deg, L = (40, -40, -60) deg, L2 = (40, 40, 60) deg. Controllers use their default
parameters (paper 000 / project choices of controllers.md §1) unless the run table says otherwise.

Each run is AttitudeCommand + <controller> + AttitudePlant + AttitudeMetrics wired by port name; the
controller is chosen by FMU name only. Prints one table (EULERINT, effort_abs, effort_sq, settling time
and overshoot per Euler angle) and writes out/paper000/summary.csv, one CSV of signals per run and PNG
figures (Euler angles, α, torques per run; comparison figures per command).

Runs whose plant kinematics mode is not available in the built AttitudePlant are listed as skipped.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from pathlib import Path


import numpy as np

from ...fmu import Fmu
from . import scenarios
from ...metrics import attitude as attitude_metrics
from ...results import write_csv
from ...engines import simulate as run_scenario

COMMANDS = scenarios.COMMANDS
KIN_NAMES = scenarios.KIN_NAMES
ANGLES = ["roll", "pitch", "yaw"]
Run = scenarios.Paper000Run
CSV_KEYS = ["time", "roll", "pitch", "yaw", "w_x", "w_y", "w_z", "torque_applied_x", "torque_applied_y",
            "torque_applied_z", "alpha_deg", "eulerint_deg_s", "effort_abs", "effort_sq"]


def run_table() -> list[Run]:
    return scenarios.paper000_runs()


def plant_supports(kinematics: int) -> bool:
    try:
        Fmu("AttitudePlant", {"kinematics": kinematics}).close()
        return True
    except Exception:
        return False


def simulate(run: Run, t_end: float, dt: float) -> dict:
    """The set-up is scenarios.paper000(run_id) (one declaration for every script and campaign)."""
    return run_scenario(scenarios.paper000(run.run_id, t_end, dt), "lean")


def summarize(run: Run, r: dict) -> dict:
    """The study's row, from the ``attitude`` metric set (the function the campaigns and the report use)."""
    m = attitude_metrics(r)
    row = {"run": run.run_id, "controller": run.controller, "label": run.label, "kinematics": run.kinematics,
           "command": run.command, "eulerint_deg_s": m["eulerint_deg_s"], "effort_abs_Nms": m["effort_abs"],
           "effort_sq_N2m2s": m["effort_sq"], "alpha_end_deg": m["final_error"]}
    for ang in ANGLES:
        row[f"ts_{ang}_s"] = m[f"settling_{ang}_s"]
        row[f"os_{ang}_pct"] = m[f"overshoot_{ang}_pct"]
    return row


def plot_run(path: Path, run: Run, r: dict, row: dict) -> None:
    import matplotlib.pyplot as plt
    t = r["time"]
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    for ang, ref in zip(ANGLES, COMMANDS[run.command]):
        line, = ax[0].plot(t, np.degrees(r[ang]), label=ang)
        ax[0].axhline(math.degrees(ref), color=line.get_color(), ls=":", lw=0.8)
    ax[0].set_ylabel("321 angle [deg]")
    ax[0].legend(fontsize=8)
    ax[1].plot(t, r["alpha_deg"])
    ax[1].set_ylabel("α [deg]")
    for a in "xyz":
        ax[2].plot(t, r[f"torque_applied_{a}"], label=f"τ_{a}")
    ax[2].set_ylabel("torque [N·m]")
    ax[2].set_xlabel("time [s]")
    ax[2].legend(fontsize=8)
    fig.suptitle(f"{run.run_id}: {run.label}, kinematics {run.kinematics}, command {run.command}, "
                 f"EULERINT {row['eulerint_deg_s']:.1f} deg·s", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_comparison(path: Path, title: str, items: list[tuple[str, dict]]) -> None:
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(5, 1, figsize=(8, 12), sharex=True)
    for label, r in items:
        t = r["time"]
        for i, ang in enumerate(ANGLES):
            ax[i].plot(t, np.degrees(r[ang]), label=label)
        ax[3].plot(t, r["alpha_deg"], label=label)
        ax[4].plot(t, np.sqrt(sum(r[f"torque_applied_{a}"] ** 2 for a in "xyz")), label=label)
    for i, ang in enumerate(ANGLES):
        ax[i].set_ylabel(f"{ang} [deg]")
    ax[3].set_ylabel("α [deg]")
    ax[4].set_ylabel("|τ| [N·m]")
    ax[4].set_xlabel("time [s]")
    ax[0].legend(fontsize=7, ncol=3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


COLUMNS = [("run", "{:<20s}", 20), ("label", "{:<10s}", 10), ("kin", "{:>3d}", 3), ("cmd", "{:<3s}", 3),
           ("EULERINT", "{:>9.2f}", 9), ("eff_abs", "{:>9.1f}", 9), ("eff_sq", "{:>10.4g}", 10),
           ("ts_r", "{:>6.2f}", 6), ("ts_p", "{:>6.2f}", 6), ("ts_y", "{:>6.2f}", 6),
           ("OS_r%", "{:>6.2f}", 6), ("OS_p%", "{:>6.2f}", 6), ("OS_y%", "{:>6.2f}", 6)]


def table_line(row: dict) -> str:
    vals = [row["run"], row["label"], row["kinematics"], row["command"], row["eulerint_deg_s"], row["effort_abs_Nms"],
            row["effort_sq_N2m2s"], row["ts_roll_s"], row["ts_pitch_s"], row["ts_yaw_s"], row["os_roll_pct"],
            row["os_pitch_pct"], row["os_yaw_pct"]]
    return " ".join(fmt.format(v) for (_, fmt, _), v in zip(COLUMNS, vals))


def _print_table(rows: list, skipped: list, args) -> None:
    """The study's table on stdout, the skipped runs, and the L vs L2 mirror-symmetry check."""
    print(f"Paper 000 study: Δ = {args.dt} s, t_end = {args.t_end} s, plant RK4 0.01 s, inertia diag(1000, 500, 700), "
          f"no torque limit; controllers at default parameters unless noted")
    print("EULERINT [deg·s], eff_abs = ∫Σ|τ| [N·m·s], eff_sq = ∫‖τ‖² [N²·m²·s], ts = 2 % settling time [s] "
          "(nan = not settled by t_end), OS = overshoot [%] per 321 angle")
    print("R1 = 10 N·m constant disturbance on each axis; R2-s = plant inertia_scale s on every axis")
    header = " ".join(f"{name:>{w}s}" if not fmt.startswith("{:<") else f"{name:<{w}s}" for name, fmt, w in COLUMNS)
    print(header)
    print("-" * len(header))
    for row in rows:
        print(table_line(row))
    for s in skipped:
        print(f"skipped: {s}")
    # L2 = (40, 40, 60) deg is the mirror image of L = (40, -40, -60) deg under the 180 deg rotation
    # about x (q -> (q_w, q_x, -q_y, -q_z)), a symmetry of the diagonal-inertia plant and of every law
    # here; without a disturbance the metrics of L and L2 must agree (R1's +10 N m breaks the symmetry).
    by_id = {row["run"]: row for row in rows}
    diffs = []
    for rid, row in by_id.items():
        if row["command"] == "L" and not rid.startswith("R1"):
            twin = by_id.get(rid[:-1] + "L2") if rid.endswith("L") else None
            if twin:
                diffs.append(abs(row["eulerint_deg_s"] - twin["eulerint_deg_s"]) / row["eulerint_deg_s"])
    if diffs:
        print(f"L vs L2 (no disturbance, {len(diffs)} pairs): max relative EULERINT difference {max(diffs):.2e} "
              f"(mirror symmetry)")


def _write_summary(out: Path, rows: list, results: dict, plots: bool) -> None:
    """summary.csv and, with `plots`, the comparison figures."""
    with open(out / "summary.csv", "w", newline="") as f:
        if rows:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    if plots:
        for cmd in ("L", "L2"):
            items = [(f"{row['run']} {row['label']}", results[row["run"]]) for row in rows
                     if row["command"] == cmd and row["run"].startswith("000-")]
            if items:
                plot_comparison(out / f"compare_000_{cmd}.png", f"Paper 000 controllers, command {cmd}", items)
        for prefix, title in (("R1", "R1: 10 N·m disturbance"), ("R2-1.2", "R2: inertia ×1.2"), ("R2-0.8", "R2: inertia ×0.8")):
            for cmd in ("L", "L2"):
                items = [(row["label"], results[row["run"]]) for row in rows
                         if row["run"].startswith(prefix) and row["command"] == cmd]
                if items:
                    plot_comparison(out / f"compare_{prefix}_{cmd}.png", f"{title}, command {cmd}", items)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/paper000")
    ap.add_argument("--t-end", type=float, default=30.0)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--only", default="", help="comma-separated run-id prefixes (default: all)")
    ap.add_argument("--no-plots", action="store_true")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if not args.no_plots:
        import matplotlib
        matplotlib.use("Agg")

    runs = run_table()
    if args.only:
        prefixes = [p.strip() for p in args.only.split(",") if p.strip()]
        runs = [r for r in runs if any(r.run_id.startswith(p) for p in prefixes)]
    available = {k: plant_supports(k) for k in sorted({r.kinematics for r in runs})}

    t0 = time.time()
    rows, skipped, results = [], [], {}
    for run in runs:
        if not available[run.kinematics]:
            skipped.append(f"{run.run_id} ({run.label}, kinematics {run.kinematics} {KIN_NAMES[run.kinematics]} "
                           f"not available in this AttitudePlant)")
            continue
        r = simulate(run, args.t_end, args.dt)
        row = summarize(run, r)
        rows.append(row)
        results[run.run_id] = r
        write_csv(out / f"{run.run_id}.csv", r, CSV_KEYS)
        if not args.no_plots:
            plot_run(out / f"{run.run_id}.png", run, r, row)

    _print_table(rows, skipped, args)
    print(f"({len(rows)} runs in {time.time() - t0:.1f} s)")

    _write_summary(out, rows, results, not args.no_plots)
    print(f"wrote {out}/summary.csv, one CSV per run" + ("" if args.no_plots else " and PNG figures"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
