"""The native engine's on-disk cache: container FMUs (``loop_<key>.fmu``) and the Co-Simulation faces of
Model Exchange units (``faces/``), in ``$SCFMU_CONTAINER_DIR`` or ``~/.cache/scfmu/containers``.

A container holds a copy of every unit it nests (each with its binaries for every platform), so a
scenario's variants (another step, other start values, a rebuilt unit) each add several megabytes. The
cache is therefore bounded: after each new entry, the least recently used entries are removed until the
cache holds at most ``$SCFMU_CONTAINER_CACHE_MB`` megabytes (default 4096). An entry used in the last
``IN_USE_S`` seconds is never removed (another worker of a campaign may be about to unpack it), so the
bound can be exceeded while that many are in use; a removed entry is simply built again when needed.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from ..fmu.units import megabytes_setting

CACHE = Path(os.environ.get("SCFMU_CONTAINER_DIR", Path.home() / ".cache" / "scfmu" / "containers"))
IN_USE_S = 600.0


def budget_bytes() -> int:
    """The cache's size bound from ``$SCFMU_CONTAINER_CACHE_MB`` (a number of megabytes, > 0; default 4096)."""
    return megabytes_setting("SCFMU_CONTAINER_CACHE_MB", 4096)


def used(path: Path) -> Path:
    """Marks a cache hit as recently used (its modification time is the last use); returns ``path``."""
    try:
        os.utime(path)
    except OSError:
        pass  # a read-only cache still serves
    return path


def prune(cache: Path = CACHE, budget: int | None = None, now: float | None = None) -> list[Path]:
    """Removes the least recently used ``*.fmu`` entries of ``cache`` (faces included) until the rest fit
    ``budget`` bytes (default :func:`budget_bytes`), sparing entries used within ``IN_USE_S`` seconds.
    Returns the removed paths."""
    budget = budget_bytes() if budget is None else budget
    now = time.time() if now is None else now
    entries = []
    for p in cache.rglob("*.fmu"):
        try:
            st = p.stat()
        except OSError:
            continue  # removed meanwhile by another process
        entries.append((st.st_mtime, st.st_size, p))
    total = sum(size for _, size, _ in entries)
    removed = []
    for mtime, size, p in sorted(entries, key=lambda e: (e[0], str(e[2]))):
        if total <= budget:
            break
        if now - mtime < IN_USE_S:
            break  # this and every later entry are in use
        try:
            p.unlink()
        except OSError:
            continue
        total -= size
        removed.append(p)
    return removed
