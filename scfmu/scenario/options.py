"""The command-line options that choose and change a scenario, shared by ``scfmu run`` and ``scfmu campaign``:

  SCENARIO                     a registered name, or a scenario file (.toml / .json)
  --fmu INSTANCE=PATH          put any FMI 2.0 Co-Simulation FMU (or another model name) in that place;
                               the old model's parameters are dropped (one notice lists them)
  --map INSTANCE.THEIRS=OURS   the unit's port THEIRS plays the scenario's port OURS
  --set INSTANCE.VAR=VALUE     a parameter or fixed input
  --params FILE                more --set values from a TOML or JSON table {"instance.var": value}
  --t-end, --dt                stop time and communication step
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

from . import files
from .model import Scenario
from ..registry import REGISTRY


def get(name: str, **kw) -> Scenario:
    return REGISTRY.scenario(name, **kw)


def value(text: str):
    """A command-line value: int, float, true/false, or the string itself."""
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def pairs(items: list[str], what: str) -> dict:
    out = {}
    for it in items:
        k, sep, v = it.partition("=")
        if not sep or not k or not v:
            raise SystemExit(f"{what} {it!r}: expected NAME=VALUE")
        out[k.strip()] = v.strip()
    return out


def add_arguments(ap) -> None:
    ap.add_argument("scenario", help="scenario name (`scfmu scenarios` lists them) or a .toml/.json scenario file")
    ap.add_argument("--fmu", action="append", default=[], metavar="INSTANCE=PATH",
                    help="use this FMU (a path to any FMI 2.0 CS FMU, or a model name) for INSTANCE (repeatable)")
    ap.add_argument("--map", action="append", default=[], metavar="INSTANCE.THEIRS=OURS",
                    help="the unit's port THEIRS plays the scenario's port OURS (repeatable)")
    ap.add_argument("--set", action="append", default=[], metavar="INSTANCE.VAR=VALUE",
                    help="parameter or fixed input for every run (repeatable)")
    ap.add_argument("--params", metavar="FILE", help="TOML or JSON table of INSTANCE.VAR = value")
    ap.add_argument("--t-end", type=float, help="override the scenario's stop time [s]")
    ap.add_argument("--dt", type=float, help="override the scenario's communication step [s]")


def load_params(path: str) -> dict:
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text()) if p.suffix.lower() == ".toml" else json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise SystemExit(f"--params {path}: {e}") from None
    flat = {}

    def walk(prefix, d):
        for k, v in d.items():
            if isinstance(v, dict):
                walk(f"{prefix}{k}.", v)
            else:
                flat[f"{prefix}{k}"] = v
    walk("", data)
    return flat


def build(args, notice=print) -> Scenario:
    """The scenario the options describe; ``notice(text)`` gets the parameters a swap dropped."""
    if files.is_scenario_file(args.scenario):
        try:
            sc = files.load(args.scenario)
        except files.ScenarioFileError as e:
            raise SystemExit(str(e)) from None
        if args.t_end is not None:
            sc.stop_time = args.t_end
        if args.dt is not None:
            sc.step = args.dt
    else:
        kw = {}
        if args.t_end is not None:
            kw["stop_time"] = args.t_end
        if args.dt is not None:
            kw["step"] = args.dt
        try:
            sc = get(args.scenario, **kw)
        except KeyError as e:
            raise SystemExit(str(e.args[0] if e.args else e)) from None
    models = {}
    for inst, target in pairs(args.fmu, "--fmu").items():
        if "/" in target or target.endswith(".fmu"):
            p = Path(target).expanduser()
            if not p.is_file():
                raise SystemExit(f"--fmu {inst}={target}: no such file")
            target = str(p.resolve())
        models[inst] = target
    try:
        dropped = sc.dropped_params(models)
        sc = sc.with_models(models)
    except KeyError as e:
        raise SystemExit(f"--fmu: {e.args[0]}") from None
    for inst, names in dropped.items():
        notice(f"notice: {inst} is now {Path(models[inst]).name}; the parameters of its old model are not "
               f"passed on: {', '.join(names)} (set the new unit's own with --set {inst}.NAME=VALUE)")
    try:
        sc = sc.with_port_map(pairs(args.map, "--map"))
    except KeyError as e:
        raise SystemExit(f"--map: {e.args[0]}") from None
    ov = load_params(args.params) if args.params else {}
    ov.update({k: value(v) for k, v in pairs(args.set, "--set").items()})
    if ov:
        try:
            sc = sc.with_overrides(ov)
        except KeyError as e:
            raise SystemExit(f"--set: {e.args[0]}") from None
    return sc
