"""Writing logged signals (the dict returned by CoSimulation.run) to CSV."""

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
