#!/usr/bin/env python3
"""Cost of one paper 002 tuner evaluation (one 20 s closed-loop run at h = 1 ms, 20,001 samples of θ
logged) per controller: the campaign engine's native path (``campaign.run_one`` of paper002/<controller>
with the gains as overrides, container instance reused as in a campaign) against ``run_case`` (the same
loop scenario on the native engine through ``scfmu.simulate``, θ only logged; before issue 20 it was a
two-FMU Python ctypes loop), side by side in one process. Minimum of --repeat runs each;
the costs of both paths are printed too (they agree to round-off).

Usage: .venv/bin/python benches/paper002_runs.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import time

from scfmu.papers.paper002 import model as p2
from scfmu.papers.paper002 import tuning


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    gains = p2.load_gains()
    print(f"load average {os.getloadavg()[0]:.1f}; min of {a.repeat} runs")
    print("| controller | campaign run [s/run] | run_case [s/run] | run_case / campaign | cost campaign | cost run_case |")
    print("|---|---:|---:|---:|---:|---:|")
    for c in p2.CONTROLLERS:
        tuning.engine_cost(c, gains[c])  # container build / unpack
        tn, td = [], []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            row = tuning.engine_cost(c, gains[c])
            tn.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            d = p2.run_case(c, gains[c])
            td.append(time.perf_counter() - t0)
        print(f"| {c} | {min(tn):.3f} | {min(td):.3f} | {min(td) / min(tn):.1f} | {row['cost']:.12f} | {d['cost']:.12f} |",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
