"""Paper 004 cases: feedback-linearising attitude control of a spacecraft whose actuators lose 90 % of
their effectiveness, and its repair by reference correction with an optimised open-loop spline.

Runs (AttitudePlant, FeedbackLinearizingController k_q = 0.5, k_qdot = 2, ReferenceCorrector; RK4
0.01 s, communication step 0.01 s, t_f = 20 s; initial rest at 321 (yaw, pitch, roll) = (6, -4, 8) deg):
  004-1    healthy actuators (10 N m), reference = identity (corrector mode 0)
  004-2    faulty actuators (1 N m), reference = identity
  004-3ol  faulty, the optimised spline torque applied open loop
  004-3    faulty, corrector mode 1 with the optimised nodes (reference corrected)
  004-X-*  the same four runs from (15, -10, 20) deg, where the optimisation must report infeasible
Each run: terminal max|w_i| (deg/s) and max|roll, pitch, yaw| (deg) at t_f, pass/fail against
0.01 deg/s and 0.1 deg; the optimiser status, evaluations and objective. Writes summary.csv, one CSV
per run and one PNG per run (rates, 321 angles, torques) plus a comparison figure to --out.

--nodes uses a saved optimisation (JSON of `scfmu paper 004 optimize`) for the default initial
state instead of optimising again; --quick skips the plots and the 004-X runs.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path


import numpy as np

from . import model as P
from ...fmu import fmu_dir
from ...results import write_csv

ANG = ["roll", "pitch", "yaw"]


def terminal(r: dict) -> dict:
    w = np.array([r[f"w_{a}"][-1] for a in P.AXES])
    e = np.array([r[n][-1] for n in ANG])
    return P.terminal_metrics(w, e)


def plot_run(path: Path, run_id: str, r: dict, row: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = r["time"]
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for a in P.AXES:
        ax[0].plot(t, np.degrees(r[f"w_{a}"]), label=f"w_{a}")
    ax[0].set_ylabel("body rate (deg/s)")
    for n in ANG:
        ax[1].plot(t, np.degrees(r[n]), label=n)
    ax[1].set_ylabel("321 angle (deg)")
    for a in P.AXES:
        ax[2].plot(t, r[f"torque_applied_{a}"], label=f"applied {a}")
    ax[2].set_ylabel("torque (N m)")
    ax[2].set_xlabel("time (s)")
    for x in ax:
        x.grid(True, alpha=0.3)
        x.legend(loc="upper right", fontsize=8)
    verdict = "PASS" if row["pass"] else "FAIL"
    fig.suptitle(f"{run_id}: terminal max|w| = {row['w_end_max_deg_s']:.4g} deg/s, "
                 f"max|Euler| = {row['euler_end_max_deg']:.4g} deg ({verdict})", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_compare(path: Path, runs: dict, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for rid, r in runs.items():
        t = r["time"]
        ang = np.degrees(np.sqrt(sum(r[n] ** 2 for n in ANG)))
        w = np.degrees(np.sqrt(sum(r[f"w_{a}"] ** 2 for a in P.AXES)))
        ax[0].semilogy(t, np.maximum(ang, 1e-6), label=rid)
        ax[1].semilogy(t, np.maximum(w, 1e-7), label=rid)
    ax[0].axhline(P.EULER_REQ_DEG, color="k", ls=":", label="0.1 deg")
    ax[1].axhline(P.W_REQ_DEG_S, color="k", ls=":", label="0.01 deg/s")
    ax[0].set_ylabel("|(roll, pitch, yaw)| (deg)")
    ax[1].set_ylabel("|w| (deg/s)")
    ax[1].set_xlabel("time (s)")
    for x in ax:
        x.grid(True, which="both", alpha=0.3)
        x.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_set(prefix: str, init: dict, nodes_json: Path | None) -> tuple[dict, dict, P.OptResult | None, dict]:
    runs = {}
    runs[f"{prefix}1"] = P.run_closed_loop(0, 1.0, init)
    runs[f"{prefix}2"] = P.run_closed_loop(0, P.A_FAULT, init)
    opt = None
    if nodes_json is not None:
        rep = json.loads(nodes_json.read_text())
        nodes = np.array([rep["nodes_N_m"][a] for a in P.AXES])
        o = rep["optimiser"]
        info = {"status": o["status"], "evaluations": o["evaluations"], "objective": o["objective_N2m2s"],
                "source": str(nodes_json)}
    else:
        # case-2 torque at the node times as the initial guess (the run above)
        lim = P.A_FAULT * P.U_MAX
        idx = [int(round(t / P.DT)) for t in P.NODE_TIMES[:-1]]
        x0 = np.concatenate([np.clip(runs[f"{prefix}2"][f"torque_applied_{a}"][idx], -lim, lim) for a in P.AXES])
        opt = P.optimise(init, x0=x0)
        nodes = opt.nodes
        info = {"status": opt.status, "evaluations": opt.evaluations, "objective": opt.objective, "source": "optimised now"}
    runs[f"{prefix}3ol"] = P.run_open_loop(nodes, P.A_FAULT, init)
    runs[f"{prefix}3"] = P.run_closed_loop(1, P.A_FAULT, init, nodes=nodes)
    return runs, info, opt, {"nodes": nodes}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out/paper004"))
    ap.add_argument("--nodes", type=Path, default=None, help="saved optimisation JSON for the default initial state")
    ap.add_argument("--quick", action="store_true", help="no plots, no 004-X runs")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"FMUs from {fmu_dir()}; dt = {P.DT} s, t_f = {P.T_F} s, RK4 {P.DT} s, I = diag{P.INERTIA} kg m^2, "
          f"u_max = {P.U_MAX} N m, faulty effectiveness {P.A_FAULT}, k_q = {P.K_Q}, k_qdot = {P.K_QDOT}")
    sets = [("004-", P.INIT_DEFAULT_DEG, args.nodes)]
    if not args.quick:
        sets.append(("004-X-", P.INIT_STRESS_DEG, None))
    rows, all_runs = [], {}
    for prefix, init, nodes_json in sets:
        runs, info, opt, extra = run_set(prefix, init, nodes_json)
        print(f"\n{prefix.rstrip('-')}: initial (yaw, pitch, roll) = ({init['yaw']}, {init['pitch']}, {init['roll']}) deg; "
              f"optimiser {info['status']}, {info['evaluations']} evaluations, objective {info['objective']:.5g} N^2 m^2 s "
              f"({info['source']})")
        if opt is not None:
            print(f"  {opt.message}; constraints: " + " ".join(f"{c:.4f}" for c in opt.constraints))
        print("  nodes (N m): " + "; ".join(f"{a}: " + ", ".join(f"{v:.4f}" for v in extra["nodes"][i])
                                             for i, a in enumerate(P.AXES)))
        d = max(float(np.max(np.abs(runs[f"{prefix}3"][k] - runs[f"{prefix}3ol"][k])))
                for k in ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"])
        dt_ = max(float(np.max(np.abs(runs[f"{prefix}3"][f"torque_applied_{a}"] - runs[f"{prefix}3ol"][f"torque_applied_{a}"])))
                  for a in P.AXES)
        print(f"  {prefix}3 vs {prefix}3ol: max |difference| of q, w = {d:.3g}, of the applied torque = {dt_:.3g} N m")
        for rid, r in runs.items():
            row = {"run": rid, **terminal(r),
                   "peak_torque_N_m": float(max(np.max(np.abs(r[f"torque_applied_{a}"])) for a in P.AXES)),
                   "effort_sq_N2m2s": float(sum(np.sum(r[f"torque_applied_{a}"][:-1] ** 2) for a in P.AXES) * P.DT),
                   "optimiser_status": info["status"] if rid.endswith("3") or rid.endswith("3ol") else "",
                   "evaluations": info["evaluations"] if rid.endswith("3") or rid.endswith("3ol") else ""}
            rows.append(row)
            all_runs[rid] = r
            write_csv(args.out / f"{rid}.csv", r)
            if not args.quick:
                plot_run(args.out / f"{rid}.png", rid, r, row)
        if not args.quick:
            plot_compare(args.out / f"compare_{prefix.rstrip('-')}.png", runs,
                         f"Paper 004 from (yaw, pitch, roll) = ({init['yaw']}, {init['pitch']}, {init['roll']}) deg")
    print("\n| run | terminal max abs w (deg/s) | terminal max abs Euler (deg) | requirement | peak torque (N m) | "
          "integral u^2 (N^2 m^2 s) | optimiser |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        opt_s = f"{r['optimiser_status']} ({r['evaluations']} evals)" if r["optimiser_status"] else ""
        print(f"| {r['run']} | {r['w_end_max_deg_s']:.3e} | {r['euler_end_max_deg']:.3e} | "
              f"{'PASS' if r['pass'] else 'FAIL'} | {r['peak_torque_N_m']:.3f} | {r['effort_sq_N2m2s']:.4g} | {opt_s} |")
    with open(args.out / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"\nwrote {args.out}/summary.csv, one CSV per run" + ("" if args.quick else " and PNG figures"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
