#!/usr/bin/env python3
"""PSO tuning of the paper 002 controllers (PD, PID, FOPD, FOPID) on the nominal single-axis loop.

Each particle is one closed-loop FMU run (SingleAxisPlant + PidController/FopidController, explicit
Euler, h = Δ = 1 ms, 30° step at t = 0, t_end = 20 s). Cost = mean |θ_ref - θ_n| in degrees over
[0, t_end) + 1000 if |θ_ref - θ| exceeds 0.5° anywhere in t >= 10 s (+1e6 for a non-finite run).
Bounds 0 <= K_P, K_I, K_D <= 20, 0 <= λ, μ <= 2. Swarm 30, at most 400 iterations, stop when the best
cost improved by less than 1e-6 over 50 iterations; inertia 0.9 -> 0.4, c1 = c2 = 2, velocity clamp 20 %
of each range, seed per controller = --seed + index.

Writes the gains with cost, seed, iterations and wall time to scripts/paper002_gains.json (the file the
sweep script reads); --quick (CI) runs a tiny swarm for two iterations and writes to out/ instead.

Usage: paper002_tune.py [--controllers PD,PID,FOPD,FOPID] [--seed 2] [--workers 2] [--quick]
                        [--particles 30] [--iters 400] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scfmu.paper002 import BOUNDS, CONTROLLERS, GAINS_FILE, ROOT, Scenario, TuneCost, pso_minimize, run_case  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--controllers", default="PD,PID,FOPD,FOPID")
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--particles", type=int, default=30)
    ap.add_argument("--iters", type=int, default=400)
    ap.add_argument("--quick", action="store_true", help="CI smoke run: 3 particles, 2 iterations, t_end 12 s")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    sc = Scenario()
    if a.quick:
        a.particles, a.iters = 3, 2
        sc = Scenario(t_end=12.0)
    out = a.out or (ROOT / "out" / "paper002" / "gains_quick.json" if a.quick else GAINS_FILE)
    out.parent.mkdir(parents=True, exist_ok=True)
    names = [c.strip() for c in a.controllers.split(",") if c.strip()]
    data = json.loads(out.read_text()) if out.exists() else {}
    data.setdefault("controllers", {})
    data["setup"] = {"theta_ref_deg": sc.theta_ref_deg, "t_end_s": sc.t_end, "step_s": sc.h,
                     "plant": "SingleAxisPlant defaults (J = 7.7 kg m^2, K = 1, T = 0.2 s, T_sat = 1 N m, "
                              "M_d = 0.01 sin(0.1 t) + 0.0001 N m), explicit Euler",
                     "particles": a.particles, "max_iterations": a.iters, "stall": "1e-6 over 50 iterations",
                     "inertia_weight": "0.9 -> 0.4", "c1": 2.0, "c2": 2.0, "velocity_clamp": "20 % of range"}
    t_all = time.perf_counter()
    for i, c in enumerate(names):
        var = CONTROLLERS[c][1]
        lo, hi = [BOUNDS[v][0] for v in var], [BOUNDS[v][1] for v in var]
        seed = a.seed + i
        r = pso_minimize(TuneCost(c, sc), lo, hi, n_particles=a.particles, max_iter=a.iters, seed=seed,
                         workers=a.workers, desc=c)
        gains = dict(zip(var, r["x"]))
        check = run_case(c, gains, sc)
        data["controllers"][c] = {"gains": gains, "cost": r["cost"], "mae_deg": check["mae_deg"],
                                  "late_max_deg": check["late_max_deg"], "seed": seed,
                                  "particles": a.particles, "max_iterations": a.iters, "iterations": r["iterations"], "evaluations": r["evaluations"],
                                  "seconds": round(r["seconds"], 1), "workers": a.workers}
        print(f"{c:6s} cost {r['cost']:.6f}  MAE {check['mae_deg']:.6f} deg  "
              + "  ".join(f"{k}={v:.6g}" for k, v in gains.items())
              + f"  ({r['iterations']} iterations, {r['seconds']:.1f} s, seed {seed})", flush=True)
        out.write_text(json.dumps(data, indent=2) + "\n")
    total = time.perf_counter() - t_all
    data["total_seconds"] = round(total, 1)
    data["machine"] = f"{platform.machine()}, {os.cpu_count()} CPUs, {a.workers} workers"
    out.write_text(json.dumps(data, indent=2) + "\n")
    print(f"total tuning time {total:.1f} s -> {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
