"""A scenario made ready for the engines: each unit's slot parameters that it declares merged into its
parameters, and the scenario's port names of renamed units (``Component.ports``) turned into the units' own
names in the logged signals and fixed inputs. Every engine, the SSP writer and the loop FMUs run the
resolved scenario; resolving twice changes nothing."""

from __future__ import annotations

import copy

from ..fmu import fmu_path, unpacked
from .model import Scenario


def declared(model: str) -> dict:
    """``{name: ScalarVariable}`` of a model's FMU (the model description is read once per process)."""
    md = unpacked(fmu_path(model))[0]
    return {v.name: v for v in md.modelVariables}


def resolve(scenario: Scenario) -> Scenario:
    s = copy.deepcopy(scenario)
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
