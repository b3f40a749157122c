"""``scfmu benchmark [PATH] --family attitude|single_axis|formation``: a controller (an FMI 2.0 or 3.0
FMU, Co-Simulation or Model Exchange, or a model name) through the family's standard scenarios beside the built-in
controllers; one HTML + Markdown page (``out/benchmark/<family>/``) with the warnings first (slot values
that reached no parameter of the unit, built-ins re-tuned for or not designed for a plant, runs whose error
grew, ties), the metrics with their units, pass/fail, the unit's rank per scenario and overlaid responses.
``--profile FILE`` binds the unit's parameters to each scenario's slot values (e.g. ``J1 = "inertia_xx"``);
``--strict`` refuses to run when one would not reach the unit; ``--mission`` adds the p95 time to fine pointing of
every controller as the fine-pointing law of the family's mission scenario (:mod:`scfmu.benchmark.mission`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..fmu import described, fmu_path
from ..registry import REGISTRY
from ..scenario import profile as profiles
from ..scenario.options import fmu_file, pairs, value
from ..scenario.values import UsageError, did_you_mean
from . import StrictRefusal, run, selected_cases
from .mission import case_of as mission_case
from .options import unit_options


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="scfmu benchmark", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("unit", nargs="?", help="the controller under test: a path to an .fmu or a model name "
                                            "(omit it to benchmark the built-in controllers only)")
    ap.add_argument("--family", default="attitude", help="attitude, single_axis or formation")
    ap.add_argument("--label", help="name of the unit in the tables (default: its file name)")
    ap.add_argument("--set", action="append", default=[], metavar="[controller.]NAME=VALUE",
                    help="a parameter of the unit (NAME or controller.NAME)")
    ap.add_argument("--map", action="append", default=[], metavar="[controller.]THEIRS=OURS",
                    help="the unit's port (or vector stem: omega=w) THEIRS plays the scenario's port OURS; a "
                         "parameter THEIRS takes the place's slot value OURS (controller.J1=inertia_xx, or "
                         "J1=inertia_xx) in every scenario; a name the unit lacks or a map that binds nothing is "
                         "refused")
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
    ap.add_argument("--mission", action="store_true",
                    help="also run every controller as the fine-pointing law of the family's mission scenario "
                         "(attitude: mission/tipoff, tip-off to fine pointing) over dispersed runs, and give the p95 "
                         "time to on target per controller (20 runs, 4 with --quick)")
    ap.add_argument("--mission-runs", type=int, default=None, metavar="N",
                    help="the number of dispersed mission runs per controller (with --mission)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=None, help="output folder (default out/benchmark/<family>)")
    ap.add_argument("--check", action="store_true", help="first run `scfmu check --quick` on the unit (an .fmu); "
                    "stop with exit status 1 if a check fails")
    return ap


def _unit(a) -> str | None:
    """The unit under test: a checked .fmu path or a known model name (None: built-ins only); a usage error
    names what is wrong (an option that needs a unit, an unreadable file, an unknown name)."""
    unit = a.unit
    if not unit:
        given = [o for o, v in (("--set", a.set), ("--map", a.map), ("--profile", a.profile), ("--label", a.label),
                                ("--strict", a.strict), ("--check", a.check)) if v]
        if given:
            raise UsageError(f"{given[0]} needs a unit under test (scfmu benchmark PATH.fmu|MODEL {given[0]} ...); "
                             "without one only the built-in controllers run")
    if unit and (unit.lower().endswith(".fmu") or "/" in unit):
        unit = fmu_file("", unit)
        try:
            described(unit)
        except Exception as e:
            raise UsageError(f"{a.unit}: not a readable FMU ({str(e).splitlines()[0] if str(e) else type(e).__name__})"
                             "; allowed: an FMI 2.0/3.0 .fmu file or a model name") from None
    elif unit:
        fmu_path(unit)  # an unknown model name: one line with the closest name (exit 2)
    return unit


def main(argv=None) -> int:
    a = _parser().parse_args(argv)
    if a.family not in REGISTRY.families():
        print(f"scfmu benchmark: no family {a.family!r}; known: {', '.join(REGISTRY.families())}", file=sys.stderr)
        return 2
    only = [x.strip() for x in a.cases.split(",")] if a.cases else None
    try:
        cases = selected_cases(a.family, only)
    except KeyError:
        known = [c.scenario for c in selected_cases(a.family)]
        raise UsageError(f"--cases {a.cases}: no benchmark scenario of family {a.family!r} matches"
                         f"{did_you_mean(only[0], known)}; allowed: scenario names or parts of their titles "
                         f"({', '.join(known)})") from None
    controllers = [x.strip() for x in a.controllers.split(",")] if a.controllers else None
    builtins = [b for b in REGISTRY.controllers if b.family == a.family]
    for c in controllers or []:
        if not any(c in (b.model, b.label) for b in builtins):
            names = sorted({b.model for b in builtins})
            raise UsageError(f"--controllers {c}: no built-in controller of family {a.family!r} is called so"
                             f"{did_you_mean(c, names)}; allowed: {', '.join(names)}")
    if a.workers < 1 or a.workers > 1024:
        raise UsageError(f"--workers {a.workers}: allowed: a whole number in [1, 1024]")
    if a.mission_runs is not None and not a.mission:
        raise UsageError(f"--mission-runs {a.mission_runs}: only with --mission")
    if a.mission_runs is not None and not 1 <= a.mission_runs <= 100_000:
        raise UsageError(f"--mission-runs {a.mission_runs}: allowed: a whole number in [1, 100000]")
    if a.mission and mission_case(a.family) is None:
        have = sorted({c.family for c in REGISTRY.mission_cases})
        raise UsageError(f"--mission: family {a.family!r} has no mission scenario; allowed with --family "
                         f"{' or '.join(have) or '(none registered)'}")
    unit = _unit(a)
    if unit and a.check:
        from ..check import check_quick
        rep = check_quick(str(fmu_path(unit)))
        print(rep.text(), file=sys.stderr)
        if not rep.ok:
            print(f"scfmu benchmark: {unit} fails scfmu check ({', '.join(sorted(rep.failed_checks()))}); "
                  "not benchmarked", file=sys.stderr)
            return 1
    label = a.label or (Path(unit).stem if unit else None)
    out = Path(a.out or Path("out") / "benchmark" / a.family)
    params = {k: value(v) for k, v in pairs(a.set, "--set").items()}
    port_map = pairs(a.map, "--map")
    if unit and (params or port_map):
        params, port_map = unit_options(unit, cases, params, port_map)
    prof = None
    if a.profile:
        try:
            prof = profiles.load(a.profile)
        except profiles.ProfileError as e:
            print(f"scfmu benchmark: {e}", file=sys.stderr)
            return 2
    print(f"benchmark {a.family}: {label or 'built-in controllers only'} → {out}")
    try:
        entries = run(unit, a.family, out, label=label, unit_params=params, port_map=port_map, quick=a.quick, workers=a.workers,
                      controllers=controllers, cases=only, profile=prof, strict=a.strict,
                      estimator=a.estimator, mission=a.mission, mission_runs_n=a.mission_runs)
    except StrictRefusal as e:
        print(f"scfmu benchmark: {e}", file=sys.stderr)
        return 2
    print(f"wrote {out / 'index.html'}, {out / 'benchmark.md'} and {out / 'results.csv'}"
          + (f" (mission: {out / 'mission.csv'})" if a.mission else ""))
    mine = [e for e in entries if e.controller == label] if label else []
    unbound = sorted({u for e in mine for u in e.unbound})
    for u in unbound:
        print(f"warning: {u} (shown beside the unit's results on the page)", file=sys.stderr)
    if mine and all(e.status for e in mine):
        print("scfmu benchmark: the unit fits none of the scenarios (see the n/a reasons)", file=sys.stderr)
        return 1
    return 0
