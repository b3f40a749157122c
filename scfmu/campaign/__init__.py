"""Campaigns: one scenario × a list/grid/random sample of parameter overrides × seeds → one row of
metrics per run (plus optional time series), run on Dask.

    from scfmu import campaign, scenario
    c = campaign.Campaign(scenario.get("default"), campaign.grid({"controller.wn": [0.5, 1.0, 2.0]}), seeds=[0])
    table = campaign.run(c, "out/campaign/wn")            # LocalCluster on this machine
    table = campaign.run(c, "out/x", scheduler="tcp://host:8786")   # an existing Dask cluster

Runs are numbered ``run = i_override * len(seeds) + i_seed`` and each run's result depends only on its
scenario, overrides and seed, so the rows are identical whatever the number of workers or the order in
which runs finish (results are sorted by ``run``). A run that fails (FMU error status, non-finite
value, bad parameter, any exception) becomes a row with ``status`` ≠ "ok" and the ``message``; the
campaign goes on.

Output folder:

* ``manifest.json``: scenario (plain data), overrides, seeds, engine (``"auto"``, the default: the
  compiled engine where its library is available, else the native one, with the same rows), FMU GUIDs and SHA-256, package
  versions, and a hash of the scenario, overrides, seeds and engine (``campaign_id``);
* ``parts/rows-*.parquet``: rows as they complete (written every ``flush_every`` rows), so an
  interrupted campaign resumes: ``run()`` on the same folder skips the runs already written (a folder
  holding a different campaign, or this one run with other FMU builds (GUID or SHA-256 of any FMU
  differs), is refused unless ``overwrite=True``, which starts afresh);
* ``results.parquet``: all rows sorted by ``run`` (written at the end);
* ``timeseries/run-<run>.parquet`` when ``timeseries`` is set (logged keys, every ``ts_every``-th sample).

A worker process that dies during a task (e.g. a crash inside an FMU's native code) makes Dask retry the
task; if it keeps failing, its runs (and those of tasks lost with it) are retried one at a time after
the others, and a run that still kills its worker gets a row with status ``worker_error``.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import logging
import math
import os
import platform
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import fmu as fmu_access
from .. import metrics as run_metrics
from ..engines import SimulationError, resolve_engine, simulate
from ..scenario.plan import build_plan
from ..scenario.model import Scenario
from ..scenario.resolve import unbound_slots

ROW_FIXED = ("run", "override_index", "seed", "status", "message")


# ----- parameter sets --------------------------------------------------------------------------------
def grid(axes: dict) -> list[dict]:
    """Full factorial: {"a.x": [1, 2], "b.y": [3, 4]} → 4 override dicts (last axis fastest)."""
    keys = list(axes)
    return [dict(zip(keys, vals)) for vals in itertools.product(*(axes[k] for k in keys))]


def random_sample(space: dict, n: int, seed: int = 0) -> list[dict]:
    """n override dicts drawn with numpy's PCG64(seed). ``space[name]`` is ("uniform", lo, hi),
    ("loguniform", lo, hi), ("normal", mean, std), ("choice", [values]) or ("int", lo, hi_inclusive).
    Parameters are drawn in the order of ``space``, sample by sample."""
    rng = np.random.Generator(np.random.PCG64(seed))
    out = []
    for _ in range(n):
        d = {}
        for k, spec in space.items():
            kind = spec[0]
            if kind == "uniform":
                d[k] = float(rng.uniform(spec[1], spec[2]))
            elif kind == "loguniform":
                d[k] = float(math.exp(rng.uniform(math.log(spec[1]), math.log(spec[2]))))
            elif kind == "normal":
                d[k] = float(rng.normal(spec[1], spec[2]))
            elif kind == "choice":
                d[k] = spec[1][int(rng.integers(len(spec[1])))]
            elif kind == "int":
                d[k] = int(rng.integers(spec[1], spec[2] + 1))
            else:
                raise ValueError(f"{k}: unknown distribution {kind!r}")
        out.append(d)
    return out


@dataclass
class Campaign:
    scenario: Scenario
    overrides: list = field(default_factory=lambda: [{}])
    seeds: list = field(default_factory=lambda: [None])
    engine: str = "auto"  # "auto" (compiled if available, else native: same rows), "compiled", "native", "lean", "reference"
    timeseries: list | None = None  # log keys to keep per run (None: metrics only; [] : all logged keys)
    ts_every: int = 1
    log_every: int = 1  # native engine: read the logged signals every n-th step (metrics see that grid)
    isolate: bool | None = None  # each run in a child process; None: when a unit is a foreign FMU (a path)
    timeout: float = 600.0  # wall-time limit of an isolated run [s]; past it the run is stopped: status "timeout"

    def isolated(self) -> bool:
        if self.isolate is not None:
            return bool(self.isolate)
        return any(fmu_access.is_path(c.model) for c in self.scenario.components)

    def foreign_files(self) -> dict:
        """``{path: SHA-256}`` of the units given as FMU files (shipped to the workers with the runs)."""
        return {c.model: fmu_access.fmu_digest(fmu_access.fmu_path(c.model))
                for c in self.scenario.components if fmu_access.is_path(c.model)}

    def runs(self) -> list[dict]:
        sc = self.scenario.to_dict()
        files = self.foreign_files()
        iso = self.isolated()
        limits = fmu_access.archive_limits().to_dict()  # the client's archive limits hold on every worker
        out = []
        for i, ov in enumerate(self.overrides):
            for j, seed in enumerate(self.seeds):
                out.append({"run": i * len(self.seeds) + j, "override_index": i, "overrides": dict(ov),
                            "seed": seed, "scenario": sc, "engine": self.engine, "timeseries": self.timeseries,
                            "ts_every": self.ts_every, "log_every": self.log_every, "fmu_files": files,
                            "isolate": iso, "timeout": float(self.timeout), "archive_limits": limits})
        return out

    def describe(self) -> dict:
        return {"scenario": self.scenario.to_dict(), "overrides": [dict(o) for o in self.overrides],
                "seeds": list(self.seeds), "engine": self.engine, "timeseries": self.timeseries,
                "ts_every": self.ts_every, **({"log_every": self.log_every} if self.log_every != 1 else {}),
                **({"isolate": self.isolate} if self.isolate is not None else {})}

    def campaign_id(self) -> str:
        return hashlib.sha256(json.dumps(self.describe(), sort_keys=True, default=str).encode()).hexdigest()[:16]


# ----- one run (executes on a worker) ----------------------------------------------------------------
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
    try:
        if spec.get("archive_limits"):
            fmu_access.set_archive_limits(spec["archive_limits"])
        spec = _materialize(spec, blobs)
    except Exception as e:
        return _failed_row(spec, "error", f"{type(e).__name__}: {e}"), None
    if spec.get("isolate") and hasattr(os, "fork"):
        return _run_isolated(spec, fmu_dir)
    return _run_body(spec, fmu_dir)


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
    """``_run_body`` in a forked child; the result comes back pickled through a pipe. A child that dies
    (e.g. a segmentation fault inside an FMU) gives status ``crash`` with the signal; one that gives no
    result within ``spec["timeout"]`` seconds is killed: status ``timeout``."""
    import pickle
    import select
    import signal
    rfd, wfd = os.pipe()
    pid = os.fork()
    if pid == 0:  # child: run, send, exit without running the parent's cleanup handlers
        code = 0
        try:
            os.close(rfd)
            data = pickle.dumps(_run_body(spec, fmu_dir))
            with os.fdopen(wfd, "wb") as w:
                w.write(data)
        except BaseException:
            code = 3
        finally:
            os._exit(code)
    os.close(wfd)
    chunks, deadline = [], time.monotonic() + float(spec.get("timeout", 600.0))
    timed_out = False
    with os.fdopen(rfd, "rb") as r:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                timed_out = True
                break
            ready, _, _ = select.select([r], [], [], min(left, 1.0))
            if ready:
                b = os.read(r.fileno(), 1 << 20)
                if not b:
                    break
                chunks.append(b)
    if timed_out:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    _, status = os.waitpid(pid, 0)
    if timed_out:
        return _failed_row(spec, "timeout", f"no result within {spec.get('timeout', 600.0):g} s of wall time: "
                                            f"the run was stopped (a unit that hangs?)"), None
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        name = signal.Signals(sig).name if sig in signal.Signals._value2member_map_ else str(sig)
        return _failed_row(spec, "crash", f"the run's process died with {name} (a crash inside a unit's native "
                                          f"code)"), None
    try:
        return pickle.loads(b"".join(chunks))
    except Exception:
        return _failed_row(spec, "crash", f"the run's process exited with code {os.WEXITSTATUS(status)} and no "
                                          f"result"), None


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
            # which hosts Co-Simulation units only
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


def _crash_row(spec: dict, c: "Campaign", e: Exception) -> dict:
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


# ----- manifest, storage ------------------------------------------------------------------------------
def package_versions() -> dict:
    from importlib import metadata
    out = {"python": platform.python_version()}
    for p in ("fmpy", "numpy", "dask", "distributed", "pyarrow", "tqdm"):
        try:
            out[p] = metadata.version(p)
        except metadata.PackageNotFoundError:
            pass
    return out


def fmu_versions(scenario: Scenario) -> dict:
    """Per unit: GUID and SHA-256 (and, for a foreign FMU given by path, its model name and file)."""
    out = {}
    for c in scenario.components:
        p = fmu_access.fmu_path(c.model)
        md = fmu_access.unpacked(p)[0]
        entry = {"guid": md.guid, "sha256": fmu_access.fmu_digest(p)}
        if fmu_access.is_path(c.model):
            entry.update(model_name=md.modelName, file=str(p), instance=c.name)
        out[c.model] = entry
    return out


def _row_columns(c: Campaign) -> list[str]:
    keys = []
    for o in c.overrides:
        for k in o:
            if k not in keys:
                keys.append(k)
    return list(ROW_FIXED) + [f"p:{k}" for k in keys] + run_metrics.columns(c.scenario.metrics)


def _table(rows: list[dict], columns: list[str]):
    import pyarrow as pa
    data = {}
    for col in columns:
        vals = [r.get(col) for r in rows]
        if col in ("run", "override_index", "seed"):
            data[col] = pa.array(vals, pa.int64())
        elif col in ("status", "message"):
            data[col] = pa.array(vals, pa.string())
        elif col.startswith("p:"):
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) or v is None for v in vals):
                data[col] = pa.array([None if v is None else float(v) for v in vals], pa.float64())
            else:
                data[col] = pa.array([None if v is None else str(v) for v in vals], pa.string())
        else:
            data[col] = pa.array([math.nan if v is None else float(v) for v in vals], pa.float64())
    return pa.table(data)


def read_results(out_dir: str | Path):
    """All rows written so far (final results.parquet, or the parts of an unfinished campaign), sorted by run."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    out_dir = Path(out_dir)
    final = out_dir / "results.parquet"
    if final.exists():
        return pq.read_table(final)
    parts = sorted((out_dir / "parts").glob("rows-*.parquet"))
    if not parts:
        return None
    t = pa.concat_tables([pq.read_table(p) for p in parts], promote_options="default")
    return t.sort_by("run")


def read_timeseries(out_dir: str | Path, run: int) -> dict:
    import pyarrow.parquet as pq
    t = pq.read_table(Path(out_dir) / "timeseries" / f"run-{run:06d}.parquet")
    return {k: t.column(k).to_numpy() for k in t.column_names}


def _write_ts(out_dir: Path, run: int, ts: dict) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq
    d = out_dir / "timeseries"
    d.mkdir(exist_ok=True)
    tmp = d / f".run-{run:06d}.parquet.tmp"
    pq.write_table(pa.table({k: np.asarray(v) for k, v in ts.items()}), tmp)
    os.replace(tmp, d / f"run-{run:06d}.parquet")


class _Writer:
    def __init__(self, out_dir: Path, columns: list[str], flush_every: int):
        self.dir = out_dir / "parts"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.columns = columns
        self.flush_every = flush_every
        self.buf: list[dict] = []
        existing = [int(p.stem.split("-")[1]) for p in self.dir.glob("rows-*.parquet")]
        self.n = max(existing) + 1 if existing else 0  # never reuse the name of a part already written

    def add(self, row: dict) -> None:
        self.buf.append(row)
        if len(self.buf) >= self.flush_every:
            self.flush()

    def flush(self) -> None:
        import pyarrow.parquet as pq
        if not self.buf:
            return
        tmp = self.dir / f".rows-{self.n:06d}.tmp"
        pq.write_table(_table(self.buf, self.columns), tmp)
        os.replace(tmp, self.dir / f"rows-{self.n:06d}.parquet")  # a part is either complete or absent
        self.n += 1
        self.buf = []


# ----- running ------------------------------------------------------------------------------------------
def _client(scheduler: str | None, n_workers: int | None):
    """(Client, LocalCluster or None): a client of the cluster at ``scheduler``, or of a new local cluster
    of ``n_workers`` single-threaded worker processes. Workers import this package as installed in their
    environment (``pip install`` it on the machines of a remote cluster, with the same version)."""
    from dask.distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler), None
    # The worker processes start with SIGINT ignored (a disposition they inherit and keep): Ctrl-C in a
    # terminal reaches the whole process group, and only this process should act on it, by closing the
    # cluster (run()'s finally) instead of each worker dying with its own traceback.
    import signal
    import threading
    main = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        cluster = LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=None, host="127.0.0.1",
                               silence_logs=logging.CRITICAL)
    finally:
        if main:
            signal.signal(signal.SIGINT, old)
    return Client(cluster), cluster


def run(c: Campaign, out_dir: str | Path, scheduler: str | None = None, n_workers: int | None = None,
        chunk: int | None = None, progress: bool = True, overwrite: bool = False, flush_every: int = 20,
        client=None):
    """Runs the campaign (resuming from what ``out_dir`` already holds); returns the results as a
    pyarrow Table sorted by ``run``. ``client``: an existing dask.distributed Client to use as is."""
    import pyarrow.parquet as pq
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cid = c.campaign_id()
    man_path = out_dir / "manifest.json"
    fmus = fmu_versions(c.scenario)
    if man_path.exists():
        old = json.loads(man_path.read_text())
        # Rows made with other FMU builds (any change of a binary or modelDescription) must not be mixed
        # with new ones: such a folder counts as another campaign.
        other = (f"another campaign ({old.get('campaign_id')} ≠ {cid})" if old.get("campaign_id") != cid else
                 "this campaign run with other FMU builds "
                 f"({', '.join(sorted(m for m in fmus if old.get('fmus', {}).get(m) != fmus[m]))} changed)"
                 if old.get("fmus") != fmus else None)
        if other:
            if not overwrite:
                raise RuntimeError(f"{out_dir} holds {other}; choose another folder or overwrite")
            import shutil
            for sub in ("parts", "timeseries"):
                shutil.rmtree(out_dir / sub, ignore_errors=True)
            (out_dir / "results.parquet").unlink(missing_ok=True)
    specs = c.runs()
    manifest = {"campaign_id": cid, **c.describe(), "n_runs": len(specs), "fmus": fmus,
                "unbound_slot_values": [u.text() for u in unbound_slots(c.scenario)],
                "engine_used": ("native" if c.log_every != 1 else resolve_engine("auto")) if c.engine == "auto" else c.engine,
                "packages": package_versions(), "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "row_columns": _row_columns(c)}
    if man_path.exists():
        manifest["created"] = json.loads(man_path.read_text()).get("created", manifest["created"])
    man_path.write_text(json.dumps(manifest, indent=1, default=str))
    (out_dir / "results.parquet").unlink(missing_ok=True)

    done_table = read_results(out_dir)
    done = set()
    if done_table is not None:
        for r, st in zip(done_table.column("run").to_pylist(), done_table.column("status").to_pylist()):
            # a successful run whose time series file is missing is redone
            if c.timeseries is None or st != "ok" or (out_dir / "timeseries" / f"run-{r:06d}.parquet").exists():
                done.add(r)
    todo = [s for s in specs if s["run"] not in done]
    columns = _row_columns(c)
    writer = _Writer(out_dir, columns, flush_every)
    t0 = time.time()
    if todo:
        own_client = client is None
        cluster = None
        if own_client:
            client, cluster = _client(scheduler, n_workers)
        try:
            n_w = max(1, len(client.nthreads()))
            size = chunk or max(1, min(8, len(todo) // (4 * n_w)))
            chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
            fmu_dir = str(fmu_access.fmu_dir().resolve())
            # foreign FMUs travel with the runs: workers that do not share this machine's folders get the bytes
            files = c.foreign_files()
            blobs = (client.scatter([{sha: Path(path).read_bytes() for path, sha in files.items()}], broadcast=True)[0]
                     if files else None)
            from dask.distributed import as_completed
            chunk_of = {}
            futures = []
            for ch in chunks:
                f = client.submit(run_chunk, ch, fmu_dir, blobs, pure=False)
                chunk_of[f.key] = ch
                futures.append(f)
            bar = None
            if progress:
                from tqdm import tqdm
                bar = tqdm(total=len(specs), initial=len(specs) - len(todo), unit="run", desc=c.scenario.name,
                           file=sys.stderr, dynamic_ncols=True)
            try:
                suspects = []

                def take(results):
                    for row, ts in results:
                        if ts is not None:
                            _write_ts(out_dir, row["run"], ts)
                        writer.add(row)
                        if bar is not None:
                            bar.update(1)
                            if row["status"] != "ok":
                                bar.set_postfix_str(f"failed: {row['run']}", refresh=False)

                for fut in as_completed(futures):
                    try:
                        results = fut.result()
                    except Exception:  # the worker died (e.g. a crash inside an FMU) or was lost
                        suspects.extend(chunk_of[fut.key])  # also innocent tasks queued on that worker
                        continue
                    take(results)
                # runs of failed tasks again, one at a time, so that only a run that kills its worker fails
                for spec in sorted(suspects, key=lambda s: s["run"]):
                    try:
                        results = client.submit(run_chunk, [spec], fmu_dir, blobs, pure=False).result()
                    except Exception as e:
                        results = [(_crash_row(spec, c, e), None)]
                    take(results)
            finally:
                writer.flush()
                if bar is not None:
                    bar.close()
        finally:
            if own_client:
                client.close()
                if cluster is not None:
                    cluster.close()
    table = read_results(out_dir)
    table = table.select([col for col in columns if col in table.column_names])
    # one row per run, sorted (a run redone for its missing time series may appear twice in the parts)
    runs = table.column("run").to_pylist()
    keep = sorted({r: i for i, r in enumerate(runs)}.values(), key=lambda i: runs[i])
    table = table.take(keep)
    pq.write_table(table, out_dir / "results.parquet")
    manifest["wall_s_last_session"] = round(time.time() - t0, 3)
    manifest["n_ok"] = int(sum(1 for s in table.column("status").to_pylist() if s == "ok"))
    man_path.write_text(json.dumps(manifest, indent=1, default=str))
    return table
