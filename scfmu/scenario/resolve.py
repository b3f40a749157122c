"""A scenario made ready for the engines: each unit's port renames expanded (a vector stem into its
elements; a renamed *parameter* into a binding), its bindings (``Component.bind``, a unit profile or
``--map controller.J1=inertia_xx``) evaluated against the place's slot values, the slot parameters it
declares merged into its parameters, and the scenario's port names of renamed units (``Component.ports``)
turned into the units' own names in the logged signals and fixed inputs. Every engine, the SSP writer and
the loop FMUs run the resolved scenario; resolving twice changes nothing.

:func:`unbound_slots` tells which slot values a swapped unit does *not* receive (no parameter of that name,
no binding reads it, not declared unused): the runs, campaigns and the benchmark report them by name."""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field

from ..fmu import described, file_key, fmu_path, is_path
from .model import Component, Scenario
from .profile import ProfileError, evaluate, names_in

VECTOR_SUFFIXES = ("w", "x", "y", "z", "xx", "yy", "zz", "xy", "xz", "yz", "1", "2", "3", "4")
_DECLARED: dict = {}


def declared(model: str) -> dict:
    """``{name: ScalarVariable}`` of a model's FMU (the model description is read once per process)."""
    p = fmu_path(model)
    key = file_key(p)
    hit = _DECLARED.get(key)
    if hit is None:
        md = described(p)
        hit = _DECLARED[key] = {v.name: v for v in md.modelVariables}
    return hit


def _plain(x):
    """A copy of a value of a scenario's tables (numbers and strings shared, containers copied)."""
    if isinstance(x, (int, float, str, bool, type(None))):
        return x
    return copy.deepcopy(x)


def copy_scenario(scenario: Scenario) -> Scenario:
    """A deep copy of a scenario, without ``copy.deepcopy``'s cost on its plain tables."""
    comps = [Component(c.name, c.model, params={k: _plain(v) for k, v in c.params.items()},
                       slot={k: _plain(v) for k, v in c.slot.items()}, ports=dict(c.ports),
                       bind={k: _plain(v) for k, v in c.bind.items()}, unused=list(c.unused), interface=c.interface,
                       solver={k: _plain(v) for k, v in c.solver.items()}) for c in scenario.components]
    out = {}
    for f in dataclasses.fields(scenario):
        v = getattr(scenario, f.name)
        if f.name == "components":
            v = comps
        elif isinstance(v, dict):
            v = {k: _plain(x) for k, x in v.items()}
        elif isinstance(v, list):
            v = [_plain(x) for x in v]
        out[f.name] = v
    return type(scenario)(**out)


def vector_members(names, stem: str) -> list[str]:
    """The suffixes s of the variables ``stem_s`` among ``names`` (``q`` → w, x, y, z), in VECTOR_SUFFIXES order."""
    return [s for s in VECTOR_SUFFIXES if f"{stem}_{s}" in names]


def expand_ports(c, names: dict) -> None:
    """In place: a port map entry whose name is no variable of the unit but a vector stem (``q`` with
    ``q_w … q_z``) becomes one entry per element; an entry that names a parameter of the unit becomes a
    binding (``bind``) of that parameter to the slot value (or expression) on the right."""
    ports = {}
    for theirs, ours in c.ports.items():
        v = names.get(theirs)
        if v is not None and v.causality == "parameter":
            c.bind.setdefault(theirs, ours)
            continue
        if v is None:
            members = vector_members(names, theirs)
            if members:
                for s in members:
                    ports[f"{theirs}_{s}"] = f"{ours}_{s}"
                continue
        ports[theirs] = ours
    c.ports = ports


def _env(s: Scenario, c) -> dict:
    """What a binding may read: the scenario's step and stop time, ``INSTANCE.PARAMETER`` of the other units
    (the value the scenario sets, else the unit's start value) and the place's slot values."""
    env = {k: getattr(s, k) for k in ("step", "stop_time")}
    for other in s.components:
        if other.name == c.name:
            continue
        try:
            names = declared(other.model)
        except Exception:
            names = {}
        for n, v in names.items():
            if v.causality == "parameter" and v.type == "Real" and v.start is not None:
                try:
                    env[f"{other.name}.{n}"] = float(v.start)
                except (TypeError, ValueError):
                    pass
        env.update({f"{other.name}.{k}": v for k, v in other.params.items()})
    return {**env, **c.slot}


def _coerce(v, var, where: str):
    if var.type in ("Integer", "Enumeration"):
        if isinstance(v, float) and v.is_integer():
            v = int(v)
        if not isinstance(v, int) or isinstance(v, bool):
            raise ProfileError(f"{where}: {v!r} is not an integer ({var.name} is {var.type})")
    elif var.type == "Boolean":
        if not isinstance(v, (bool, int)) or v not in (0, 1):
            raise ProfileError(f"{where}: {v!r} is not a Boolean")
        v = bool(v)
    elif var.type == "Real":
        v = float(v)
    return v


def resolve(scenario: Scenario) -> Scenario:
    s = copy_scenario(scenario)
    for inst in s.swapped:  # the old model's own signals (diagnostics) are not logged from its replacement
        names = declared(s.component(inst).model)
        s.log = {k: q for k, q in s.log.items()
                 if q.partition(".")[0] != inst or s.native_name(inst, q.partition(".")[2]) in names}
    for c in s.components:
        if not (c.slot or c.ports or c.bind):
            continue
        names = declared(c.model)
        if c.ports:
            expand_ports(c, names)
        for k, expr in c.bind.items():
            where = f"{c.name}.{k} = {expr!r}"
            var = names.get(k)
            if var is None or var.causality != "parameter":
                raise ProfileError(f"binding {where}: the unit ({c.model}) has no parameter {k!r}"
                                   + (f" ({k!r} is its {var.causality})" if var is not None else ""))
            if k in c.params:  # an explicit --set / params value wins over the profile
                continue
            c.params[k] = _coerce(evaluate(expr, _env(s, c), f"binding {where}"), var, f"binding {where}")
        for k, v in c.slot.items():
            if k in names and names[k].causality == "parameter" and k not in c.params:
                c.params[k] = v
    if any(c.ports for c in s.components):
        log = {}
        for key, q in s.log.items():
            inst, sep, var = q.partition(".")
            log[key] = f"{inst}.{s.native_name(inst, var)}" if sep and inst in {c.name for c in s.components} else q
        s.log = log
        inputs = {}
        for q, v in s.inputs.items():
            inst, _, var = q.partition(".")
            inputs[f"{inst}.{s.native_name(inst, var)}"] = v
        s.inputs = inputs
    return s


# ----- what a swapped unit does not receive ----------------------------------------------------------------
@dataclass
class Unbound:
    """A slot value that no parameter of the unit in ``instance`` receives; ``kept``: the unit's own
    parameters of the same unit of measure that keep their start values instead (name, start, unit)."""
    instance: str
    model: str
    slot: str
    value: object
    kept: list = field(default_factory=list)

    def text(self) -> str:
        v = f"{self.value:g}" if isinstance(self.value, float) else str(self.value)
        head = f"{self.instance}: slot value {self.slot} = {v} not passed"
        if self.kept:
            own = ", ".join(f"{n} = {st}" for n, st, _ in self.kept)
            if len(self.kept) == 1 and self.kept[0][1] == v:
                own += " (equal to the slot value here, by its default)"
            return (f"{head}: the unit kept its own {own} (bind it: a profile line {self.kept[0][0]} = "
                    f"\"{self.slot}\", or --map {self.instance}.{self.kept[0][0]}={self.slot})")
        return (f"{head}: the unit has no parameter {self.slot!r} and no binding reads it (bind it with a profile "
                f"or --map {self.instance}.THEIR_PARAM={self.slot}, or declare it unused in the profile)")


def _start(v):
    st = getattr(v, "start", None)
    try:
        return f"{float(st):g}"
    except (TypeError, ValueError):
        return str(st)


def unbound_slots(scenario: Scenario, instances=None, resolved: bool = False) -> list[Unbound]:
    """The slot values of the swapped instances, of the units given as files and of those with a profile (or
    of ``instances``) that their units do not receive:
    no parameter of that name, not read by a binding (``bind``, ``--map`` of a parameter), not listed in
    ``unused``. Reads the units' model descriptions; an instance whose unit cannot be read is skipped
    (the pre-flight check reports it). ``resolved``: the scenario is already resolved (a plan's)."""
    try:
        s = scenario if resolved else resolve(scenario)
    except Exception:  # a wrong binding is reported by the pre-flight check
        s = scenario
    out = []
    if instances is None:  # swapped units, units given by path (a scenario file's), units with a profile
        instances = [c.name for c in s.components if c.name in s.swapped or c.bind or c.unused or is_path(c.model)]
    for inst in instances:
        c = s.component(inst)
        if not c.slot:
            continue
        try:
            names = declared(c.model)
        except Exception:
            continue
        read = set()
        for expr in c.bind.values():
            try:
                read |= names_in(expr) if isinstance(expr, str) else set()
            except ProfileError:
                pass
        missing = [k for k in c.slot if not (k in names and names[k].causality == "parameter")
                   and k not in read and k not in c.unused]
        if not missing:
            continue
        units = _slot_units(s, inst)
        free = [v for n, v in names.items() if v.causality == "parameter" and n not in c.params]
        by_unit: dict = {}
        for k in missing:
            by_unit.setdefault(units.get(k), []).append(k)
        for unit, keys in by_unit.items():
            cands = [(v.name, _start(v), unit) for v in free if unit and _unit(v) == unit]
            for i, k in enumerate(keys):
                # no more candidates than missing values of that unit: paired in declaration order
                # (J1 ↔ inertia_xx, J2 ↔ inertia_yy, …); more candidates: all of them are named
                kept = ([cands[i]] if i < len(cands) else []) if len(cands) <= len(keys) else cands
                out.append(Unbound(inst, c.model, k, c.slot[k], kept))
    return out


def _unit(v):
    u = getattr(v, "unit", None)
    if u:
        return u
    return getattr(getattr(v, "declaredType", None), "unit", None)


def _slot_units(s: Scenario, inst: str) -> dict:
    """The unit of measure of each slot value of ``inst``, from a variable of that name in another unit of
    the loop (the plant's ``inertia_xx`` is in kg.m2)."""
    c = s.component(inst)
    out = {}
    for other in s.components:
        if other.name == inst:
            continue
        try:
            names = declared(other.model)
        except Exception:
            continue
        for k in c.slot:
            if k not in out and k in names and _unit(names[k]):
                out[k] = _unit(names[k])
    return out
