"""``scfmu benchmark [PATH] --family attitude|single_axis|formation``: a controller (an FMI 2.0 or 3.0
FMU, Co-Simulation or Model Exchange, or a model name) through the family's standard scenarios beside the built-in
controllers; one HTML + Markdown page (``out/benchmark/<family>/``) with the warnings first (slot values
that reached no parameter of the unit, built-ins re-tuned for or not designed for a plant, runs whose error
grew, ties), the metrics with their units, pass/fail, the unit's rank per scenario and overlaid responses.
``--profile FILE`` binds the unit's parameters to each scenario's slot values (e.g. ``J1 = "inertia_xx"``);
``--strict`` refuses to run when one would not reach the unit."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..registry import REGISTRY
from ..scenario import profile as profiles
from ..scenario.options import pairs, value
from . import StrictRefusal, run


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="scfmu benchmark", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("unit", nargs="?", help="the controller under test: a path to an .fmu or a model name "
                                            "(omit it to benchmark the built-in controllers only)")
    ap.add_argument("--family", default="attitude", help="attitude, single_axis or formation")
    ap.add_argument("--label", help="name of the unit in the tables (default: its file name)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a parameter of the unit")
    ap.add_argument("--map", action="append", default=[], metavar="THEIRS=OURS",
                    help="the unit's port (or vector stem: omega=w) THEIRS plays the scenario's port OURS; a "
                         "parameter THEIRS takes the place's slot value OURS (J1=inertia_xx) in every scenario")
    ap.add_argument("--profile", metavar="FILE", help="the unit's profile (TOML: [params] J1 = \"inertia_xx\", "
                                                      "[ports], unused = [...]), applied in every scenario")
    ap.add_argument("--strict", action="store_true",
                    help="refuse to run (exit 2) when a slot value of a scenario reaches no parameter of the unit")
    ap.add_argument("--controllers", help="comma-separated built-in controllers to compare (default: all of the family)")
    ap.add_argument("--cases", help="comma-separated scenario names (or parts of their titles) to run (default: all)")
    ap.add_argument("--quick", action="store_true", help="Monte Carlo cases with 10 draws (the same set-up otherwise)")
    ap.add_argument("--estimator", action="store_true",
                    help="also run every pair with the estimator in the loop (sensing+estimation/<scenario>: sensors, "
                         "ephemeris, Mekf, 10 Hz flight computer) and show its primary metric in a column (twice the runs)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=None, help="output folder (default out/benchmark/<family>)")
    ap.add_argument("--check", action="store_true", help="first run `scfmu check --quick` on the unit (an .fmu); "
                    "stop with exit status 1 if a check fails")
    a = ap.parse_args(argv)
    if a.family not in REGISTRY.families():
        print(f"scfmu benchmark: no family {a.family!r}; known: {', '.join(REGISTRY.families())}", file=sys.stderr)
        return 2
    unit = a.unit
    if unit and (unit.endswith(".fmu") or "/" in unit):
        p = Path(unit).expanduser()
        if not p.is_file():
            print(f"scfmu benchmark: {unit}: no such file", file=sys.stderr)
            return 2
        unit = str(p.resolve())
        if a.check:
            from ..check import check_quick
            rep = check_quick(unit)
            print(rep.text(), file=sys.stderr)
            if not rep.ok:
                print(f"scfmu benchmark: {unit} fails scfmu check ({', '.join(sorted(rep.failed_checks()))}); "
                      "not benchmarked", file=sys.stderr)
                return 1
    label = a.label or (Path(unit).stem if unit else None)
    out = Path(a.out or Path("out") / "benchmark" / a.family)
    prof = None
    if a.profile:
        if not unit:
            print("scfmu benchmark: --profile needs a unit under test", file=sys.stderr)
            return 2
        try:
            prof = profiles.load(a.profile)
        except profiles.ProfileError as e:
            print(f"scfmu benchmark: {e}", file=sys.stderr)
            return 2
    print(f"benchmark {a.family}: {label or 'built-in controllers only'} → {out}")
    try:
        entries = run(unit, a.family, out, label=label, unit_params={k: value(v) for k, v in pairs(a.set, "--set").items()},
                      port_map=pairs(a.map, "--map"), quick=a.quick, workers=a.workers,
                      controllers=[x.strip() for x in a.controllers.split(",")] if a.controllers else None,
                      cases=[x.strip() for x in a.cases.split(",")] if a.cases else None, profile=prof, strict=a.strict,
                      estimator=a.estimator)
    except StrictRefusal as e:
        print(f"scfmu benchmark: {e}", file=sys.stderr)
        return 2
    print(f"wrote {out / 'index.html'}, {out / 'benchmark.md'} and {out / 'results.csv'}")
    mine = [e for e in entries if e.controller == label] if label else []
    unbound = sorted({u for e in mine for u in e.unbound})
    for u in unbound:
        print(f"warning: {u} (shown beside the unit's results on the page)", file=sys.stderr)
    if mine and all(e.status for e in mine):
        print("scfmu benchmark: the unit fits none of the scenarios (see the n/a reasons)", file=sys.stderr)
        return 1
    return 0
