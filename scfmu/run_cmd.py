"""``scfmu run SCENARIO``: one run of a scenario, its metrics printed, its logged signals written as CSV
and a PNG figure.

``scfmu run default`` is paper 000 run 000-6: the quaternion PD law on the large command (roll 40°,
pitch -40°, yaw -60° from rest), AttitudeCommand + PdController + AttitudePlant + AttitudeMetrics,
inertia diag(1000, 500, 700) kg·m², no torque limit, RK4 0.01 s, communication step 0.01 s, 30 s.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import sys

from . import metrics
from .engines import ENGINES, SimulationError, simulate
from .results import write_csv
from .scenario import options
from .fmu import FmuError
from .scenario.check import IncompatibleUnit, require
from .scenario.values import UsageError, bounded_int, timing_problems
from .scenario.ssp import file_stem

ANGLES = ("roll", "pitch", "yaw")


def _groups(keys: list[str]) -> dict[str, list[str]]:
    """Logged keys grouped for plotting: 321 angles (with references), vectors by their base name."""
    g: dict[str, list[str]] = {}
    for k in keys:
        base = k[:-4] if k.endswith("_ref") else k
        if base in ANGLES:
            name = "321 angles [deg]"
        elif len(base) > 2 and base[-2] == "_" and base[-1] in "wxyz":
            name = base[:-2]
        else:
            name = base
        g.setdefault(name, []).append(k)
    return g


def plot(r: dict, path: Path, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = _groups([k for k in r if k != "time"])
    prefer = ["321 angles [deg]", "alpha_deg", "theta", "pos", "torque_applied", "torque_cmd", "force", "u",
              "applied_torque"]
    chosen = [n for n in prefer if n in groups][:4]
    chosen += [n for n in groups if n not in chosen][: max(0, 3 - len(chosen))]
    fig, axs = plt.subplots(len(chosen), 1, figsize=(8, 2.6 * len(chosen) + 0.6), sharex=True, squeeze=False)
    t = r["time"]
    for ax, name in zip(axs[:, 0], chosen):
        for k in groups[name]:
            y = np.asarray(r[k])
            if name.startswith("321"):
                y = np.degrees(y)
            ax.plot(t, y, ls=":" if k.endswith("_ref") else "-", label=k)
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, ncol=3)
    axs[-1, 0].set_xlabel("time [s]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="scfmu run", description=__doc__ + "\n" + options.__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    options.add_arguments(ap)
    ap.add_argument("--engine", default="native", choices=ENGINES, help="engine (all give bit-identical results)")
    ap.add_argument("--out", default=None, help="output folder (default out/<scenario>)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--log-every", type=int, default=1, metavar="N",
                    help="native engine: log every N-th communication step (for long runs; metrics on that grid)")
    args = ap.parse_args(argv)
    sc = options.build(args, notice=lambda t: print(t, file=sys.stderr))
    bounded_int("--log-every", args.log_every, 1, 10 ** 9)
    if args.log_every != 1 and args.engine != "native":
        raise UsageError(f"--log-every {args.log_every}: allowed only with --engine native (the {args.engine} "
                         f"engine logs every step)")
    problems = timing_problems(sc.start_time, sc.stop_time, sc.step, log_every=args.log_every,
                               log_hint=args.engine == "native")
    if problems:
        raise UsageError(problems[0])
    try:
        require(sc, warn=lambda t: print(f"warning: {t}", file=sys.stderr))
    except IncompatibleUnit as e:
        print(f"scfmu run: {e.one_line()}", file=sys.stderr)
        return 2
    stem = file_stem(sc.name)
    out = Path(args.out or Path("out") / stem)
    out.mkdir(parents=True, exist_ok=True)
    try:
        r = simulate(sc, args.engine, **({"log_every": args.log_every} if args.log_every != 1 else {}))
    except SimulationError as e:
        print(f"scfmu run: the run failed ({e.status}): {e}", file=sys.stderr)
        return 1
    except FmuError as e:
        print(f"scfmu run: the run failed: {e}", file=sys.stderr)
        return 1
    m = metrics.compute(sc.metrics, r)
    print(f"{sc.name}: {sc.description or ''}".rstrip(": "))
    models = ", ".join(f"{c.name}={Path(c.model).name}" for c in sc.components)
    print(f"  {len(r['time']) - 1} steps of {sc.step:g} s to t = {sc.stop_time:g} s on the {args.engine} engine; "
          f"units {models}; metric set {sc.metrics or '(none)'}")
    for k, v in m.items():
        if isinstance(v, float) and math.isfinite(v):
            print(f"  {k:24s} {v:14.6g}")
    csv = out / f"{stem}.csv"
    write_csv(csv, r)
    written = [csv]
    if not args.no_plot:
        png = out / f"{stem}.png"
        title = sc.name + (f": EULERINT = {m['eulerint_deg_s']:.2f} deg·s"
                           if math.isfinite(m.get("eulerint_deg_s", math.nan)) else "")
        plot(r, png, title)
        written.append(png)
    print("wrote " + " and ".join(str(p) for p in written))
    return 0
