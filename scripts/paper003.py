#!/usr/bin/env python3
"""Paper 003: GA-tuned sliding-mode (GA-SMC) and type-2 fuzzy sliding-mode (T2F-SMC) attitude control of a
LEO satellite with reaction wheels and magnetorquer momentum dumping.

Setup: AttitudePlant with full inertia [[4, 0.05, -0.03], [0.05, 5, 0.02], [-0.03, 0.02, 3.5]] kg m²,
quaternion kinematics, three reaction wheels (torque limit 0.05 N m, momentum limit 0.504 N m s) with
magnetorquer dumping, gravity gradient on a 700 km / 98° circular orbit, RK4 0.01 s; rest at identity;
AttitudeCommand roll 20°, pitch -15°, yaw 0° from t = 0; communication step 0.01 s, t_end = 150 s.
Loop: AttitudeCommand -> controller -> AttitudePlant -> AttitudeMetrics, wired by port name (the plant's
wheel momentum h_wheel_* feeds the controller's input of the same name).

Scenarios: 003-N none; 003-C constant 5e-4 N m per axis; 003-S sinusoid 5e-4 N m, 0.1 rad/s, phases
0, π/2, π; 003-W white noise σ = 5e-4 N m, hold 0.1 s, seed 1; 003-U 100 runs with inertia_scale_{x,y,z}
uniform in [0.8, 1.2] drawn from numpy's default_rng(run seed), run seeds 1…100, no disturbance.

Commands:
  paper003.py tune [--quick] [--seed S] [--workers N]     GA: k for GA-SMC, then (e_scale, edot_scale, kappa)
  paper003.py scenarios [--quick] [--workers N] [--runs N] the four scenarios + Monte Carlo, table, CSV, PNG

`tune` writes scripts/paper003_tuned.json (or out/paper003/tuned_quick.json with --quick); `scenarios`
reads scripts/paper003_tuned.json. Every run is one call of `simulate(case)` (parameters + seed in, metrics
dict and optional signals out), mapped over a process pool; results depend only on the inputs, never on
the worker count.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from scfmu import CoSimulation, Fmu  # noqa: E402
from scfmu.results import write_csv  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TUNED = ROOT / "scripts" / "paper003_tuned.json"
OUT = ROOT / "out" / "paper003"

D = math.radians
COMMAND = (D(20.0), D(-15.0), 0.0)
DT = 0.01
T_END = 150.0
ISF_WEIGHT = 1e4
AX = "xyz"
ANGLES = ("roll", "pitch", "yaw")

PLANT = {
    "inertia_xx": 4.0, "inertia_yy": 5.0, "inertia_zz": 3.5,
    "inertia_xy": 0.05, "inertia_xz": -0.03, "inertia_yz": 0.02,
    "kinematics": 0, "actuator_mode": 1, "mtq_enable": 1, "gg_enable": 1,
    "max_internal_step": 0.01,
}
CONTROLLERS = {"GA-SMC": "SlidingModeController", "T2F-SMC": "Type2FuzzySmcController"}
SCENARIOS = {
    "003-N": {},
    "003-C": {f"dist_const_{a}": 5e-4 for a in AX},
    "003-S": {**{f"dist_sin_amp_{a}": 5e-4 for a in AX}, "dist_sin_freq": 0.1,
              "dist_sin_phase_x": 0.0, "dist_sin_phase_y": math.pi / 2, "dist_sin_phase_z": math.pi},
    "003-W": {**{f"dist_noise_std_{a}": 5e-4 for a in AX}, "dist_noise_hold": 0.1, "dist_noise_seed": 1},
}
GA_BOUNDS = {"k_switch": (1e-4, 0.05), "e_scale": (0.005, 0.5), "edot_scale": (0.001, 0.1), "kappa": (0.0, 0.9)}


@dataclass
class Case:
    """One closed-loop run: controller FMU and parameters, plant parameters, horizon."""
    controller: str
    ctrl_params: dict = field(default_factory=dict)
    plant_params: dict = field(default_factory=dict)
    t_end: float = T_END
    dt: float = DT
    signals: bool = False
    label: str = ""


def uncertainty_scales(seed: int) -> dict:
    """003-U: inertia_scale_{x,y,z} uniform in [0.8, 1.2] from numpy's default_rng(seed)."""
    s = np.random.default_rng(seed).uniform(0.8, 1.2, 3)
    return {f"inertia_scale_{a}": float(v) for a, v in zip(AX, s)}


def simulate(case: Case) -> tuple[dict, dict | None]:
    """Runs one case; returns the metrics dict and, if case.signals, the logged signals."""
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
        log.update({f"s_{a}": (ctrl, f"s_{a}") for a in AX})
        log.update({f"k_gain_{a}": (ctrl, f"k_gain_{a}") for a in AX})
        log["alpha_deg"] = (met, "alpha_deg")
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
    if case.signals:
        return m, sig
    return m, None


def run_many(cases: list[Case], workers: int, desc: str) -> list[tuple[dict, dict | None]]:
    """Maps `simulate` over the cases (order kept); progress bar on stderr."""
    from tqdm import tqdm
    if workers <= 1:
        return [simulate(c) for c in tqdm(cases, desc=desc, leave=False)]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(tqdm(pool.map(simulate, cases), total=len(cases), desc=desc, leave=False))


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


def ga_optimise(genes: list[str], make_case, seed: int, pop: int, gens: int, workers: int, desc: str) -> dict:
    """Real-coded GA (pygad): tournament of 2, BLX-0.5 crossover p = 0.9, Gaussian mutation (σ = 10 % of
    the range, p = 0.2 per gene), 1 elite; minimises J = ISE + 1e4 ISF. Evaluations are cached by gene
    values (the cost is deterministic), so the elite is not re-simulated."""
    import pygad
    from tqdm import tqdm
    lo = np.array([GA_BOUNDS[g][0] for g in genes])
    hi = np.array([GA_BOUNDS[g][1] for g in genes])
    cache: dict[tuple, float] = {}
    pool = ProcessPoolExecutor(max_workers=workers) if workers > 1 else None
    bar = tqdm(total=gens, desc=desc)

    def fitness(ga, solutions, idx):
        sols = [tuple(float(x) for x in s) for s in np.atleast_2d(solutions)]
        todo = [s for s in dict.fromkeys(sols) if s not in cache]
        cases = [make_case(dict(zip(genes, s))) for s in todo]
        res = pool.map(simulate, cases) if pool else map(simulate, cases)
        for s, (m, _) in zip(todo, res):
            cache[s] = m["cost"]
        return [-cache[s] for s in sols]

    ga = pygad.GA(num_generations=gens, sol_per_pop=pop, num_parents_mating=pop, num_genes=len(genes),
                  fitness_func=fitness, fitness_batch_size=pop,
                  gene_space=[{"low": float(a), "high": float(b)} for a, b in zip(lo, hi)],
                  init_range_low=float(lo.min()), init_range_high=float(hi.max()),
                  parent_selection_type="tournament", K_tournament=2,
                  crossover_type=_blx_crossover(0.9, 0.5, lo, hi), mutation_type=_gauss_mutation(0.2, lo, hi),
                  keep_elitism=1, random_seed=seed, suppress_warnings=True,
                  on_generation=lambda g: bar.update(1))
    try:
        ga.run()
    finally:
        bar.close()
        if pool:
            pool.shutdown()
    best = min(cache.items(), key=lambda kv: kv[1])
    return {"values": dict(zip(genes, best[0])), "cost": best[1], "evaluations": len(cache)}


def cmd_tune(args) -> None:
    t0 = time.time()
    pop, gens, t_end = (4, 2, 10.0) if args.quick else (20, 30, T_END)
    gens = args.generations or gens
    smc = ga_optimise(["k_switch"], lambda v: Case("SlidingModeController", v, t_end=t_end), args.seed, pop, gens,
                      args.workers, "GA-SMC k")
    k = smc["values"]["k_switch"]
    print(f"GA-SMC: k = {k:.6g} N m, J = {smc['cost']:.6g} ({smc['evaluations']} evaluations)")
    t2f = ga_optimise(["e_scale", "edot_scale", "kappa"],
                      lambda v: Case("Type2FuzzySmcController", {"k_switch": k, **v}, t_end=t_end),
                      args.seed, pop, gens, args.workers, "T2F-SMC fuzzy")
    print("T2F-SMC: " + ", ".join(f"{n} = {x:.6g}" for n, x in t2f["values"].items())
          + f", J = {t2f['cost']:.6g} ({t2f['evaluations']} evaluations)")
    result = {
        "seed": args.seed,
        "cost": "J = ISE + 1e4 ISF on 003-N (roll 20 deg, pitch -15 deg, yaw 0; dt 0.01 s, t_end %g s)" % t_end,
        "ga": {"population": pop, "generations": gens, "selection": "tournament of 2", "crossover": "BLX-0.5, p = 0.9",
               "mutation": "Gaussian, sigma = 10 % of range, p = 0.2 per gene", "elite": 1},
        "GA-SMC": {"SlidingModeController": smc["values"], "J": smc["cost"]},
        "T2F-SMC": {"Type2FuzzySmcController": {"k_switch": k, **t2f["values"]}, "J": t2f["cost"]},
        "run_time_s": round(time.time() - t0, 1),
    }
    path = Path(args.out) if args.out else (OUT / "tuned_quick.json" if args.quick else TUNED)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n")
    print(f"wrote {path} ({result['run_time_s']} s)")


# ----- scenarios ------------------------------------------------------------------------------------
def tuned_params(path: Path) -> dict[str, dict]:
    if path.exists():
        t = json.loads(path.read_text())
        return {"GA-SMC": t["GA-SMC"]["SlidingModeController"], "T2F-SMC": t["T2F-SMC"]["Type2FuzzySmcController"]}
    print(f"note: {path} not found; using the FMUs' default parameters", file=sys.stderr)
    return {"GA-SMC": {}, "T2F-SMC": {}}


def plot_scenarios(runs: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    for scen in SCENARIOS:
        fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
        for name, style in (("GA-SMC", "-"), ("T2F-SMC", "--")):
            s = runs[(scen, name)]
            t = s["time"]
            for ang, c in zip(ANGLES, "rgb"):
                ax[0].plot(t, np.degrees(s[ang]), style, color=c, label=f"{ang} {name}")
                ax[1].plot(t, s[f"torque_{AX[ANGLES.index(ang)]}"] * 1e3, style, color=c,
                           label=f"{AX[ANGLES.index(ang)]} {name}")
                ax[2].plot(t, s[f"h_wheel_{AX[ANGLES.index(ang)]}"] * 1e3, style, color=c,
                           label=f"{AX[ANGLES.index(ang)]} {name}")
        s = runs[(scen, "GA-SMC")]
        for a, c in zip(AX, "rgb"):
            ax[3].plot(s["time"], s[f"torque_ext_{a}"] * 1e3, color=c, lw=0.6, label=f"{a}")
        ax[0].set_ylabel("Euler 321 angle (deg)")
        ax[1].set_ylabel("applied torque (mN m)")
        ax[2].set_ylabel("wheel momentum (mN m s)")
        ax[3].set_ylabel("external torque (mN m)\n(disturbance + gravity gradient)")
        ax[3].set_xlabel("time (s)")
        for a in ax:
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7, ncol=3)
        ax[0].set_title(f"{scen}: GA-SMC (solid) vs T2F-SMC (dashed)")
        fig.tight_layout()
        fig.savefig(out / f"{scen}.png", dpi=110)
        plt.close(fig)


def plot_monte_carlo(mc: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    names = list(mc)
    for i, key, unit in ((0, "ise", "rad² s"), (1, "isf", "N² m² s")):
        ax[i].boxplot([[m[key] for m in mc[n]] for n in names])
        ax[i].set_xticks(range(1, len(names) + 1), names)
        ax[i].set_ylabel(f"{key.upper()} ({unit})")
        ax[i].set_title(f"003-U: {key.upper()} over {len(mc[names[0]])} runs")
        ax[i].grid(True, alpha=0.3)
    for n in names:
        ax[2].hist([m["cost"] for m in mc[n]], bins=20, alpha=0.6, label=n)
    ax[2].set_xlabel("J = ISE + 1e4 ISF (-)")
    ax[2].set_ylabel("runs")
    ax[2].legend()
    ax[2].grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "003-U.png", dpi=110)
    plt.close(fig)


def cmd_scenarios(args) -> None:
    t0 = time.time()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = tuned_params(Path(args.tuned))
    t_end = 20.0 if args.quick else T_END
    n_mc = args.runs if args.runs is not None else (4 if args.quick else 100)
    cases, keys = [], []
    for scen, pp in SCENARIOS.items():
        for name, model in CONTROLLERS.items():
            cases.append(Case(model, params[name], pp, t_end=t_end, signals=True, label=f"{scen} {name}"))
            keys.append((scen, name))
    res = run_many(cases, args.workers, "scenarios")
    rows, runs = [], {}
    for (scen, name), (m, sig) in zip(keys, res):
        runs[(scen, name)] = sig
        rows.append({"scenario": scen, "controller": name, **m})
        write_csv(out / f"{scen}_{name}.csv", sig, every=10)
    seeds = list(range(1, n_mc + 1))
    mc_cases, mc_keys = [], []
    for name, model in CONTROLLERS.items():
        for s in seeds:
            mc_cases.append(Case(model, params[name], uncertainty_scales(s), t_end=t_end))
            mc_keys.append((name, s))
    mc_res = run_many(mc_cases, args.workers, "003-U Monte Carlo")
    mc: dict[str, list] = {n: [] for n in CONTROLLERS}
    with open(out / "003-U_runs.csv", "w", newline="") as f:
        w = None
        for (name, s), (m, _) in zip(mc_keys, mc_res):
            row = {"controller": name, "seed": s, **uncertainty_scales(s), **m}
            mc[name].append(m)
            if w is None:
                w = csv.DictWriter(f, fieldnames=list(row))
                w.writeheader()
            w.writerow({k: repr(v) if isinstance(v, float) else v for k, v in row.items()})
    for name in CONTROLLERS:
        ise = np.array([m["ise"] for m in mc[name]])
        isf = np.array([m["isf"] for m in mc[name]])
        rows.append({"scenario": "003-U", "controller": name, "ise_mean": ise.mean(), "ise_std": ise.std(ddof=1) if len(ise) > 1 else 0.0,
                     "isf_mean": isf.mean(), "isf_std": isf.std(ddof=1) if len(isf) > 1 else 0.0, "runs": len(ise)})
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with open(out / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    plot_scenarios(runs, out)
    plot_monte_carlo(mc, out)
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
    print(f"wrote {out}/summary.csv, 003-U_runs.csv, per-run CSV and PNG ({time.time() - t0:.1f} s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("tune", help="GA tuning of k (GA-SMC), then of the fuzzy coefficients (T2F-SMC)")
    t.add_argument("--seed", type=int, default=1)
    t.add_argument("--workers", type=int, default=2)
    t.add_argument("--quick", action="store_true", help="population 4, 2 generations, 10 s runs (CI)")
    t.add_argument("--generations", type=int, default=None, help="override the number of generations (default 30)")
    t.add_argument("--out", default=None, help="JSON path (default scripts/paper003_tuned.json)")
    s = sub.add_parser("scenarios", help="003-N, -C, -S, -W and the 003-U Monte Carlo")
    s.add_argument("--workers", type=int, default=2)
    s.add_argument("--quick", action="store_true", help="20 s runs, 4 Monte Carlo runs (CI)")
    s.add_argument("--runs", type=int, default=None, help="Monte Carlo runs (default 100; 4 with --quick)")
    s.add_argument("--tuned", default=str(TUNED))
    s.add_argument("--out", default=str(OUT))
    args = ap.parse_args()
    {"tune": cmd_tune, "scenarios": cmd_scenarios}[args.cmd](args)


if __name__ == "__main__":
    main()
