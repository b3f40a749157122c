"""The changes a user makes to a scenario, as plain data (:class:`RunChanges`: the scenario by name or
file, units swapped in, port maps, profiles, values, stop time and step), and :func:`build`, the scenario
they describe. The command lines of ``scfmu run``, ``scfmu campaign`` and ``scfmu export`` fill a
:class:`RunChanges` from their options; the argparse definitions live there (:mod:`scfmu.run_cmd`,
``add_scenario_arguments``). The timing and the values are checked once, when the scenario's plan is built
(:func:`scfmu.scenario.plan.build_plan`; the pre-flight :func:`scfmu.scenario.check.check`).
"""

from __future__ import annotations

import json
import math
import sys
import tomllib
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from . import files, profile
from .model import Scenario
from .values import UsageError, did_you_mean, parse_cli
from ..registry import REGISTRY


def get(name: str, **kw) -> Scenario:
    return REGISTRY.scenario(name, **kw)


def value(text: str):
    """A command-line value: int, float, true/false, or the string itself (:func:`values.parse_cli`; the
    pre-flight check then holds it to the declared type and bounds of what it sets)."""
    return parse_cli(text)


def pairs(items: list[str], what: str) -> dict:
    out = {}
    for it in items:
        k, sep, v = it.partition("=")
        if not sep or not k.strip() or not v.strip():
            raise UsageError(f"{what} {it!r}: expected NAME=VALUE")
        out[k.strip()] = v.strip()
    return out


def scenario_by_name(name: str, **kw) -> Scenario:
    """A registered scenario; an unknown name is a :class:`UsageError` with the closest known names."""
    try:
        return get(name, **kw)
    except KeyError:
        known = [n for n, _ in REGISTRY.scenario_names("*")]
        if name in known:
            raise
        if name.lower().endswith((".toml", ".json")):
            raise UsageError(f"scenario file {name!r} not found") from None
        raise UsageError(f"unknown scenario {name!r}{did_you_mean(name, known)} (`scfmu scenarios` lists them)") \
            from None


def fmu_file(option: str, text: str) -> str:
    """The resolved path of an FMU file given on the command line; a :class:`UsageError` when it is a
    directory, missing, not an ``.fmu`` file, or not a zip archive (truncated, another kind of file)."""
    p = Path(text).expanduser()
    if p.is_dir():
        raise UsageError(f"{option}{text}: a directory, not an FMU file (give the .fmu archive)")
    if not p.is_file():
        raise UsageError(f"{option}{text}: no such file")
    if p.suffix.lower() != ".fmu":
        raise UsageError(f"{option}{text}: not an .fmu file (give the FMU archive)")
    if not zipfile.is_zipfile(p):
        raise UsageError(f"{option}{text}: not an FMU archive (not a zip file: truncated, or another kind of file); "
                         f"allowed: an FMI 2.0/3.0 .fmu file")
    return str(p.resolve())


@dataclass
class RunChanges:
    """What the user changes in a scenario: ``scenario`` (a registered name or a scenario file), units
    (``fmu``: ``INSTANCE=PATH``), port maps (``map``), unit profiles (``profile``), values (``set``:
    ``INSTANCE.VAR=VALUE``; ``params``: a TOML/JSON file of them), ``strict`` binding, and the stop time
    ``t_end`` and step ``dt`` [s] (None: the scenario's)."""

    scenario: str
    fmu: list = field(default_factory=list)
    map: list = field(default_factory=list)
    profile: list = field(default_factory=list)
    set: list = field(default_factory=list)
    params: str | None = None
    strict: bool = False
    t_end: float | None = None
    dt: float | None = None

    def origins(self) -> dict:
        """``{"instance.name": "--set" | "--params"}``: where each value the user gives comes from (the
        plan's :class:`~scfmu.scenario.plan.Setting` origin)."""
        out = {k: "--params" for k in (load_params(self.params) if self.params else {})}
        out.update({k: "--set" for k in pairs(self.set, "--set")})
        return out


def load_params(path: str) -> dict:
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text()) if p.suffix.lower() == ".toml" else json.loads(p.read_text())
    except OSError as e:
        raise UsageError(f"--params {path}: {e.strerror or e}") from None
    except ValueError as e:
        raise UsageError(f"--params {path}: not valid {'TOML' if p.suffix.lower() == '.toml' else 'JSON'}: "
                         f"{str(e).splitlines()[0]}") from None
    if not isinstance(data, dict):
        raise UsageError(f"--params {path}: expected a table of INSTANCE.VAR = value")
    flat = {}

    def walk(prefix, d):
        for k, v in d.items():
            if isinstance(v, dict):
                walk(f"{prefix}{k}.", v)
            else:
                flat[f"{prefix}{k}"] = v
    walk("", data)
    return flat


def build(args: RunChanges, notice=print) -> Scenario:
    """The scenario the changes describe; ``notice(text)`` gets the parameters a swap dropped. A user's
    mistake raises :class:`~scfmu.scenario.values.UsageError` (one line; ``scfmu`` exits 2). Its timing
    and values are checked when its plan is built."""
    if files.is_scenario_file(args.scenario):
        try:
            sc = files.load(args.scenario)
        except files.ScenarioFileError as e:
            raise UsageError(str(e)) from None
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
        sc = scenario_by_name(args.scenario, **kw)
    for opt, v in (("--t-end", args.t_end), ("--dt", args.dt)):
        if v is not None and not math.isfinite(v):
            raise UsageError(f"{opt} {v}: not finite; allowed: a finite number of seconds")
    models = {}
    for inst, target in pairs(args.fmu, "--fmu").items():
        if "/" in target or target.endswith(".fmu"):
            target = fmu_file(f"--fmu {inst}=", target)
        models[inst] = target
    instances = [c.name for c in sc.components]
    for inst in models:
        if inst not in instances:
            raise UsageError(f"--fmu {inst}=...: scenario {sc.name!r} has no instance {inst!r}"
                             f"{did_you_mean(inst, instances)} (it has {', '.join(instances)})")
    dropped = sc.dropped_params(models)
    sc = sc.with_models(models)
    for inst, names in dropped.items():
        notice(f"notice: {inst} is now {Path(models[inst]).name}; the parameters of its old model are not "
               f"passed on: {', '.join(names)} (set the new unit's own with --set {inst}.NAME=VALUE)")
    for item in args.profile:
        inst, sep, path = item.partition("=")
        if not sep:
            inst, path = "", item
        if not inst:
            if len(models) != 1:
                _fail(f"--profile {item}: say which instance it is for (--profile INSTANCE={item}); "
                      f"units given with --fmu: {', '.join(models) or 'none'}")
            inst = next(iter(models))
        try:
            sc = profile.apply(sc, inst, profile.load(path))
        except profile.ProfileError as e:
            _fail(str(e))
        except KeyError as e:
            _fail(f"--profile {item}: {e.args[0]}")
    try:
        sc = sc.with_port_map(pairs(args.map, "--map"))
    except KeyError as e:
        raise UsageError(f"--map: {e.args[0]}") from None
    ov = load_params(args.params) if args.params else {}
    ov.update({k: value(v) for k, v in pairs(args.set, "--set").items()})
    if ov:
        for key in ov:
            inst = key.partition(".")[0] if not key.startswith("input:") else key[6:].partition(".")[0]
            if "." not in key:
                raise UsageError(f"--set {key}: expected INSTANCE.NAME=VALUE")
            if inst not in instances:
                raise UsageError(f"--set {key}: scenario {sc.name!r} has no instance {inst!r}"
                                 f"{did_you_mean(inst, instances)} (it has {', '.join(instances)})")
        try:
            sc = sc.with_overrides(ov)
        except KeyError as e:
            raise UsageError(f"--set: {e.args[0]}") from None
    return sc


def binding_report(sc: Scenario, prog: str, strict: bool, warn, resolved: bool = False) -> list[str]:
    """The slot values that reach no parameter of a swapped unit, each passed to ``warn("warning: …")``;
    with ``strict`` raises SystemExit(2) with one line naming the first (and how many more). ``resolved``:
    ``sc`` is already resolved (a plan's scenario)."""
    from .resolve import unbound_slots
    texts = [u.text() for u in unbound_slots(sc, resolved=resolved)]
    if strict and texts:
        _fail(f"{prog}: --strict: {texts[0]}" + (f" (and {len(texts) - 1} more)" if len(texts) > 1 else ""))
    for t in texts:
        warn(f"warning: {t}")
    return texts


def _fail(line: str):
    """A user's mistake: one line on stderr, exit code 2."""
    print(line, file=sys.stderr)
    raise SystemExit(2)
