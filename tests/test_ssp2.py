"""SSP 2.0 files (issue 48 item 4): `scfmu export ssp --ssp-version 2.0` writes FMI 3.0 components (ours: the
FMI 3.0 builds in fmus/fmi3/; a user's: any FMI 3.0 FMU given by path), connectors typed as the FMU's
variables (Float64, Int32, ...), clock connectors and clock associations for a clocked unit, array
dimensions, SSV 2.0 parameter files; `scfmu run FILE.ssp` reads 1.0 and 2.0 files and runs them.

What is checked, and against what:
* the structure the SSP 2.0 schemas require of the elements written (root version, namespaces, required
  attributes, allowed values, the order of children), by this file's own reading of the exported XML,
  independently of the writer (the expected connector types come from the FMUs' modelDescription.xml read
  here with ElementTree, not through fmpy);
* the official SSP 2.0 schemas themselves, when ``SCFMU_SSP2_SCHEMA`` names a folder holding them (they are
  not shipped; the test is skipped otherwise);
* a run of the exported file against a direct run of the same scenario (bit-identical: the same FMUs, the
  same master, the same order);
* the refusals: FMI 3.0 units in an SSP 1.0 file, an unknown version (one line, exit 2).
"""

from __future__ import annotations

import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from cli_run import refused, scfmu  # tests/ is on the path (pyproject.toml)
from scfmu import scenario as scenarios
from scfmu.engines import run_reference
from scfmu.fmu import fmu_dir
from scfmu.scenario import ssp, ssp2
from scfmu.scenario.model import Component, Scenario

SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"
SSC = "{http://ssp-standard.org/SSP1/SystemStructureCommon}"
SSV = "{http://ssp-standard.org/SSP1/SystemStructureParameterValues}"
T_END = 2.0


def fmi3(model: str) -> Path:
    return fmu_dir() / "fmi3" / f"{model}.fmu"


def fmi3_scenario(stop_time=T_END) -> Scenario:
    """The default scenario with every unit's FMI 3.0 build given by path, parameters kept."""
    sc = scenarios.get("default", stop_time=stop_time)
    out = sc.with_models({c.name: str(fmi3(c.model)) for c in sc.components})
    for c, o in zip(out.components, sc.components):
        c.params = dict(o.params)
    return out


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("ssp2")
    r = scfmu("export", "ssp", "default", "--ssp-version", "2.0", "--out", d)
    assert r.returncode == 0, r.stderr
    return d / "default.ssp"


def md_types(fmu: Path) -> dict:
    """name -> (FMI 3.0 type element, causality) read straight from the FMU's modelDescription.xml."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert root.get("fmiVersion") == "3.0"
    return {v.get("name"): (v.tag, v.get("causality", "local")) for v in root.find("ModelVariables")}


def ssd_of(path: Path):
    with zipfile.ZipFile(path) as z:
        return ET.fromstring(z.read("SystemStructure.ssd")), {n: z.read(n) for n in z.namelist()}


def test_exported_file_has_the_ssp_2_0_structure(exported):
    root, members = ssd_of(exported)
    assert root.tag == f"{SSD}SystemStructureDescription" and root.get("version") == "2.0"
    assert [ch.tag for ch in root] == [f"{SSD}System", f"{SSD}DefaultExperiment"]
    system = root.find(f"{SSD}System")
    assert [ch.tag for ch in system] == [f"{SSD}Elements", f"{SSD}Connections", f"{SSD}Annotations"]
    comps = system.findall(f"{SSD}Elements/{SSD}Component")
    assert [c.get("name") for c in comps] == ["command", "controller", "plant", "metrics"]
    for c in comps:
        assert c.get("type") == "application/x-fmu-sharedlibrary"
        assert c.get("implementation", "any") in ("any", "ModelExchange", "CoSimulation", "ScheduledExecution")
        src = c.get("source")
        assert src.startswith("resources/") and src in members
        with zipfile.ZipFile(exported) as z:  # the component's FMU is an FMI 3.0 one
            inner = ET.fromstring(zipfile.ZipFile(z.open(src)).read("modelDescription.xml"))
        assert inner.get("fmiVersion") == "3.0"
        want = md_types(fmi3(Path(src).stem))
        conns = c.findall(f"{SSD}Connectors/{SSD}Connector")
        assert conns, c.get("name")
        for k in conns:
            tag, causality = want[k.get("name")]
            assert k.get("kind") == causality and causality in ("input", "output")
            assert [t.tag for t in k] == [f"{SSC}{tag}"]  # one type, the variable's own (Float64, Int32, ...)
        for b in c.findall(f"{SSD}ParameterBindings/{SSD}ParameterBinding"):
            ps = ET.fromstring(members[b.get("source")])
            assert ps.tag == f"{SSV}ParameterSet" and ps.get("version") == "2.0" and ps.get("name")
            for p in ps.findall(f"{SSV}Parameters/{SSV}Parameter"):
                (val,) = list(p)
                assert val.tag == f"{SSV}{want[p.get('name')][0]}" and val.get("value") is not None
    for e in system.findall(f"{SSD}Connections/{SSD}Connection"):
        assert e.get("startConnector") and e.get("endConnector") and e.get("startElement") and e.get("endElement")
    exp = root.find(f"{SSD}DefaultExperiment")
    assert float(exp.get("startTime")) == 0.0 and float(exp.get("stopTime")) == scenarios.get("default").stop_time
    # the step for libcosim and OMSimulator (SSP 2.0 has no element for it)
    osp = exp.find(f"{SSD}Annotations/{SSC}Annotation[@type='com.opensimulationplatform']")
    assert float(next(osp.iter("{http://opensimulationplatform.com/SSP/OSPAnnotations}FixedStepAlgorithm")).get(
        "baseStepSize")) == 0.01
    assert ssp2.structure_problems(exported) == []


def _rewrite(src: Path, dst: Path, old: bytes, new: bytes, member="SystemStructure.ssd") -> Path:
    with zipfile.ZipFile(src) as z, zipfile.ZipFile(dst, "w") as out:
        for n in z.namelist():
            data = z.read(n)
            out.writestr(n, data.replace(old, new, 1) if n == member else data)
    return dst


@pytest.mark.parametrize("old,new,what", [
    (b'kind="input"', b'kind="sideways"', "kind 'sideways'"),
    (b'version="2.0"', b'version="2.1"', "version '2.1'"),
    (b'<ssc:Float64 />', b'<ssc:Float64 /><ssc:Int32 />', "types (at most one)"),
    (b' startConnector="', b' startConnecter="', "required attribute startConnector"),
])
def test_structure_check_catches_a_broken_file(exported, tmp_path, old, new, what):
    bad = _rewrite(exported, tmp_path / "bad.ssp", old, new)
    problems = ssp2.structure_problems(bad)
    assert any(what in p for p in problems), problems


def test_structure_check_catches_children_out_of_order(exported, tmp_path):
    root, _ = ssd_of(exported)
    text = ET.tostring(root)
    exp = text[text.index(b"<ssd:DefaultExperiment"):text.index(b"</ssd:DefaultExperiment>") + 24]
    moved = text.replace(exp, b"").replace(b"<ssd:System ", exp + b"<ssd:System ", 1)
    with zipfile.ZipFile(exported) as z, zipfile.ZipFile(tmp_path / "bad.ssp", "w") as out:
        for n in z.namelist():
            out.writestr(n, moved if n == "SystemStructure.ssd" else z.read(n))
    assert any("out of order" in p for p in ssp2.structure_problems(tmp_path / "bad.ssp"))


@pytest.mark.skipif(ssp2.schema_dir() is None, reason="the official SSP 2.0 schemas are not shipped: set "
                    "SCFMU_SSP2_SCHEMA to a folder holding SystemStructureDescription.xsd etc. to run this")
def test_exported_file_is_valid_against_the_official_ssp_2_0_schemas(exported, tmp_path):
    assert ssp2.xsd_problems(exported, ssp2.schema_dir()) == []
    bad = _rewrite(exported, tmp_path / "bad.ssp", b'kind="input"', b'kind="sideways"')
    assert ssp2.xsd_problems(bad, ssp2.schema_dir())


def test_ssp_2_0_run_equals_the_direct_run(exported, tmp_path):
    ref = run_reference(fmi3_scenario())
    sc, files = ssp.read_ssp(exported, tmp_path)
    assert {c.name: c.model for c in sc.components} == {"command": "AttitudeCommand", "controller": "PdController",
                                                        "plant": "AttitudePlant", "metrics": "AttitudeMetrics"}
    out = run_reference(sc.with_overrides(stop_time=T_END), path_of=files.__getitem__)
    assert set(out) == set(ref)
    for k in ref:
        np.testing.assert_array_equal(out[k], ref[k], err_msg=k)
    assert [k for k in ref if k != "time" and np.ptp(ref[k]) > 0]  # not two constant signals


def test_scfmu_run_reads_an_ssp_2_0_file(exported, tmp_path):
    r = scfmu("run", exported, "--t-end", 1, "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    assert "FMI 3.0 Co-Simulation" in r.stdout
    csv = np.genfromtxt(tmp_path / "run" / "default.csv", delimiter=",", names=True)
    ref = run_reference(fmi3_scenario(stop_time=1.0))
    for k in ("q_w", "w_x", "eulerint_deg_s"):  # the CSV holds every value at full (round-trip) precision
        np.testing.assert_array_equal(csv[k], ref[k], err_msg=k)


def test_scfmu_run_reads_an_ssp_1_0_file(tmp_path):
    shipped = fmu_dir() / "ssp" / "default.ssp"
    if not shipped.exists():
        pytest.fail(f"{shipped} missing: run scripts/build_fmus.sh")
    r = scfmu("run", shipped, "--t-end", 1, "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    csv = np.genfromtxt(tmp_path / "run" / "default.csv", delimiter=",", names=True)
    ref = run_reference(scenarios.get("default", stop_time=1.0))
    for k in ("q_w", "w_x", "eulerint_deg_s"):
        np.testing.assert_array_equal(csv[k], ref[k], err_msg=k)


def test_a_file_without_our_annotation_takes_the_tool_step(exported, tmp_path):
    """Another tool's file (no scfmu annotation): the step from libcosim's annotation, every connected
    output logged by its qualified name."""
    root, _ = ssd_of(exported)
    text = ET.tostring(root)
    i = text.index(b'<ssc:Annotation type="com.github.spacecraft-fmus.scfmu"')
    j = text.index(b"</ssc:Annotation>", i) + len(b"</ssc:Annotation>")
    foreign = tmp_path / "foreign.ssp"
    with zipfile.ZipFile(exported) as z, zipfile.ZipFile(foreign, "w") as out:
        for n in z.namelist():
            out.writestr(n, text[:i] + text[j:] if n == "SystemStructure.ssd" else z.read(n))
    sc, _ = ssp.read_ssp(foreign, tmp_path / "x")
    assert sc.step == 0.01 and sc.name == "default" and sc.stop_time == scenarios.get("default").stop_time
    assert "controller.torque_cmd_x" in sc.log and sc.log["controller.torque_cmd_x"] == "controller.torque_cmd_x"


def test_a_users_fmi3_unit_in_an_ssp_2_0_file(tmp_path):
    theirs = tmp_path / "TheirController.fmu"
    theirs.write_bytes(fmi3("PdController").read_bytes())
    r = scfmu("export", "ssp", "default", "--ssp-version", "2.0", "--fmu", f"controller={theirs}",
              "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    path = tmp_path / "out" / "default.ssp"
    root, members = ssd_of(path)
    (c,) = [c for c in root.iter(f"{SSD}Component") if c.get("name") == "controller"]
    assert c.get("source") == "resources/TheirController.fmu" and "resources/TheirController.fmu" in members
    assert ssp.validate_ssp(path) == []
    sc, files = ssp.read_ssp(path, tmp_path / "x")
    direct = scenarios.get("default", stop_time=1.0).with_models({"controller": str(theirs)})
    ref = run_reference(direct)
    out = run_reference(sc.with_overrides(stop_time=1.0), path_of=files.__getitem__)
    for k in ref:
        np.testing.assert_array_equal(out[k], ref[k], err_msg=k)


def test_ssp_1_0_stays_the_default(tmp_path):
    r = scfmu("export", "ssp", "default", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    assert ssp.ssp_version(tmp_path / "default.ssp") == "1.0"
    assert ssp.validate_ssp(tmp_path / "default.ssp") == []  # fmpy's SSP 1.0 schemas


def test_fmi3_unit_in_ssp_1_0_is_refused():
    line = refused(scfmu("export", "ssp", "default", "--fmu", f"controller={fmi3('PdController')}",
                         "--out", "/nonexistent"))
    assert "FMI 3.0 units cannot be written to an SSP 1.0 file" in line and "--ssp-version 2.0" in line


@pytest.mark.parametrize("version", ["3.0", "2", "1.1"])
def test_unknown_ssp_version_is_refused(version):
    line = refused(scfmu("export", "ssp", "default", "--ssp-version", version, "--out", "/nonexistent"))
    assert f"--ssp-version {version}" in line and "1.0 or 2.0" in line


def test_run_of_a_broken_ssp_file_is_one_line(tmp_path):
    bad = tmp_path / "bad.ssp"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("SystemStructure.ssd", b'<a version="9"/>')
    line = refused(scfmu("run", bad))
    assert "bad.ssp" in line and "not an SSP" in line


CLOCKED_MD = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Clocked" instantiationToken="{8c4e810f-3df3-4a00-8276-176fa3c9f000}">
  <CoSimulation modelIdentifier="Clocked" hasEventMode="true"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Clock name="tick" valueReference="1" causality="input" variability="discrete" intervalVariability="triggered"/>
    <Float64 name="u" valueReference="2" causality="input" variability="discrete" clocks="1" start="0"/>
    <Float64 name="y" valueReference="3" causality="output" variability="discrete" clocks="1"/>
    <UInt64 name="n" valueReference="4" causality="structuralParameter" variability="fixed" start="3"/>
    <Float64 name="w" valueReference="5" causality="input" variability="continuous" start="0 0 0">
      <Dimension valueReference="4"/></Float64>
    <Float64 name="v" valueReference="6" causality="output" variability="continuous"><Dimension start="3"/></Float64>
    <Float64 name="k" valueReference="7" causality="parameter" variability="fixed" start="1"/>
    <Int32 name="mode" valueReference="8" causality="parameter" variability="fixed" start="0"/>
  </ModelVariables>
  <ModelStructure><Output valueReference="3"/><Output valueReference="6"/></ModelStructure>
</fmiModelDescription>
"""


def test_clocked_unit_gets_clock_connectors(tmp_path):
    """A user's clocked FMI 3.0 unit (a modelDescription written here: no clocked FMU is at hand, and the
    writer reads nothing else): its clock is a connector of type Clock, its clocked input and output name
    the clock, its arrays carry their dimensions (a fixed size, or the structural parameter holding it, which
    becomes a connector too), and two instances wire y -> u."""
    fmu = tmp_path / "Clocked.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", CLOCKED_MD)
    sc = Scenario(name="clocked", components=[Component("a", str(fmu), {"k": 2.5, "mode": 3}), Component("b", str(fmu))],
                  stop_time=1.0, step=0.1, connections={"b.u": "a.y"}, unconnected=["*"], auto_connect=False)
    path = ssp.write_ssp(sc, tmp_path / "clocked.ssp", path_of=Path, version="2.0")
    root, members = ssd_of(path)
    conns = {k.get("name"): k for k in root.find(f"{SSD}System/{SSD}Elements/{SSD}Component").iter(f"{SSD}Connector")}
    assert set(conns) == {"tick", "u", "y", "w", "v", "n"}
    assert [(t.tag, t.get("intervalVariability")) for t in conns["tick"]] == [(f"{SSC}Clock", "triggered")]
    assert conns["tick"].get("kind") == "input"
    for name in ("u", "y"):
        assert [t.tag for t in conns[name]] == [f"{SSC}Float64", f"{SSD}Clock"]
        assert conns[name].find(f"{SSD}Clock").get("name") == "tick"
    assert [(t.tag, t.get("size"), t.get("sizeConnector")) for t in conns["v"]] == \
        [(f"{SSC}Float64", None, None), (f"{SSC}Dimension", "3", None)]
    assert [(t.tag, t.get("sizeConnector")) for t in conns["w"]] == [(f"{SSC}Float64", None), (f"{SSC}Dimension", "n")]
    assert conns["n"].get("kind") == "structuralParameter" and conns["n"][0].tag == f"{SSC}UInt64"
    (e,) = root.iter(f"{SSD}Connection")
    assert (e.get("startElement"), e.get("startConnector"), e.get("endElement"), e.get("endConnector")) == \
        ("a", "y", "b", "u")
    ps = ET.fromstring(members["resources/a.ssv"])
    assert {p.get("name"): (p[0].tag, p[0].get("value")) for p in ps.iter(f"{SSV}Parameter")} == \
        {"k": (f"{SSV}Float64", "2.5"), "mode": (f"{SSV}Int32", "3")}
    assert ssp2.structure_problems(path) == []
    if ssp2.schema_dir() is not None:
        assert ssp2.xsd_problems(path, ssp2.schema_dir()) == []
    sc2, _ = ssp.read_ssp(path, tmp_path / "x")  # read back: parameters typed, the connection explicit
    assert sc2.components[0].params == {"k": 2.5, "mode": 3} and sc2.connections == {"b.u": "a.y"}


def test_libcosim_reads_ssp_2_0_with_fmi2_units_and_refuses_fmi3_units(exported, tmp_path):
    """The measurement behind the docs' table: libcosim 0.0.6 runs a 2.0 file whose units are FMI 2.0 ones
    (the same final values as the 1.0 file), and refuses one with FMI 3.0 units (no crash)."""
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy._internal import get_last_error_message
    from scfmu.engines.libcosim import run_libcosim_ssp
    sc = scenarios.get("default")
    fmi2 = sc.with_models({c.name: str(fmu_dir() / f"{c.model}.fmu") for c in sc.components})
    for c, o in zip(fmi2.components, sc.components):
        c.params = dict(o.params)
    v2 = ssp.write_ssp(fmi2, tmp_path / "fmi2_in_2_0.ssp", version="2.0")
    v1 = ssp.write_ssp(sc, tmp_path / "fmi2_in_1_0.ssp")
    assert ssp.ssp_version(v2) == "2.0" and ssp.validate_ssp(v2) == []
    a, b = run_libcosim_ssp(v2, stop_time=0.5), run_libcosim_ssp(v1, stop_time=0.5)
    assert a == b and a["eulerint_deg_s"] > 0
    with pytest.raises(AssertionError):
        CosimExecution.from_ssp_file(str(exported), step_size=10_000_000)
    assert "connector type" in get_last_error_message()


def test_clock_attributes_come_from_the_fmus_own_description(tmp_path):
    """A clock as our units declare them (value reference 1000200000, fixed interval, a priority): fmpy 0.3.32
    keeps `clocks` as the attribute's text and reads no priority, so the writer reads the FMU's XML: the Clock
    connector carries intervalVariability and priority, the clocked connectors name the clock (not one clock
    per digit of its value reference)."""
    md = CLOCKED_MD.replace('valueReference="1" causality="input" variability="discrete" intervalVariability='
                            '"triggered"', 'valueReference="1000200000" causality="input" variability="discrete" '
                            'intervalVariability="fixed" priority="0"').replace('clocks="1"', 'clocks="1000200000"')
    assert md.count("1000200000") == 3
    fmu = tmp_path / "Clocked.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", md)
    sc = Scenario(name="clocked", components=[Component("a", str(fmu))], stop_time=1.0, step=0.1, unconnected=["*"],
                  auto_connect=False)
    path = ssp.write_ssp(sc, tmp_path / "clocked.ssp", path_of=Path, version="2.0")
    root, _ = ssd_of(path)
    conns = {k.get("name"): k for k in root.iter(f"{SSD}Connector")}
    assert [(t.tag, dict(t.attrib)) for t in conns["tick"]] == \
        [(f"{SSC}Clock", {"intervalVariability": "fixed", "priority": "0"})]
    for name in ("u", "y"):
        assert [(t.tag, t.get("name")) for t in conns[name]] == [(f"{SSC}Float64", None), (f"{SSD}Clock", "tick")]
    assert ssp2.structure_problems(path) == []
    if ssp2.schema_dir() is not None:
        assert ssp2.xsd_problems(path, ssp2.schema_dir()) == []


CLOCKED_SCENARIO = "leo/nadir-textbook"  # gyro, star tracker, MEKF, sample-and-hold: clocked units, two with two clocks


def _clocks_in(fmu_bytes: bytes) -> tuple[dict, dict]:
    """From a unit's own modelDescription.xml (ElementTree): its clocks {name: attributes} and its clocked
    outputs {name: [clock names]}."""
    import io
    with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    mv = root.find("ModelVariables")
    clocks = {e.get("valueReference"): e for e in mv if e.tag == "Clock"}
    return ({e.get("name"): dict(e.attrib) for e in clocks.values()},
            {e.get("name"): [clocks[r].get("name") for r in e.get("clocks").split()] for e in mv
             if e.get("clocks") and e.get("causality") == "output"})


def test_clocked_units_in_an_ssp_2_0_file(tmp_path):
    """A scenario of clocked units exported as SSP 2.0: every clock of every unit is a connector (kind input,
    type ssc:Clock with the clock's intervalVariability and priority), every clocked output names its clocks
    by ssd:Clock, the file passes the structure check (and the official schemas when given), and `scfmu run`
    runs it with the same results as the scenario run directly with the FMI 3.0 units."""
    r = scfmu("export", "ssp", CLOCKED_SCENARIO, "--ssp-version", "2.0", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    path = tmp_path / (CLOCKED_SCENARIO.replace("/", "_") + ".ssp")
    root, members = ssd_of(path)
    n_clocked = 0
    for c in root.iter(f"{SSD}Component"):
        clocks, clocked = _clocks_in(members[c.get("source")])
        conns = {k.get("name"): k for k in c.iter(f"{SSD}Connector")}
        n_clocked += bool(clocks)
        for name, attrs in clocks.items():
            (t,) = list(conns[name])
            assert conns[name].get("kind") == "input" and t.tag == f"{SSC}Clock", (c.get("name"), name)
            assert dict(t.attrib) == {a: attrs[a] for a in ssp2.CLOCK_ATTRS if a in attrs}
            assert t.get("intervalVariability") == "fixed" and t.get("priority") is not None
        for name, k in conns.items():
            assert [x.get("name") for x in k.findall(f"{SSD}Clock")] == clocked.get(name, []), (c.get("name"), name)
    assert n_clocked >= 4, "the gyro, star tracker, MEKF and sample-and-hold declare clocks"
    assert ssp2.structure_problems(path) == []
    if ssp2.schema_dir() is not None:
        assert ssp2.xsd_problems(path, ssp2.schema_dir()) == []
    r = scfmu("run", path, "--t-end", 5, "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    sc = scenarios.get(CLOCKED_SCENARIO, stop_time=5.0)
    direct = sc.with_models({c.name: str(fmi3(c.model)) for c in sc.components})
    for c, o in zip(direct.components, sc.components):
        c.params = dict(o.params)
    ref = run_reference(direct)
    csv = np.genfromtxt(tmp_path / "run" / f"{CLOCKED_SCENARIO.replace('/', '_')}.csv", delimiter=",", names=True)
    keys = [k for k in ref if k in csv.dtype.names and k != "time"]
    assert len(keys) >= 3, (sorted(ref), csv.dtype.names)
    for k in keys:
        np.testing.assert_array_equal(csv[k], ref[k], err_msg=k)
