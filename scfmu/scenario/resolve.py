"""A scenario made ready for the engines: each unit's slot parameters that it declares merged into its
parameters, and the scenario's port names of renamed units (``Component.ports``) turned into the units' own
names in the logged signals and fixed inputs. Every engine, the SSP writer and the loop FMUs run the
resolved scenario; resolving twice changes nothing."""

from __future__ import annotations

import copy
import dataclasses

from ..fmu import fmu_path, unpacked
from .model import Component, Scenario

_DECLARED: dict = {}


def declared(model: str) -> dict:
    """``{name: ScalarVariable}`` of a model's FMU (the model description is read once per process)."""
    p = fmu_path(model)
    st = p.stat()
    key = (str(p), st.st_mtime_ns, st.st_size)
    hit = _DECLARED.get(key)
    if hit is None:
        md = unpacked(p)[0]
        hit = _DECLARED[key] = {v.name: v for v in md.modelVariables}
    return hit


def _plain(x):
    """A copy of a value of a scenario's tables (numbers and strings shared, containers copied)."""
    if isinstance(x, (int, float, str, bool, type(None))):
        return x
    return copy.deepcopy(x)


def copy_scenario(scenario: Scenario) -> Scenario:
    """A deep copy of a scenario, without ``copy.deepcopy``'s cost on its plain tables."""
    comps = [Component(c.name, c.model, {k: _plain(v) for k, v in c.params.items()},
                       {k: _plain(v) for k, v in c.slot.items()}, dict(c.ports), c.interface,
                       {k: _plain(v) for k, v in c.solver.items()}) for c in scenario.components]
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


def resolve(scenario: Scenario) -> Scenario:
    s = copy_scenario(scenario)
    for inst in s.swapped:  # the old model's own signals (diagnostics) are not logged from its replacement
        names = declared(s.component(inst).model)
        s.log = {k: q for k, q in s.log.items()
                 if q.partition(".")[0] != inst or s.native_name(inst, q.partition(".")[2]) in names}
    for c in s.components:
        if c.slot:
            names = declared(c.model)
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
