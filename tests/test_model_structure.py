"""ModelStructure of every committed modelDescription: <InitialUnknowns> is the exact FMI 2.0 list and
its dependencies agree with the feed-through declared in <Outputs>; for a Model Exchange model the
continuous states and their derivatives are initial unknowns too and <Derivatives> lists the derivatives.

FMI 2.0 (ModelStructure): the initial unknowns are the outputs with initial "approx"/"calculated" and the
calculated parameters, in ScalarVariable order, no duplicates; a missing ``dependencies`` attribute means
"depends on every known" (inputs included), which makes masters such as OMSimulator see algebraic loops at
initialization through plants whose outputs depend on their state only. The knowns in Initialization Mode
are the inputs and the variables with initial="exact" (here: the parameters).
"""

from pathlib import Path
import xml.etree.ElementTree as ET

import pytest

MD_DIR = Path(__file__).resolve().parents[1] / "modelDescription"
FILES = sorted(MD_DIR.glob("*.xml"))


def _indices(attr):
    return [int(i) for i in attr.split()] if attr else []


def _children(parent, tag):
    e = parent.find(tag)
    return list(e) if e is not None else []


def test_there_are_model_descriptions():
    assert len(FILES) >= 10


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_initial_unknowns_match_declared_feedthrough(path):
    root = ET.parse(path).getroot()
    svs = root.find("ModelVariables").findall("ScalarVariable")
    var = {i + 1: sv for i, sv in enumerate(svs)}  # 1-based ScalarVariable index

    def causality(i):
        return var[i].get("causality", "local")

    def initial(i):
        sv = var[i]
        if sv.get("initial"):
            return sv.get("initial")
        return {"parameter": "exact", "input": None}.get(causality(i), "calculated")

    inputs = {i for i in var if causality(i) == "input"}
    exact = {i for i in var if initial(i) == "exact" and causality(i) == "parameter"}
    # Model Exchange: der(x) carries derivative="<index of x>"; the states and derivatives are unknowns too
    ders = {i for i in var if var[i].find("Real") is not None and var[i].find("Real").get("derivative")}
    states = {int(var[i].find("Real").get("derivative")) for i in ders}
    ms = root.find("ModelStructure")
    outputs = {int(u.get("index")): u for u in _children(ms, "Outputs")}
    assert set(outputs) == {i for i in var if causality(i) == "output"}
    # Outputs: the declared feed-through, always explicit, inputs (and continuous states) only
    out_deps = {}
    for i, u in outputs.items():
        assert u.get("dependencies") is not None, f"{path.stem}: output {var[i].get('name')} without dependencies"
        deps = _indices(u.get("dependencies"))
        assert set(deps) <= inputs | states and deps == sorted(set(deps))
        out_deps[i] = set(deps) & inputs
    # Derivatives: exactly the der() variables, depending on inputs and states only (which ones is checked
    # against the running FMUs in test_derivative_structure.py)
    derivs = _children(ms, "Derivatives")
    assert [int(u.get("index")) for u in derivs] == sorted(ders)
    der_deps = {}
    for u in derivs:
        deps = _indices(u.get("dependencies"))
        assert set(deps) <= inputs | states and deps == sorted(set(deps))
        der_deps[int(u.get("index"))] = set(deps)
    # a state starts from parameters and, for some (a reference model starting at the measurement),
    # inputs: what its own InitialUnknowns entry lists
    iu = {int(u.get("index")): set(_indices(u.get("dependencies"))) for u in _children(ms, "InitialUnknowns")}
    start_in = {x: iu.get(x, set()) & inputs for x in states}
    for i in outputs:  # an output may read every state
        out_deps[i] |= set().union(*(start_in[x] for x in states))
    for i in ders:  # at initialization: its inputs and the inputs the states it reads start from
        out_deps[i] = (der_deps[i] & inputs).union(*(start_in[x] for x in der_deps[i] & states))
    for x in states:
        out_deps[x] = start_in[x]

    expected = sorted([i for i in var if causality(i) == "output" and initial(i) in ("approx", "calculated")]
                      + [i for i in var if causality(i) == "calculatedParameter"] + sorted(states | ders))
    unknowns = _children(ms, "InitialUnknowns")
    listed = [int(u.get("index")) for u in unknowns]
    assert listed == expected, f"{path.stem}: InitialUnknowns {listed} != {expected}"
    for u in unknowns:
        i = int(u.get("index"))
        name = var[i].get("name")
        attr = u.get("dependencies")
        assert attr is not None, f"{path.stem}: initial unknown {name} has no dependencies (= every known)"
        deps = _indices(attr)
        assert deps == sorted(set(deps)), f"{path.stem}: {name}: dependencies not ascending/unique"
        assert set(deps) <= inputs | exact, f"{path.stem}: {name} depends on a variable that is not a known"
        want_inputs = out_deps.get(i, set())  # calculated parameters depend on no input
        assert set(deps) & inputs == want_inputs, (
            f"{path.stem}: {name}: initial input dependencies {sorted(set(deps) & inputs)} "
            f"!= feed-through {sorted(want_inputs)}")
        assert set(deps) - inputs == exact, f"{path.stem}: {name}: parameter dependencies incomplete"


def test_plant_state_outputs_do_not_depend_on_torque_inputs():
    """The case an OMSimulator trial reported: AttitudePlant's attitude outputs at initialization."""
    root = ET.parse(MD_DIR / "AttitudePlant.xml").getroot()
    svs = root.find("ModelVariables").findall("ScalarVariable")
    index = {sv.get("name"): i + 1 for i, sv in enumerate(svs)}
    inputs = {i + 1 for i, sv in enumerate(svs) if sv.get("causality") == "input"}
    deps = {int(u.get("index")): set(_indices(u.get("dependencies")))
            for u in root.find("ModelStructure").find("InitialUnknowns")}
    for n in ("q_w", "q_x", "w_x", "w_z"):
        assert deps[index[n]] & inputs == set(), n
    # every command: the actuator misalignment (actuator_misalignment_*) couples the axes; the magnetorquer
    # dipole command (mtq_mode = 1) acts through m x B on every axis, B from the input b_eci with the
    # environment inputs (environment_inputs = 1)
    assert deps[index["torque_applied_x"]] & inputs == {index[f"{p}_{a}"] for p in ("torque_cmd", "m_cmd", "b_eci")
                                                        for a in "xyz"}
