"""The ``scfmu`` command line (also ``python -m scfmu``).

Subcommands (each has ``--help``):

  run SCENARIO            one run: metrics, CSV and PNG           (scfmu run default)
  scenarios [PATTERN]     the registered scenarios, with descriptions
  campaign SCENARIO ...   many runs on Dask: grids, random samples, seeds; Parquet + figures
  benchmark [FMU]         your controller beside the papers' ones on a family's scenarios (HTML + Markdown)
  export ssp|loop [NAME]  SSP 1.0 files or loop FMUs (one container FMU per closed loop)
  report [--quick]        the reproduction report of every paper (HTML + Markdown)
  paper NNN COMMAND ...   a paper's own experiments (tuning, sweeps, cases): `scfmu paper` lists them
  verify FMU [--importer] replay the reference results an FMU carries; largest deviation per output

``--fmus DIR`` (before the subcommand) takes the FMUs from DIR; otherwise ``SCFMU_FMU_DIR``, the FMUs
shipped in the package, or a source checkout's ``fmus/``.
"""

from __future__ import annotations

import argparse
import sys

from .registry import REGISTRY, resolve

COMMANDS = {
    "run": ("one run of a scenario: metrics, CSV and PNG", "scfmu.run_cmd:main"),
    "campaign": ("many runs of a scenario on Dask (grids, random samples, seeds)", "scfmu.campaign.cli:main"),
    "report": ("the reproduction report of the papers (HTML + Markdown)", "scfmu.report.cli:main"),
    "benchmark": ("a controller (any FMU) beside the built-in ones on a family's scenarios", "scfmu.benchmark.cli:main"),
    "verify": ("replay the reference results an FMU carries (fmi-ls-ref) in an importer", "scfmu.verify:main"),
}


def _scenarios(argv) -> int:
    ap = argparse.ArgumentParser(prog="scfmu scenarios", description="List the registered scenarios, or print one "
                                 "as a scenario file (a starting point for `scfmu run my_loop.toml`).")
    ap.add_argument("pattern", nargs="?", default="*", help="glob pattern, e.g. 'paper003/*'")
    ap.add_argument("--show", metavar="NAME", help="print scenario NAME in the scenario-file format")
    ap.add_argument("--json", action="store_true", help="with --show: JSON instead of TOML")
    a = ap.parse_args(argv)
    if a.show:
        from .scenario import files
        try:
            sc = REGISTRY.scenario(a.show)
        except KeyError as e:
            print(f"scfmu scenarios: {e.args[0]}", file=sys.stderr)
            return 2
        print(files.dumps_json(sc) if a.json else files.dumps_toml(sc), end="")
        return 0
    rows = REGISTRY.scenario_names(a.pattern)
    if not rows:
        print(f"no scenario matches {a.pattern!r}", file=sys.stderr)
        return 1
    width = max(len(n) for n, _ in rows)
    for n, d in rows:
        print(f"{n:{width}s}  {d}")
    return 0


def _export(argv) -> int:
    from .export import KINDS, export
    from .scenario import options
    ap = argparse.ArgumentParser(prog="scfmu export", description="Write SSP 1.0 files or loop FMUs of scenarios "
                                 "(default: the standard set the plug-ins export) and validate each. With --fmu, "
                                 "--map or --set, one scenario (a name or a scenario file) with those changes.")
    ap.add_argument("kind", choices=KINDS)
    ap.add_argument("names", nargs="*", help="scenario names or files (default: the standard set)")
    ap.add_argument("--out", default=None, help="output folder (default fmus/ssp or fmus/loops)")
    ap.add_argument("--fmu", action="append", default=[], metavar="INSTANCE=PATH", help="use this FMU for INSTANCE")
    ap.add_argument("--map", action="append", default=[], metavar="INSTANCE.THEIRS=OURS", help="rename a unit's port")
    ap.add_argument("--set", action="append", default=[], metavar="INSTANCE.VAR=VALUE", help="parameter or input")
    a = ap.parse_args(argv)
    out = a.out or ("fmus/ssp" if a.kind == "ssp" else "fmus/loops")
    items = a.names or None
    if a.fmu or a.map or a.set or any(n.endswith((".toml", ".json")) for n in a.names):
        if len(a.names) != 1:
            print("scfmu export: --fmu/--map/--set and scenario files take exactly one scenario", file=sys.stderr)
            return 2
        ns = argparse.Namespace(scenario=a.names[0], fmu=a.fmu, map=a.map, set=a.set, params=None, t_end=None, dt=None)
        items = [options.build(ns, notice=lambda t: print(t, file=sys.stderr))]
    try:
        export(a.kind, out, items)
    except (RuntimeError, KeyError, ValueError) as e:
        print(f"scfmu export: {e}", file=sys.stderr)
        return 1
    return 0


def _paper(argv) -> int:
    papers = REGISTRY.all_papers()
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: scfmu paper NNN COMMAND [options]\n\npapers and their commands:")
        for p in papers:
            print(f"  {p.key}  {p.title}")
            for name, (help_, _) in p.commands.items():
                print(f"         {name:12s} {help_}")
        return 0
    try:
        plugin = REGISTRY.paper_plugin(argv[0])
    except KeyError as e:
        print(f"scfmu paper: {e.args[0]}", file=sys.stderr)
        return 2
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(f"usage: scfmu paper {plugin.key} COMMAND [options]\n\n{plugin.title}; commands:")
        for name, (help_, _) in plugin.commands.items():
            print(f"  {name:12s} {help_}")
        return 0
    if argv[1] not in plugin.commands:
        print(f"scfmu paper {plugin.key}: no command {argv[1]!r}; known: {', '.join(plugin.commands)}", file=sys.stderr)
        return 2
    rc = resolve(plugin.commands[argv[1]][1])(argv[2:])
    return int(rc or 0)


LOCAL = {"scenarios": ("list the registered scenarios with descriptions", _scenarios),
         "export": ("SSP 1.0 files or loop FMUs of scenarios", _export),
         "paper": ("a paper's own experiments: `scfmu paper` lists them", _paper)}
ORDER = ("run", "scenarios", "campaign", "benchmark", "export", "report", "paper", "verify")


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ap = argparse.ArgumentParser(prog="scfmu", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmus", metavar="DIR", help="folder of the FMUs to use")
    ap.add_argument("--version", action="store_true", help="print the version and exit")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    for name in ORDER:
        help_ = (COMMANDS.get(name) or LOCAL[name])[0]
        sub.add_parser(name, help=help_, add_help=False)
    # everything after the subcommand goes to it unparsed (each has its own --help)
    i = next((k for k, a in enumerate(argv) if a in ORDER), len(argv))
    top, rest = argv[:i + 1], argv[i + 1:]
    a = ap.parse_args(top)
    if a.version:
        from . import __version__
        print(f"scfmu {__version__}")
        return 0
    if a.fmus:
        from .fmu import set_fmu_dir
        set_fmu_dir(a.fmus)
    if not a.command:
        ap.print_help()
        return 2
    if a.command in LOCAL:
        return LOCAL[a.command][1](rest)
    return int(resolve(COMMANDS[a.command][1])(rest) or 0)


if __name__ == "__main__":
    sys.exit(main())
