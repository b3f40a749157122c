"""The ``scfmu`` command line (also ``python -m scfmu``).

Subcommands (each has ``--help``):

  run SCENARIO            one run: metrics, CSV and PNG           (scfmu run default)
  scenarios [PATTERN]     the registered scenarios, with descriptions
  campaign SCENARIO ...   many runs on Dask: grids, random samples, seeds; Parquet + figures
  benchmark [FMU]         your controller beside the papers' ones on a family's scenarios (HTML + Markdown)
  export ssp|loop [NAME]  SSP files (1.0; --ssp-version 2.0) or loop FMUs (one container FMU per closed loop)
  report [--quick]        the reproduction report of every paper (HTML + Markdown)
  paper NNN COMMAND ...   a paper's own experiments (tuning, sweeps, cases): `scfmu paper` lists them
  check FMU [--quick]     conformance and robustness gauntlet for any FMI 2.0/3.0 FMU (table, HTML, JSON)
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
    "check": ("conformance and robustness gauntlet for any FMI 2.0/3.0 FMU", "scfmu.check.cli:main"),
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
        from .scenario.options import scenario_by_name
        sc = scenario_by_name(a.show)  # an unknown name: one line with the closest known names (exit 2)
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
    from .scenario.ssp2 import Refused
    from .scenario import options
    ap = argparse.ArgumentParser(prog="scfmu export", description="Write SSP 1.0 files or loop FMUs of scenarios "
                                 "(default: the standard set the plug-ins export) and validate each. With --fmu, "
                                 "--map or --set, one scenario (a name or a scenario file) with those changes.")
    ap.add_argument("kind", choices=KINDS)
    ap.add_argument("names", nargs="*", help="scenario names or files (default: the standard set)")
    ap.add_argument("--out", default=None, help="output folder (default fmus/ssp or fmus/loops)")
    ap.add_argument("--platform", choices=("host", "all"), default="host",
                    help="binaries the files carry: this machine's only (host, default: about 4x smaller) or every "
                         "platform the FMUs carry (all: a file for other machines)")
    ap.add_argument("--fmu", action="append", default=[], metavar="INSTANCE=PATH", help="use this FMU for INSTANCE")
    ap.add_argument("--map", action="append", default=[], metavar="INSTANCE.THEIRS=OURS", help="rename a unit's port")
    ap.add_argument("--set", action="append", default=[], metavar="INSTANCE.VAR=VALUE", help="parameter or input")
    ap.add_argument("--profile", action="append", default=[], metavar="[INSTANCE=]FILE", help="unit profile (TOML)")
    ap.add_argument("--ssp-version", default="1.0", metavar="{1.0,2.0}",
                    help="SSP version of the files (ssp only): 1.0 (default; FMI 1.0/2.0 units) or 2.0 (FMI 3.0 units too)")
    a = ap.parse_args(argv)
    if a.ssp_version not in ("1.0", "2.0") or (a.ssp_version != "1.0" and a.kind != "ssp"):
        print(f"scfmu export: --ssp-version {a.ssp_version}: allowed: 1.0 or 2.0, with `scfmu export ssp`",
              file=sys.stderr)
        return 2
    out = a.out or ("fmus/ssp" if a.kind == "ssp" else "fmus/loops")
    items = a.names or None
    if a.fmu or a.map or a.set or a.profile or any(n.endswith((".toml", ".json")) for n in a.names):
        if len(a.names) != 1:
            print("scfmu export: --fmu/--map/--set and scenario files take exactly one scenario", file=sys.stderr)
            return 2
        changes = options.RunChanges(a.names[0], fmu=a.fmu, map=a.map, set=a.set, profile=a.profile)
        items = [options.build(changes, notice=lambda t: print(t, file=sys.stderr))]
        options.binding_report(items[0], "scfmu export", False, lambda t: print(t, file=sys.stderr))
        from .scenario.check import IncompatibleUnit, require
        from .scenario.plan import PlanError
        try:  # names, values against the declared types and bounds (no run)
            require(items[0], instantiate=False, warn=lambda t: print(f"warning: {t}", file=sys.stderr))
        except IncompatibleUnit as e:
            print(f"scfmu export: {e.one_line()}", file=sys.stderr)
            return 2
        except PlanError as e:  # a scenario file's times
            print(f"scfmu export: {e}", file=sys.stderr)
            return 2
    try:
        export(a.kind, out, items, platform=a.platform, ssp_version=a.ssp_version)
    except KeyError as e:  # an unknown scenario name or prefix (the message names the known ones)
        print(f"scfmu export: {e.args[0] if e.args else e}", file=sys.stderr)
        return 2
    except Refused as e:  # what the SSP version asked for cannot hold (FMI 3.0 units in SSP 1.0)
        print(f"scfmu export: {e}", file=sys.stderr)
        return 2
    except (RuntimeError, ValueError) as e:
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
        from .scenario.values import did_you_mean
        print(f"scfmu paper {plugin.key}: no command {argv[1]!r}{did_you_mean(argv[1], plugin.commands)}; known: "
              f"{', '.join(plugin.commands)}", file=sys.stderr)
        return 2
    rc = resolve(plugin.commands[argv[1]][1])(argv[2:])
    return int(rc or 0)


LOCAL = {"scenarios": ("list the registered scenarios with descriptions", _scenarios),
         "export": ("SSP 1.0 files or loop FMUs of scenarios", _export),
         "paper": ("a paper's own experiments: `scfmu paper` lists them", _paper)}
ORDER = ("run", "scenarios", "campaign", "benchmark", "export", "report", "paper", "check", "verify")


# the optional extras (pyproject.toml) and the modules they provide (tests/test_first_hour.py holds each to
# the extra's requirements in pyproject.toml)
EXTRAS = {"campaigns": ("pyarrow", "dask", "distributed", "control"), "papers": ("pyswarms", "pygad"),
          "libcosim": ("libcosim",)}
# the extra a command needs and the modules of it the command imports (checked before it starts; not for --help)
NEEDS = {"campaign": ("campaigns", ("pyarrow", "dask", "distributed")),
         # python-control: the benchmark's stability margins (scfmu.benchmark.margins)
         "benchmark": ("campaigns", ("pyarrow", "dask", "distributed", "control")),
         "report": ("campaigns", ("pyarrow", "dask", "distributed"))}
RESUME = {"run": "nothing was written; run the same command again to start over",
          "campaign": "the workers were stopped and the runs finished so far are kept; run the same command "
                      "again to resume",
          "benchmark": "the workers were stopped; run the same command again to start over"}


def _extra_of(module: str | None) -> str | None:
    root = (module or "").split(".")[0]
    for extra, mods in EXTRAS.items():
        if root in mods or root == "libcosimpy" and extra == "libcosim":
            return extra
    return None


def _missing_extra(command: str) -> str | None:
    """The one line for a command whose extra is not installed (None when it is)."""
    if command not in NEEDS:
        return None
    extra, modules = NEEDS[command]
    import importlib
    for mod in modules:
        try:
            importlib.import_module(mod)
        except ImportError:
            return (f"scfmu {command} needs the {extra!r} extra ({mod} is not installed): "
                    f"pip install 'scfmu[{extra}]'")
    return None


def _wants_help(rest: list) -> bool:
    """``-h``/``--help`` among a subcommand's options (before a ``--``): its help needs no extra."""
    opts = rest[:rest.index("--")] if "--" in rest else rest
    return "-h" in opts or "--help" in opts


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread as Ctrl-C is, so that a command ends the same way: its ``finally``
    blocks stop its workers and kill its child processes, then one line (exit 143)."""


def _on_sigterm(signum, frame):
    raise Terminated()


def _run_command(command: str, rest: list) -> int:
    """Runs a subcommand; a user's mistake, a refused archive or unknown model name, an FMU's error, a missing
    extra or Ctrl-C (or SIGTERM) end in one line on stderr (exit 2, 2, 1, 2, 130), never in a traceback."""
    from .fmu import ArchiveError, UnknownModel
    from .scenario.values import UsageError
    from fmpy.fmi1 import FMICallException
    import signal
    import threading
    if threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        missing = None if _wants_help(rest) else _missing_extra(command)
        if missing:
            print(missing, file=sys.stderr)
            return 2
        if command in LOCAL:
            return LOCAL[command][1](rest)
        return int(resolve(COMMANDS[command][1])(rest) or 0)
    except UsageError as e:
        print(f"scfmu {command}: {e.message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        how, code = ("SIGTERM", 143) if isinstance(e, Terminated) else ("Ctrl-C", 130)
        print(f"\nscfmu {command}: interrupted ({how}); {RESUME.get(command, 'run the same command again')}",
              file=sys.stderr)
        return code
    except (ArchiveError, UnknownModel) as e:  # a refused archive, a misspelled model name
        print(f"scfmu {command}: {e}", file=sys.stderr)
        return 2
    except FMICallException as e:
        print(f"scfmu {command}: an FMU call failed: {e}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as e:
        extra = _extra_of(e.name)
        if extra is None:
            raise
        print(f"scfmu {command} needs the {extra!r} extra ({e.name} is not installed): pip install 'scfmu[{extra}]'",
              file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into a program that stopped reading (`| head`)
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as e:  # an output folder that cannot be written, a full disk, ...
        where = f"{e.filename}: " if e.filename else ""
        print(f"scfmu {command}: {where}{e.strerror or e}", file=sys.stderr)
        return 1


def _one_line_error(self, message):
    """argparse's refusal of an option as one line (its usage is one ``--help`` away), exit status 2."""
    self.exit(2, f"{self.prog}: {message} (`{self.prog} --help` lists the options)\n")


def main(argv=None) -> int:
    import argparse
    error, argparse.ArgumentParser.error = argparse.ArgumentParser.error, _one_line_error
    try:
        return _main(argv)
    except KeyboardInterrupt as e:  # before a command started (imports, parsing): nothing to stop yet
        how, code = ("SIGTERM", 143) if isinstance(e, Terminated) else ("Ctrl-C", 130)
        print(f"\nscfmu: interrupted ({how}) while starting; nothing was done", file=sys.stderr)
        return code
    finally:
        argparse.ArgumentParser.error = error


def _main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    first = next((a for a in argv if not a.startswith("-")), None)
    if first is not None and first not in ORDER and not (argv.index(first) > 0 and argv[argv.index(first) - 1] == "--fmus"):
        from .scenario.values import did_you_mean
        print(f"scfmu: unknown command {first!r}{did_you_mean(first, ORDER)} (commands: {', '.join(ORDER)}; "
              f"`scfmu --help`)", file=sys.stderr)
        return 2
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
    return _run_command(a.command, rest)


if __name__ == "__main__":
    sys.exit(main())
