"""SSP 1.0 files of the standard scenarios (fmus/ssp/, written by scripts/build_fmus.sh through `scfmu export ssp`):
valid against the SSP 1.0 schemas in fmpy's package data, the same components, parameters and wiring as
the scenario declaration, and, read back and run through the project's reference master (fixed-step
Gauss–Seidel, the same scheme and order as the reference run), results bit-identical to the reference run
of the declaration (short horizons to keep the test fast)."""

from pathlib import Path

import numpy as np
import pytest

from scfmu import scenario as scenarios
from scfmu.registry import REGISTRY
from scfmu.scenario import ssp
from scfmu.scenario.resolve import resolve

from scfmu.engines.lean import build_fmus, ports_of
from scfmu.engines import run_reference

STANDARD = REGISTRY.exported_scenarios()

ROOT = Path(__file__).resolve().parents[1]
SSP_DIR = ROOT / "fmus" / "ssp"


def ssp_file(name):
    p = SSP_DIR / f"{ssp.file_stem(name)}.ssp"
    if not p.exists():
        pytest.fail(f"{p} missing: run scripts/build_fmus.sh")
    return p


@pytest.mark.parametrize("name", STANDARD)
def test_ssp_is_valid_ssp_1_0(name):
    assert ssp.validate_ssp(ssp_file(name)) == []


def test_validation_catches_an_invalid_ssd(tmp_path):
    import zipfile
    bad = tmp_path / "bad.ssp"
    with zipfile.ZipFile(ssp_file("default")) as z, zipfile.ZipFile(bad, "w") as out:
        for n in z.namelist():
            data = z.read(n)
            if n == "SystemStructure.ssd":
                data = data.replace(b'kind="input"', b'kind="sideways"', 1)
            out.writestr(n, data)
    problems = ssp.validate_ssp(bad)
    assert problems and "kind" in problems[0]


@pytest.mark.parametrize("name", STANDARD)
def test_ssp_reads_back_to_the_declared_scenario(name, tmp_path):
    ref = resolve(scenarios.get(name))  # an SSP file has no slots: the slot values a unit declares are its parameters
    sc, files = ssp.read_ssp(ssp_file(name), tmp_path)
    assert [(c.name, c.model) for c in sc.components] == [(c.name, c.model) for c in ref.components]
    for c, r in zip(sc.components, ref.components):
        assert c.params == r.params and all(type(c.params[k]) is type(r.params[k]) for k in r.params)
    assert sc.inputs == ref.inputs
    assert (sc.start_time, sc.stop_time, sc.step, sc.log) == (ref.start_time, ref.stop_time, ref.step, ref.log)
    fmus = build_fmus(sc, path_of=files.__getitem__)
    try:
        ports = ports_of(fmus)
    finally:
        for f in fmus.values():
            f.close()
    assert sc.wiring(ports) == ref.wiring(ports)  # same links in the same Gauss–Seidel order


@pytest.mark.parametrize("name,t", [("default", 3.0), ("paper000/000-9L", 2.0), ("paper000/000-11L", 2.0),
                                    ("paper001/c", 0.5), ("wheel_fault", 5.0),
                                    ("paper003/T2FSMC/N", 2.0), ("paper003/SMC/N", 2.0)])
def test_ssp_run_is_bit_identical_to_reference(name, t, tmp_path):
    ref = run_reference(scenarios.get(name, stop_time=t))
    sc, files = ssp.read_ssp(ssp_file(name), tmp_path)
    out = run_reference(sc.with_overrides(stop_time=t), path_of=files.__getitem__)
    assert set(out) == set(ref)
    for k in ref:
        np.testing.assert_array_equal(out[k], ref[k], err_msg=k)
    moved = [k for k in ref if k != "time" and np.ptp(ref[k]) > 0]
    assert moved  # the comparison is not between two constant signals


@pytest.mark.parametrize("name,t", [("default", 3.0), ("paper001/c", 0.5), ("wheel_fault", 5.0)])
def test_ssp_in_libcosim_equals_libcosim_run_of_the_declaration(name, t):
    """libcosim's own SSP loader (parameter bindings and connections from the archive) against libcosim
    driven from the declaration: the same master (Jacobi, fixed step), so the results are bit-identical.
    (libcosim against the Gauss–Seidel reference differs by its one-step coupling delay; that comparison
    is tests/test_campaign.py::test_second_master_libcosim_agrees_within_the_coupling_delay.)"""
    pytest.importorskip("libcosimpy")
    from scfmu.engines.libcosim import run_libcosim, run_libcosim_ssp
    ref = run_libcosim(scenarios.get(name, stop_time=t))
    out = run_libcosim_ssp(ssp_file(name), stop_time=t)
    assert set(out) == set(ref) - {"wall_s"}
    for k, v in out.items():
        assert v == ref[k], k


@pytest.mark.parametrize("name", ["default", "paper001/b", "wheel_fault"])
def test_fmpy_ssd_reader_sees_components_parameters_and_connections(name):
    """fmpy's SSP reader (an independent parser, schema-validating the .ssd and .ssv files) finds the
    declared instances, their parameter values and one connection per link."""
    from fmpy.ssp.ssd import read_ssd
    ref = resolve(scenarios.get(name))
    ssd = read_ssd(str(ssp_file(name)))
    comps = {e.name: e for e in ssd.system.elements}
    assert list(comps) == [c.name for c in ref.components]
    for c in ref.components:
        assert comps[c.name].source == f"resources/{c.model}.fmu"
        values = {p.name: p.value for b in comps[c.name].parameterBindings for s in b.parameterValues
                  for p in s.parameters}
        want = dict(c.params)
        want.update({q.partition(".")[2]: v for q, v in ref.inputs.items() if q.startswith(c.name + ".")})
        assert {k: float(v) for k, v in values.items()} == {k: float(v) for k, v in want.items()}
    assert len(ssd.system.connections) == sum(1 for _ in ref.wiring(_ports(ref)))


def _ports(sc):
    from fmpy import read_model_description
    from scfmu.fmu import fmu_path
    out = {}
    for c in sc.components:
        md = read_model_description(str(fmu_path(c.model)))
        out[c.name] = ([v.name for v in md.modelVariables if v.causality == "input"],
                       [v.name for v in md.modelVariables if v.causality == "output"])
    return out


def _ssd(name):
    import zipfile
    from xml.etree import ElementTree as ET
    with zipfile.ZipFile(ssp_file(name)) as z:
        return ET.fromstring(z.read("SystemStructure.ssd"))


def test_every_name_inside_every_shipped_ssp_is_a_unique_identifier():
    """OMSimulator refuses system and element names that are not identifiers (paper000_000-7L did):
    the SystemStructureDescription, System, Element and ParameterSet names in every shipped file are
    letters, digits and _ (not starting with a digit), unique within the file, and the descriptions'
    names are unique across the shipped set."""
    import re
    import zipfile
    from xml.etree import ElementTree as ET
    rule = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
    tops = []
    for name in STANDARD:
        root = _ssd(name)
        system = root.find("ssd:System", ssp.NS)
        elems = [e.get("name") for e in system.find("ssd:Elements", ssp.NS)]
        with zipfile.ZipFile(ssp_file(name)) as z:
            sets = [ET.fromstring(z.read(n)).get("name") for n in z.namelist() if n.endswith(".ssv")]
        names = [root.get("name"), system.get("name"), *elems, *sets]
        bad = [n for n in names if not rule.match(n or "")]
        assert not bad, f"{name}: names that are not identifiers: {bad}"
        assert len(set(elems)) == len(elems), f"{name}: duplicate element names {elems}"
        tops.append(root.get("name"))
    assert len(set(tops)) == len(tops), tops
    assert "paper000_000_7L" in tops  # the file is still paper000_000-7L.ssp; the name inside is an identifier


def test_identifier_rule_maps_and_refuses():
    assert ssp.identifier("paper000/000-7L") == "paper000_000_7L"
    assert ssp.identifier("3d model") == "_3d_model"
    from scfmu.scenario.model import Component, Scenario
    bad = Scenario(name="x", components=[Component("my-plant", "AttitudePlant", {})], stop_time=1.0, step=0.1)
    with pytest.raises(ValueError, match="identifiers"):
        ssp.write_ssp(bad, Path("/nonexistent/x.ssp"))


@pytest.mark.parametrize("name", STANDARD)
def test_step_is_where_omsimulator_and_libcosim_look_for_it(name):
    root = _ssd(name)
    sc = resolve(scenarios.get(name))
    oms = root.find("ssd:System/ssd:Annotations/ssc:Annotation[@type='org.openmodelica']", ssp.NS)
    assert float(oms.find(".//oms:FixedStepMaster", ssp.NS).get("stepSize")) == sc.step
    osp = root.find("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation[@type='com.opensimulationplatform']", ssp.NS)
    assert float(osp.find("osp:Algorithm/osp:FixedStepAlgorithm", ssp.NS).get("baseStepSize")) == sc.step


@pytest.mark.parametrize("name", STANDARD)
def test_every_shipped_ssp_imports_in_libcosim_as_shipped(name):
    """libcosim's SSP loader opens every shipped file with no step passed by hand (it takes the step from
    the com.opensimulationplatform annotation) and runs one step of it; without the annotation it refuses."""
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.ERROR)
    sc = resolve(scenarios.get(name))
    ex = CosimExecution.from_ssp_file(str(ssp_file(name)))
    assert ex is not None
    assert ex.num_slaves() == len(sc.components)
    assert ex.step()
    st = ex.status()
    assert st.current_time == int(round(sc.step * 1e9))  # one step of the annotated size, in ns
