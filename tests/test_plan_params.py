"""Issue 47, item 1: one plan, built once. A parameter given on the command line is resolved once, into the
plan's settings (value reference, FMI type, value, origin), and set through one function in every engine.

Oracles: the value references and types read here straight from the FMU's modelDescription.xml (zip + XML,
not through the package), the values the scenario is documented with (run 000-6: inertia diag(1000, 500, 700)
kg·m²), and the value read back from the initialized unit by name (fmpy's getter, not the plan's path)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from scfmu.engines.instances import build_fmus
from scfmu.scenario import get
from scfmu.scenario.check import check
from scfmu.scenario.plan import PlanError, Setting, apply_params, build_plan

FMUS = Path(__file__).resolve().parents[1] / "fmus"


def declared(model: str) -> dict:
    """{name: (valueReference, type tag)} read from the FMU's own modelDescription.xml."""
    with zipfile.ZipFile(FMUS / f"{model}.fmu") as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    out = {}
    for sv in root.iter("ScalarVariable"):
        tag = next(iter(sv)).tag
        out[sv.get("name")] = (int(sv.get("valueReference")), tag)
    return out


def test_a_set_value_is_one_setting_with_its_reference_type_and_origin():
    sc = get("default").with_overrides({"controller.wn": 2})
    plan = build_plan(sc, origins={"controller.wn": "--set"})
    ctl = {s.name: s for s in plan.params["controller"]}
    md = declared(plan.unit("controller").model)
    assert ctl["wn"] == Setting("wn", md["wn"][0], "Real", 2, "--set")
    # the place's slot values reach the controller's parameters of the same names: diag(1000, 500, 700) kg·m²
    assert [(ctl[k].value, ctl[k].origin, ctl[k].vr) for k in ("inertia_xx", "inertia_yy", "inertia_zz")] == \
        [(1000.0, "slot", md["inertia_xx"][0]), (500.0, "slot", md["inertia_yy"][0]), (700.0, "slot", md["inertia_zz"][0])]
    assert ctl["error_law"].type == "Integer" and md["error_law"][1] == "Integer"
    assert plan.problems == [] and plan.input_problems == []


def test_values_are_checked_once_when_the_plan_is_built():
    plan = build_plan(get("default").with_overrides({"controller.error_law": 1.5}))
    assert len(plan.problems) == 1 and plan.problems[0].startswith("controller.error_law = 1.5: not a whole number")
    with pytest.raises(KeyError, match="PdController has no parameter 'nosuch'"):  # no engine can set it
        build_plan(get("default").with_overrides({"controller.nosuch": 1.0}))
    rep = check(get("default").with_overrides({"controller.nosuch": 1.0}), instantiate=False)  # the pre-flight's words
    assert rep.errors == ["controller (PdController): no parameter 'nosuch'"]
    with pytest.raises(PlanError, match="not a positive multiple of step = 0.07"):
        build_plan(get("default", step=0.07))


def test_apply_params_sets_one_call_per_run_of_one_type():
    calls = []
    s = [Setting("a", 1, "Real", 1.5), Setting("b", 2, "Real", 2.5), Setting("n", 7, "Integer", 3),
         Setting("c", 3, "Real", 4.0)]
    apply_params(s, lambda t, vrs, vals: calls.append((t, vrs, vals)))
    assert calls == [("Real", [1, 2], [1.5, 2.5]), ("Integer", [7], [3]), ("Real", [3], [4.0])]
    calls.clear()
    apply_params(s[:1], lambda t, vrs, vals: calls.append((t, vrs, vals)), vr_of=lambda x: 100 + x.vr)
    assert calls == [("Real", [101], [1.5])]


def test_the_set_value_reaches_the_unit_and_the_preflight_hands_on_its_plan():
    rep = check(get("default").with_overrides({"controller.wn": 2}), origins={"controller.wn": "--set"})
    assert rep.errors == [] and rep.plan is not None
    assert {s.name: s.origin for s in rep.plan.params["controller"]}["wn"] == "--set"
    fmus = build_fmus(rep.plan)
    try:
        assert fmus["controller"].slave.getReal([declared(rep.plan.unit("controller").model)["wn"][0]]) == [2.0]
    finally:
        for f in fmus.values():
            f.close()


def test_the_preflight_instantiates_each_unit_once(monkeypatch):
    """Four units in run 000-6: four instantiations before the run (it used to be seven: each unit bare,
    then the three given parameters again in their trial)."""
    import fmpy.fmi2 as fmi2
    made = []
    real = fmi2.FMU2Slave.instantiate

    def counted(self, *a, **k):
        made.append(self.instanceName)
        return real(self, *a, **k)
    monkeypatch.setattr(fmi2.FMU2Slave, "instantiate", counted)
    sc = get("default")
    rep = check(sc.with_overrides({"controller.wn": 2}))
    assert rep.errors == []
    assert sorted(made) == sorted(c.name for c in sc.components) and len(made) == 4
