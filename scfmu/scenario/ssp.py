"""SSP 1.0 and 2.0 system files (``.ssp``) written from a :class:`~scfmu.scenario.Scenario`, and read back.

SSP 1.0 is the default (FMI 1.0/2.0 units only; FMI 3.0 units are refused); ``version="2.0"`` writes an
SSP 2.0 file, which may hold FMI 3.0 units (ours from ``fmus/fmi3/``, or anyone's given by path), with the
connector types, clocks and array dimensions :mod:`scfmu.scenario.ssp2` describes. Both are laid out as
below and :func:`read_ssp` reads both (told apart by the root's ``version``).

One scenario declaration is the only source of the wiring: :func:`write_ssp` resolves
it with :meth:`Scenario.wiring` (the same call the masters use) and writes

* ``SystemStructure.ssd`` (named by the scenario's name made an identifier, :func:`identifier`; the
  instance names must be identifiers already): one ``ssd:Component`` per instance (``source="resources/<Model>.fmu"``;
  ``implementation="ModelExchange"`` when the instance runs as Model Exchange, read back as its ``interface``) with a
  connector for every input and output of its FMU, one ``ssd:Connection`` per link, a
  ``ssd:DefaultExperiment`` (start and stop time) and, as an ``ssc:Annotation`` of type
  ``com.github.spacecraft-fmus.scfmu``, the master settings that SSP 1.0 has no element for
  (communication step, Gauss–Seidel order = element order, logged signals, metrics name, seed parameters);
  the communication step also where OpenModelica/OMSimulator (``org.openmodelica`` system annotation,
  ``oms:FixedStepMaster stepSize``) and libcosim (``com.opensimulationplatform`` DefaultExperiment
  annotation, ``osp:FixedStepAlgorithm baseStepSize``) look for it, so both import the file as shipped;
* ``resources/<instance>.ssv``: the instance's parameter values (SSP 1.0 parameter values, typed after the
  FMU's modelDescription) and the constant values of its open inputs that the scenario fixes (disturbances),
  bound to the component by an ``ssd:ParameterBinding``;
* ``resources/<Model>.fmu``: the FMUs themselves (each model once).

Inputs left open keep their FMU start value (no connection, no value). :func:`read_ssp` reads an ``.ssp``
back into a Scenario whose FMU paths point into the unpacked archive (``path_of``), so any master of the
package runs it; :func:`validate_ssp` checks the ``.ssd`` and ``.ssv`` files against the SSP 1.0 XML
schemas shipped in fmpy's package data (``fmpy/ssp/schema``).

Standard files: ``scfmu export ssp`` (called by ``scripts/build_fmus.sh``) writes
``<scenario name with / replaced by _>.ssp`` for the scenarios the plug-ins mark as exported.
"""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from fmpy import read_model_description

from ..fmu import fmu_path, is_path
from .model import Component, Scenario
from .resolve import resolve
from .ssp2 import (Refused, check_version, clock_attributes, connector_extras, connector_type, fmi3_path,
                   size_variables, structure_problems, value_tag)

SSD_NS = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC_NS = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV_NS = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
ANNOTATION_TYPE = "com.github.spacecraft-fmus.scfmu"
SCFMU_NS = "https://github.com/spacecraft-fmus/scfmu/ssp-annotation"
# OMSimulator reads the kind of a system and its master from its own annotation (without it, it takes the
# system's type as "none" and refuses the file): a fixed-step master with the scenario's step
OMS_TYPE = "org.openmodelica"
OMS_NS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
# libcosim (Open Simulation Platform) reads the step of its fixed-step algorithm from its own annotation
# of the DefaultExperiment, matched by literal prefixed tag names (a Boost property tree, no namespace
# processing): <ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm><osp:FixedStepAlgorithm
# baseStepSize="…"/></osp:Algorithm></ssc:Annotation>, with the prefix osp bound to OSP_NS
OSP_TYPE = "com.opensimulationplatform"
OSP_NS = "http://opensimulationplatform.com/SSP/OSPAnnotations"
NS = {"ssd": SSD_NS, "ssc": SSC_NS, "ssv": SSV_NS, "scfmu": SCFMU_NS, "oms": OMS_NS, "osp": OSP_NS}
for _p, _u in NS.items():
    ET.register_namespace(_p, _u)

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def file_stem(scenario_name: str) -> str:
    return scenario_name.replace("/", "_")


def identifier(name: str) -> str:
    """``name`` as an identifier every SSP importer accepts (letters, digits and ``_``, not starting with
    a digit; OMSimulator refuses any other character in a system or element name): every other character
    becomes ``_`` (``paper000/000-7L`` → ``paper000_000_7L``), a leading digit gets a ``_`` before it."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    if not out or out[0].isdigit():
        out = "_" + out
    return out


def _q(ns: str, tag: str) -> str:
    return f"{{{NS[ns]}}}{tag}"


def _type_elem(parent, ns: str, vtype: str, **attrs):
    tag = {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean", "Enumeration": "Integer"}[vtype]
    return ET.SubElement(parent, _q(ns, tag), {k: v for k, v in attrs.items()})


def _base_type(vtype: str) -> str:
    """The FMI 2.0 type an FMI 3.0 type is written as (Float64 -> Real, Int32 -> Integer)."""
    if vtype.startswith("Float"):
        return "Real"
    return "Integer" if vtype.startswith(("Int", "UInt")) else vtype


def _value_text(vtype: str, value) -> str:
    if vtype == "Real":
        return repr(float(value))  # shortest round-trip text: read back bit-identical
    if vtype in ("Integer", "Enumeration"):
        if float(value) != int(value):
            raise ValueError(f"integer parameter with non-integer value {value!r}")
        return str(int(value))
    if vtype == "Boolean":
        return "true" if value else "false"
    raise ValueError(f"unsupported variable type {vtype}")


def _ssv(values: list[tuple[str, str, object]], name: str, version: str = "1.0", fmi: int = 2) -> bytes:
    root = ET.Element(_q("ssv", "ParameterSet"), {"version": version, "name": name})
    params = ET.SubElement(root, _q("ssv", "Parameters"))
    for vname, vtype, value in values:
        p = ET.SubElement(params, _q("ssv", "Parameter"), {"name": vname})
        tag = value_tag(vtype, fmi)
        ET.SubElement(p, _q("ssv", tag), {"value": _value_text(_base_type(vtype), value)})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def resource_name(model: str) -> str:
    """The file name of a model's FMU inside the archive: ``<model>.fmu``, or the file's own name for a
    model given as a path."""
    return Path(model).name if is_path(model) else f"{model}.fmu"


def write_ssp(scenario: Scenario, path: str | Path, path_of=None, version: str = "1.0") -> Path:
    """Writes ``scenario`` as an SSP ``version`` ("1.0", the default, or "2.0": FMI 3.0 units, clocks,
    :mod:`scfmu.scenario.ssp2`) archive at ``path``; FMUs from ``path_of(model)`` (default
    ``fmus/<Model>.fmu``; for 2.0 ``fmus/fmi3/<Model>.fmu``; or the model's own path). Returns the path."""
    check_version(version)
    if path_of is None:
        scenario = resolve(scenario)
    path = Path(path)
    bad = [c.name for c in scenario.components if not IDENTIFIER.match(c.name)]
    if bad or len({c.name for c in scenario.components}) != len(scenario.components):
        raise ValueError(f"scenario {scenario.name}: instance names must be unique identifiers (letters, digits, _) "
                         f"for SSP importers; got {[c.name for c in scenario.components]}")
    path_of = path_of or (fmi3_path if version == "2.0" else fmu_path)
    mds = {c.model: read_model_description(str(path_of(c.model))) for c in scenario.components}
    if version == "1.0":
        refuse_fmi3(scenario, mds)
    root = ET.Element(_q("ssd", "SystemStructureDescription"),
                      {"version": version, "name": identifier(file_stem(scenario.name)), "generationTool": "scfmu.ssp",
                       "description": scenario.description or scenario.name})
    system = ET.SubElement(root, _q("ssd", "System"), {"name": "loop"})
    clocks = {m: clock_attributes(path_of(m)) for m in mds if _fmi(mds[m]) >= 3} if version == "2.0" else {}
    ssv_files = _system(system, scenario, mds, version, clocks)
    _experiment(root, scenario)
    ET.indent(root)
    ssd = ET.tostring(root, encoding="UTF-8", xml_declaration=True)

    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".ssp.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", ssd)
        for src, data in sorted(ssv_files.items()):
            z.writestr(src, data)
        for model in dict.fromkeys(c.model for c in scenario.components):
            z.write(path_of(model), f"resources/{resource_name(model)}")
    tmp.replace(path)
    return path


def refuse_fmi3(scenario: Scenario, mds: dict) -> None:
    """One-line refusal of FMI 3.0 units (``mds``: model -> model description): SSP 1.0 gives the meaning of
    an FMU component's connectors and parameter bindings for FMI 1.0 and 2.0 variables only (its types are
    Real/Integer/Boolean/String/Enumeration/Binary, its rules speak of FMI 1.0 and 2.0 causality, variability
    and initial); FMI 3.0 components and types (Float64, Int32, ...) are SSP 2.0's, and fmpy ships the SSP 1.0
    schemas and reads SSP 1.0 only."""
    fmi3 = [c.name for c in scenario.components if mds[c.model].fmiVersion.startswith("3")]
    if fmi3:
        raise Refused(f"{', '.join(fmi3)}: FMI 3.0 units cannot be written to an SSP 1.0 file (SSP 1.0 defines "
                         f"FMU components for FMI 1.0 and 2.0 only; FMI 3.0 came with SSP 2.0): write an SSP 2.0 "
                         f"file (--ssp-version 2.0), use the unit's FMI 2.0 FMU, or a loop FMU (scfmu export loop)")


def _fmi(md) -> int:
    return int(md.fmiVersion.split(".")[0])


def _system(system, scenario: Scenario, mds: dict, version: str = "1.0", clocks: dict | None = None) -> dict:
    """Fills the ``ssd:System``: elements with connectors and parameter bindings, connections and the
    OMSimulator master annotation (``clocks``: model -> its clocks' attributes, 2.0 files). Returns the ``.ssv``
    files (archive name -> bytes)."""
    vars_of = {c.name: {v.name: v for v in mds[c.model].modelVariables} for c in scenario.components}
    ports = {c.name: ([v.name for v in mds[c.model].modelVariables if v.causality == "input" and v.type != "Clock"],
                      [v.name for v in mds[c.model].modelVariables if v.causality == "output" and v.type != "Clock"])
             for c in scenario.components}  # clocks are connectors of a 2.0 file, never wired by name
    terms = None
    if scenario.terminals:  # terminal connections are written as the scalar links they expand into
        from ..fmu.terminals import terminals_of
        terms = {c.name: terminals_of(fmu_path(c.model)) for c in scenario.components}
    links = scenario.wiring(ports, terms)
    fixed = {}
    for q, value in scenario.inputs.items():
        inst, _, var = q.partition(".")
        if var not in ports[inst][0]:
            raise KeyError(f"scenario input {q}: not an input of {inst}")
        fixed.setdefault(inst, []).append((var, value))
    elements = ET.SubElement(system, _q("ssd", "Elements"))
    ssv_files = {}
    for c in scenario.components:
        attrs = {"name": c.name, "type": "application/x-fmu-sharedlibrary",
                 "source": f"resources/{resource_name(c.model)}"}
        impl = _implementation(c, mds[c.model])
        if impl:
            attrs["implementation"] = impl
        comp = ET.SubElement(elements, _q("ssd", "Component"), attrs)
        conns = ET.SubElement(comp, _q("ssd", "Connectors"))
        for v in mds[c.model].modelVariables:
            if v.causality in ("input", "output"):
                conn = ET.SubElement(conns, _q("ssd", "Connector"), {"name": v.name, "kind": v.causality})
                if version == "1.0":
                    _type_elem(conn, "ssc", v.type)
                else:
                    connector_type(conn, SSC_NS, v, _fmi(mds[c.model]), (clocks or {}).get(c.model))
                    connector_extras(conn, v, mds[c.model])
        if version == "2.0":
            for v in size_variables(mds[c.model]):  # the sizes named by sizeConnector are connectors too
                connector_type(ET.SubElement(conns, _q("ssd", "Connector"), {"name": v.name, "kind": v.causality}),
                               SSC_NS, v, 3)
        values = []
        for k, value in c.params.items():
            if k not in vars_of[c.name]:
                raise KeyError(f"{c.model} has no parameter {k!r}")
            values.append((k, vars_of[c.name][k].type, value))
        values += [(k, vars_of[c.name][k].type, value) for k, value in fixed.get(c.name, [])]
        if values:
            src = f"resources/{c.name}.ssv"
            ssv_files[src] = _ssv(values, c.name, version, _fmi(mds[c.model]))
            binds = ET.SubElement(comp, _q("ssd", "ParameterBindings"))
            ET.SubElement(binds, _q("ssd", "ParameterBinding"),
                          {"source": src, "type": "application/x-ssp-parameter-set"})
    connections = ET.SubElement(system, _q("ssd", "Connections")) if links else None  # (the schema: one or more)
    for d, di, s, so in links:
        ET.SubElement(connections, _q("ssd", "Connection"),
                      {"startElement": s, "startConnector": so, "endElement": d, "endConnector": di})
    sys_anns = ET.SubElement(system, _q("ssd", "Annotations"))
    oms = ET.SubElement(ET.SubElement(sys_anns, _q("ssc", "Annotation"), {"type": OMS_TYPE}), _q("oms", "Annotations"))
    ET.SubElement(ET.SubElement(oms, _q("oms", "SimulationInformation")), _q("oms", "FixedStepMaster"),
                  {"description": "oms-ma", "stepSize": repr(float(scenario.step)), "absoluteTolerance": "0.0001",
                   "relativeTolerance": "0.0001"})
    return ssv_files


def _implementation(c, md) -> str:
    """SSP's ``implementation`` of a component: "ModelExchange" when the instance runs as Model Exchange
    (``Component.interface`` "me", or a unit that offers Model Exchange only), "CoSimulation" when the
    scenario asks for it explicitly, "" (SSP's default "any") otherwise."""
    if c.interface == "me" or (not c.interface and md.coSimulation is None and md.modelExchange is not None):
        return "ModelExchange"
    return "CoSimulation" if c.interface == "cs" else ""


def _experiment(root, scenario: Scenario) -> None:
    """The ``ssd:DefaultExperiment`` with libcosim's step annotation and the package's master settings."""
    exp = ET.SubElement(root, _q("ssd", "DefaultExperiment"),
                        {"startTime": repr(float(scenario.start_time)), "stopTime": repr(float(scenario.stop_time))})
    anns = ET.SubElement(exp, _q("ssd", "Annotations"))
    osp = ET.SubElement(ET.SubElement(anns, _q("ssc", "Annotation"), {"type": OSP_TYPE}), _q("osp", "Algorithm"))
    ET.SubElement(osp, _q("osp", "FixedStepAlgorithm"), {"baseStepSize": repr(float(scenario.step))})
    ann = ET.SubElement(anns, _q("ssc", "Annotation"), {"type": ANNOTATION_TYPE})
    master = ET.SubElement(ann, _q("scfmu", "Master"),
                           {"scheme": "fixed-step Gauss-Seidel in element order", "stepSize": repr(float(scenario.step))})
    master.text = json.dumps({"name": scenario.name, "log": scenario.log, "metrics": scenario.metrics,
                              "seed_params": scenario.seed_params, "inputs": sorted(scenario.inputs)}, sort_keys=True)


def _typed(elem, ns: str):
    """The value of an SSV parameter: SSP 1.0's Real/Integer/Boolean or SSP 2.0's FMI 3.0 types (scalars)."""
    from .ssp2 import FLOATS, INTEGERS
    for tags, conv in ((FLOATS, float), (INTEGERS, int), (("Boolean",), lambda s: s in ("true", "1"))):
        for tag in tags:
            e = elem.find(f"{ns}:{tag}", NS)
            if e is not None:
                if len(e.get("value").split()) != 1:
                    raise ValueError(f"parameter {elem.get('name')}: array values are not supported")
                return conv(e.get("value"))
    raise ValueError(f"parameter {elem.get('name')}: no float, integer or Boolean value")


def read_ssp(path: str | Path, workdir: str | Path | None = None) -> tuple[Scenario, dict]:
    """Reads an ``.ssp`` written by :func:`write_ssp` back into a Scenario: components, parameters and
    fixed inputs from the ``.ssd``/``.ssv`` files, every connection explicit (nothing matched by name),
    master settings from the annotation. Returns ``(scenario, fmu_files)`` where ``fmu_files[model]`` is
    the FMU unpacked from the archive into ``workdir`` (a new temporary directory by default); pass
    ``path_of=fmu_files.__getitem__`` to a master."""
    from ..fmu import safe_extract  # the archive limits of FMUs hold for an SSP and the FMUs inside it
    workdir = Path(safe_extract(path, workdir))
    root = ET.parse(workdir / "SystemStructure.ssd").getroot()
    if root.tag != _q("ssd", "SystemStructureDescription") or root.get("version") not in ("1.0", "2.0"):
        raise ValueError(f"{path}: not an SSP 1.0 or 2.0 system structure (root {root.tag}, version "
                         f"{root.get('version')!r}; allowed: version 1.0 or 2.0 in the SSP namespace)")
    system = root.find("ssd:System", NS)
    components, fixed, files = [], {}, {}
    for c in system.findall("ssd:Elements/ssd:Component", NS):
        name, source = c.get("name"), c.get("source")
        model = Path(source).stem
        files[model] = workdir / source
        kinds = {k.get("name"): k.get("kind") for k in c.findall("ssd:Connectors/ssd:Connector", NS)}
        params = {}
        for b in c.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS):
            ps = ET.parse(workdir / b.get("source")).getroot()
            for p in ps.findall("ssv:Parameters/ssv:Parameter", NS):
                value = _typed(p, "ssv")
                if kinds.get(p.get("name")) == "input":
                    fixed[f"{name}.{p.get('name')}"] = value
                else:
                    params[p.get("name")] = value
        comp = Component(name, model, params)
        comp.interface = {"ModelExchange": "me", "CoSimulation": "cs"}.get(c.get("implementation", ""), "")
        components.append(comp)
    connections = {f"{e.get('endElement')}.{e.get('endConnector')}": f"{e.get('startElement')}.{e.get('startConnector')}"
                   for e in system.findall("ssd:Connections/ssd:Connection", NS)}
    exp = root.find("ssd:DefaultExperiment", NS)
    master = None if exp is None else \
        exp.find(f"ssd:Annotations/ssc:Annotation[@type='{ANNOTATION_TYPE}']/scfmu:Master", NS)
    meta = json.loads(master.text) if master is not None else _foreign_meta(root, system, path)
    step = master.get("stepSize") if master is not None else meta["step"]
    sc = Scenario(name=meta["name"], components=components, start_time=float(exp.get("startTime", 0.0)),
                  stop_time=float(exp.get("stopTime")), step=float(step), log=meta["log"],
                  connections=connections, unconnected=["*"], inputs=fixed, auto_connect=False,
                  seed_params=meta["seed_params"], metrics=meta["metrics"], description=root.get("description", ""))
    return sc, files


def _foreign_meta(root, system, path) -> dict:
    """The master settings of an SSP file another tool wrote (no annotation of this package): the step from
    libcosim's or OMSimulator's annotation, every connected output logged as ``instance.output``."""
    steps = [e.get("baseStepSize") for e in root.iter(_q("osp", "FixedStepAlgorithm"))]
    steps += [e.get("stepSize") for e in system.iter(_q("oms", "FixedStepMaster"))]
    steps = [s for s in steps if s]
    if not steps or root.find("ssd:DefaultExperiment", NS) is None:
        raise ValueError(f"{path}: no communication step (none of the libcosim, OMSimulator or scfmu annotations) "
                         f"or no DefaultExperiment stop time; allowed: an SSP file with one of them")
    outs = dict.fromkeys(f"{e.get('startElement')}.{e.get('startConnector')}"
                         for e in system.findall("ssd:Connections/ssd:Connection", NS))
    return {"name": root.get("name"), "step": steps[0], "log": {k: k for k in outs}, "metrics": "",
            "seed_params": []}


def schema_dir() -> Path:
    import fmpy
    return Path(fmpy.__file__).parent / "ssp" / "schema"


def ssp_version(path: str | Path) -> str:
    """The ``version`` attribute of the archive's ``SystemStructure.ssd``."""
    with zipfile.ZipFile(path) as z:
        if "SystemStructure.ssd" not in z.namelist():
            return ""
        return ET.fromstring(z.read("SystemStructure.ssd")).get("version", "")


def validate_ssp(path: str | Path) -> list[str]:
    """Problems found by validating the archive's ``.ssd`` (SSP 1.0 SystemStructureDescription.xsd) and
    ``.ssv`` files (SystemStructureParameterValues.xsd) with lxml; empty when valid. An SSP 2.0 file:
    :func:`scfmu.scenario.ssp2.structure_problems`, and the official 2.0 schemas when ``SCFMU_SSP2_SCHEMA``
    names a folder holding them."""
    from lxml import etree
    if ssp_version(path) == "2.0":
        from .ssp2 import schema_dir as schema2, xsd_problems
        return structure_problems(path) + (xsd_problems(path, schema2()) if schema2() else [])
    schemas = {ext: etree.XMLSchema(file=str(schema_dir() / f)) for ext, f in
               ((".ssd", "SystemStructureDescription.xsd"), (".ssv", "SystemStructureParameterValues.xsd"))}
    problems = []
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        if "SystemStructure.ssd" not in names:
            problems.append("no SystemStructure.ssd at the archive root")
        for n in names:
            ext = Path(n).suffix
            if ext in schemas:
                doc = etree.fromstring(z.read(n))
                if not schemas[ext].validate(doc):
                    problems += [f"{n}:{e.line}: {e.message}" for e in schemas[ext].error_log]
    return problems
