"""The unit's ``--set`` and ``--map`` of ``scfmu benchmark``, checked before anything runs.

One syntax everywhere: a name may be given bare (``--map J1=inertia_xx``, ``--set wn=2``) or qualified by the
benchmark's slot instance, the form the warnings print and ``scfmu run`` takes (``--map
controller.J1=inertia_xx``, ``--set controller.wn=2``); both mean the same. A name the unit does not declare
(neither a port, a vector stem ``NAME_x…`` nor a parameter) is refused by name, and so is a ``--map`` that binds
nothing in any of the selected scenarios: a parameter bound to an expression of values no scenario's place
offers, or a port renamed to a name no other unit of the loop connects to. Each refusal is a
:class:`~scfmu.scenario.values.UsageError` (one line, exit status 2)."""

from __future__ import annotations

from ..scenario import get
from ..scenario.profile import ProfileError, names_in
from ..scenario.resolve import _env, declared, vector_members
from ..scenario.values import UsageError, did_you_mean


def _bare(option: str, key: str, value, names: dict, slots: set, unit: str) -> str:
    """The unit's own name of ``key`` (``controller.J1`` → ``J1`` when ``controller`` is the slot and ``J1`` is
    the unit's; ``J1`` as given); a UsageError when the unit has no such variable (or vector stem, ``--map``)."""
    def known(n: str) -> bool:
        return n in names or bool(option == "--map" and vector_members(names, n))
    inst, sep, rest = key.partition(".")
    if known(key):
        return key
    if sep and inst in slots and known(rest):
        return rest
    slot = sorted(slots)[0]
    if sep and inst not in slots:
        raise UsageError(f"{option} {key}={value}: the unit under test is instance {slot!r}, not {inst!r}; "
                         f"allowed: NAME=... or {slot}.NAME=... (NAME: a variable of the unit)")
    name = rest if sep else key
    if option == "--map":
        raise UsageError(f"{option} {key}={value}: the unit ({unit}) has no variable or vector stem {name!r}"
                         f"{did_you_mean(name, names)}; allowed: a port, a vector stem (NAME_x…) or a parameter "
                         f"of the unit")
    params = [n for n, v in names.items() if v.causality == "parameter"]
    raise UsageError(f"{option} {key}={value}: the unit ({unit}) has no parameter {name!r}"
                     f"{did_you_mean(name, params)}; allowed: a parameter of the unit")


def unit_options(unit: str, cases, unit_params: dict, port_map: dict) -> tuple[dict, dict]:
    """(parameters, port map) of the unit under test with bare names, each checked (module docstring)."""
    names = declared(unit)
    slots = {c.slot for c in cases}
    label = unit.rsplit("/", 1)[-1]
    params = {}
    for k, v in unit_params.items():
        bare = _bare("--set", k, v, names, slots, label)
        if names.get(bare) is None or names[bare].causality != "parameter":
            raise UsageError(f"--set {k}={v}: {bare!r} is the unit's {names[bare].causality}, not a parameter; "
                             f"allowed: a parameter of the unit (a fixed input: scfmu run --set INSTANCE.NAME)")
        params[bare] = v
    maps, given = {}, {}
    for k, ours in port_map.items():
        bare = _bare("--map", k, ours, names, slots, label)
        maps[bare], given[bare] = ours, k
    for theirs, ours in maps.items():
        if not any(_binds(get(c.scenario), c.slot, names, theirs, ours) for c in cases):
            v = names.get(theirs)
            if v is not None and v.causality == "parameter":
                why = (f"{', '.join(sorted(names_in_safe(ours)))} is no value the place offers (slot values, step, "
                       f"stop_time, INSTANCE.PARAMETER of the other units)")
            else:
                why = f"no other unit of the loop has a port {ours!r} (or {ours}_x…) to connect it to"
            raise UsageError(f"--map {given[theirs]}={ours}: binds nothing in the selected scenarios: {why}")
    return params, maps


def names_in_safe(expr) -> set:
    try:
        return names_in(expr) if isinstance(expr, str) else set()
    except ProfileError:
        return {str(expr)}


def _binds(sc, slot: str, names: dict, theirs: str, ours: str) -> bool:
    """Whether ``--map theirs=ours`` reaches something in scenario ``sc`` with the unit in ``slot``: a parameter
    whose expression reads only what the place offers, or a port (or every element of a vector stem) whose
    new name another unit's port, a connection, a fixed input or a logged signal uses."""
    v = names.get(theirs)
    if v is not None and v.causality == "parameter":
        try:
            env = _env(sc, sc.component(slot))
        except KeyError:
            return False
        return names_in_safe(ours) <= set(env)
    elems = [(theirs, ours)] if v is not None else [(f"{theirs}_{s}", f"{ours}_{s}")
                                                    for s in vector_members(names, theirs)]
    used = set()
    for c in sc.components:
        if c.name == slot:
            continue
        try:
            other = declared(c.model)
        except Exception:
            continue
        used |= {c.ports.get(n, n) for n, x in other.items() if x.causality in ("input", "output")}
    refs = [*sc.connections, *sc.connections.values(), *sc.inputs, *sc.log.values()]
    used |= {q.partition(".")[2] for q in refs if q.partition(".")[0] == slot}
    return all(o in used for _, o in elems)
