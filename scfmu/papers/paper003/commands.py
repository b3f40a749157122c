"""Paper 003: GA-tuned sliding-mode (GA-SMC) and type-2 fuzzy sliding-mode (T2F-SMC) attitude control of a
LEO satellite with reaction wheels and magnetorquer momentum dumping.

The closed loops are the declared scenarios ``paper003/<SMC|T2FSMC>/<N|C|S|W|U>`` (``scfmu.paper003``):
AttitudePlant with full inertia [[4, 0.05, -0.03], [0.05, 5, 0.02], [-0.03, 0.02, 3.5]] kg m², quaternion
kinematics, three reaction wheels (torque limit 0.05 N m, momentum limit 0.504 N m s) with magnetorquer
dumping, gravity gradient on a 700 km / 98° circular orbit, RK4 0.01 s; rest at identity; AttitudeCommand
roll 20°, pitch -15°, yaw 0° from t = 0; communication step 0.01 s, t_end = 150 s.

Scenarios: 003-N none; 003-C constant 5e-4 N m per axis; 003-S sinusoid 5e-4 N m, 0.1 rad/s, phases
0, π/2, π; 003-W white noise σ = 5e-4 N m, hold 0.1 s, seed 1; 003-U 100 runs with inertia_scale_{x,y,z}
uniform in [0.8, 1.2] drawn from numpy's default_rng(run seed), run seeds 1…100, no disturbance.

Commands:
  paper003.py tune [--quick] [--seed S] [--workers N]     GA: k for GA-SMC, then (e_scale, edot_scale, kappa)
  paper003.py scenarios [--quick] [--workers N] [--runs N] the four scenarios + Monte Carlo, table, CSV, PNG

Every run (GA candidate, scenario, Monte Carlo sample) goes through the campaign engine
(``scfmu.campaign``, native container loop, Dask LocalCluster with --workers ≤ 2 processes); results
depend only on the inputs, never on the worker count. Each GA generation is one campaign folder under
out/paper003/ga/ (or --ckpt): an interrupted tuning run resumes from them (same seed, same candidates),
and the generation log ga_log.jsonl records the best cost after every generation.

`tune` writes the package data file paper003/data/tuned.json (or out/paper003/tuned_quick.json with --quick); `scenarios`
reads that file.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path


import numpy as np

from ...engines.reference import CoSimulation
from ...fmu import Fmu
from .data import data_file
from . import model as p3
from .model import (ANGLES, AX, COMMAND, DT, GA_BOUNDS, ISF_WEIGHT, PLANT, T_END,  # noqa: F401
                            uncertainty_scales)
from ...results import write_csv

TUNED = data_file("tuned.json")
OUT = Path("out") / "paper003"

CONTROLLERS = {"GA-SMC": "SlidingModeController", "T2F-SMC": "Type2FuzzySmcController"}
KEY = {"GA-SMC": "SMC", "T2F-SMC": "T2FSMC"}
SCENARIOS = {f"003-{c}": p3.DISTURBANCES[c] for c in "NCSW"}


@dataclass
class Case:
    """One closed-loop run for the reference path: controller FMU and parameters, plant parameters, horizon."""
    controller: str
    ctrl_params: dict = field(default_factory=dict)
    plant_params: dict = field(default_factory=dict)
    t_end: float = T_END
    dt: float = DT
    signals: bool = False
    label: str = ""


def simulate_reference(case: Case) -> tuple[dict, dict | None]:
    """The loop written out with the reference master (``scfmu.CoSimulation``, names matched each step),
    independent of the scenario declaration and the campaign engine: the yardstick the engine is tested
    against (src/models/attitude/tests/test_paper003_controllers.py). Returns the metrics dict (and the
    signals if asked)."""
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": COMMAND[0], "ref_euler321_pitch": COMMAND[1],
                                  "ref_euler321_yaw": COMMAND[2]})
    ctrl = Fmu(case.controller, case.ctrl_params)
    plant = Fmu("AttitudePlant", {**PLANT, **case.plant_params})
    met = Fmu("AttitudeMetrics")
    sim = CoSimulation([cmd, ctrl, plant, met])
    log = {n: (plant, n) for n in ["roll", "pitch", "yaw"]}
    log.update({f"torque_{a}": (plant, f"torque_applied_{a}") for a in AX})
    if case.signals:
        log.update({f"h_wheel_{a}": (plant, f"h_wheel_{a}") for a in AX})
        log.update({f"torque_ext_{a}": (plant, f"torque_ext_{a}") for a in AX})
    try:
        sig = sim.run(case.t_end, case.dt, log)
        m = {"ise": met.get("ise"), "isf": met.get("isf")}
    finally:
        sim.close()
    m["cost"] = m["ise"] + ISF_WEIGHT * m["isf"]
    n_ss = max(1, int(round(0.1 * (len(sig["time"]) - 1))))
    for ang, ref in zip(ANGLES, COMMAND):
        err = np.angle(np.exp(1j * (ref - sig[ang])))  # wrapped to (-pi, pi]
        m[f"sse_{ang}_deg"] = float(np.degrees(np.mean(np.abs(err[-n_ss:]))))
    for a in AX:
        m[f"tmax_{a}"] = float(np.max(sig[f"torque_{a}"]))
        m[f"tmin_{a}"] = float(np.min(sig[f"torque_{a}"]))
    return m, (sig if case.signals else None)


class Engine:
    """The campaign engine with one Dask LocalCluster (``workers`` processes) for a whole command."""

    def __init__(self, workers: int = 2, client=None):
        self.own = client is None
        self.cluster = None
        if self.own:
            from scfmu.campaign import _client
            client, self.cluster = _client(None, max(1, int(workers)))
        self.client = client

    def run(self, c, out_dir, progress: bool = False):
        from scfmu import campaign
        return campaign.run(c, out_dir, client=self.client, overwrite=True, progress=progress)

    def close(self):
        if self.own:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ----- genetic algorithm ----------------------------------------------------------------------------
def _blx_crossover(p_cross: float, alpha: float, lo: np.ndarray, hi: np.ndarray):
    """BLX-alpha crossover for pygad (custom operator drawing from the GA's own seeded generator)."""
    def op(parents, offspring_size, ga):
        rng = ga.numpy_random_generator
        out = np.empty(offspring_size)
        for k in range(offspring_size[0]):
            a = parents[k % parents.shape[0]]
            b = parents[(k + 1) % parents.shape[0]]
            if rng.random_sample() < p_cross:
                mn, mx = np.minimum(a, b), np.maximum(a, b)
                span = mx - mn
                child = rng.uniform(mn - alpha * span, mx + alpha * span)
            else:
                child = a.copy()
            out[k] = np.clip(child, lo, hi)
        return out
    return op


def _gauss_mutation(p_gene: float, lo: np.ndarray, hi: np.ndarray):
    """Gaussian mutation, σ = 10 % of each gene's range, probability p_gene per gene."""
    def op(offspring, ga):
        rng = ga.numpy_random_generator
        for k in range(offspring.shape[0]):
            for g in range(offspring.shape[1]):
                if rng.random_sample() < p_gene:
                    offspring[k, g] = np.clip(offspring[k, g] + rng.normal(0.0, 0.1 * (hi[g] - lo[g])), lo[g], hi[g])
        return offspring
    return op


def ga_optimise(stage: str, controller: str, base: dict, genes: list[str], seed: int, pop: int, gens: int,
                engine: Engine, t_end: float, ckpt: Path, desc: str) -> dict:
    """Real-coded GA (pygad): tournament of 2, BLX-0.5 crossover p = 0.9, Gaussian mutation (σ = 10 % of
    the range, p = 0.2 per gene), 1 elite; minimises J = ISE + 1e4 ISF on 003-N. Each batch of new
    candidates is one campaign (``ckpt/<stage>/batch-NNN``), so a restarted run replays the finished
    batches from disk; evaluations are cached by gene values (the elite is not re-simulated). A failed
    run costs +inf. Appends one line per generation to ``ckpt/ga_log.jsonl``."""
    import pygad
    from tqdm import tqdm
    lo = np.array([GA_BOUNDS[g][0] for g in genes])
    hi = np.array([GA_BOUNDS[g][1] for g in genes])
    cache: dict[tuple, float] = {}
    bar = tqdm(total=gens, desc=desc)
    batch = [0]
    t0 = time.time()
    log_path = ckpt / "ga_log.jsonl"

    def fitness(ga, solutions, idx):
        sols = [tuple(float(x) for x in s) for s in np.atleast_2d(solutions)]
        todo = [s for s in dict.fromkeys(sols) if s not in cache]
        if todo:
            c = p3.ga_campaign(controller, base, genes, todo, t_end)
            table = engine.run(c, ckpt / stage / f"batch-{batch[0]:03d}")
            batch[0] += 1
            for s, r in zip(todo, p3.rows(table)):
                cache[s] = r["cost"] if r["status"] == "ok" and math.isfinite(r["cost"]) else math.inf
        return [-cache[s] for s in sols]

    def on_generation(ga):
        bar.update(1)
        best = min(cache.items(), key=lambda kv: kv[1])
        rec = {"stage": stage, "generation": ga.generations_completed, "best_cost": best[1],
               "best": dict(zip(genes, best[0])), "evaluations": len(cache), "elapsed_s": round(time.time() - t0, 1)}
        with open(log_path, "a") as f:
            f.write(json.dumps(rec) + "\n")

    ga = pygad.GA(num_generations=gens, sol_per_pop=pop, num_parents_mating=pop, num_genes=len(genes),
                  fitness_func=fitness, fitness_batch_size=pop,
                  gene_space=[{"low": float(a), "high": float(b)} for a, b in zip(lo, hi)],
                  init_range_low=float(lo.min()), init_range_high=float(hi.max()),
                  parent_selection_type="tournament", K_tournament=2,
                  crossover_type=_blx_crossover(0.9, 0.5, lo, hi), mutation_type=_gauss_mutation(0.2, lo, hi),
                  keep_elitism=1, random_seed=seed, suppress_warnings=True, on_generation=on_generation)
    try:
        ga.run()
    finally:
        bar.close()
    best = min(cache.items(), key=lambda kv: kv[1])
    return {"values": dict(zip(genes, best[0])), "cost": best[1], "evaluations": len(cache),
            "generations": int(ga.generations_completed), "wall_s": round(time.time() - t0, 1)}


def cmd_tune(args) -> None:
    t0 = time.time()
    pop, gens, t_end = (4, 2, 10.0) if args.quick else (20, 30, T_END)
    gens = args.generations or gens
    path = Path(args.out) if args.out else (OUT / "tuned_quick.json" if args.quick else TUNED)
    ckpt = Path(args.ckpt) if args.ckpt else path.parent / f"ga_ckpt_{path.stem}" if args.out or args.quick \
        else OUT / "ga"
    ckpt.mkdir(parents=True, exist_ok=True)
    (ckpt / "ga_log.jsonl").unlink(missing_ok=True)
    with Engine(args.workers) as eng:
        smc = ga_optimise("smc", "SMC", {}, ["k_switch"], args.seed, pop, gens, eng, t_end, ckpt, "GA-SMC k")
        k = smc["values"]["k_switch"]
        print(f"GA-SMC: k = {k:.6g} N m, J = {smc['cost']:.6g} ({smc['evaluations']} evaluations, "
              f"{smc['generations']} generations, {smc['wall_s']} s)")
        t2f = ga_optimise("t2f", "T2FSMC", {"k_switch": k}, ["e_scale", "edot_scale", "kappa"], args.seed, pop, gens,
                          eng, t_end, ckpt, "T2F-SMC fuzzy")
    print("T2F-SMC: " + ", ".join(f"{n} = {x:.6g}" for n, x in t2f["values"].items())
          + f", J = {t2f['cost']:.6g} ({t2f['evaluations']} evaluations, {t2f['generations']} generations, "
            f"{t2f['wall_s']} s)")
    result = {
        "seed": args.seed,
        "cost": "J = ISE + 1e4 ISF on 003-N (roll 20 deg, pitch -15 deg, yaw 0; dt 0.01 s, t_end %g s)" % t_end,
        "ga": {"population": pop, "generations": gens, "selection": "tournament of 2", "crossover": "BLX-0.5, p = 0.9",
               "mutation": "Gaussian, sigma = 10 % of range, p = 0.2 per gene", "elite": 1},
        "engine": f"campaign engine, native container loop, {args.workers} Dask worker(s)",
        "GA-SMC": {"SlidingModeController": smc["values"], "J": smc["cost"], "evaluations": smc["evaluations"],
                   "generations_run": smc["generations"], "wall_s": smc["wall_s"]},
        "T2F-SMC": {"Type2FuzzySmcController": {"k_switch": k, **t2f["values"]}, "J": t2f["cost"],
                    "evaluations": t2f["evaluations"], "generations_run": t2f["generations"], "wall_s": t2f["wall_s"]},
        "run_time_s": round(time.time() - t0, 1),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n")
    print(f"wrote {path} ({result['run_time_s']} s)")


# ----- scenarios ------------------------------------------------------------------------------------
def tuned_params(path: Path) -> dict[str, dict]:
    if path.exists():
        t = p3.tuned_params(path)
        return {"GA-SMC": t["SMC"], "T2F-SMC": t["T2FSMC"]}
    print(f"note: {path} not found; using the FMUs' default parameters", file=sys.stderr)
    return {"GA-SMC": {}, "T2F-SMC": {}}


def cmd_scenarios(args) -> None:
    t0 = time.time()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = tuned_params(Path(args.tuned))
    t_end = 20.0 if args.quick else T_END
    n_mc = args.runs if args.runs is not None else (4 if args.quick else 100)
    seeds = list(range(1, n_mc + 1))
    rows, runs = [], {}
    mc: dict[str, list] = {}
    times = {}
    with Engine(args.workers) as eng:
        for scen in SCENARIOS:
            for name in CONTROLLERS:
                c = p3.scenario_campaign(KEY[name], scen[-1], params[name], t_end, timeseries=[])
                d = out / "runs" / f"{scen}_{name}"
                table = eng.run(c, d)
                r = p3.rows(table)[0]
                if r["status"] != "ok":
                    raise SystemExit(f"{scen} {name}: {r['status']}: {r['message']}")
                from scfmu.campaign import read_timeseries
                sig = read_timeseries(d, 0)
                runs[(scen, name)] = sig
                rows.append({"scenario": scen, "controller": name, **{k: r[k] for k in p3.TABLE_COLUMNS}})
                write_csv(out / f"{scen}_{name}.csv", sig, every=10)
        t_mc = time.time()
        for name in CONTROLLERS:
            table = eng.run(p3.mc_campaign(KEY[name], seeds, params[name], t_end), out / "runs" / f"003-U_{name}",
                            progress=True)
            mc[name] = p3.rows(table)
        times["003-U"] = round(time.time() - t_mc, 1)
    with open(out / "003-U_runs.csv", "w", newline="") as f:
        w = None
        for name in CONTROLLERS:
            for s, r in zip(seeds, mc[name]):
                row = {"controller": name, "seed": s, **uncertainty_scales(s), "status": r["status"],
                       **{k: r[k] for k in p3.TABLE_COLUMNS}}
                if w is None:
                    w = csv.DictWriter(f, fieldnames=list(row))
                    w.writeheader()
                w.writerow({k: repr(v) if isinstance(v, float) else v for k, v in row.items()})
    for name in CONTROLLERS:
        rows.append({"scenario": "003-U", "controller": name, **p3.mc_stats(mc[name])})
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with open(out / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    for scen in SCENARIOS:
        p3.plot_scenario({n: runs[(scen, n)] for n in CONTROLLERS}, scen, out / f"{scen}.png")
    p3.plot_monte_carlo(mc, out / "003-U.png")
    # table
    print(f"paper 003, dt = {DT} s, t_end = {t_end} s; tuned parameters from {args.tuned}")
    hdr = f"{'run':7} {'ctrl':8} {'sse roll':>9} {'pitch':>9} {'yaw':>9} {'ISE':>10} {'ISF':>10} " + \
          " ".join(f"{'Tmax_' + a:>9} {'Tmin_' + a:>9}" for a in AX)
    print(hdr + "   (sse in deg, ISE rad² s, ISF N² m² s, T in N m)")
    for r in rows:
        if r["scenario"] == "003-U":
            continue
        print(f"{r['scenario']:7} {r['controller']:8} {r['sse_roll_deg']:9.3g} {r['sse_pitch_deg']:9.3g} {r['sse_yaw_deg']:9.3g} "
              f"{r['ise']:10.5g} {r['isf']:10.5g} " + " ".join(f"{r['tmax_' + a]:9.3g} {r['tmin_' + a]:9.3g}" for a in AX))
    for r in rows:
        if r["scenario"] == "003-U":
            print(f"003-U   {r['controller']:8} ISE mean {r['ise_mean']:.5g} std {r['ise_std']:.3g}   "
                  f"ISF mean {r['isf_mean']:.5g} std {r['isf_std']:.3g}   ({r['runs']} runs)")
    for scen in [*SCENARIOS, "003-U"]:
        sel = [r for r in rows if r["scenario"] == scen]
        ki, kf = ("ise_mean", "isf_mean") if scen == "003-U" else ("ise", "isf")
        wi = min(sel, key=lambda r: r[ki])["controller"]
        wf = min(sel, key=lambda r: r[kf])["controller"]
        print(f"{scen}: lower ISE: {wi}; lower ISF: {wf}")
    print(f"wrote {out}/summary.csv, 003-U_runs.csv, per-run CSV and PNG "
          f"({time.time() - t0:.1f} s; 003-U Monte Carlo {times['003-U']} s)")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("tune", help="GA tuning of k (GA-SMC), then of the fuzzy coefficients (T2F-SMC)")
    t.add_argument("--seed", type=int, default=1)
    t.add_argument("--workers", type=int, default=2)
    t.add_argument("--quick", action="store_true", help="population 4, 2 generations, 10 s runs (CI)")
    t.add_argument("--generations", type=int, default=None, help="override the number of generations (default 30)")
    t.add_argument("--out", default=None, help="JSON path (default: the package data file paper003/data/tuned.json)")
    t.add_argument("--ckpt", default=None, help="folder of the GA's campaign batches (resume) and ga_log.jsonl")
    s = sub.add_parser("scenarios", help="003-N, -C, -S, -W and the 003-U Monte Carlo")
    s.add_argument("--workers", type=int, default=2)
    s.add_argument("--quick", action="store_true", help="20 s runs, 4 Monte Carlo runs (CI)")
    s.add_argument("--runs", type=int, default=None, help="Monte Carlo runs (default 100; 4 with --quick)")
    s.add_argument("--tuned", default=str(TUNED))
    s.add_argument("--out", default=str(OUT))
    args = ap.parse_args(argv)
    {"tune": cmd_tune, "scenarios": cmd_scenarios}[args.cmd](args)


if __name__ == "__main__":
    main()


def main_tune(argv=None) -> int:
    main(["tune", *(argv or [])])
    return 0


def main_scenarios(argv=None) -> int:
    main(["scenarios", *(argv or [])])
    return 0
