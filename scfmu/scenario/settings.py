"""A plan's settings: the values set in each unit (parameters in initialization mode, fixed inputs after
it), worked out once when the plan is built (:func:`values`), and :func:`apply_params`, the one function
through which every engine, and the pre-flight's trial initialization, sets them.

A :class:`Setting` carries the variable's name, value reference and FMI type, the value as given, and where
the value came from (``scenario``, ``--set``, ``--params``, ``binding``, ``slot``, ``seed``). The values are
checked here against the declared type and bounds (:func:`scfmu.scenario.values.value_problem`); the problems
are kept in the pre-flight's words (``plan.problems``, ``plan.input_problems``) for the pre-flight to report.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..fmu import scalar_type
from .model import Scenario
from .values import INT32, did_you_mean, value_problem


@dataclass(frozen=True)
class Setting:
    """One value to set in a unit: its variable ``name``, value reference ``vr``, FMI ``type`` (Real,
    Integer, Boolean: the scenario type; else the declared one, which the engines refuse), the ``value``
    as given and ``origin`` (``scenario``, ``--set``, ``--params``, ``binding``, ``slot``, ``seed``)."""

    name: str
    vr: int
    type: str
    value: object
    origin: str = "scenario"


def _origin(raw: Scenario, c, k: str, origins: dict) -> str:
    q = f"{c.name}.{k}"
    if q in origins:
        return origins[q]
    if q in raw.seed_params:
        return "seed"
    try:
        given = raw.component(c.name).params
    except KeyError:
        given = {}
    if k in given:
        return "scenario"
    return "binding" if k in c.bind else "slot"


def values(plan, raw: Scenario, origins: dict) -> None:
    """The plan's parameter and fixed-input settings and the problems of their values. A variable the unit
    has but may not be set so (an output, a parameter given as a fixed input) is still a setting: the unit
    refuses it with its own message; a name the unit does not have is in ``plan.unknown`` too."""
    sc, problems = plan.scenario, plan.problems
    plan.params, plan.inputs, plan.problems[:], plan.input_problems[:], plan.unknown[:] = {}, {}, [], [], []
    for c in sc.components:
        u = plan.unit(c.name)
        out = plan.params[c.name] = []
        for k, val in c.params.items():
            v = u.vars.get(k)
            if v is None or v.causality != "parameter":
                problems.append(f"{c.name} ({c.model}): no parameter {k!r}"
                                + (f" ({k!r} is its {v.causality})" if v is not None else did_you_mean(
                                    k, [n for n, x in u.vars.items() if x.causality == "parameter"])))
                if v is None:
                    plan.unknown.append(f"{c.model} has no parameter {k!r}")
                    continue
            else:
                problem = value_problem(f"{c.name}.{k}", v, val)
                if problem:
                    problems.append(problem)
            out.append(Setting(k, v.valueReference, _fmi_type(v, u.fmi), val, _origin(raw, c, k, origins)))
        for theirs in c.ports:
            if theirs not in u.vars:
                problems.append(f"{c.name} ({c.model}): port map names {theirs!r}, which the unit does not have "
                                f"(neither a port, a vector stem {theirs}_x…, nor a parameter)")
        plan.inputs[c.name] = []
    for q, val in sc.inputs.items():
        inst, _, var = q.partition(".")
        u = next((x for x in plan.units if x.name == inst), None)
        v = u.vars.get(var) if u is not None else None
        if v is None or v.causality != "input":
            plan.input_problems.append(f"fixed input {q}: {inst} has no input {var!r}")
            if v is None:
                plan.unknown.append(f"{u.model if u is not None else inst} has no variable {var!r}")
                continue
        else:
            problem = value_problem(f"fixed input {q}", v, val)
            if problem:
                plan.input_problems.append(problem)
        plan.inputs[inst].append(Setting(var, v.valueReference, _fmi_type(v, u.fmi), val,
                                         origins.get(q, origins.get(f"input:{q}", "scenario"))))


def apply_params(settings, set_values, vr_of=None) -> None:
    """Sets a unit's :class:`Setting` list (``plan.params[instance]`` or ``plan.inputs[instance]``), in
    order, with one ``set_values(fmi_type, vrs, values)`` per run of settings of one type (Real, Integer,
    Boolean: an FMI 2.0 ``fmi2SetReal`` / FMI 3.0 ``fmi3SetFloat64`` call, ...; :meth:`scfmu.fmu.Fmu.set_refs`
    for an instance). ``vr_of(setting)`` gives the value reference the engine's instance knows the variable
    by (the native engine's container renumbers them); default the unit's own. The one way every engine,
    and the pre-flight's trial initialization, sets a plan's values."""
    run: list = []

    def flush():
        if run:
            set_values(run[0].type, [vr_of(x) if vr_of else x.vr for x in run], [x.value for x in run])
            run.clear()
    for s in settings:
        _settable(s)
        if run and s.type != run[0].type:
            flush()
        run.append(s)
    flush()


def _settable(s: Setting) -> None:
    """Refuses, before any FMU call, a value its C type cannot hold (an integer is never wrapped) and a type
    no engine sets."""
    v = s.value
    if s.type == "Integer":
        if isinstance(v, (bool, str)) or not (isinstance(v, int) or float(v).is_integer()):
            raise ValueError(f"{s.name} = {v!r}: an Integer needs a whole number")
        if not INT32[0] <= int(v) <= INT32[1]:
            raise ValueError(f"{s.name} = {v!r} is outside the Integer range [{INT32[0]}, {INT32[1]}]")
    elif s.type == "Boolean":
        if isinstance(v, str) or v not in (0, 1):
            raise ValueError(f"{s.name} = {v!r}: a Boolean needs true or false")
    elif s.type != "Real":
        raise TypeError(f"{s.name}: unsupported type {s.type}")


def _fmi_type(v, fmi: int) -> str:
    """The type a value is set as: the scenario type (an FMI 2.0 Enumeration is set as an Integer), else
    the declared one (no engine sets it: the unit's ``set`` refuses it by name)."""
    t = scalar_type(v)
    if t is None and fmi == 2 and v.type == "Enumeration" and not getattr(v, "dimensions", None):
        return "Integer"
    return t or v.type
