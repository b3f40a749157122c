"""Paper 004 spline optimisation: the open-loop torque that brings the faulty spacecraft (every
actuator at 10 % effectiveness, limit 1 N m) to rest at the target attitude by t_f = 20 s.

Variables: nodes 0-4 of a not-a-knot cubic spline per axis at t = 0, 4, 8, 12, 16 s (node 5 at 20 s
is fixed at 0; the torque is 0 after 20 s), bounds |node| <= 1 N m. Objective: integral of the applied
torque squared. Constraints at t_f: |w_i| <= 0.01 deg/s and |roll|, |pitch|, |yaw| (321) <= 0.1 deg,
two smooth inequalities each (12), imposed 1 % inside the requirement (--margin). SciPy SLSQP, at most
300 simulations of the AttitudePlant FMU (finite-difference gradients included). Initial guess: the
case-2 closed-loop torque (feedback-linearising controller, faulty plant) at the node times.

Writes the nodes and the optimiser report to a JSON file (default: the package data file paper004/data/nodes.json,
committed: the ReferenceCorrector's node parameters for case 004-3).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path


import numpy as np

from . import model as P
from .data import data_file

DEFAULT_JSON = data_file("nodes.json")
CON_NAMES = [f"{s}{n}" for s, names in (("w", ["w_x", "w_y", "w_z"]), ("a", ["roll", "pitch", "yaw"])) for n in names]


def constraint_table(c: np.ndarray) -> list[dict]:
    """The 12 constraint values g >= 0 (scaled by the optimiser's bound) with their physical meaning."""
    rows = []
    labels = ([f"1 - w_{a}/w_max" for a in P.AXES] + [f"1 + w_{a}/w_max" for a in P.AXES]
              + [f"1 - {n}/a_max" for n in ("roll", "pitch", "yaw")] + [f"1 + {n}/a_max" for n in ("roll", "pitch", "yaw")])
    for lab, v in zip(labels, c):
        rows.append({"constraint": lab, "value": float(v), "satisfied": bool(v >= -1e-6)})
    return rows


def report(res: P.OptResult, init_deg: dict, margin: float) -> dict:
    return {
        "initial_euler321_deg": init_deg,
        "effectiveness": P.A_FAULT,
        "u_max_N_m": P.U_MAX,
        "node_times_s": P.NODE_TIMES.tolist(),
        "nodes_N_m": {a: res.nodes[i].tolist() for i, a in enumerate(P.AXES)},
        "corrector_parameters": {f"node_{a}_{j}": float(res.nodes[i, j]) for i, a in enumerate(P.AXES) for j in range(P.N_NODES)},
        "optimiser": {
            "method": "scipy.optimize.minimize(method='SLSQP')",
            "status": res.status,
            "message": res.message,
            "evaluations": res.evaluations,
            "budget": P.BUDGET,
            "iterations": res.iterations,
            "objective_N2m2s": res.objective,
            "margin": margin,
            "constraints": constraint_table(res.constraints),
            "terminal": res.terminal,
            "initial_guess": res.x0.tolist(),
        },
    }


def print_report(rep: dict, title: str) -> None:
    o = rep["optimiser"]
    print(f"== {title}: initial 321 angles (yaw, pitch, roll) = ({rep['initial_euler321_deg']['yaw']}, "
          f"{rep['initial_euler321_deg']['pitch']}, {rep['initial_euler321_deg']['roll']}) deg")
    print(f"optimiser status: {o['status']} ({o['message']})")
    print(f"evaluations: {o['evaluations']} of {o['budget']}, iterations: {o['iterations']}, "
          f"objective: {o['objective_N2m2s']:.6g} N^2 m^2 s")
    print("constraints (>= 0 when met; bounds {:.4g} deg/s and {:.4g} deg):".format(
        P.W_REQ_DEG_S * (1 - o["margin"]), P.EULER_REQ_DEG * (1 - o["margin"])))
    for r in o["constraints"]:
        print(f"  {r['constraint']:<18s} {r['value']: .6f}  {'ok' if r['satisfied'] else 'VIOLATED'}")
    t = o["terminal"]
    print(f"terminal max|w| = {t['w_end_max_deg_s']:.6g} deg/s, max|Euler| = {t['euler_end_max_deg']:.6g} deg, "
          f"requirement {'PASS' if t['pass'] else 'FAIL'}")
    for a in P.AXES:
        print(f"  nodes {a}: " + ", ".join(f"{v: .5f}" for v in rep["nodes_N_m"][a]))


def bang_bang_bound_deg() -> list[float]:
    """Largest rest-to-rest rotation per axis in t_f with the faulty limit (single-axis bang-bang),
    u t_f^2 / (4 I_i), in degrees."""
    lim = P.A_FAULT * P.U_MAX
    return [math.degrees(lim * P.T_F ** 2 / (4 * i)) for i in P.INERTIA]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--initial", choices=["default", "calibrated", "stress"], default="default",
                    help="default (6, -4, 8) deg, calibrated (the report's start, model.INIT_SCALE_CALIBRATED × the "
                         "default) or the stress run 004-X (15, -10, 20) deg (yaw, pitch, roll)")
    ap.add_argument("--json", type=Path, default=None,
                    help=f"output JSON (default {DEFAULT_JSON} for the default initial state, none for stress)")
    ap.add_argument("--margin", type=float, default=P.MARGIN)
    ap.add_argument("--budget", type=int, default=P.BUDGET)
    args = ap.parse_args(argv)
    init = {"default": P.INIT_DEFAULT_DEG, "calibrated": P.init_deg_scaled(P.INIT_SCALE_CALIBRATED),
            "stress": P.INIT_STRESS_DEG}[args.initial]
    res = P.optimise(init, budget=args.budget, margin=args.margin)
    rep = report(res, init, args.margin)
    print_report(rep, f"paper 004 spline optimisation ({args.initial})")
    print(f"({res.seconds:.1f} s; single-axis bang-bang reach in {P.T_F:g} s at 1 N m: "
          + ", ".join(f"{a} {d:.1f} deg" for a, d in zip(P.AXES, bang_bang_bound_deg())) + ")")
    path = args.json if args.json is not None else {"default": DEFAULT_JSON, "calibrated": data_file(
        "nodes_calibrated.json")}.get(args.initial)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(rep, indent=1) + "\n")
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
