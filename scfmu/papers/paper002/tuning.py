"""Paper 002 PSO tuning on the campaign engine: every particle is one native-engine run of the declared
scenario ``paper002/<controller>`` with its gains as overrides; several swarms run in lockstep."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ... import campaign
from ... import fmu as fmu_access
from . import scenarios
from .model import BOUNDS, CONTROLLERS, PENALTY_LATE, PENALTY_NONFINITE, Pso, Scenario


# ----- particle evaluations on the campaign engine ---------------------------------------------------
def engine_scenario(controller: str, sc: Scenario = Scenario()):
    """The declared scenario ``paper002/<controller>`` for this setup (stop time, step, reference), with the
    plant and memory options of `sc` as overrides."""
    base = scenarios.paper002(controller, theta_ref_deg=sc.theta_ref_deg, stop_time=sc.t_end, step=sc.h)
    ov = {f"plant.{k}": v for k, v in sc.plant.items()}
    ov.update({"controller.gl_memory": sc.gl_memory, "controller.history_before_start": sc.history_before_start})
    return base.with_overrides(ov)


def gain_overrides(controller: str, x) -> dict:
    """Campaign overrides ``controller.<gain>`` for the tuned variables x of `controller`."""
    return {f"controller.{k}": float(v) for k, v in zip(CONTROLLERS[controller][1], x)}


def row_cost(row: dict) -> float:
    """PSO cost of a campaign row: its ``cost`` metric, or the non-finite cost for a failed run."""
    c = row.get("cost", math.nan)
    if row.get("status") != "ok" or not math.isfinite(c):
        return PENALTY_NONFINITE + PENALTY_LATE
    return float(c)


def _timed_chunk(specs: list[dict], fmu_dir: str) -> list[tuple[dict, float]]:
    """Worker task: campaign.run_one per spec, with the wall time of each run."""
    out = []
    for s in specs:
        t0 = time.perf_counter()
        row, _ = campaign.run_one(s, fmu_dir)
        out.append((row, time.perf_counter() - t0))
    return out


def engine_rows(batches: list[tuple[str, np.ndarray]], sc: Scenario = Scenario(), client=None,
                chunk: int = 4) -> list[list[tuple[dict, float]]]:
    """Evaluates particles on the campaign engine (native path): ``batches`` = [(controller, xs)], each xs a
    (particles × variables) array; every particle is one campaign run of ``paper002/<controller>`` with its
    gains as overrides. With a dask.distributed ``client`` the runs go to its workers in tasks of `chunk`
    runs (all batches at once); without, they run in this process. Returns, per batch, the (row, seconds)
    of each particle in order. Rows depend only on (scenario, overrides), never on the worker count."""
    fmu_dir = str(fmu_access.fmu_dir().resolve())
    specs = []
    for b, (c, xs) in enumerate(batches):
        camp = campaign.Campaign(engine_scenario(c, sc), [gain_overrides(c, x) for x in xs], engine="native")
        specs += [(b, s) for s in camp.runs()]
    if client is None:
        done = _timed_chunk([s for _, s in specs], fmu_dir)
    else:
        futs = [client.submit(_timed_chunk, [s for _, s in specs[i:i + chunk]], fmu_dir, pure=False)
                for i in range(0, len(specs), chunk)]
        done = [r for f in futs for r in f.result()]
    out: list[list] = [[] for _ in batches]
    for (b, _), r in zip(specs, done):
        out[b].append(r)
    return out


def engine_cost(controller: str, gains: dict, sc: Scenario = Scenario(), client=None) -> dict:
    """One gain set evaluated on the campaign engine: the run's row (metrics incl. ``cost``)."""
    x = [gains[k] for k in CONTROLLERS[controller][1]]
    row, _ = engine_rows([(controller, np.array([x]))], sc, client)[0][0]
    return row


def tune(controllers: list[str], sc: Scenario = Scenario(), n_particles: int = 30, max_iter: int = 400,
         seed: int = 2, client=None, checkpoint: Path | None = None, deadline: float | None = None,
         progress: bool = True, on_round=None, **pso_kw) -> dict:
    """PSO tuning of several controllers in lockstep on the campaign engine: each iteration, the particles
    of every swarm still running are evaluated as one batch of campaign runs (``engine_rows``), so the
    workers stay busy while swarms stop at different iterations. Controller c gets the seed
    ``seed + index of c in CONTROLLERS`` (PD 2, PID 3, FOPD 4, FOPID 5 by default) whichever subset runs.

    `checkpoint`: JSON file written after every iteration (swarm states, generator states, run times);
    an existing checkpoint of the same set-up (and the same FMU builds) is resumed. `deadline`: a time.time() value; no iteration
    starts after it (the result then says ``stop = "deadline"``). Returns {controller: result dict}."""
    setup = {"controllers": list(controllers), "scenario": {"theta_ref_deg": sc.theta_ref_deg, "t_end": sc.t_end,
             "h": sc.h, "plant": sc.plant, "gl_memory": sc.gl_memory, "history_before_start": sc.history_before_start},
             "n_particles": n_particles, "max_iter": max_iter, "seed": seed, "pso": pso_kw,
             # a checkpoint made with other FMU builds is not resumed (costs from two builds never mix)
             "fmus": {m: fmu_access.fmu_digest(fmu_access.fmu_path(m))
                      for m in ("SingleAxisPlant", "PidController", "FopidController")}}
    swarms, info = {}, {}
    if checkpoint is not None and Path(checkpoint).exists():
        ck = json.loads(Path(checkpoint).read_text())
        if ck.get("setup") == json.loads(json.dumps(setup)):
            swarms = {c: Pso.from_state(st) for c, st in ck["swarms"].items()}
            info = ck["info"]
    for c in controllers:
        if c not in swarms:
            var = CONTROLLERS[c][1]
            swarms[c] = Pso([BOUNDS[v][0] for v in var], [BOUNDS[v][1] for v in var], n_particles, max_iter,
                            seed + list(CONTROLLERS).index(c), **pso_kw)
            info[c] = {"run_seconds": 0.0, "wall_seconds": 0.0, "stop": None}
    bar = tqdm(total=max_iter, initial=min(s.it for s in swarms.values()), desc="PSO " + ",".join(controllers),
               disable=not progress)
    t_last = time.perf_counter()
    try:
        while True:
            active = [c for c in controllers if not swarms[c].done]
            if not active:
                break
            if deadline is not None and time.time() >= deadline:
                for c in active:
                    info[c]["stop"] = "deadline"
                break
            res = engine_rows([(c, swarms[c].positions()) for c in active], sc, client)
            now = time.perf_counter()
            for c, rows in zip(active, res):
                swarms[c].tell([row_cost(r) for r, _ in rows])
                info[c]["run_seconds"] += sum(t for _, t in rows)
                info[c]["wall_seconds"] += now - t_last
                if swarms[c].done:
                    info[c]["stop"] = "stall" if swarms[c].stalled else "max_iter"
            t_last = now
            if checkpoint is not None:
                tmp = Path(str(checkpoint) + ".tmp")
                tmp.write_text(json.dumps({"setup": setup, "swarms": {c: s.state() for c, s in swarms.items()},
                                           "info": info}))
                tmp.replace(checkpoint)
            bar.n = max(s.it for s in swarms.values())
            bar.set_postfix_str(" ".join(f"{c}:{swarms[c].best_cost:.6g}" for c in controllers))
            if on_round is not None:
                on_round(swarms, info)
    finally:
        bar.close()
    out = {}
    for c in controllers:
        s = swarms[c]
        out[c] = {"x": s.best_x, "gains": dict(zip(CONTROLLERS[c][1], s.best_x)), "cost": s.best_cost,
                  "iterations": s.it, "evaluations": s.it * n_particles, "history": s.history,
                  "stalled": s.stalled, "stop": info[c]["stop"], "seed": s.cfg["seed"],
                  "run_seconds": info[c]["run_seconds"], "wall_seconds": info[c]["wall_seconds"]}
    return out
