"""``scfmu run SCENARIO``: one run of a scenario, its metrics printed, its logged signals written as CSV
and a PNG figure.

``scfmu run default`` is paper 000 run 000-6: the quaternion PD law on the large command (roll 40°,
pitch -40°, yaw -60° from rest), AttitudeCommand + PdController + AttitudePlant + AttitudeMetrics,
inertia diag(1000, 500, 700) kg·m², no torque limit, RK4 0.01 s, communication step 0.01 s, 30 s.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

import sys

from .engines import ENGINES, SimulationError, simulate
from .fmu import is_path
from .scenario.plan import PlanError
from .results import write_csv
from .scenario import options
from .fmu import FmuError
from .scenario.check import IncompatibleUnit, require
from .scenario.values import UsageError, bounded_int
from .scenario.ssp import file_stem

ANGLES = ("roll", "pitch", "yaw")


def _groups(keys: list[str]) -> dict[str, list[str]]:
    """Logged keys grouped for plotting: 321 angles (with references), vectors by their base name."""
    g: dict[str, list[str]] = {}
    for k in keys:
        base = k[:-4] if k.endswith("_ref") else k
        if base in ANGLES:
            name = "321 angles"
        elif len(base) > 2 and base[-2] == "_" and base[-1] in "wxyz":
            name = base[:-2]
        else:
            name = base
        g.setdefault(name, []).append(k)
    return g


_LABELS = {"321 angles": "321 angles", "alpha_deg": "attitude error α", "w": "body rates ω",
           "torque_applied": "applied torque", "torque_cmd": "commanded torque", "q": "attitude quaternion"}


def plot(r: dict, path: Path, title: str, units: dict | None = None) -> None:
    """The run's figure: up to four panels, the preferred ones first (321 angles with their references,
    α on a log axis, body rates, applied torque), each axis labelled with its unit."""
    from matplotlib.figure import Figure  # no pyplot: no global figure state, the Agg canvas by default
    from matplotlib.ticker import FuncFormatter, NullFormatter
    units = units or {}
    groups = _groups([k for k in r if k != "time"])
    prefer = ["321 angles", "alpha_deg", "w", "torque_applied", "theta", "pos", "torque_cmd", "force", "u",
              "applied_torque"]
    chosen = [n for n in prefer if n in groups][:4]
    chosen += [n for n in groups if n not in chosen][: max(0, 3 - len(chosen))]
    fig = Figure(figsize=(8, 2.6 * len(chosen) + 0.8))
    axs = fig.subplots(len(chosen), 1, sharex=True, squeeze=False)
    t = r["time"]
    for ax, name in zip(axs[:, 0], chosen):
        unit = "deg" if name == "321 angles" else units.get(groups[name][0], "")
        for k in groups[name]:
            y = np.asarray(r[k], dtype=float)
            if name == "321 angles" and units.get(k, "rad") == "rad":
                y = np.degrees(y)
            if name == "alpha_deg":
                pos = y[y > 0]
                y = np.clip(y, pos.min() if pos.size else 1e-12, None)  # log axis: α = 0 exactly is not drawn
            ax.plot(t, y, ls=":" if k.endswith("_ref") else "-", label=k)
        if name == "alpha_deg":
            ax.set_yscale("log")
            # plain tick labels ("1e-05"): the default ones are mathtext, whose parser costs ~0.3 s CPU to build
            ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:.0e}"))
            ax.yaxis.set_minor_formatter(NullFormatter())
        label = _LABELS.get(name, name)
        ax.set_ylabel(f"{label} [{unit}]" if unit else f"{label} [-]", fontsize=9)
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(fontsize=8, ncol=3)
    axs[-1, 0].set_xlabel("time [s]")
    fig.suptitle(title, fontsize=9)
    # fixed margins in inches, the top one by the title's lines (tight_layout measures every text: about 0.1 s
    # of CPU a figure, a tenth of a warm `scfmu run default`)
    h = fig.get_figheight()
    top = 0.25 + 0.17 * (title.count("\n") + 1)
    fig.subplots_adjust(left=0.95 / 8, right=1 - 0.15 / 8, bottom=0.55 / h, top=1 - top / h, hspace=0.12)
    # zlib level 1: the default level 6 costs about 0.1 s more of CPU for a file 0.6 times the size (140 kB)
    fig.savefig(path, dpi=110, pil_kwargs={"compress_level": 1})


def unit_label(model: str) -> str:
    """A model's name, or for a unit given by path its folder and file (``fmi3/PdController.fmu``)."""
    if not is_path(model):
        return model
    p = Path(model)
    return f"{p.parent.name}/{p.name}" if p.parent.name else p.name


def run_folder_name(sc) -> str:
    """``<scenario>`` plus ``+<unit>`` for every instance whose unit was swapped (``--fmu``)."""
    name = file_stem(sc.name)
    for inst in sc.swapped:
        name += "+" + Path(sc.component(inst).model).stem
    return name


def run_identity(sc, engine: str) -> dict:
    """What makes a run this run: the scenario (models, parameters, wiring, times), the engine and the FMU
    files' SHA-256 (a rebuilt unit is another run)."""
    from .fmu import fmu_digest, fmu_path
    return {"scenario": json.loads(sc.to_json()), "engine": engine,
            "fmus": {c.model: fmu_digest(fmu_path(c.model)) for c in sc.components}}


def choose_folder(base: Path, ident: dict, chosen: bool) -> tuple[Path, str | None]:
    """The folder to write a run to and a notice (None when there is nothing to say): ``base`` when it is
    new or holds this same run (its ``run.json``); otherwise, when the folder was not chosen with
    ``--out``, the first free ``base-2``, ``base-3``, ... (another run's files are never overwritten);
    with ``--out`` the files are replaced, with a notice."""
    def holds_other(p: Path) -> bool:
        if not p.exists() or not any(p.iterdir()):
            return False
        try:
            return json.loads((p / "run.json").read_text()) != ident
        except (OSError, ValueError):
            return True  # files of something else
    if not holds_other(base):
        return base, None
    if chosen:
        return base, f"note: {base} held the files of another run; files of the same names are replaced"
    i = 2
    while holds_other(base.with_name(f"{base.name}-{i}")):
        i += 1
    p = base.with_name(f"{base.name}-{i}")
    return p, f"note: {base} holds another run; this one is written to {p}"


OPTIONS_HELP = """The command-line options that choose and change a scenario, shared by ``scfmu run`` and ``scfmu campaign``:

  SCENARIO                     a registered name, or a scenario file (.toml / .json)
  --fmu INSTANCE=PATH          put any FMI 2.0 or 3.0 FMU, Co-Simulation or Model Exchange (or another model
                               name) in that place; the old model's parameters are dropped (one notice
                               lists them)
  --map INSTANCE.THEIRS=OURS   the unit's port THEIRS plays the scenario's port OURS; a vector stem renames
                               every element (--map controller.omega=w); a parameter THEIRS takes the
                               place's slot value OURS (--map controller.J1=inertia_xx)
  --profile [INSTANCE=]FILE    the unit's profile (TOML: [params] J1 = "inertia_xx", [ports], unused = [...]);
                               INSTANCE defaults to the one given with --fmu
  --strict                     refuse to run when a slot value of the place reaches no parameter of the unit
  --set INSTANCE.VAR=VALUE     a parameter or fixed input
  --params FILE                more --set values from a TOML or JSON table {"instance.var": value}
  --t-end, --dt                stop time and communication step
"""


def add_scenario_arguments(ap: argparse.ArgumentParser) -> None:
    """The options that choose and change a scenario (``scfmu run`` and ``scfmu campaign``); read them back
    with :func:`run_changes`."""
    ap.add_argument("scenario", help="scenario name (`scfmu scenarios` lists them) or a .toml/.json scenario file")
    ap.add_argument("--fmu", action="append", default=[], metavar="INSTANCE=PATH",
                    help="use this FMU (a path to any FMI 2.0 or 3.0 FMU, Co-Simulation or Model Exchange, or a model "
                         "name) for INSTANCE (repeatable)")
    ap.add_argument("--map", action="append", default=[], metavar="INSTANCE.THEIRS=OURS",
                    help="the unit's port (or vector stem) THEIRS plays the scenario's port OURS; a parameter "
                         "THEIRS takes the place's slot value OURS (repeatable)")
    ap.add_argument("--profile", action="append", default=[], metavar="[INSTANCE=]FILE",
                    help="unit profile (TOML) binding the unit's parameters to the place's slot values")
    ap.add_argument("--strict", action="store_true",
                    help="refuse to run when a slot value (e.g. the nominal inertia) reaches no parameter of a unit")
    ap.add_argument("--set", action="append", default=[], metavar="INSTANCE.VAR=VALUE",
                    help="parameter or fixed input for every run (repeatable)")
    ap.add_argument("--params", metavar="FILE", help="TOML or JSON table of INSTANCE.VAR = value")
    ap.add_argument("--t-end", type=float, help="override the scenario's stop time [s]")
    ap.add_argument("--dt", type=float, help="override the scenario's communication step [s]")


def run_changes(args) -> options.RunChanges:
    """The plain :class:`~scfmu.scenario.options.RunChanges` of parsed scenario options."""
    return options.RunChanges(args.scenario, fmu=list(args.fmu), map=list(args.map), profile=list(args.profile),
                              set=list(args.set), params=args.params, strict=args.strict, t_end=args.t_end,
                              dt=args.dt)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="scfmu run", description=__doc__ + "\n" + OPTIONS_HELP,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scenario_arguments(ap)
    ap.add_argument("--engine", default=None, choices=ENGINES,
                    help="engine (all give bit-identical results on Co-Simulation units); default native, or, "
                         "when a unit runs as Model Exchange, compiled (else native; lean, SciPy, only "
                         "without either Rust library)")
    ap.add_argument("--clocks", default="sampled", choices=("sampled", "clocked", "scheduled"),
                    help="how FMI 3.0 units with clocks run: sampled (default: they sample inside doStep, as "
                         "FMI 2.0 units always do), clocked (clocked Co-Simulation: each clock's partition "
                         "activated at its ticks) or scheduled (Scheduled Execution, by a small scheduler); "
                         "bit-identical results; clocked and scheduled run on the lean engine")
    ap.add_argument("--out", default=None, help="output folder (default out/<scenario>[+<unit>...]: its own folder "
                                                "per run; another run's folder gets a -2, -3, ... suffix)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--log-every", type=int, default=1, metavar="N",
                    help="native engine: log every N-th communication step (for long runs; metrics on that grid)")
    return ap


def _unit_labels(sc, plan, clocks: str = "sampled") -> str:
    """``plant=AttitudePlant.fmu, controller=X.fmu (FMI 3.0 Model Exchange)``: each unit's file, with how it
    runs when that is not FMI 2.0 Co-Simulation (a unit with clocks: clocked Co-Simulation or Scheduled
    Execution under ``--clocks``)."""
    how = {u.name: (u.fmi, u.interface) for u in plan.units} if plan is not None else {}
    clocked = {u.name for u in plan.units if u.clocks} if plan is not None and clocks != "sampled" else set()
    cs = {"clocked": "clocked Co-Simulation", "scheduled": "Scheduled Execution"}.get(clocks, "Co-Simulation")
    out = []
    for c in sc.components:
        fmi, itf = how.get(c.name, (2, "cs"))
        note = "" if (fmi, itf) == (2, "cs") else \
            f" (FMI {fmi}.0 {'Model Exchange' if itf == 'me' else cs if c.name in clocked else 'Co-Simulation'})"
        out.append(f"{c.name}={Path(c.model).name}{note}")
    return ", ".join(out)


def _write(sc, r, args, out: Path, ident: dict, unbound: list, plan=None) -> None:
    """Prints the run's summary and metrics and writes the CSV, run.json, the manifest and the plot."""
    stem = file_stem(sc.name)
    out.mkdir(parents=True, exist_ok=True)
    m, mu = r.metrics, r.metric_units
    print(f"{sc.name}: {sc.description or ''}".rstrip(": "))
    models = _unit_labels(sc, plan, getattr(args, "clocks", "sampled"))
    clocks = "" if getattr(args, "clocks", "sampled") == "sampled" else f" (units on their clocks: {args.clocks})"
    print(f"  {len(r['time']) - 1} steps of {sc.step:g} s to t = {sc.stop_time:g} s on the {args.engine} engine{clocks}; "
          f"units {models}; metric set {sc.metrics or '(none)'}")
    for k, v in m.items():
        if isinstance(v, float) and math.isfinite(v):
            print(f"  {k:24s} {v:14.6g} {mu.get(k, '')}".rstrip())
    csv = out / f"{stem}.csv"
    write_csv(csv, r)
    (out / "run.json").write_text(json.dumps(ident, indent=1, sort_keys=True))
    manifest = out / f"{stem}.manifest.json"  # what ran: the scenario as plain data, units, metrics, warnings
    manifest.write_text(json.dumps({"scenario": sc.to_dict(), "engine": args.engine, "clocks": args.clocks, "metrics": m,
                                    "unbound_slot_values": unbound}, indent=1, default=str))
    written = [csv, manifest]
    if not args.no_plot:
        png = out / f"{stem}.png"
        units = ", ".join(f"{c.name} = {unit_label(c.model)}" for c in sc.components)
        title = f"{sc.name} ({args.engine} engine)\n{units}"
        if math.isfinite(m.get("eulerint_deg_s", math.nan)):
            title += f"\nEULERINT = {m['eulerint_deg_s']:.2f} deg·s"
        if unbound:
            title += f"\n⚠ {len(unbound)} slot value(s) not passed to the unit: " + ", ".join(
                t.split("slot value ")[1].split(" not passed")[0] for t in unbound)
        plot(r, png, title, r.units)
        written.append(png)
    print("wrote " + " and ".join(str(p) for p in written))


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    changes = run_changes(args)
    sc = options.build(changes, notice=lambda t: print(t, file=sys.stderr))
    bounded_int("--log-every", args.log_every, 1, 10 ** 9)
    if args.log_every != 1 and args.engine not in (None, "native"):
        raise UsageError(f"--log-every {args.log_every}: allowed only with --engine native (the {args.engine} "
                         f"engine logs every step)")
    try:  # the pre-flight builds the plan (timing, units, wiring, values: once) and tries the units
        plan = require(sc, warn=lambda t: print(f"warning: {t}", file=sys.stderr), log_every=args.log_every,
                       log_hint=args.engine in (None, "native"), origins=changes.origins()).plan
    except IncompatibleUnit as e:
        print(f"scfmu run: {e.one_line()}", file=sys.stderr)
        return 2
    except (PlanError, KeyError, ValueError) as e:
        print(f"scfmu run: {e}", file=sys.stderr)
        return 2
    unbound = options.binding_report(plan.scenario, "scfmu run", args.strict, lambda t: print(t, file=sys.stderr),
                                     resolved=True)
    if args.clocks != "sampled":
        from .engines.clocked import clock_notice, clock_problem, order_notice
        why = clock_problem(plan, args.clocks)
        if why is None and args.engine not in (None, "lean"):
            why = f"--clocks {args.clocks} runs on the lean engine (its clocked master), not --engine {args.engine}"
        if why:
            print(f"scfmu run: {why}", file=sys.stderr)
            return 2
        for notice in (clock_notice(plan, args.clocks), order_notice(plan, args.clocks)):
            if notice:
                print(notice, file=sys.stderr)
        args.engine = "lean"
    if args.engine is None:
        args.engine = "native"
        if plan.model_exchange:  # both Rust engines step a Model Exchange unit with the one stepper
            # (scfmu/engines/fmi_stepper): the compiled loop directly, native through the unit's Co-Simulation
            # face (scfmu.engines.cs_face, the wrapper library of this platform). SciPy (lean) only when
            # neither library is here, and then said.
            from .engines.compiled import available
            from .engines.cs_face import wrapper_library
            args.engine = "compiled" if available() else "native" if wrapper_library() else "lean"
            if args.engine == "lean":
                print("scfmu run: no compiled loop or Model Exchange wrapper library for this platform: the "
                      "Model Exchange units are integrated by SciPy (--engine lean)", file=sys.stderr)
    if args.log_every != 1 and args.engine != "native":
        raise UsageError(f"--log-every {args.log_every}: allowed only with --engine native (the {args.engine} "
                         f"engine logs every step)")
    ident = run_identity(sc, args.engine)
    if args.clocks != "sampled":  # (a sampled run's identity stays what it was)
        ident["clocks"] = args.clocks
    out, notice = choose_folder(Path(args.out) if args.out else Path("out") / run_folder_name(sc), ident,
                                chosen=args.out is not None)
    if notice:
        print(notice, file=sys.stderr)
    try:
        r = simulate(plan, args.engine, clocks=args.clocks,
                     **({"log_every": args.log_every} if args.log_every != 1 else {}))
    except PlanError as e:
        print(f"scfmu run: {e}", file=sys.stderr)
        return 2
    except SimulationError as e:
        print(f"scfmu run: the run failed ({e.status}): {e}", file=sys.stderr)
        return 1
    except FmuError as e:
        print(f"scfmu run: the run failed: {e}", file=sys.stderr)
        return 1
    _write(sc, r, args, out, ident, unbound, plan)
    return 0
