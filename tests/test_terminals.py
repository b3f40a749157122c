"""FMI 3.0 terminals (issue 48): every FMI 3.0 archive with vector ports carries
``terminalsAndIcons/terminalsAndIcons.xml``, valid against the official FMI 3.0 XSD (the copy fmpy ships),
equal to the committed ``modelDescription/fmi3/terminalsAndIcons/<Model>.xml``, naming only variables of
the model description and holding every vector input and output; and scfmu's master connects units by
terminals alone: the default attitude loop wired by terminals gives the CSV of the loop wired by names, also
with another paper's controller swapped in, and a terminal that does not match is refused in one line."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from scfmu.engines import simulate
from scfmu.results import write_csv
from scfmu.scenario import get
from scfmu.scenario.check import check

ROOT = Path(__file__).resolve().parents[1]
FMUS = ROOT / "fmus"
COMMITTED = ROOT / "modelDescription" / "fmi3" / "terminalsAndIcons"
MODELS = sorted(p.stem for p in (ROOT / "modelDescription" / "fmi3").glob("*.xml"))
T = 3.0
# the default loop by terminals alone: controller <-> plant one connection each way
BY_TERMINALS = {"controller.attitude": "plant.attitude", "controller.attitude_ref": "command.attitude_ref",
                "controller.w_ref_dot": "command.w_ref_dot", "plant.torque_cmd": "controller.torque_cmd",
                "metrics.q": "plant.q", "metrics.q_ref": "command.q_ref",
                "metrics.torque_applied": "plant.torque_applied"}


def _schema():
    import fmpy
    from lxml import etree
    xsd = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd"
    return etree.XMLSchema(etree.parse(str(xsd)))


def _vector_ports(md_xml: bytes) -> set[str]:
    """Inputs and outputs named <stem>_x/_y/_z/_w, read from the model description itself."""
    root = ET.fromstring(md_xml)
    return {v.get("name") for v in root.find("ModelVariables")
            if v.get("causality") in ("input", "output") and re.search(r"_[wxyz]$", v.get("name"))}


@pytest.mark.parametrize("model", MODELS)
def test_terminals_file_is_valid_committed_and_covers_every_vector_port(model):
    from lxml import etree
    with zipfile.ZipFile(FMUS / "fmi3" / f"{model}.fmu") as z:
        md = z.read("modelDescription.xml")
        names = z.namelist()
        vectors = _vector_ports(md)
        path = COMMITTED / f"{model}.xml"
        if "terminalsAndIcons/terminalsAndIcons.xml" not in names:
            assert not vectors and not path.exists(), f"{model}: vector ports {sorted(vectors)} but no terminals"
            return
        text = z.read("terminalsAndIcons/terminalsAndIcons.xml")
    assert text == path.read_bytes()
    schema = _schema()
    doc = etree.fromstring(text)
    assert schema.validate(doc), schema.error_log
    # FMI 3.0 2.4.9: fmiVersion equals the model description's; plug/bus need unique member names
    assert doc.get("fmiVersion") == ET.fromstring(md).get("fmiVersion")
    declared = {v.get("name") for v in ET.fromstring(md).find("ModelVariables")}
    covered = set()
    for t in doc.iter("Terminal"):
        members = t.findall("TerminalMemberVariable")
        assert members, t.get("name")
        if t.get("matchingRule") in ("plug", "bus"):
            m = [x.get("memberName") for x in members]
            assert None not in m and len(set(m)) == len(m), t.get("name")
        for x in members:
            assert x.get("variableName") in declared, (t.get("name"), x.get("variableName"))
            covered.add(x.get("variableName"))
    assert vectors <= covered, f"{model}: not in a terminal: {sorted(vectors - covered)}"


def _fmi3(sc):
    for c in sc.components:
        c.model = str(FMUS / "fmi3" / f"{c.model}.fmu")
    return sc


def _csv(result, path: Path) -> bytes:
    write_csv(path, result)
    return path.read_bytes()


@pytest.mark.parametrize("scenario", ["default", "paper000/000-7L"])
def test_the_loop_wired_by_terminals_alone_gives_the_name_wired_csv(scenario, tmp_path):
    by_name = _fmi3(get(scenario, stop_time=T))
    by_terms = _fmi3(get(scenario, stop_time=T))
    by_terms.auto_connect = False
    by_terms.terminals = dict(BY_TERMINALS)
    if "PdController" not in by_terms.component("controller").model:  # only the PD law reads w_ref_dot
        del by_terms.terminals["controller.w_ref_dot"]
    rep = check(by_terms, instantiate=False)
    assert not rep.errors, rep.errors
    assert rep.plan.links == check(by_name, instantiate=False).plan.links  # the same links, in the same order
    a = _csv(simulate(by_name, "reference"), tmp_path / "name.csv")
    b = _csv(simulate(by_terms, "reference"), tmp_path / "terminals.csv")
    assert a == b and len(a.splitlines()) == 302  # header + 301 rows (0 … 3 s by 0.01 s)


@pytest.mark.parametrize("dst, src, why", [
    ("plant.torque_cmd", "command.w_ref", "kinds differ: _scfmu_AngularVelocity -> _scfmu_Torque"),
    ("controller.attitude", "plant.q", "kinds differ: _scfmu_AttitudeQuaternion -> _scfmu_AttitudeState"),
    ("controller.attitude", "plant.attitud", "plant has no terminal 'attitud' (has attitude, "),
    ("plant.torque_cmd", "controller.q", "kinds differ"),
    ("controller.torque_cmd", "plant.torque_applied", "controller.torque_cmd_x is not an input"),
])
def test_a_terminal_that_does_not_match_is_refused_in_one_line(dst, src, why):
    sc = _fmi3(get("default", stop_time=T))
    sc.auto_connect = False
    sc.terminals = {**BY_TERMINALS, dst: src}
    rep = check(sc, instantiate=False)
    hit = [e for e in rep.errors if why in e]
    assert hit and "\n" not in hit[0] and f"terminal connection {dst} <- {src}" in hit[0], rep.errors


def test_plug_members_and_units_are_checked():
    from scfmu.fmu.terminals import Member, Terminal
    from scfmu.scenario.model import Component, Scenario
    from scfmu.scenario.terminals import expand
    mk = lambda names, unit, caus: Terminal("t", "plug", "k", tuple(Member(n, "v_" + n, unit, caus) for n in names))  # noqa: E731
    sc = Scenario("s", [Component("a", "A"), Component("b", "B")], 1.0, 0.1, terminals={"a.t": "b.t"})
    _, p = expand(sc, {"a": {"t": mk("xyz", "N", "input")}, "b": {"t": mk("xy", "N", "output")}})
    assert p == ["terminal connection a.t <- b.t: members do not match: source lacks z"]
    _, p = expand(sc, {"a": {"t": mk("xyz", "N", "input")}, "b": {"t": mk("xyz", "N.m", "output")}})
    assert p[0] == "terminal connection a.t <- b.t: unit of b.v_x (N.m) differs from a.v_x (N)"
    links, p = expand(sc, {"a": {"t": mk("xyz", "N", "input")}, "b": {"t": mk("zyx", "N", "output")}})
    assert not p and links == {"a.v_x": "b.v_x", "a.v_y": "b.v_y", "a.v_z": "b.v_z"}
