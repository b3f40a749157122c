"""One campaign run, as a worker executes it: the spec's scenario with the run's overrides and seed, the
foreign FMUs materialized on this machine, the simulation (isolated in a child process when asked) and
the run's row of metrics (plus its time series). A failing run becomes a row with a status, never an
exception."""

from __future__ import annotations

import json
import math
import os
import traceback
from pathlib import Path

import numpy as np

from .. import fmu as fmu_access
from .. import metrics as run_metrics
from ..fmu import isolate
from ..engines import SimulationError, resolve_engine, simulate
from ..scenario.model import Scenario
from ..scenario.plan import build_plan

FMU_CACHE = Path(os.environ.get("SCFMU_FMU_CACHE", Path.home() / ".cache" / "scfmu" / "fmus"))


def _materialize(spec: dict, blobs: dict | None) -> dict:
    """The spec with each foreign FMU (``spec["fmu_files"]``: path -> SHA-256) pointing at a file with that
    content on this machine: the same path when it holds those bytes, else a copy written from ``blobs``
    (SHA-256 -> bytes, shipped by the client) into the worker's FMU cache."""
    files = spec.get("fmu_files") or {}
    if not files:
        return spec
    spec = dict(spec, scenario=json.loads(json.dumps(spec["scenario"])))
    for comp in spec["scenario"]["components"]:
        sha = files.get(comp["model"])
        if sha is None:
            continue
        p = Path(comp["model"])
        if p.is_file() and fmu_access.fmu_digest(p) == sha:
            continue
        local = FMU_CACHE / sha[:24] / p.name
        if not local.is_file():
            if not blobs or sha not in blobs:
                raise FileNotFoundError(f"{comp['model']} is not on this worker and was not shipped with the runs")
            local.parent.mkdir(parents=True, exist_ok=True)
            tmp = local.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_bytes(blobs[sha])
            os.replace(tmp, local)
        comp["model"] = str(local)
    return spec


def run_one(spec: dict, fmu_dir: str | None = None, blobs: dict | None = None) -> tuple[dict, dict | None]:
    """Simulates one run; returns (row, time series or None). Never raises for a failing simulation.
    An isolated run (``spec["isolate"]``) executes in a child process with a wall-time limit, so a unit
    that crashes or hangs costs that run only (status ``crash`` or ``timeout``)."""
    if os.environ.get("SCFMU_CRASH_TEST_RUN") == str(spec["run"]):  # test hook: a worker that dies mid-run
        os._exit(70)
    # the client's archive limits hold for this run only: a run in the client's own process (a local
    # campaign, a notebook) must not freeze them for whatever that process extracts afterwards
    limits, before = spec.get("archive_limits"), None
    try:
        try:
            if limits:
                before = fmu_access.set_archive_limits(limits)
            spec = _materialize(spec, blobs)
        except Exception as e:
            return _failed_row(spec, "error", f"{type(e).__name__}: {e}"), None
        if spec.get("isolate") and isolate.available():
            return _run_isolated(spec, fmu_dir)
        return _run_body(spec, fmu_dir)
    finally:
        if limits:
            fmu_access.set_archive_limits(before)


def _failed_row(spec: dict, status: str, message: str) -> dict:
    base = Scenario.from_dict(spec["scenario"])
    row = {"run": spec["run"], "override_index": spec["override_index"],
           "seed": -1 if spec["seed"] is None else int(spec["seed"]), "status": status, "message": message[:2000]}
    for k, v in spec["overrides"].items():
        row[f"p:{k}"] = v
    for k in run_metrics.columns(base.metrics):
        row[k] = math.nan
    return row


def _run_isolated(spec: dict, fmu_dir: str | None) -> tuple[dict, dict | None]:
    """``_run_body`` in a forked child (scfmu.fmu.isolate): a child that dies (e.g. a segmentation fault
    inside an FMU) gives status ``crash`` with the signal; one that gives no result within
    ``spec["timeout"]`` seconds is killed: status ``timeout``."""
    limit = float(spec.get("timeout", 600.0))
    kind, value = isolate.in_child(lambda: _run_body(spec, fmu_dir), limit)
    if kind == "timeout":
        return _failed_row(spec, "timeout", f"no result within {limit:g} s of wall time: the run was stopped "
                                            f"(a unit that hangs?)"), None
    if kind == "crash" and value.startswith("exit code"):
        return _failed_row(spec, "crash", f"the run's process exited with {value} and no result"), None
    if kind == "crash":
        return _failed_row(spec, "crash", f"the run's process died with {value} (a crash inside a unit's native "
                                          f"code)"), None
    return value


def _run_body(spec: dict, fmu_dir: str | None = None) -> tuple[dict, dict | None]:
    if fmu_dir:
        fmu_access.set_fmu_dir(fmu_dir)
    base = Scenario.from_dict(spec["scenario"])
    row = {"run": spec["run"], "override_index": spec["override_index"],
           "seed": -1 if spec["seed"] is None else int(spec["seed"]), "status": "ok", "message": ""}
    for k, v in spec["overrides"].items():
        row[f"p:{k}"] = v
    ts = None
    metric_cols = run_metrics.columns(base.metrics)
    try:
        sc = base.with_overrides(spec["overrides"])  # a copy: the spec's scenario stays as it is
        if spec["seed"] is not None:
            sc = sc.with_seed(spec["seed"])
        sc.log = _log_kept(sc, spec["timeseries"])
        every = max(1, int(spec.get("log_every", 1)))
        engine = spec["engine"]
        plan = build_plan(sc)  # the run's one plan (the scenario resolved once)
        if engine == "auto":  # the compiled loop logs every step; a coarser log grid is the native engine's,
            # except with Model Exchange units, which the compiled loop integrates directly (native would nest
            # each as its Co-Simulation face, scfmu.engines.cs_face)
            engine = resolve_engine("auto") if every == 1 or plan.model_exchange else "native"
        kw = {"log_every": every} if engine == "native" else {}
        r = simulate(plan, engine, **kw)
        m = run_metrics.compute(sc.metrics, r)
        for k in metric_cols:
            row[k] = float(m.get(k, math.nan))
        if spec["timeseries"] is not None:
            keys = ["time"] + (list(spec["timeseries"]) or [k for k in r if k != "time"])
            e = max(1, int(spec["ts_every"]))
            idx = np.arange(0, len(r["time"]), e)
            if idx[-1] != len(r["time"]) - 1:
                idx = np.append(idx, len(r["time"]) - 1)
            ts = {k: np.asarray(r[k])[idx] for k in keys}
    except SimulationError as e:
        row["status"], row["message"] = e.status, str(e)[:2000]
    except (KeyError, ValueError, TypeError) as e:
        row["status"], row["message"] = "bad_input", f"{type(e).__name__}: {e}"[:2000]
    except Exception as e:  # an FMU that refuses to initialize, etc.
        row["status"] = "error"
        row["message"] = (f"{type(e).__name__}: {e}" + "".join(traceback.format_exception_only(e))[-500:])[:2000]
    for k in metric_cols:
        row.setdefault(k, math.nan)
    return row, ts


def _log_kept(sc: Scenario, timeseries) -> dict:
    """The scenario's log restricted to what the run's row and time series read: the keys of its metric
    set (``metrics.logs_needed``; None: all) plus the time series' keys ([]: all). Fewer logged signals
    change no value (each FMU output is read at the same points whatever else is read), only the cost."""
    need = run_metrics.logs_needed(sc.metrics)
    if need is None or (timeseries is not None and not list(timeseries)):
        return sc.log
    keep = set(need) | set(timeseries or ())
    return {k: v for k, v in sc.log.items() if k in keep}


def _crash_row(spec: dict, c, e: Exception) -> dict:
    """The row of a run that killed its worker every time it was tried (``c``: the Campaign)."""
    row = {"run": spec["run"], "override_index": spec["override_index"],
           "seed": -1 if spec["seed"] is None else int(spec["seed"]), "status": "worker_error",
           "message": f"{type(e).__name__}: {e}"[:2000]}
    for k, v in spec["overrides"].items():
        row[f"p:{k}"] = v
    for k in run_metrics.columns(c.scenario.metrics):
        row[k] = math.nan
    return row


def run_chunk(specs: list[dict], fmu_dir: str | None = None, blobs: dict | None = None) -> list[tuple[dict, dict | None]]:
    return [run_one(s, fmu_dir, blobs) for s in specs]

