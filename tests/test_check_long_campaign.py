"""A long campaign that measures the Dask workers' memory per run (issue 33, item 6): run 000-6 shortened to
1 s (100 steps; the cost is the per-run machinery, not the physics) with a random natural frequency per run,
on a LocalCluster of 2 single-threaded worker processes kept warm across segments; after each segment the
resident memory (RSS) of every worker is read on the worker (`client.run`). The growth per run over the
second half of the runs tells whether the memory levels off. CI: 800 runs in 8 segments; SCFMU_LONG=1:
10,000 runs in 20 segments (`python tests/test_check_long_campaign.py [RUNS] [SEGMENTS]` prints the table
recorded in docs/benchmarks.md)."""

from __future__ import annotations

import logging
import os
import sys
import time
from pathlib import Path



def _rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _rss_trimmed() -> int:
    """RSS after a garbage collection and glibc's malloc_trim: what the worker really keeps."""
    import ctypes
    import gc
    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except OSError:
        pass
    return _rss()


def _objects() -> int:
    import gc
    return len(gc.get_objects())


def measure(out: Path, runs: int, segments: int, workers: int = 2, profiler: bool = True,
            short_history: bool = False) -> list[dict]:
    """[{runs, ok, seconds, rss_kB, trimmed_kB, objects (per worker)}] after each segment (first row: the
    workers before any run). `profiler=False` switches Dask's statistical profiler of the workers off;
    `short_history=True` keeps Dask's defaults but shortens its bounded histories (the profiler's 1,000
    one-second cycles and the system monitor's 7,200 half-second samples) to 30 and 60 entries, so that a
    campaign of a few minutes shows where the memory levels off."""
    import dask
    from dask.distributed import Client, LocalCluster
    cfg = {"distributed.worker.profile.enabled": profiler}
    if short_history:
        cfg.update({"distributed.admin.low-level-log-length": 30, "distributed.admin.system-monitor.log-length": 60})
    with dask.config.set(cfg):
        return _measure(out, runs, segments, workers, Client, LocalCluster)


def _measure(out, runs, segments, workers, Client, LocalCluster):
    from scfmu import campaign, scenario
    sc = scenario.get("default").with_overrides(stop_time=1.0)
    per = runs // segments
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           host="127.0.0.1", silence_logs=logging.CRITICAL)
    client = Client(cluster)
    try:
        rows = []

        def snapshot(done, ok, t):
            rss = client.run(_rss)
            trimmed = client.run(_rss_trimmed)
            objs = client.run(_objects)
            rows.append({"runs": done, "ok": ok, "seconds": round(t, 1),
                         "rss_kB": [round(rss[w] / 1024) for w in sorted(rss)],
                         "trimmed_kB": [round(trimmed[w] / 1024) for w in sorted(trimmed)],
                         "objects": [objs[w] for w in sorted(objs)]})
        snapshot(0, 0, 0.0)
        done = ok = 0
        t0 = time.time()
        for k in range(segments):
            c = campaign.Campaign(sc, campaign.random_sample({"controller.wn": ("uniform", 0.5, 2.0)}, per, seed=k),
                                  seeds=[0])
            table = campaign.run(c, out / f"segment{k:02d}", client=client, progress=False)
            done += table.num_rows
            ok += sum(1 for s in table.column("status").to_pylist() if s == "ok")
            snapshot(done, ok, time.time() - t0)
        return rows
    finally:
        client.close()
        cluster.close()


def growth_per_run(rows: list[dict], start: int, key: str = "rss_kB") -> float:
    """The workers' RSS growth from row `start` to the last row per run they executed (bytes per run: the
    summed growth of the workers divided by the runs, each run having been executed by one worker)."""
    a, b = rows[start], rows[-1]
    n_runs = b["runs"] - a["runs"]
    total = sum(y - x for x, y in zip(a[key], b[key])) * 1024
    return total / n_runs


def test_long_campaign_worker_memory_levels_off(tmp_path):
    long = os.environ.get("SCFMU_LONG") == "1"
    runs, segments = (10_000, 20) if long else (800, 8)
    rows = measure(tmp_path, runs, segments)
    for r in rows:
        print(r)
    assert rows[-1]["runs"] == runs and rows[-1]["ok"] == runs
    first = growth_per_run(rows[:2], 0)
    second_half = growth_per_run(rows, len(rows) // 2)
    print(f"worker RSS growth: {first:.0f} B/run in the first segment, {second_half:.0f} B/run over the second half")
    # levels off: the second half of the runs adds less than 1 kB per run to the workers (the first segment,
    # which loads the FMUs, the engines and fills the caches, adds far more)
    assert second_half < 1024, rows


if __name__ == "__main__":
    import tempfile
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    s = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    mode = sys.argv[3] if len(sys.argv) > 3 else "default"  # default | noprofile | shorthistory
    with tempfile.TemporaryDirectory() as d:
        rows = measure(Path(d), n, s, profiler=mode != "noprofile", short_history=mode == "shorthistory")
    print("| runs | s | worker RSS (kB) | after gc + malloc_trim (kB) | Python objects |")
    print("|---:|---:|---|---|---|")
    for r in rows:
        print(f"| {r['runs']:,} | {r['seconds']} | {', '.join(f'{x:,}' for x in r['rss_kB'])} | "
              f"{', '.join(f'{x:,}' for x in r['trimmed_kB'])} | {', '.join(f'{x:,}' for x in r['objects'])} |")
    for key in ("rss_kB", "trimmed_kB"):
        print(f"{key}: first segment {growth_per_run(rows[:2], 0, key):.0f} B/run; second half "
              f"{growth_per_run(rows, len(rows) // 2, key):.0f} B/run; after the first segment "
              f"{growth_per_run(rows, 1, key):.0f} B/run")
