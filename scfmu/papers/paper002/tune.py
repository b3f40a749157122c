"""PSO tuning of the paper 002 controllers (PD, PID, FOPD, FOPID) on the nominal single-axis loop.

Each particle evaluation is one run of the campaign engine (native path: the whole loop in fmpy's
container FMU) of the declared scenario paper002/<controller> with the particle's gains as overrides:
SingleAxisPlant + PidController/FopidController, explicit Euler, h = Δ = 1 ms, 30° step at t = 0,
t_end = 20 s. Cost = mean |θ_ref - θ_n| in degrees over [0, t_end) + 1000 if |θ_ref - θ| exceeds 0.5°
anywhere in t >= 10 s (+1e6 for a failed or non-finite run). Bounds 0 <= K_P, K_I, K_D <= 20,
0 <= λ, μ <= 2. Swarm 30, at most 400 iterations, stop when the best cost improved by less than 1e-6
over 50 iterations; inertia 0.9 -> 0.4, c1 = c2 = 2, velocity clamp 20 % of each range; seed per
controller = --seed + its index in PD, PID, FOPD, FOPID (2, 3, 4, 5 by default).

The swarms of all selected controllers advance in lockstep: each iteration, the particles of every swarm
still running go to the Dask workers (one LocalCluster for the whole tuning) as one batch of runs.
Results do not depend on the number of workers. After every iteration a checkpoint is written
(--checkpoint); re-running the same command resumes from it. --deadline HH:MM (UTC) starts no iteration
after that time and records how far each swarm got.

Writes the gains with cost, seed, iterations, stop reason and times to the package data file paper002/data/gains.json (the
file the sweep command and the paper002/<controller> scenarios read); --quick (CI) runs a tiny swarm for
two iterations with t_end = 12 s and writes to out/ instead.

Usage: scfmu paper 002 tune [--controllers PD,PID,FOPD,FOPID] [--seed 2] [--workers 2] [--quick]
                        [--particles 30] [--iters 400] [--out FILE] [--checkpoint FILE] [--deadline HH:MM]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import time
from pathlib import Path

from .model import CONTROLLERS, GAINS_FILE, Scenario, run_case
from .tuning import tune

OUT = Path("out") / "paper002"


def _deadline(text: str | None) -> float | None:
    if not text:
        return None
    now = dt.datetime.now(dt.timezone.utc)
    hh, mm = (int(v) for v in text.split(":"))
    d = now.replace(hour=hh, minute=mm, second=0, microsecond=0)
    if d < now - dt.timedelta(hours=12):
        d += dt.timedelta(days=1)
    return d.timestamp()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--controllers", default="PD,PID,FOPD,FOPID")
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1),
                    help="Dask workers (0: evaluate in this process, no cluster)")
    ap.add_argument("--particles", type=int, default=30)
    ap.add_argument("--iters", type=int, default=400)
    ap.add_argument("--quick", action="store_true", help="CI smoke run: 3 particles, 2 iterations, t_end 12 s")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--checkpoint", type=Path, default=None,
                    help="resume file (default: out/paper002/tune_checkpoint.json; none with --quick)")
    ap.add_argument("--deadline", default=None, help="HH:MM UTC: start no iteration after this time")
    a = ap.parse_args(argv)
    sc = Scenario()
    if a.quick:
        a.particles, a.iters = 3, 2
        sc = Scenario(t_end=12.0)
    out = a.out or (OUT / "gains_quick.json" if a.quick else GAINS_FILE)
    ckpt = a.checkpoint or (None if a.quick else OUT / "tune_checkpoint.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    if ckpt is not None:
        ckpt.parent.mkdir(parents=True, exist_ok=True)
    names = [c.strip() for c in a.controllers.split(",") if c.strip()]
    unknown = [c for c in names if c not in CONTROLLERS]
    if unknown:
        ap.error(f"unknown controllers {unknown}; expected some of {list(CONTROLLERS)}")

    t_all = time.perf_counter()
    client = cluster = None
    if a.workers > 0:
        from scfmu.campaign import _client
        client, cluster = _client(None, a.workers)
    load0 = os.getloadavg()[0]
    try:
        res = tune(names, sc, n_particles=a.particles, max_iter=a.iters, seed=a.seed, client=client,
                   checkpoint=ckpt, deadline=_deadline(a.deadline))
    finally:
        if client is not None:
            client.close()
            cluster.close()
    session = time.perf_counter() - t_all

    data = json.loads(out.read_text()) if out.exists() else {}
    data.setdefault("controllers", {})
    data["setup"] = {"theta_ref_deg": sc.theta_ref_deg, "t_end_s": sc.t_end, "step_s": sc.h,
                     "plant": "SingleAxisPlant defaults (J = 7.7 kg m^2, K = 1, T = 0.2 s, T_sat = 1 N m, "
                              "M_d = 0.01 sin(0.1 t) + 0.0001 N m), explicit Euler",
                     "particles": a.particles, "max_iterations": a.iters, "stall": "1e-6 over 50 iterations",
                     "inertia_weight": "0.9 -> 0.4", "c1": 2.0, "c2": 2.0, "velocity_clamp": "20 % of range",
                     "evaluation": "campaign engine, native path, scenario paper002/<controller> with the gains "
                                   "as overrides; swarms in lockstep on one Dask LocalCluster"}
    for c in names:
        r = res[c]
        check = run_case(c, r["gains"], sc)  # the direct two-FMU loop, independent of the engine
        data["controllers"][c] = {
            "gains": r["gains"], "cost": r["cost"], "mae_deg": check["mae_deg"],
            "late_max_deg": check["late_max_deg"], "cost_direct_loop": check["cost"], "seed": r["seed"],
            "particles": a.particles, "max_iterations": a.iters, "iterations": r["iterations"],
            "evaluations": r["evaluations"], "stop": r["stop"], "stall_rule_fired": bool(r["stalled"]),
            "seconds": round(r["wall_seconds"], 1), "run_seconds": round(r["run_seconds"], 1),
            "workers": a.workers, "engine": "native"}
        print(f"{c:6s} cost {r['cost']:.9f} (direct loop {check['cost']:.9f})  "
              + "  ".join(f"{k}={v:.6g}" for k, v in r["gains"].items())
              + f"  ({r['iterations']} iterations, stop: {r['stop']}, {r['wall_seconds']:.1f} s, seed {r['seed']})",
              flush=True)
    total = max(res[c]["wall_seconds"] for c in names)
    data["total_seconds"] = round(total, 1)
    data["last_session_seconds"] = round(session, 1)
    data["machine"] = (f"{platform.machine()}, {os.cpu_count()} CPUs, {a.workers} workers, "
                       f"load average {load0:.1f} at start, {os.getloadavg()[0]:.1f} at end")
    data["finished_utc"] = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    out.write_text(json.dumps(data, indent=2) + "\n")
    print(f"total tuning time {total:.1f} s (this session {session:.1f} s) -> {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
