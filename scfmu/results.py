"""Writing logged signals (the dict returned by CoSimulation.run) to CSV or Parquet, and the units of signals and
metrics (as the units declare them; a metric's unit follows from the signal it is read from or from its
name's suffix)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


def write_csv(path: Path, signals: dict, keys: list[str] | None = None, every: int = 1, fmt: str | None = None) -> None:
    """One column per signal (`keys`, default all). `every` > 1 keeps every n-th sample plus the last;
    `fmt` (e.g. ".10g") formats the numbers, default full precision."""
    keys = list(signals.keys()) if keys is None else keys
    n = len(signals[keys[0]])
    idx = np.arange(0, n, every)
    if idx[-1] != n - 1:
        idx = np.append(idx, n - 1)
    table = np.column_stack([np.asarray(signals[k])[idx] for k in keys])
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys)
        if fmt is None:
            w.writerows(table.tolist())
        else:
            w.writerows([[format(x, fmt) for x in row] for row in table])


def write_parquet(path: Path, signals) -> None:
    """The logged signals as a Parquet table, one float64 column per signal, each column's SI unit in its field
    metadata (``unit``; from ``signals.units`` when the result has them, else "")."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    units = getattr(signals, "units", {}) or {}
    fields = [pa.field(k, pa.float64(), metadata={"unit": units.get(k, "")}) for k in signals.keys()]
    columns = [np.asarray(signals[k], dtype=float) for k in signals.keys()]
    pq.write_table(pa.table(columns, schema=pa.schema(fields)), path)


def declared_unit(v) -> str:
    """The unit a model variable declares (its own, else its declared type's), "" when none."""
    unit = getattr(v, "unit", None)
    if not unit:
        unit = getattr(getattr(v, "declaredType", None), "unit", None)
    return unit or ""


# final_error of each metric set: the final value of the set's main error signal
_FINAL_ERROR = {"attitude": "deg", "attitude_nometrics": "deg", "single_axis": "deg", "paper002": "deg",
                "formation": "m"}
_SUFFIX = (("_deg_s", "deg.s"), ("_pct", "%"), ("_deg", "deg"), ("_s", "s"), ("_m", "m"))
_NAMED = {"peak_torque": "N.m", "peak_force": "N"}


def metric_unit(key: str, units: dict, metric_set: str = "") -> str:
    """The unit of a metric: that of the logged signal of the same name when there is one (e.g. ise,
    effort_abs), else from the name (…_s seconds, …_pct percent, …_deg degrees, …_m metres), "" when
    neither tells (a dimensionless number or one whose unit the metric set does not state)."""
    if units.get(key):
        return units[key]
    if key == "final_error":
        return _FINAL_ERROR.get(metric_set, "")
    if key in _NAMED:
        return _NAMED[key]
    for suffix, unit in _SUFFIX:
        if key.endswith(suffix):
            return unit
    return ""
