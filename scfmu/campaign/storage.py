"""A campaign's output folder: the manifest's package and FMU versions, the rows as Parquet parts written as
runs complete (the resumable record), the final sorted table and the per-run time series."""

from __future__ import annotations

import math
import os
import platform
from pathlib import Path

import numpy as np

from .. import fmu as fmu_access
from .. import metrics as run_metrics
from ..scenario.model import Scenario

ROW_FIXED = ("run", "override_index", "seed", "status", "message")


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
        md = fmu_access.described(p)
        entry = {"guid": md.guid, "sha256": fmu_access.fmu_digest(p)}
        if fmu_access.is_path(c.model):
            entry.update(model_name=md.modelName, file=str(p), instance=c.name)
        out[c.model] = entry
    return out


def _row_columns(c) -> list[str]:
    """The row columns of campaign ``c``: the fixed ones, one per overridden parameter, the metric columns."""
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

