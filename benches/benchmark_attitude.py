"""Cost of `scfmu benchmark UNIT --family attitude` (all attitude scenarios, the robustness Monte Carlo at
its default size, the margins) against the run cost of the same scenarios on the native engine.

Measures, in this process: the benchmark's wall time and its CPU time (this process + its Dask workers,
``getrusage`` of the children after the cluster closed), then the CPU time of simulating every run the
benchmark simulates (the registered scenarios' runs and the robustness draws, every controller) on the
native engine (``simulate(sc, "native", log_every=0)``, no Python per step; ``--engines native,compiled``
adds the compiled engine, which logs every step) in this process. The machine
may be shared: CPU times are the numbers to compare, wall times depend on the load (printed).

    .venv/bin/python benches/benchmark_attitude.py [--unit PdController] [--quick] [--skip-benchmark]
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def all_runs(unit: str, quick: bool) -> list:
    """(scenario, overrides, seed) of every run the benchmark simulates (built-ins + the unit)."""
    from scfmu import benchmark as B
    from scfmu.benchmark import engineering, robustness
    from scfmu.registry import REGISTRY
    from scfmu.scenario import get
    REGISTRY.load()
    cases = [c for c in REGISTRY.benchmark_cases if c.family == "attitude"]
    ctrls = [(b.label, b.model, dict(b.params)) for b in REGISTRY.controllers if b.family == "attitude"]
    ctrls.append(("unit", unit, {}))
    runs, first = [], {}
    for case in cases:
        sets, seeds = B._case_overrides(case, quick)
        for name, model, params in ctrls:
            sc = get(case.scenario).with_models({case.slot: model})
            sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in params.items()})
            first.setdefault(case.label, sc)
            runs += [(sc, o, s) for o in sets for s in seeds]
    n = robustness.QUICK_RUNS if quick else robustness.DEFAULT_RUNS
    for case in engineering.pick(cases, first, with_units=False):
        draws = robustness.dispersions(first[case.label], n, seed=0)
        for name, model, params in ctrls:
            sc = get(case.scenario).with_models({case.slot: model})
            sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in params.items()})
            runs += [(sc, o, None) for o in draws]
    return runs


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--unit", default="PdController")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--skip-benchmark", action="store_true")
    ap.add_argument("--engines", default="native", help="comma-separated engines for the run cost (native, compiled)")
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()}")
    if not a.skip_benchmark:
        from scfmu import benchmark as B
        out = Path(tempfile.mkdtemp(prefix="scfmu_bench_"))
        c0, s0, t0 = cpu_children(), cpu_self(), time.perf_counter()
        B.run(a.unit, "attitude", out, label="unit", quick=a.quick, workers=2, log=lambda *x: None)
        wall = time.perf_counter() - t0
        cpu = (cpu_children() - c0) + (cpu_self() - s0)
        print(f"benchmark: wall {wall:.1f} s, CPU {cpu:.1f} s (this process {cpu_self() - s0:.1f} s, workers "
              f"{cpu_children() - c0:.1f} s); load average after: {os.getloadavg()}")
    from scfmu.engines import simulate
    runs = all_runs(a.unit, a.quick)
    for engine in a.engines.split(","):
        kw = {"log_every": 0} if engine == "native" else {}
        c0, t0 = cpu_self(), time.perf_counter()
        for sc, o, seed in runs:
            s = sc.with_overrides(o)
            if seed is not None:
                s = s.with_seed(seed)
            simulate(s, engine, **kw)
        print(f"{engine} engine, the same {len(runs)} runs: wall {time.perf_counter() - t0:.1f} s, "
              f"CPU {cpu_self() - c0:.1f} s")


if __name__ == "__main__":
    main()
