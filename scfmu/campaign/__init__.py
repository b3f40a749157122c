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
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import fmu as fmu_access
from ..engines import resolve_engine
from ..scenario.model import Scenario
from ..scenario.resolve import unbound_slots
from . import runs as _runs
from .runs import FMU_CACHE, run_chunk, run_one  # noqa: F401  (the worker side, re-exported)
from .storage import (ROW_FIXED, _row_columns, _Writer, _write_ts, fmu_versions,  # noqa: F401
                      package_versions, read_results, read_timeseries)


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
    # This process ignores it too while the workers start, so a Ctrl-C then is seen by a watcher process
    # (_CtrlCWatcher) in the same process group, and acted on as soon as the cluster stands.
    import signal
    import threading
    main = threading.current_thread() is threading.main_thread()
    watcher = _CtrlCWatcher() if main and signal.getsignal(signal.SIGINT) is signal.default_int_handler else None
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    cluster = None
    try:
        cluster = LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=None, host="127.0.0.1",
                               # no dashboard; the scheduler's HTTP routes on a free local port, not 8787:
                               # a second campaign (or any Dask) on the machine holds 8787, and Dask would
                               # print a port warning into the command's one-line messages
                               scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                               silence_logs=logging.CRITICAL)
    finally:
        if main:
            signal.signal(signal.SIGINT, old)
        if watcher is not None and watcher.interrupted() and cluster is not None:
            cluster.close()  # Ctrl-C during the start: the workers stop, then the interrupt as if at once
            raise KeyboardInterrupt
    return Client(cluster), cluster


class _CtrlCWatcher:
    """A forked process that waits, with SIGINT at its default action, until :meth:`interrupted` is asked:
    it dies of a Ctrl-C sent to the process group in between (which the caller, ignoring SIGINT while the
    workers start, cannot see), and :meth:`interrupted` tells whether it did. Nothing of it outlives the call
    (killed with its parent on Linux)."""

    def __init__(self):
        import signal
        self.pid = None
        if not hasattr(os, "fork"):
            return
        r, self.w = os.pipe()
        parent = os.getpid()
        pid = os.fork()
        if pid == 0:  # the watcher: no Python cleanup of the caller's, only a read until EOF or death by SIGINT
            try:
                os.close(self.w)
                signal.signal(signal.SIGINT, signal.SIG_DFL)
                from ..binding import die_with_parent
                die_with_parent()  # Linux: SIGKILL when this process's parent ends (prctl PR_SET_PDEATHSIG)
                if os.getppid() == parent:
                    os.read(r, 1)
            finally:
                os._exit(0)
        os.close(r)
        self.pid = pid

    def interrupted(self) -> bool:
        """Whether a SIGINT ended the watcher; ends it otherwise (and reaps it)."""
        import signal
        if self.pid is None:
            return False
        os.close(self.w)  # the watcher's read returns: it exits 0, unless SIGINT killed it before
        _, status = os.waitpid(self.pid, 0)
        self.pid = None
        return os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGINT


def run(c: Campaign, out_dir: str | Path, scheduler: str | None = None, n_workers: int | None = None,
        chunk: int | None = None, progress: bool = True, overwrite: bool = False, flush_every: int = 20,
        client=None):
    """Runs the campaign (resuming from what ``out_dir`` already holds); returns the results as a
    pyarrow Table sorted by ``run``. ``client``: an existing dask.distributed Client to use as is."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    specs = c.runs()
    manifest = _open_folder(c, out_dir, overwrite, len(specs))
    done = _done_runs(c, out_dir)
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
            _execute(c, client, todo, len(specs), out_dir, writer, chunk, progress)
        finally:
            if own_client:
                client.close()
                if cluster is not None:
                    cluster.close()
    table = _final_table(out_dir, columns)
    manifest["wall_s_last_session"] = round(time.time() - t0, 3)
    manifest["n_ok"] = int(sum(1 for s in table.column("status").to_pylist() if s == "ok"))
    (out_dir / "manifest.json").write_text(json.dumps(manifest, indent=1, default=str))
    return table


def _open_folder(c: Campaign, out_dir: Path, overwrite: bool, n_runs: int) -> dict:
    """Checks that ``out_dir`` holds nothing or this campaign made with the same FMU builds (else refuses, or
    empties it with ``overwrite``), writes the manifest and returns it."""
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
    manifest = {"campaign_id": cid, **c.describe(), "n_runs": n_runs, "fmus": fmus,
                "unbound_slot_values": [u.text() for u in unbound_slots(c.scenario)],
                "engine_used": ("native" if c.log_every != 1 else resolve_engine("auto")) if c.engine == "auto" else c.engine,
                "packages": package_versions(), "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "row_columns": _row_columns(c)}
    if man_path.exists():
        manifest["created"] = json.loads(man_path.read_text()).get("created", manifest["created"])
    man_path.write_text(json.dumps(manifest, indent=1, default=str))
    (out_dir / "results.parquet").unlink(missing_ok=True)
    return manifest


def _done_runs(c: Campaign, out_dir: Path) -> set:
    """The runs already written in ``out_dir`` (a successful run whose time series file is missing is redone)."""
    done_table = read_results(out_dir)
    done = set()
    if done_table is not None:
        for r, st in zip(done_table.column("run").to_pylist(), done_table.column("status").to_pylist()):
            if c.timeseries is None or st != "ok" or (out_dir / "timeseries" / f"run-{r:06d}.parquet").exists():
                done.add(r)
    return done


def _execute(c: Campaign, client, todo: list[dict], n_total: int, out_dir: Path, writer: _Writer,
             chunk: int | None, progress: bool) -> None:
    """Runs ``todo`` on the client's workers in chunks, writing rows (and time series) as chunks complete;
    the runs of tasks whose worker died are retried one at a time after the others."""
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
        bar = tqdm(total=n_total, initial=n_total - len(todo), unit="run", desc=c.scenario.name,
                   file=sys.stderr, dynamic_ncols=True)

    def take(results):
        for row, ts in results:
            if ts is not None:
                _write_ts(out_dir, row["run"], ts)
            writer.add(row)
            if bar is not None:
                bar.update(1)
                if row["status"] != "ok":
                    bar.set_postfix_str(f"failed: {row['run']}", refresh=False)

    try:
        suspects = []
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
                results = [(_runs._crash_row(spec, c, e), None)]
            take(results)
    finally:
        writer.flush()
        if bar is not None:
            bar.close()


def _final_table(out_dir: Path, columns: list[str]):
    """All rows of ``out_dir``, one per run, sorted, written as ``results.parquet``."""
    import pyarrow.parquet as pq
    table = read_results(out_dir)
    table = table.select([col for col in columns if col in table.column_names])
    # one row per run, sorted (a run redone for its missing time series may appear twice in the parts)
    runs = table.column("run").to_pylist()
    keep = sorted({r: i for i, r in enumerate(runs)}.values(), key=lambda i: runs[i])
    table = table.take(keep)
    pq.write_table(table, out_dir / "results.parquet")
    return table
