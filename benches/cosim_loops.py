#!/usr/bin/env python3
"""Co-simulation loop speed, measured side by side in one run (docs/benchmarks.md, issue 9).

Loops: 2 FMUs (PdController + AttitudePlant, reference fixed at the paper 000 large command) and the
4-FMU run 000-6 of `scfmu run default` (AttitudeCommand + PdController + AttitudePlant +
AttitudeMetrics), Δ = 0.01 s, 3,000 communication steps. Per loop, µs per communication step of:

* reference: scfmu.engines.reference.CoSimulation (fmpy high-level calls, logging the scenario's signals);
* lean: scfmu.engines.lean.LeanMaster (logging), and without logging;
* minimal ctypes: the same FMI calls as straight-line Python code (generated, unrolled, no logging,
  no status checks): the floor of any master written in Python;
* native: scfmu.engines.native.NativeLoop, the loop inside fmpy's container FMU, logging every step (one
  fmi2DoStep + one fmi2GetReal from Python per step) and with no Python call per step (log_every=0);
* C floor: the lean master's exact call list run by a small C function (benches/cosim_floor.c,
  compiled here with cc): the cost of the FMUs themselves plus the FMI call overhead;
* libcosim: the same scenario on libcosim's fixed-step algorithm (simulate_until, last-value
  observer), for comparison (a Jacobi scheme: not the same results).

Only the stepping loop is timed (instantiation and initialization excluded); each figure is the
minimum over --repeat interleaved repetitions. With --campaign, also campaign throughput (runs/s of
the 30 s run 000-6 on the native path, warm workers) with 1 and 2 Dask workers.

* compiled: scfmu.engines.compiled.CompiledLoop, the lean master's plan with logging of every step run
  by the Rust library scfmu/engines/native_loop (cargo build --release);

With --run-cost, the cost of one campaign run (campaign.run_one, as a worker runs it, on the compiled and
on the native engine) against the native stepping of the same run without logging, side by side in this
process (issue 20), and the compiled loop's run with FMI 3.0 and Model Exchange units against the FMI 2.0
Co-Simulation units they replace (issue 34).

With --unit-cost (and --no-loops), only that last comparison.

Usage: .venv/bin/python benches/cosim_loops.py [--repeat 5] [--campaign] [--run-cost] [--unit-cost] [--runs 40] [--check]
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import os
import platform
import subprocess
import sys
import tempfile
import time
from ctypes import c_double, c_long, c_size_t, c_void_p
from pathlib import Path

from scfmu import scenario as scenarios
from scfmu.papers.paper000 import scenarios as p000_scenarios
from scfmu.engines.lean import LeanMaster
from scfmu.fmu import Fmu
from scfmu.engines.native import NativeLoop
from scfmu.scenario.model import Component, Scenario, log_of
from scfmu.engines.libcosim import run_libcosim
from scfmu.engines import reference_master

ROOT = Path(__file__).resolve().parents[1]


def two_fmu_scenario(stop_time=30.0) -> Scenario:
    c = p000_scenarios.COMMANDS["L"]
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": c[0], "ref_euler321_pitch": c[1], "ref_euler321_yaw": c[2]})
    qref = {f"controller.q_ref_{a}": cmd.get(f"q_ref_{a}") for a in "wxyz"}
    cmd.close()
    return Scenario("pd+plant", [Component("controller", "PdController", {"error_law": 0}),
                                 Component("plant", "AttitudePlant", {"max_internal_step": 0.01})],
                    stop_time, 0.01, log=log_of("plant", ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]),
                    inputs={**qref, **{f"controller.w_ref_{a}": 0.0 for a in "xyz"}})


def t_reference(sc):
    sim, fmus, log = reference_master(sc)
    t = time.perf_counter()
    sim.run(sc.stop_time, sc.step, log)
    dt = time.perf_counter() - t
    sim.close()
    return dt


def t_lean(sc, log=True):
    if not log:
        sc = sc.with_overrides(log={})
    with LeanMaster(sc) as m:
        t = time.perf_counter()
        m.run()
        return time.perf_counter() - t


def raw_ops(m: LeanMaster):
    """The lean master's propagation as (raw FMI 2.0 function, component, vr array, n, buffer) and its steps
    as (raw fmi2DoStep, component)."""
    ops = []
    for (kind, typ, inst, _v, _b, _o), (_fn, vrs, n, buf) in zip(m.plan_ops, m._ops):
        c = m.calls[inst]
        ops.append((c.fn[f"{kind}:{typ}"], c.comp, vrs, n, buf))
    return ops, [(m.calls[name].fn["step"], m.calls[name].comp) for name in m.fmus]


def unrolled(m: LeanMaster):
    """Straight-line Python for one communication step of the lean master's call list."""
    lines, env = [], {}
    ops, steps = raw_ops(m)
    for i, (fn, comp, vrs, n, buf) in enumerate(ops):
        env[f"f{i}"] = fn
        lines.append(f"f{i}({comp}, {vrs}, {n}, {buf})")
    for j, (fn, comp) in enumerate(steps):
        env[f"s{j}"] = fn
        lines.append(f"s{j}({comp}, t, dt, 1)")
    src = "def loop(n, t0, dt):\n    for k in range(n):\n        t = t0 + k * dt\n" + "".join(
        f"        {ln}\n" for ln in lines)
    exec(src, env)
    return env["loop"], len(lines)


def t_minimal(sc):
    with LeanMaster(sc.with_overrides(log={})) as m:
        loop, calls = unrolled(m)
        t = time.perf_counter()
        loop(m.n, sc.start_time, sc.step)
        return time.perf_counter() - t


_FLOOR = None


def floor_lib():
    global _FLOOR
    if _FLOOR is None:
        d = Path(tempfile.mkdtemp(prefix="scfmu_floor_"))
        so = d / "cosim_floor.so"
        subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(so), str(ROOT / "benches" / "cosim_floor.c")],
                       check=True)
        lib = ctypes.CDLL(str(so))
        lib.run_loop.argtypes = [c_void_p, c_size_t, c_long, c_double, c_double]
        lib.run_loop.restype = ctypes.c_int
        _FLOOR = lib
    return _FLOOR


class Op(ctypes.Structure):
    _fields_ = [("kind", ctypes.c_int), ("fn", c_void_p), ("component", c_void_p), ("vr", c_void_p),
                ("n", c_size_t), ("buf", c_void_p)]


def t_floor(sc):
    lib = floor_lib()
    with LeanMaster(sc.with_overrides(log={})) as m:
        raw, steps = raw_ops(m)
        ops = [Op(0, ctypes.cast(fn, c_void_p).value, comp, vrs, n, buf) for fn, comp, vrs, n, buf in raw]
        ops += [Op(2, ctypes.cast(fn, c_void_p).value, comp, None, 0, None) for fn, comp in steps]
        arr = (Op * len(ops))(*ops)
        t = time.perf_counter()
        st = lib.run_loop(arr, len(ops), m.n, sc.start_time, sc.step)
        dt = time.perf_counter() - t
        assert st <= 1, st
        return dt


def t_native(sc, log_every):
    with NativeLoop(sc, log_every=log_every) as m:
        t = time.perf_counter()
        m.run()
        return time.perf_counter() - t


def t_compiled(sc):
    from scfmu.engines.compiled import CompiledLoop
    with CompiledLoop(sc) as m:
        t = time.perf_counter()
        m.run()
        return time.perf_counter() - t


METHODS = [("reference master (fmpy, CoSimulation)", t_reference), ("lean master, logging", t_lean),
           ("lean master, no logging", lambda sc: t_lean(sc, False)), ("minimal ctypes loop (unrolled)", t_minimal),
           ("native container, logging every step", lambda sc: t_native(sc, 1)),
           ("native container, no Python per step", lambda sc: t_native(sc, 0)),
           ("compiled loop (scfmu/engines/native_loop), logging every step", t_compiled),
           ("C floor (same FMI calls from C)", t_floor),
           ("libcosim (libcosimpy; Jacobi coupling)", lambda sc: run_libcosim(sc)["wall_s"])]


def loops(repeat: int):
    scs = {"2 FMUs": two_fmu_scenario(), "4 FMUs (run 000-6)": scenarios.get("default")}
    best = {(ln, mn): float("inf") for ln in scs for mn, _ in METHODS}
    for _ in range(repeat):
        for ln, sc in scs.items():
            for mn, f in METHODS:
                best[(ln, mn)] = min(best[(ln, mn)], f(sc) / sc.n_steps * 1e6)
    calls = {ln: unrolled_calls(sc) for ln, sc in scs.items()}
    print("\n| loop (µs per communication step; ratio to the minimal ctypes loop) | "
          + " | ".join(f"{ln} ({calls[ln]} FMI calls/step)" for ln in scs) + " |")
    print("|---|" + "---:|" * len(scs))
    for mn, _ in METHODS:
        cells = []
        for ln in scs:
            us = best[(ln, mn)]
            cells.append(f"{us:.2f} µs ({us / best[(ln, 'minimal ctypes loop (unrolled)')]:.2f}×)")
        print(f"| {mn} | " + " | ".join(cells) + " |")
    return best


def unrolled_calls(sc):
    with LeanMaster(sc.with_overrides(log={})) as m:
        return len(m._ops) + len(m._steps)


def campaign_throughput(n_runs: int):
    from dask.distributed import Client, LocalCluster
    from scfmu import campaign
    sc = scenarios.get("default")
    sets = campaign.random_sample({"controller.wn": ("uniform", 0.5, 2.0)}, n_runs, 1)
    res = {}
    for nw in (1, 2):
        with LocalCluster(n_workers=nw, threads_per_worker=1, processes=True, dashboard_address=None,
                          host="127.0.0.1", silence_logs=logging.CRITICAL) as cl, Client(cl) as client:
            warm = campaign.Campaign(sc, [{}] * (2 * nw), seeds=[None])
            with tempfile.TemporaryDirectory() as d:
                campaign.run(warm, Path(d) / "w", client=client, progress=False, chunk=1)
                c = campaign.Campaign(sc, sets, seeds=[None])
                t = time.perf_counter()
                campaign.run(c, Path(d) / "c", client=client, progress=False)
                res[nw] = n_runs / (time.perf_counter() - t)
    print(f"\n| campaign: {n_runs} runs of run 000-6 (30 s, 3,001 samples, native path, metrics) | runs/s |")
    print("|---|---:|")
    print(f"| 1 Dask worker | {res[1]:.2f} |")
    print(f"| 2 Dask workers | {res[2]:.2f} ({res[2] / res[1]:.2f}× of 1 worker) |")
    return res


RUN_COST_TARGET = 1.5  # issue 34: a campaign run costs at most 1.5x the native stepping of the same run
UNIT_COST_TARGET = 1.2  # issue 34: an ME / FMI 3.0 unit costs at most 1.2x the FMI 2.0 CS unit it replaces


def _verdict(ratio: float, target: float) -> str:
    return f"{ratio:.2f}× ({'≤' if ratio <= target else '>'} {target}×: {'met' if ratio <= target else 'NOT met'})"


def campaign_cost(n_runs: int, repeat: int):
    """Side by side in this process: the native stepping of run 000-6 with no Python call per step
    (log_every=0), and one campaign run of it (``campaign.run_one``, what a worker does per run: scenario
    from the spec, overrides, instances from the pool, logging of the metric set's signals, metrics, row)
    on the compiled engine (the campaigns' default "auto" when its library is available) and on the
    native engine. Interleaved run by run (native stepping, compiled loop alone, campaign run on each
    engine, then the next run), so that both sides of a ratio see the same machine load; each figure is
    the minimum over ``repeat`` repetitions of the total over the ``n_runs`` runs. Returns the ratios."""
    from scfmu import campaign
    from scfmu.engines import compiled
    sc = scenarios.get("default")
    sets = campaign.random_sample({"controller.wn": ("uniform", 0.5, 2.0)}, n_runs, 1)
    engines = ["compiled", "native"] if compiled.available() else ["native"]
    specs = {e: campaign.Campaign(sc, sets, seeds=[None], engine=e).runs() for e in engines}
    for e in engines:
        campaign.run_one(specs[e][0])  # container built, unpacked, instances pooled
    inf = (float("inf"), float("inf"))
    step, stepc = inf, inf
    run = dict.fromkeys(engines, inf)

    def best(a, b):
        return min(a[0], b[0]), min(a[1], b[1])

    def add(a, b):
        return a[0] + b[0], a[1] + b[1]

    def timed(f):
        w, c = time.perf_counter(), time.process_time()
        f()
        return time.perf_counter() - w, time.process_time() - c

    def native_step():
        with NativeLoop(sc, log_every=0) as m:
            return timed(m.run)

    def compiled_alone():
        from scfmu.engines.compiled import CompiledLoop
        with CompiledLoop(sc) as m:
            return timed(m.run)

    def one(s):
        row, _ = campaign.run_one(s)
        assert row["status"] == "ok", row["message"]

    for _ in range(repeat):
        tot_step, tot_stepc, tot_run = (0.0, 0.0), (0.0, 0.0), dict.fromkeys(engines, (0.0, 0.0))
        for i in range(n_runs):
            tot_step = add(tot_step, native_step())
            if compiled.available():
                tot_stepc = add(tot_stepc, compiled_alone())
            for e in engines:
                tot_run[e] = add(tot_run[e], timed(lambda: one(specs[e][i])))
        step = best(step, (tot_step[0] / n_runs, tot_step[1] / n_runs))
        stepc = best(stepc, (tot_stepc[0] / n_runs, tot_stepc[1] / n_runs))
        for e in engines:
            run[e] = best(run[e], (tot_run[e][0] / n_runs, tot_run[e][1] / n_runs))
    print(f"\n| run 000-6 (3,000 steps), one process, mean of {n_runs} interleaved runs (min over {repeat}) "
          "| wall ms per run | CPU ms per run | wall µs per step |")
    print("|---|---:|---:|---:|")
    print(f"| native stepping, log_every=0 | {step[0] * 1e3:.2f} | {step[1] * 1e3:.2f} | {step[0] / sc.n_steps * 1e6:.2f} |")
    if compiled.available():
        print(f"| compiled loop alone, all 22 signals logged every step | {stepc[0] * 1e3:.2f} | {stepc[1] * 1e3:.2f} | "
              f"{stepc[0] / sc.n_steps * 1e6:.2f} |")
    for e in engines:
        print(f"| campaign run on the {e} engine (run_one, 1 worker's work) | {run[e][0] * 1e3:.2f} "
              f"({1 / run[e][0]:.1f} runs/s) | {run[e][1] * 1e3:.2f} | {run[e][0] / sc.n_steps * 1e6:.2f} |")
    ratios = {}
    for e in engines:
        ratios[e] = (run[e][0] / step[0], run[e][1] / step[1])
        print(f"| ratio campaign run ({e}) / native stepping | {_verdict(ratios[e][0], RUN_COST_TARGET)} (wall) | "
              f"{_verdict(ratios[e][1], RUN_COST_TARGET)} (CPU) | |")
    return ratios


def _unit_variants(base):
    """(label, plan, target label or None) of the unit-cost table: each Model Exchange or FMI 3.0 variant is
    compared with the FMI 2.0 Co-Simulation run that uses the same integration method (like with like)."""
    from scfmu.scenario.plan import build_plan
    f = ROOT / "fmus"
    out = []
    for label, ver, me, solver, plant, ref in [
            ("FMI 2.0 CS, plant RK4 at the communication step (reference)", "", False, None, {}, None),
            ("FMI 3.0 CS", "fmi3", False, None, {}, "FMI 2.0 CS, plant RK4 at the communication step (reference)"),
            ("FMI 2.0 plant ME, RK4 at the communication step", "", True, {"method": "RK4"}, {},
             "FMI 2.0 CS, plant RK4 at the communication step (reference)"),
            ("FMI 3.0 plant ME, RK4 at the communication step", "fmi3", True, {"method": "RK4"}, {},
             "FMI 2.0 CS, plant RK4 at the communication step (reference)"),
            ("FMI 2.0 CS, plant DP5(4) inside, tol 1e-8", "", False, None, {"integrator": 2}, None),
            ("FMI 2.0 plant ME, DP5(4) rtol = atol = 1e-8", "", True, {"rtol": 1e-8, "atol": 1e-8}, {},
             "FMI 2.0 CS, plant DP5(4) inside, tol 1e-8"),
            ("FMI 3.0 plant ME, DP5(4) rtol = atol = 1e-8", "fmi3", True, {"rtol": 1e-8, "atol": 1e-8}, {},
             "FMI 2.0 CS, plant DP5(4) inside, tol 1e-8"),
            ("FMI 2.0 plant ME, DP5(4) rtol 1e-10 (default)", "", True, {}, {}, None),
            ("accurate solution: FMI 2.0 CS, plant RK4 at step/20", "", False, None,
             {"max_internal_step": 0.0005}, None)]:
        d = f / ver if ver else f
        sc = base.with_models({"controller": str(d / "PdController.fmu"), "plant": str(d / "AttitudePlant.fmu")})
        if plant:
            sc = sc.with_overrides({f"plant.{k}": v for k, v in plant.items()})
        if solver:
            sc.component("plant").solver = dict(solver)
        out.append((label, build_plan(sc, model_exchange={"plant"} if me else frozenset()), ref))
    return out


def unit_cost(repeat: int):
    """Side by side in this process, the compiled loop's run 000-6 (3,000 steps, every signal logged) with
    the FMI 2.0 Co-Simulation PdController and AttitudePlant, with their FMI 3.0 Co-Simulation FMUs, and
    with the plant as a Model Exchange unit (FMI 2.0 and 3.0) under the loop's fixed-step RK4 (against the
    CS plant's own RK4 at the same step) and under its Dormand–Prince 5(4) (against the CS plant's own
    DP5(4) at the same tolerance). The variants run one after the other in each of ``repeat`` rounds, so
    that a variant and its CS run see the same machine load within a round. Per variant: the minimum over
    the rounds of the wall and CPU time; the ratio of the minimum CPU times to its CS run's; and the
    spread of the paired ratios (this round's CPU time over its CS run's in the same round: median, lowest
    and highest). The largest deviation of any logged signal from the FMI 2.0 CS run with the same method,
    and from an accurate solution (the CS plant's RK4 at a twentieth of the step), relative to the signal's
    range. Returns {label: (ratio of the minimum CPU times, median paired CPU ratio)} of the variants with
    a target; a target counts as met only when both are within it."""
    import numpy as np
    from scfmu.engines.compiled import CompiledLoop, available
    if not available():
        print("compiled loop library not available: cargo build --release")
        return {}
    variants = _unit_variants(scenarios.get("default"))
    results = {}
    for label, plan, _ in variants:
        with CompiledLoop(plan) as m:
            results[label] = m.run()

    def dev(a, b):
        return max(float(np.max(np.abs(a[s] - b[s])) / max(1e-300, np.max(np.abs(a[s])))) for s in a if s != "time")

    acc = results[variants[-1][0]]
    timed = variants[:-1]
    walls = {label: [] for label, _, _ in timed}
    cpus = {label: [] for label, _, _ in timed}
    for _ in range(repeat):
        for label, plan, _ in timed:
            with CompiledLoop(plan) as m:
                w, c = time.perf_counter(), time.process_time()
                m.run()
                w, c = time.perf_counter() - w, time.process_time() - c
            walls[label].append(w)
            cpus[label].append(c)
    print(f"\n| run 000-6 in the compiled loop (3,000 steps, 22 signals logged), min over {repeat} rounds | wall ms | "
          "CPU ms | ratio to its CS run (wall) | ratio to its CS run (CPU) | paired CPU ratio per round: median "
          "[lowest, highest] | deviation from its CS run | error (accurate solution) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    ratios = {}
    for label, _, ref in timed:
        w, c = min(walls[label]), min(cpus[label])
        if ref:
            rw, rc = w / min(walls[ref]), c / min(cpus[ref])
            paired = sorted(a / b for a, b in zip(cpus[label], cpus[ref]))
            med = float(np.median(paired))
            ratios[label] = (rc, med)
            cells = (f"{rw:.2f}× | {_verdict(rc, UNIT_COST_TARGET)} | {med:.2f}× [{paired[0]:.2f}, {paired[-1]:.2f}] | "
                     f"{dev(results[ref], results[label]):.1e}")
        else:
            cells = "— | — | — | —"
        print(f"| {label} | {w * 1e3:.2f} | {c * 1e3:.2f} | {cells} | {dev(acc, results[label]):.1e} |")
    return ratios


def _unit_missed(unit_ratios) -> list[str]:
    return [f"{lb}: {r[0]:.2f}× (minimum CPU times), median paired {r[1]:.2f}× > {UNIT_COST_TARGET}×"
            for lb, r in unit_ratios.items() if max(r) > UNIT_COST_TARGET]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--campaign", action="store_true")
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--no-loops", action="store_true", help="only the campaign throughput")
    ap.add_argument("--run-cost", action="store_true",
                    help="campaign run cost against native stepping, side by side in this process")
    ap.add_argument("--unit-cost", action="store_true",
                    help="only the FMI 3.0 / Model Exchange units against the FMI 2.0 CS units (part of --run-cost)")
    ap.add_argument("--check", action="store_true",
                    help="with --run-cost or --unit-cost: exit 1 when a target of issue 34 is not met")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, load average {load:.1f}, "
          f"Python {platform.python_version()}")
    if not args.no_loops:
        loops(args.repeat)
    if args.run_cost:
        run_ratios = campaign_cost(args.runs, args.repeat)
        unit_ratios = unit_cost(args.repeat)
        missed = [f"campaign run ({e}, {'wall' if k == 0 else 'CPU'}) {r[k]:.2f}× > {RUN_COST_TARGET}×"
                  for e, r in run_ratios.items() if e == "compiled" for k in (0, 1) if r[k] > RUN_COST_TARGET]
        missed += _unit_missed(unit_ratios)
        print("\ntargets (issue 34): campaign run on the default engine ≤ 1.5× native stepping (wall and CPU); "
              "ME / FMI 3.0 units ≤ 1.2× the CS run with the same method (CPU: the ratio of the minimum times "
              "and the median of the paired ratios): " + ("all met" if not missed else "NOT met: " + "; ".join(missed)))
        if args.check and missed:
            return 1
    elif args.unit_cost:
        missed = _unit_missed(unit_cost(args.repeat))
        print("\ntarget (issue 34): ME / FMI 3.0 units ≤ 1.2× the CS run with the same method (CPU: the ratio of "
              "the minimum times and the median of the paired ratios): "
              + ("met" if not missed else "NOT met: " + "; ".join(missed)))
        if args.check and missed:
            return 1
    if args.campaign:
        campaign_throughput(args.runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
