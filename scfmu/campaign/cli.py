"""Run a campaign: one standard scenario × parameter overrides (list, grid or random sample) × seeds,
on Dask (a LocalCluster on this machine by default, or an existing cluster with --scheduler), with a
progress bar; one metrics row per run in OUT/results.parquet (+ manifest.json), optional time series,
and PNG figures. Re-running the same command on the same OUT resumes an interrupted campaign.

Examples:
  # 100 random (ω_n, ζ) pairs for the quaternion PD of run 000-6, 2 workers, figures
  scfmu campaign default --random controller.wn=uniform:0.3:2 --random controller.zeta=uniform:0.5:1.5 \\
      --samples 100 --workers 2 --timeseries alpha_deg --plot-vs controller.wn --out out/campaign/pd_random
  # a grid and three seeds of the plant's noise generator
  scfmu campaign paper000/000-6 --grid controller.wn=0.5,1,2 --set plant.dist_noise_std_x=1 --seeds 0:3
  # list of override sets from a JSON file ([{"controller.wn": 1.0}, ...]) on an existing cluster
  scfmu campaign default --list sets.json --scheduler tcp://127.0.0.1:8786

Values: numbers (int if written without '.', 'e'), or strings. Random distributions: uniform:lo:hi,
loguniform:lo:hi, normal:mean:std, int:lo:hi, choice:a,b,c. Scenarios: any registered name
(`scfmu scenarios` lists them).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path


from .. import campaign
from .. import metrics as run_metrics
from ..registry import REGISTRY
from ..scenario import options
from ..scenario.check import IncompatibleUnit, override_problems, require
from ..scenario.options import value
from ..scenario.plan import timing_problem
from ..scenario.values import UsageError, bounded_float, bounded_int, did_you_mean
from ..run_cmd import add_scenario_arguments, run_changes
from . import plots as campaign_plots


MAX_RUNS = 10_000_000  # runs of one campaign (parameter sets × seeds)
SEED_RANGE = (0, 2 ** 31 - 1)  # a seed is given to Integer (fmi2Integer) seed parameters


def _seed(text: str) -> int:
    v = value(text)
    if isinstance(v, bool) or not isinstance(v, int) or not SEED_RANGE[0] <= v <= SEED_RANGE[1]:
        raise UsageError(f"--seeds: {text!r}: allowed: whole numbers in [{SEED_RANGE[0]}, {SEED_RANGE[1]}] "
                         f"(0,1,2 or 0:10)")
    return v


def parse_seeds(text: str) -> list:
    if not text:
        return [None]
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 2:
            raise UsageError(f"--seeds {text!r}: expected FIRST:END (END excluded) or a list 0,1,2")
        a, b = _seed(parts[0]), _seed(parts[1])
        if b <= a:
            raise UsageError(f"--seeds {text!r}: END must be greater than FIRST")
        bounded_int("--seeds: the number of seeds", b - a, 1, MAX_RUNS)
        return list(range(a, b))
    seeds = [_seed(x) for x in text.split(",")]
    bounded_int("--seeds: the number of seeds", len(seeds), 1, MAX_RUNS)
    return seeds


DISTRIBUTIONS = ("uniform", "loguniform", "normal", "int", "choice")


def parse_random(items: list[str]) -> dict:
    space = {}
    for it in items:
        name, sep, spec = it.partition("=")
        kind, _, rest = spec.partition(":")
        if not sep or not name:
            raise UsageError(f"--random {it!r}: expected INST.VAR=DIST:A:B")
        if kind not in DISTRIBUTIONS:
            raise UsageError(f"--random {it!r}: unknown distribution {kind!r}{did_you_mean(kind, DISTRIBUTIONS)}; "
                             f"allowed: {', '.join(DISTRIBUTIONS)}")
        if kind == "choice":
            vals = [value(x) for x in rest.split(",") if x]
            if not vals:
                raise UsageError(f"--random {it!r}: choice needs values: choice:a,b,c")
            space[name] = ("choice", vals)
            continue
        parts = rest.split(":")
        if len(parts) != 2:
            raise UsageError(f"--random {it!r}: expected {kind}:A:B")
        lo, hi = value(parts[0]), value(parts[1])
        for x in (lo, hi):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise UsageError(f"--random {it!r}: {x!r} is not a finite number")
        if kind == "int" and not (isinstance(lo, int) and isinstance(hi, int)):
            raise UsageError(f"--random {it!r}: int:A:B needs whole numbers")
        if kind == "normal" and not hi >= 0:
            raise UsageError(f"--random {it!r}: the standard deviation {hi} must be ≥ 0")
        if kind != "normal" and not lo <= hi:
            raise UsageError(f"--random {it!r}: A = {lo} must not exceed B = {hi}")
        if kind == "loguniform" and not lo > 0:
            raise UsageError(f"--random {it!r}: loguniform needs 0 < A ≤ B")
        space[name] = (kind, lo, hi)
    return space


def dispersed(sc) -> dict:
    """The scenario's registered dispersions and a draw of every seed parameter per run, in the syntax of
    ``--random`` (``{"instance.parameter": "DIST:A:B"}``)."""
    seeds = {p: f"int:{SEED_RANGE[0] + 1}:{SEED_RANGE[1]}" for p in sc.seed_params}
    return {**REGISTRY.dispersions_of(sc.name), **seeds}


def dispersed_sets(sc, n: int, seed: int = 0) -> list[dict]:
    """n override sets drawn from :func:`dispersed` (one generator seeded ``seed``): the runs of
    ``--runs n``, and the same draws for every controller put in the scenario."""
    return campaign.random_sample(parse_random([f"{k}={v}" for k, v in dispersed(sc).items()]), n, seed=seed)


def runs_space(sc, args) -> list[str]:
    """``--runs N``: the scenario's registered dispersions, each run's own draw of every seed parameter
    (recorded in its row), then the user's ``--random`` axes (which replace a dispersion of the same name)."""
    bounded_int("--runs", args.runs, 1, MAX_RUNS)
    disp = REGISTRY.dispersions_of(sc.name)
    if not disp:
        raise UsageError(f"--runs: scenario {sc.name!r} declares no dispersions (scenarios with them: "
                         f"{', '.join(sorted(REGISTRY.dispersion_sets)) or 'none'}); use --random ... --samples N")
    if args.seeds:
        raise UsageError(f"--seeds {args.seeds!r}: not with --runs, which draws each run's seeds "
                         f"({', '.join(sc.seed_params)})")
    return [f"{k}={v}" for k, v in dispersed(sc).items()] + list(args.random)


def build(args) -> campaign.Campaign:
    sc = options.build(run_changes(args), notice=lambda t: print(t, file=sys.stderr))
    bounded_int("--samples", args.samples, 1, MAX_RUNS)
    bounded_int("--ts-every", args.ts_every, 1, 10 ** 9)
    bounded_int("--log-every", args.log_every, 1, 10 ** 9)
    if args.workers is not None:
        bounded_int("--workers", args.workers, 1, 1024)
    if args.chunk is not None:
        bounded_int("--chunk", args.chunk, 1, 10 ** 6)
    bounded_float("--timeout", args.timeout, 0.0, 10 ** 7)
    why = timing_problem(sc, log_every=args.log_every)  # the plan's one timing check, before any run
    if why:
        raise UsageError(why)
    sets = [{}]
    if args.list:
        try:
            sets = json.loads(Path(args.list).read_text())
        except OSError as e:
            raise UsageError(f"--list {args.list}: {e.strerror or e}") from None
        except ValueError as e:
            raise UsageError(f"--list {args.list}: not valid JSON: {e}") from None
        if not isinstance(sets, list) or not all(isinstance(x, dict) for x in sets) or not sets:
            raise UsageError(f"--list {args.list}: expected a list of tables [{{\"inst.var\": value}}, ...]")
    if args.grid:
        axes = {}
        for it in args.grid:
            k, sep, v = it.partition("=")
            if not sep or not k or not v:
                raise UsageError(f"--grid {it!r}: expected INST.VAR=V1,V2,...")
            axes[k] = [value(x) for x in v.split(",") if x]
        n = len(sets)
        for vals in axes.values():
            n *= len(vals)
        bounded_int("--grid: the number of parameter sets", n, 1, MAX_RUNS)
        g = campaign.grid(axes)
        sets = [dict(a, **b) for a in sets for b in g]
    seeds = parse_seeds(args.seeds)
    if args.runs is not None:
        args.random, args.samples = runs_space(sc, args), args.runs
    if args.random:
        bounded_int("the number of runs", len(sets) * args.samples * len(seeds), 1, MAX_RUNS)
        r = campaign.random_sample(parse_random(args.random), args.samples, args.sample_seed)
        sets = [dict(a, **b) for a in sets for b in r]
    bounded_int("the number of runs (parameter sets × seeds)", len(sets) * len(seeds), 1, MAX_RUNS)
    ts = None
    if args.timeseries is not None:
        ts = [x for x in args.timeseries.split(",") if x]
    return campaign.Campaign(sc, sets, seeds, engine=args.engine, timeseries=ts,
                             ts_every=args.ts_every, log_every=args.log_every,
                             isolate=True if args.isolate else None, timeout=args.timeout)


def _parser() -> argparse.ArgumentParser:
    """The command line of ``scfmu campaign``: the scenario options, the parameter sets, seeds, engine, Dask
    and output options."""
    ap = argparse.ArgumentParser(prog="scfmu campaign", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scenario_arguments(ap)
    ap.add_argument("--grid", action="append", default=[], metavar="INST.VAR=V1,V2,...", help="grid axis (repeatable)")
    ap.add_argument("--random", action="append", default=[], metavar="INST.VAR=DIST:A:B", help="random axis (repeatable)")
    ap.add_argument("--samples", type=int, default=100, help="number of random samples (with --random)")
    ap.add_argument("--runs", type=int, default=None, metavar="N",
                    help="a Monte Carlo of N runs over the scenario's own dispersions (e.g. mission/tipoff), each "
                         "run with its own seeds (drawn with --sample-seed)")
    ap.add_argument("--sample-seed", type=int, default=0, help="seed of the random sampler")
    ap.add_argument("--list", help="JSON file: list of override dicts")
    ap.add_argument("--seeds", default="", help="run seeds given to the scenario's seed parameters: 0,1,2 or 0:10")
    ap.add_argument("--isolate", action="store_true",
                    help="run each run in a child process (automatic when a unit is given as an FMU file)")
    ap.add_argument("--timeout", type=float, default=600.0,
                    help="wall-time limit of an isolated run [s] (default 600); past it: status timeout")
    ap.add_argument("--engine", default="auto", choices=["auto", "compiled", "native", "lean", "reference"],
                    help="auto (default): the compiled loop when its library is present, else native")
    ap.add_argument("--timeseries", nargs="?", const="", default=None, metavar="KEYS",
                    help="keep time series per run (comma-separated logged keys; all when empty)")
    ap.add_argument("--ts-every", type=int, default=10, help="keep every n-th sample of the time series")
    ap.add_argument("--log-every", type=int, default=1,
                    help="native engine: sample the logged signals every n-th step (faster; metrics on that grid)")
    ap.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: CPU count)")
    ap.add_argument("--scheduler", help="address of an existing Dask scheduler (tcp://host:port)")
    ap.add_argument("--chunk", type=int, default=None, help="runs per Dask task (default: automatic)")
    ap.add_argument("--out", default=None, help="output folder (default out/campaign/<scenario>)")
    ap.add_argument("--overwrite", action="store_true", help="replace a different campaign found in --out")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--metric", default=None, help="metric of the summary and the figures (default: the scenario's "
                    "metric set's first column, e.g. eulerint_deg_s or t_fine_pointing_s)")
    ap.add_argument("--plot-vs", action="append", default=[], metavar="INST.VAR", help="metric-vs-parameter figure")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--check", action="store_true", help="first run `scfmu check --quick` on every unit given as "
                    "an .fmu file; stop with exit status 1 if a check fails")
    return ap


def _summary(table, out: Path, metric: str) -> tuple[list, list]:
    """Prints the status counts, the failed runs and the main metrics' spread (min, median, p95, p99, max over the
    ok runs, and how many ok runs have no value: e.g. never reached fine pointing); returns (rows, ok rows)."""
    rows = table.to_pylist()
    ok = [r for r in rows if r["status"] == "ok"]
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print(f"{len(ok)} of {len(rows)} runs ok ({', '.join(f'{k}: {v}' for k, v in sorted(counts.items()))}); "
          f"results {out / 'results.parquet'}, manifest {out / 'manifest.json'}")
    for r in rows:
        if r["status"] != "ok":
            print(f"  run {r['run']}: {r['status']}: {r['message'][:160]}")
    import numpy as np
    names = dict.fromkeys([metric, "eulerint_deg_s", "ise", "settling_s", "effort_abs", "final_error"])
    for m in (m for m in names if ok and m in ok[0]):
        v = np.array([r[m] for r in ok], dtype=float)
        fin = v[np.isfinite(v)]
        if fin.size:
            p50, p95, p99 = np.percentile(fin, [50, 95, 99])
            print(f"  {m:16s} min {fin.min():11.6g}  median {p50:11.6g}  p95 {p95:11.6g}  p99 {p99:11.6g}  "
                  f"max {fin.max():11.6g}  ({fin.size} runs{f', {v.size - fin.size} without a value' if fin.size < v.size else ''})")
    return rows, ok


def _figures(c, table, out: Path, args) -> None:
    """The metric histogram, the metric-vs-parameter figures and the time-series envelopes."""
    figs = [campaign_plots.hist(table, args.metric, out / f"hist_{args.metric}.png")]
    for p in args.plot_vs:
        figs.append(campaign_plots.metric_vs_param(table, p, args.metric,
                                                   out / f"{args.metric}_vs_{p.replace('.', '_')}.png"))
    if c.timeseries is not None:
        keys = c.timeseries or [k for k in c.scenario.log]
        for k in keys[:3]:
            figs.append(campaign_plots.envelope(out, k, out / f"envelope_{k}.png"))
    print("figures: " + ", ".join(str(f) for f in figs))


def _units_pass_check(scenario) -> bool:
    """``--check``: `scfmu check --quick` on each unit given as a file (the report on stderr); False (and
    one line naming the unit and the failed checks) when any fails."""
    from ..check import check_quick
    from ..fmu import is_path
    ok = True
    for comp in scenario.components:
        if not is_path(comp.model):
            continue
        rep = check_quick(str(comp.model))
        print(rep.text(), file=sys.stderr)
        if not rep.ok:
            print(f"scfmu campaign: {comp.name} ({comp.model}) fails scfmu check "
                  f"({', '.join(sorted(rep.failed_checks()))}); the campaign was not run", file=sys.stderr)
            ok = False
    return ok


def main(argv=None) -> int:
    args = _parser().parse_args(argv)

    c = build(args)
    if args.metric is None:
        cols = run_metrics.columns(c.scenario.metrics)
        args.metric = cols[0] if cols else "eulerint_deg_s"
    try:
        require(c.scenario, warn=lambda t: print(f"warning: {t}", file=sys.stderr))
    except IncompatibleUnit as e:
        print(f"scfmu campaign: {e.one_line()}", file=sys.stderr)
        return 2
    options.binding_report(c.scenario, "scfmu campaign", args.strict, lambda t: print(t, file=sys.stderr))
    if args.check and not _units_pass_check(c.scenario):
        return 1
    bad = override_problems(c.scenario, c.overrides)
    if bad:
        more = " (and more)" if len(bad) > 1 else ""
        raise UsageError(f"{bad[0]}{more}")
    out = Path(args.out or Path("out") / "campaign" / c.scenario.name.replace("/", "_"))
    print(f"campaign {c.campaign_id()}: scenario {c.scenario.name}, {len(c.overrides)} parameter set(s) × "
          f"{len(c.seeds)} seed(s) = {len(c.overrides) * len(c.seeds)} runs, engine {c.engine} → {out}")
    try:
        table = campaign.run(c, out, scheduler=args.scheduler, n_workers=args.workers, chunk=args.chunk,
                             progress=not args.no_progress, overwrite=args.overwrite)
    except KeyboardInterrupt:  # campaign.run has stopped its workers (LocalCluster closed) and kept the rows
        done = campaign.read_results(out)
        n = 0 if done is None else done.num_rows
        print(f"\nscfmu campaign: interrupted (Ctrl-C) after {n} of {len(c.overrides) * len(c.seeds)} runs; the "
              f"workers were stopped and the rows are kept in {out}; run the same command again to resume",
              file=sys.stderr)
        return 130
    except RuntimeError as e:
        if "holds another campaign" in str(e) or "other FMU builds" in str(e):
            raise UsageError(f"{e} (--overwrite replaces it)") from None
        raise
    rows, ok = _summary(table, out, args.metric)
    if not args.no_plots and ok:
        _figures(c, table, out, args)
    if len(ok) < len(rows):
        print(f"scfmu campaign: {len(rows) - len(ok)} of {len(rows)} runs failed", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
