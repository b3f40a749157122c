"""The plan of a scenario: what every engine executes, worked out once.

:func:`build_plan` resolves a scenario (:func:`~scfmu.scenario.resolve.resolve`) and reads each unit's
model description once, then fixes everything the engines need:

* ``units``: the instances in Gauss–Seidel order, each with its FMU file, model description, FMI major
  version (2 or 3), interface (``"cs"`` Co-Simulation or ``"me"`` Model Exchange, with the solver
  settings of an ME instance) and, per variable name, its value reference and scenario type;
* ``links``: the wiring ``(dst, dst_input, src, src_output)`` in Gauss–Seidel order (:meth:`Scenario.wiring`);
* ``groups``: the links grouped by destination (in component order), then by source (in order of first
  appearance among the destination's inputs) and type, with the value references of both ends: one
  get of the source and one set of the destination per group;
* ``log``: the logged signals grouped by instance (in order of first appearance) and type;
* ``params``: per instance, the parameters to set in initialization mode, each a :class:`Setting` (value
  reference, FMI type, value, where it came from: the scenario, ``--set``, a binding, a slot value, a seed);
  ``inputs``: the fixed inputs, written after initialization, the same way. Every engine sets them through
  one function (:func:`apply_params`);
* ``problems`` and ``input_problems``: what is wrong with the values (a parameter or fixed input the unit
  does not have, a value outside its declared type or bounds), in the pre-flight's words (a name no unit
  has is a ``KeyError`` of :func:`build_plan`); the pre-flight
  (:mod:`scfmu.scenario.check`) reports them, an engine lets the unit refuse a value itself.

The timing (start, stop, step, the logged rows) is checked here too (:func:`timing_problem`), before
anything is read.

One rule decides which connections are allowed (:data:`LINK_TYPES`): Real, Integer and Boolean, the
two ends of the same type. FMI 3.0 ``Float64``, ``Int32`` and ``Boolean`` are the scenario's Real,
Integer and Boolean (:func:`scfmu.fmu.scalar_type`); any other FMI 3.0 type, and arrays, cannot be
connected or logged (a :class:`PlanError` says which port and why). The pre-flight check
(:mod:`scfmu.scenario.check`) applies the same rule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..fmu import described, fmu_path, scalar_type
from .model import Scenario
from .resolve import resolve
from .settings import Setting, apply_params, values  # noqa: F401  (a plan's settings; re-exported)
from .values import max_rows, timing_problems

LINK_TYPES = ("Real", "Integer", "Boolean")
# solvers of a Model Exchange instance: SciPy solve_ivp's methods (the compiled engine runs its own
# Dormand–Prince 5(4) for each of them), and "RK4": classic Runge–Kutta 4 with a fixed step (every engine)
ME_SOLVERS = ("DOP853", "RK45", "Radau", "BDF", "LSODA", "RK4")


class PlanError(ValueError):
    """A scenario that no engine can run as declared (a connection of an unsupported type, an array port,
    a unit without the interface asked for); the message names the port or instance."""


@dataclass
class Unit:
    """One instance of the plan."""

    name: str
    model: str
    path: Path
    md: object
    fmi: int  # FMI major version: 2 or 3
    interface: str  # "cs" or "me"
    solver: dict = field(default_factory=dict)  # ME: {"method", "rtol", "atol"}
    vars: dict = field(default_factory=dict)  # name -> fmpy ModelVariable

    def vr(self, name: str) -> int:
        return self.vars[name].valueReference

    def type(self, name: str) -> str | None:
        """The scenario type of a variable (Real, Integer, Boolean), None for any other."""
        return scalar_type(self.vars[name])

    @property
    def inputs(self) -> list[str]:
        return [n for n, v in self.vars.items() if v.causality == "input"]

    @property
    def outputs(self) -> list[str]:
        return [n for n, v in self.vars.items() if v.causality == "output"]


@dataclass
class LinkGroup:
    """Consecutive links of one (destination, source, type): one get of the source's outputs, one set of
    the destination's inputs."""

    dst: str
    src: str
    type: str
    dst_names: list[str]
    src_names: list[str]
    dst_vrs: list[int]
    src_vrs: list[int]


@dataclass
class LogGroup:
    """Logged signals of one instance and type, read by one get."""

    inst: str
    type: str
    keys: list[str]
    names: list[str]
    vrs: list[int]


@dataclass
class Plan:
    scenario: Scenario  # resolved
    units: list[Unit]
    links: list[tuple[str, str, str, str]]
    groups: list[LinkGroup]
    log: list[LogGroup]
    params: dict = field(default_factory=dict)  # instance -> [Setting], parameters (initialization mode)
    inputs: dict = field(default_factory=dict)  # instance -> [Setting], fixed inputs (after initialization)
    problems: list = field(default_factory=list)  # what is wrong with the parameters (the pre-flight's errors)
    input_problems: list = field(default_factory=list)  # what is wrong with the fixed inputs (the same)
    unknown: list = field(default_factory=list)  # names the units do not have (build_plan: a KeyError)
    log_every: int | None = 1  # the logging grid the timing was checked for
    steps: int | None = None  # the communication steps (n_steps)

    def unit(self, name: str) -> Unit:
        for u in self.units:
            if u.name == name:
                return u
        raise KeyError(name)

    @property
    def names(self) -> list[str]:
        return [u.name for u in self.units]

    def ports(self) -> dict[str, tuple[list[str], list[str]]]:
        return {u.name: (u.inputs, u.outputs) for u in self.units}

    def by_destination(self) -> list[tuple[str, list[LinkGroup]]]:
        """The groups per destination, destinations in Gauss–Seidel order."""
        out: dict[str, list[LinkGroup]] = {}
        for g in self.groups:
            out.setdefault(g.dst, []).append(g)
        return list(out.items())

    @property
    def n_steps(self) -> int:
        """The communication steps of the run (the timing was checked when the plan was built)."""
        if self.steps is None:
            sc = self.scenario
            self.steps = int(round((sc.stop_time - sc.start_time) / sc.step))
        return self.steps

    @property
    def model_exchange(self) -> frozenset:
        return frozenset(u.name for u in self.units if u.interface == "me")


def _interface(c, md, model_exchange) -> str:
    want = "me" if c.name in model_exchange else (c.interface or "auto")
    if want == "auto":
        want = "cs" if md.coSimulation is not None else "me"
    if want == "me" and md.modelExchange is None:
        raise PlanError(f"{c.name} ({c.model}) offers no Model Exchange interface (Co-Simulation only)")
    if want == "cs" and md.coSimulation is None:
        raise PlanError(f"{c.name} ({c.model}) offers no Co-Simulation interface (Model Exchange only)")
    return want


def solver_of(c) -> dict:
    """The solve settings of a Model Exchange instance (``Component.solver``, defaults filled in)."""
    s = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12, "max_step": 0.0}
    for k, v in (c.solver or {}).items():
        if k not in s:
            raise PlanError(f"{c.name}: solver option {k!r} is unknown (allowed: method, rtol, atol, max_step)")
        s[k] = v
    if not (isinstance(s["max_step"], (int, float)) and s["max_step"] >= 0):
        raise PlanError(f"{c.name}: solver max_step = {s['max_step']!r} must be a number >= 0 (0: the "
                        f"communication step; RK4's fixed step)")
    s["max_step"] = float(s["max_step"])
    if s["method"] not in ME_SOLVERS:
        raise PlanError(f"{c.name}: solver method {s['method']!r} is unknown (allowed: {', '.join(ME_SOLVERS)})")
    for k in ("rtol", "atol"):
        if not (isinstance(s[k], (int, float)) and 0 < float(s[k]) < 1):
            raise PlanError(f"{c.name}: solver {k} = {s[k]!r} must be a number in (0, 1)")
        s[k] = float(s[k])
    return s


def link_problem(u_dst: Unit, di: str, u_src: Unit, so: str) -> str | None:
    """Why the connection ``src.so -> dst.di`` cannot be made (None when it can): the one connection rule."""
    vd, vs = u_dst.vars[di], u_src.vars[so]
    for u, v in ((u_src, vs), (u_dst, vd)):
        if getattr(v, "dimensions", None):
            return (f"{u.name}.{v.name} is an FMI 3.0 array ({v.type}[{len(v.dimensions)}-D]): array ports "
                    f"are not supported, only scalar ports can be connected")
    td, ts = scalar_type(vd), scalar_type(vs)
    if td is None or ts is None:
        return (f"only {', '.join(LINK_TYPES)} connections are supported (FMI 3.0 Float64, Int32, Boolean); "
                f"got {vs.type} -> {vd.type}")
    if td != ts:
        return f"types differ: {vs.type} -> {vd.type}"
    return None


def timing_problem(sc: Scenario, log_every: int | None = 1, log_hint: bool = True) -> str | None:
    """Why the scenario's times cannot run (None when they can): finite, bounded in steps, the stop time a
    whole number of steps after the start (:attr:`Scenario.n_steps`), and with ``log_every`` bounded in
    logged rows (:func:`scfmu.scenario.values.timing_problems` words each refusal). The one timing check."""
    try:
        sc.n_steps
    except ValueError as e:
        return str(e)
    n = (float(sc.stop_time) - float(sc.start_time)) / float(sc.step)  # (the rows as timing_problems counts them)
    if log_every is not None and (2 if int(log_every) <= 0 else math.ceil(n / int(log_every)) + 1) > max_rows():
        return timing_problems(sc.start_time, sc.stop_time, sc.step, log_every=log_every, log_hint=log_hint)[0]
    return None


def build_plan(scenario: Scenario, path_of=None, model_exchange=frozenset(), resolved: bool = False,
               log_every: int | None = 1, origins: dict | None = None, log_hint: bool = True) -> Plan:
    """The plan of a scenario (see the module docstring). ``path_of(model)`` gives a model's FMU file
    (default :func:`scfmu.fmu.fmu_path`); the instances named in ``model_exchange`` (and those whose
    ``Component.interface`` is ``"me"``, or that offer Model Exchange only) run as Model Exchange
    units. ``resolved``: the scenario is already resolved. ``log_every``: the run logs every n-th step
    (bounds the logged rows; None: not counted). ``origins``: ``{"instance.name": origin}`` of values the
    caller changed (``--set``, ``--params``); the others are told apart by the scenario."""
    why = timing_problem(scenario, log_every, log_hint)
    if why:
        raise PlanError(why)
    unknown = set(model_exchange) - {c.name for c in scenario.components}
    if unknown:
        raise KeyError(f"model_exchange names no instance of {scenario.name}: {sorted(unknown)}")
    sc = scenario if resolved else resolve(scenario)
    paths = [Path(path_of(c.model)) if path_of else fmu_path(c.model) for c in sc.components]
    sig = _signature(sc, paths, model_exchange)
    hit = _SKELETONS.get(sig)
    if hit is not None:  # the same structure as a plan made before (e.g. the runs of a campaign)
        plan = Plan(sc, *hit)
    else:
        plan = _build(sc, paths, model_exchange)
        remember(plan, paths, model_exchange)
    values(plan, scenario, origins or {})
    if plan.unknown:  # a value no unit can take (the pre-flight words it, with the closest names)
        raise KeyError(plan.unknown[0])
    plan.log_every = log_every
    return plan


_SKELETONS: dict = {}  # structure of a resolved scenario -> (units, links, groups, log), per process


def _signature(sc: Scenario, paths, model_exchange) -> tuple:
    """Everything a plan depends on except parameter and input values: instances, models and their FMU
    files (path, modification time, size), interfaces and solvers, port renames, wiring declaration,
    fixed-input names, logged signals."""
    comps = []
    for c, p in zip(sc.components, paths):
        st = p.stat()
        comps.append((c.name, c.model, str(p), st.st_mtime_ns, st.st_size, c.interface,
                      tuple(sorted((k, repr(v)) for k, v in c.solver.items())), tuple(sorted(c.ports.items()))))
    return (tuple(comps), tuple(sorted(sc.connections.items())), tuple(sorted(sc.terminals.items())), tuple(sc.unconnected), tuple(sorted(sc.inputs)),
            sc.auto_connect, tuple(sc.log.items()), frozenset(model_exchange))


def plan_units(sc: Scenario, paths, model_exchange=frozenset()) -> list[Unit]:
    """The units of a resolved scenario: each FMU's model description read once (cached per process)."""
    units = []
    for c, p in zip(sc.components, paths):
        md = described(p)
        fmi = int(str(md.fmiVersion).split(".")[0])
        if fmi not in (2, 3):
            raise PlanError(f"{c.name} ({c.model}): FMI {md.fmiVersion} is not supported (FMI 2.0 or 3.0)")
        itf = _interface(c, md, model_exchange)
        units.append(Unit(c.name, c.model, p, md, fmi, itf, solver_of(c) if itf == "me" else {},
                          {v.name: v for v in md.modelVariables}))
    return units


def _build(sc: Scenario, paths, model_exchange) -> Plan:
    return wire(sc, plan_units(sc, paths, model_exchange))


def remember(plan: Plan, paths, model_exchange=frozenset()) -> None:
    """Keeps a plan's structure for the next plan of the same structure (built by the pre-flight)."""
    if len(_SKELETONS) > 256:
        _SKELETONS.clear()
    _SKELETONS[_signature(plan.scenario, paths, model_exchange)] = (plan.units, plan.links, plan.groups, plan.log)


def unit_terminals(sc: Scenario, units: list[Unit]) -> dict | None:
    """Each unit's FMI 3.0 terminals when the scenario connects terminals (else None: nothing is read)."""
    if not sc.terminals:
        return None
    from ..fmu.terminals import terminals_of
    return {u.name: terminals_of(u.path) for u in units}


def wire(sc: Scenario, units: list[Unit], links=None) -> Plan:
    """The plan of a resolved scenario's units: its wiring (``links``, when the caller computed it), link
    groups and logged signals; a :class:`PlanError` names a connection or logged signal no engine can make."""
    by_name = {u.name: u for u in units}
    if links is None:
        links = sc.wiring({u.name: (u.inputs, u.outputs) for u in units}, unit_terminals(sc, units))
    problems = []
    for d, di, s, so in links:
        why = link_problem(by_name[d], di, by_name[s], so)
        if why:
            problems.append(f"{s}.{so} -> {d}.{di}: {why}")
    if problems:
        raise PlanError("; ".join(problems))
    groups: list[LinkGroup] = []
    i = 0
    while i < len(links):  # consecutive links of one (dst, src) pair; within it one group per type
        d, _, s, _ = links[i]
        j = i
        while j < len(links) and links[j][0] == d and links[j][2] == s:
            j += 1
        per_type: dict[str, LinkGroup] = {}
        for _, di, _, so in links[i:j]:
            t = by_name[d].type(di)
            g = per_type.get(t)
            if g is None:
                g = per_type[t] = LinkGroup(d, s, t, [], [], [], [])
                groups.append(g)
            g.dst_names.append(di)
            g.src_names.append(so)
            g.dst_vrs.append(by_name[d].vr(di))
            g.src_vrs.append(by_name[s].vr(so))
        i = j
    log: dict[tuple[str, str], LogGroup] = {}
    for key, inst, var in sc.log_items():
        u = by_name.get(inst)
        if u is None:
            raise KeyError(f"log {key!r}: unknown instance {inst!r}")
        if var not in u.vars:
            raise KeyError(f"log {key!r}: {u.model} has no variable {var!r}")
        t = u.type(var)
        if t is None:
            raise PlanError(f"log {key!r}: {inst}.{var} is of type {u.vars[var].type}"
                            + (" (an array)" if u.vars[var].dimensions else "")
                            + f": only {', '.join(LINK_TYPES)} signals can be logged")
        g = log.get((inst, t))
        if g is None:
            g = log[(inst, t)] = LogGroup(inst, t, [], [], [])
        g.keys.append(key)
        g.names.append(var)
        g.vrs.append(u.vr(var))
    return Plan(sc, units, links, groups, list(log.values()))
