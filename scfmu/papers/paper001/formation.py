"""Paper 001 experiments: leader-follower formation control with the
nonlinear predictive PID.

Loop (Gauss-Seidel, wired by port name): RelativePositionCommand -> PredictivePidController ->
RelativeOrbitPlant. Plant defaults (a = 6000 km, e = 0, m = 100 kg, mu = 3.986004418e14), follower at
the origin at rest, step command (50, 40, 60) m at t = 0 with zero reference velocity/acceleration,
RK4 internal step = Δ. Cases 001-a..d: T1 = 0, (T2, c) = (5, 5), (25, 5), (25, 25), (25, 150), each
without disturbance and with dist = 0.01 N on every axis (optionally also 1 N, the alternative reading
d = 0.01 m/s², with --alt).

Prints per case and axis: 2 % settling time, overshoot, peak |F_i|, ∫|F_i| dt, steady-state error (mean
|e_i| over the last 10 %), final dist_est_i; and per run ∫Σ|F_i| dt, ∫‖F‖² dt (left rectangle on the
communication grid). Writes out/paper001/summary.csv, one CSV per run (decimated to --csv-every
samples) and PNGs (tracking, error, F_z, estimated vs true disturbance; plus a four-case comparison).

Usage: scfmu paper 001 formation [--dt 0.001] [--t-end 300] [--alt] [--cases a,b,c,d]
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

import numpy as np

from . import scenarios
from ...engines.native import NativeLoop
from ...metrics import formation as formation_metrics
from ...results import write_csv

AX = "xyz"
CASES = scenarios.PAPER001_CASES
REF = scenarios.PAPER001_REF


def run_case(t2: float, c: float, dist: float, dt: float, t_end: float) -> dict[str, np.ndarray]:
    """The set-up is scenarios.paper001 (one declaration for every script and campaign), run on the native
    path (the loop inside fmpy's container FMU; bit-identical to the reference master, about 3x faster
    than the lean master for 300,000 steps); (T2, c) may differ from the four named cases."""
    sc = scenarios.paper001("a", dist, t_end, dt).with_overrides({"controller.T2": t2, "controller.c": c})
    with NativeLoop(sc) as m:
        gains = {k: m.get(f"controller.{k}") for k in ("K1", "K2", "P_x", "D_x", "I_g_x")}
        out = m.run()
    out["gains"] = gains
    return out


def metrics(out: dict, dist: float, dt: float) -> dict:
    """The per-axis and per-run numbers this command prints, taken from the ``formation`` metric set (the
    same function the campaigns and the report use), under this command's column names."""
    m = {}
    f = formation_metrics(out)
    for a in AX:
        m[f"settling_{a}"] = f[f"settling_{a}_s"]
        m[f"overshoot_{a}"] = f[f"overshoot_{a}_pct"]
        m[f"peak_F_{a}"] = f[f"peak_force_{a}"]
        m[f"int_abs_F_{a}"] = f[f"effort_abs_{a}"]
        m[f"sse_{a}"] = f[f"sse_{a}_m"]
        m[f"dist_est_end_{a}"] = f[f"dist_est_end_{a}"]
    m["int_sum_abs_F"] = f["effort_abs"]
    m["int_F2"] = f["effort_sq"]
    m["dist"] = dist
    return m


def write_run_csv(path: Path, out: dict, every: int) -> None:
    keys = ["time"] + [f"{k}_{a}" for k in ("pos", "pos_ref", "vel", "force", "dist_est") for a in AX]
    write_csv(path, out, keys, every, ".10g")


def plot_run(path: Path, title: str, out: dict, dist: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = out["time"]
    fig, axs = plt.subplots(4, 1, figsize=(9, 12), sharex=True)
    for i, a in enumerate(AX):
        line, = axs[0].plot(t, out[f"pos_{a}"], label=f"{a}")
        axs[0].plot(t, out[f"pos_ref_{a}"], "--", color=line.get_color(), lw=0.8)
        axs[1].plot(t, out[f"pos_ref_{a}"] - out[f"pos_{a}"], label=f"e_{a}")
        axs[3].plot(t, out[f"dist_est_{a}"], label=f"dist_est_{a}")
    axs[0].set_ylabel("position [m] (dashed: reference)")
    axs[1].set_ylabel("error ref - pos [m]")
    axs[1].set_yscale("symlog", linthresh=1e-3)
    axs[2].plot(t, out["force_z"], color="C2", label="F_z")
    axs[2].set_ylabel("F_z [N]")
    axs[2].set_yscale("symlog", linthresh=1e-2)
    axs[3].axhline(dist, color="k", ls="--", lw=0.8, label=f"true dist = {dist} N")
    axs[3].set_yscale("symlog", linthresh=1e-3)
    axs[3].set_ylabel("disturbance [N]")
    axs[3].set_xlabel("time [s]")
    for ax in axs:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axs[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_compare(path: Path, runs: dict, dist: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(3, 1, figsize=(9, 10), sharex=True)
    for name, out in runs.items():
        t2, c = CASES[name]
        lab = f"001-{name}: T2 = {t2:g} s, c = {c:g} 1/s"
        axs[0].plot(out["time"], out["pos_z"], label=lab)
        axs[1].plot(out["time"], out["force_z"], label=lab)
        axs[2].plot(out["time"], out["dist_est_z"], label=lab)
    axs[0].axhline(REF[2], color="k", ls="--", lw=0.8)
    axs[0].set_ylabel("pos_z [m]")
    axs[1].set_ylabel("F_z [N]")
    axs[1].set_yscale("symlog", linthresh=1e-2)
    axs[2].axhline(dist, color="k", ls="--", lw=0.8)
    axs[2].set_ylabel("dist_est_z [N]")
    axs[2].set_yscale("symlog", linthresh=1e-3)
    axs[2].set_xlabel("time [s]")
    for ax in axs:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axs[0].set_title(f"Paper 001, four cases, dist = {dist} N per axis")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dt", type=float, default=0.001, help="communication step = RK4 step [s] (paper: 0.001)")
    ap.add_argument("--t-end", type=float, default=300.0, help="simulated time [s] (paper: 300)")
    ap.add_argument("--alt", action="store_true", help="also run dist = 1 N (reading d = 0.01 m/s^2)")
    ap.add_argument("--cases", default="a,b,c,d")
    ap.add_argument("--csv-every", type=int, default=100, help="write every n-th sample to the per-run CSV")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--out", type=Path, default=Path("out") / "paper001", help="output folder")
    args = ap.parse_args(argv)

    out_dir = args.out
    out_dir.mkdir(parents=True, exist_ok=True)
    dists = [0.0, 0.01] + ([1.0] if args.alt else [])
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    print(f"Paper 001 formation runs: Δ = RK4 step = {args.dt} s, t_end = {args.t_end} s; RelativeOrbitPlant "
          f"defaults (mu = 3.986004418e14 m^3/s^2, a = 6.0e6 m, e = 0, m = 100 kg), start at rest at the origin; "
          f"RelativePositionCommand step to {REF} m at t = 0; PredictivePidController T1 = 0, m = 100 kg, structure 0.")
    rows = []
    for dist in dists:
        runs = {}
        for name in cases:
            t2, c = CASES[name]
            if c * args.dt > 0.2:
                print(f"warning: c Δ = {c * args.dt:g} is not << 1 for case {name}")
            t0 = time.time()
            out = run_case(t2, c, dist, args.dt, args.t_end)
            wall = time.time() - t0
            m = metrics(out, dist, args.dt)
            g = out["gains"]
            tag = f"001-{name}_dist{dist:g}N"
            print(f"\n{tag}: T2 = {t2:g} s, c = {c:g} 1/s, dist = {dist:g} N per axis "
                  f"(K1 = {g['K1']:.6g}, K2 = {g['K2']:.6g}, P = {g['P_x']:.6g}, D = {g['D_x']:.6g}, "
                  f"I_g = {g['I_g_x']:.6g}; wall time {wall:.1f} s)")
            print("  axis  settling[s]  overshoot[%]   peak|F|[N]  int|F|dt[N s]  ss-error[m]   dist_est_end[N]")
            for a in AX:
                print(f"  {a}    {m[f'settling_{a}']:10.3f}  {m[f'overshoot_{a}']:12.4f}  {m[f'peak_F_{a}']:11.5g}  "
                      f"{m[f'int_abs_F_{a}']:13.6g}  {m[f'sse_{a}']:11.3e}   {m[f'dist_est_end_{a}']:.9g}")
            print(f"  int sum|F_i| dt = {m['int_sum_abs_F']:.6g} N s, int |F|^2 dt = {m['int_F2']:.6g} N^2 s")
            rows.append({"run": tag, "T1": 0.0, "T2": t2, "c": c, "dt": args.dt, "t_end": args.t_end,
                         **{k: g[k] for k in ("K1", "K2", "P_x", "D_x", "I_g_x")}, **m, "wall_s": wall})
            write_run_csv(out_dir / f"{tag}.csv", out, args.csv_every)
            if not args.no_plots:
                plot_run(out_dir / f"{tag}.png", f"{tag}: T2 = {t2:g} s, c = {c:g} 1/s, Δ = {args.dt} s", out, dist)
            runs[name] = out
        if not args.no_plots:
            plot_compare(out_dir / f"compare_dist{dist:g}N.png", runs, dist)
    with (out_dir / "summary.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"\nwrote {out_dir}/summary.csv, per-run CSV (every {args.csv_every}th sample) and PNGs")


if __name__ == "__main__":
    main()
