"""What an SSP 2.0 file adds to the SSP 1.0 ones :mod:`scfmu.scenario.ssp` writes, and a structural check of
the 2.0 files written from what the 2.0 schemas require.

SSP 2.0 keeps the SSP 1.0 XML namespaces (``http://ssp-standard.org/SSP1/...``); a file says which version
it follows only by the ``version`` attribute of its root element ("1.0" or "2.0", major and minor only).
For the elements this package writes, 2.0 changes:

* connector and parameter types: next to SSP 1.0's Real/Integer/Boolean/String/Enumeration/Binary (the FMI
  2.0 types), the FMI 3.0 types Float64, Float32, Int8 … UInt64 and Clock; an FMU component's connector
  carries the type of its FMU variable, so an FMI 3.0 unit's connectors are Float64/Int32/Boolean;
* clocks: a connector of type Clock (an FMI 3.0 clock variable, with its ``intervalVariability``), and a
  clocked connector names the clocks it ticks with by ``ssd:Clock name="…"`` children (after the type and
  the dimensions);
* arrays: ``ssc:Dimension`` children of a connector (``size``, or ``sizeConnector`` naming the structural
  parameter holding the size); an SSV value of an array is the list of its values in row-major order;
* ``implementation`` of a component may also be "ScheduledExecution"; the component's ``type`` stays
  ``application/x-fmu-sharedlibrary`` for an FMU of any FMI version (the FMU's own modelDescription says which);
* the ``ssd:DefaultExperiment`` still has start and stop time only: the communication step stays in the
  tool annotations (OMSimulator, libcosim) and the package's own, as in the 1.0 files.

:func:`structure_problems` checks a 2.0 ``.ssd``/``.ssv`` pair for what the 2.0 schemas require of the
elements written here (root version, required attributes, allowed values, the order of children);
:func:`xsd_problems` validates against the official 2.0 schemas when a folder holding them is given
(``SCFMU_SSP2_SCHEMA``): the schemas are not shipped with the package.
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"

VERSIONS = ("1.0", "2.0")
FLOATS = ("Real", "Float64", "Float32")
INTEGERS = ("Integer", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64")
# the connector types of SSP 2.0 (ssc type choice); Enumeration needs a named enumeration, not written here
TYPES = FLOATS + INTEGERS + ("Boolean", "String", "Enumeration", "Binary", "Clock")
KINDS = ("input", "output", "parameter", "calculatedParameter", "structuralParameter", "constant", "local", "inout",
         "unspecified")
IMPLEMENTATIONS = ("any", "ModelExchange", "CoSimulation", "ScheduledExecution")
INTERVAL_VARIABILITY = ("constant", "fixed", "tunable", "changing", "countdown", "triggered")
# the order of the children of the elements written (each optional unless listed in REQUIRED_CHILDREN)
ORDER = {
    "SystemStructureDescription": ("System", "Enumerations", "Units", "DefaultExperiment", "MetaData", "Signature",
                                   "Annotations"),
    "System": ("Connectors", "ElementGeometry", "ParameterBindings", "MetaData", "Signature", "Elements",
               "Connections", "SignalDictionaries", "SystemGeometry", "GraphicalElements", "Annotations"),
    "Component": ("Connectors", "ElementGeometry", "ParameterBindings", "MetaData", "Signature", "Annotations"),
    "Connector": TYPES + ("Dimension", "Clock_", "ConnectorGeometry", "Annotations"),
    "ParameterSet": ("Parameters", "Enumerations", "Units", "MetaData", "Signature", "Annotations"),
}
REQUIRED_ATTRS = {"SystemStructureDescription": ("version", "name"), "System": ("name",), "Component": ("name",),
                  "Connector": ("name", "kind"), "Connection": ("startConnector", "endConnector"),
                  "ParameterBinding": (), "Annotation": ("type",), "ParameterSet": ("version", "name"),
                  "Parameter": ("name",), "Dimension": (), "Clock": ("name",)}


class Refused(ValueError):
    """A scenario or option an SSP file of the asked version cannot hold (``scfmu export``: one line, exit 2)."""


def check_version(version: str) -> str:
    if version not in VERSIONS:
        raise Refused(f"--ssp-version {version}: not an SSP version this package writes; allowed: "
                         f"{', '.join(VERSIONS)}")
    return version


def fmi3_path(model: str) -> Path:
    """The FMU an SSP 2.0 file carries for a component: a unit given by path as it is, one of ours by name
    its FMI 3.0 build ``<FMU folder>/fmi3/<Model>.fmu``."""
    from ..fmu import UnknownModel, fmu_dir, fmu_path, is_path
    if is_path(model):
        return fmu_path(model)
    p = fmu_dir() / "fmi3" / f"{model}.fmu"
    if not p.is_file():
        fmu_path(model)  # an unknown name: the message with the closest names
        raise UnknownModel(f"{p} not found: the FMI 3.0 build of {model} (SSP 2.0 files carry FMI 3.0 units); "
                           f"build the FMUs (scripts/build_fmus.sh in a checkout) or give the unit by path")
    return p


# the attributes of an FMI 3.0 clock that SSP 2.0's ssc:Clock carries too (same names, same meaning)
CLOCK_ATTRS = ("intervalVariability", "intervalDecimal", "shiftDecimal", "supportsFraction", "resolution",
               "intervalCounter", "shiftCounter", "priority")


def clock_attributes(fmu) -> dict[int, dict[str, str]]:
    """The SSP attributes of each clock of the FMI 3.0 FMU ``fmu`` (an archive or an unpacked folder), by value
    reference, as written in its ``modelDescription.xml``. fmpy (0.3.32) reads of a clock only its
    ``intervalVariability`` (not its priority, interval or shift), so the writer takes them from the file."""
    fmu = Path(fmu)
    if fmu.is_dir():
        text = (fmu / "modelDescription.xml").read_bytes()
    else:
        with zipfile.ZipFile(fmu) as z:
            text = z.read("modelDescription.xml")
    root = ET.fromstring(text)
    variables = root.find("ModelVariables")
    return {int(e.get("valueReference")): {a: e.get(a) for a in CLOCK_ATTRS if e.get(a) is not None}
            for e in ([] if variables is None else variables) if e.tag == "Clock"}


def clock_refs(v) -> list[int]:
    """The value references of the clocks variable ``v`` ticks with: fmpy (0.3.32) keeps the ``clocks``
    attribute as its text (value references separated by blanks), a description built by hand may hold a
    list of value references or of clock variables."""
    clocks = getattr(v, "clocks", None) or []
    if isinstance(clocks, str):
        return [int(x) for x in clocks.split()]
    return [c.valueReference if hasattr(c, "valueReference") else int(c) for c in clocks]


def connector_type(parent, ns: str, v, fmi: int, clocks: dict | None = None):
    """The type child of a 2.0 connector for FMU variable ``v`` (of an FMI ``fmi`` unit): the variable's own
    type; None (type left to the FMU, as the standard allows) for an enumeration. A clock's attributes come
    from ``clocks`` (:func:`clock_attributes`) when given, else from ``v``."""
    vtype = v.type
    if fmi < 3 and vtype == "Enumeration":
        vtype = "Integer"  # as in the 1.0 files
    if vtype == "Enumeration" or vtype not in TYPES:
        return None
    attrs = {}
    if vtype == "Clock":
        if clocks is not None and v.valueReference in clocks:
            attrs = dict(clocks[v.valueReference])
        else:
            for a in CLOCK_ATTRS:
                val = getattr(v, a, None)
                if val is not None and not (a == "supportsFraction" and val is False) and \
                        not (a == "shiftCounter" and val == 0):  # (fmpy's defaults: attributes not written)
                    attrs[a] = str(val).lower() if isinstance(val, bool) else str(val)
    return ET.SubElement(parent, f"{{{ns}}}{vtype}", attrs)


def connector_extras(conn, v, md) -> None:
    """Dimensions and clock associations of a 2.0 connector, in the schema's order."""
    by_vr = {x.valueReference: x for x in md.modelVariables}
    for d in getattr(v, "dimensions", None) or []:
        if d.start is not None:
            ET.SubElement(conn, f"{{{SSC}}}Dimension", {"size": str(int(d.start))})
        elif d.valueReference in by_vr:
            ET.SubElement(conn, f"{{{SSC}}}Dimension", {"sizeConnector": by_vr[d.valueReference].name})
    for vr in clock_refs(v):
        if vr not in by_vr:
            raise Refused(f"{md.modelName}: variable {v.name} names clock value reference {vr}, which the "
                          f"model description does not declare")
        ET.SubElement(conn, f"{{{SSD}}}Clock", {"name": by_vr[vr].name})


def size_variables(md) -> list:
    """The variables holding the size of an input's or output's array dimension (structural parameters):
    a 2.0 connector names them by ``sizeConnector``, so they get connectors of their own."""
    by_vr = {x.valueReference: x for x in md.modelVariables}
    vrs = dict.fromkeys(d.valueReference for v in md.modelVariables if v.causality in ("input", "output")
                        for d in (getattr(v, "dimensions", None) or []) if d.start is None)
    return [by_vr[vr] for vr in vrs if vr in by_vr and by_vr[vr].causality not in ("input", "output")]


def value_tag(vtype: str, fmi: int) -> str:
    """The SSV element of a parameter of type ``vtype``: FMI 1.0/2.0 units keep the 1.0 names (an enumeration is
    an Integer), FMI 3.0 ones their own type."""
    if fmi < 3:
        return {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean", "Enumeration": "Integer"}[vtype]
    if vtype in FLOATS + INTEGERS + ("Boolean",):
        return vtype
    raise Refused(f"FMI 3.0 parameters of type {vtype} cannot be written to an SSV file by this package "
                     f"(allowed: float, integer and Boolean types)")


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _order_problems(elem, where: str) -> list[str]:
    order = ORDER.get(_local(elem.tag))
    if order is None:
        return []
    out, last = [], -1
    for ch in elem:
        name = _local(ch.tag)
        if name == "Clock" and _local(elem.tag) == "Connector" and ch.tag == f"{{{SSD}}}Clock":
            name = "Clock_"  # the clock association, not the Clock type
        if name not in order:
            out.append(f"{where}: {name} is not allowed in {_local(elem.tag)}")
            continue
        i = order.index(name)
        if i < last or (i == last and name not in ("Dimension", "Clock_", "MetaData", "Signature")):
            out.append(f"{where}: {name} out of order in {_local(elem.tag)} (expected order {', '.join(order)})")
        last = i
    return out


def _elem_problems(root, where: str) -> list[str]:
    out = []
    for e in root.iter():
        name = _local(e.tag)
        required = () if name == "Clock" and e.tag != f"{{{SSD}}}Clock" else REQUIRED_ATTRS.get(name, ())
        for a in required:  # (ssc:Clock, the connector type, has no required attribute; ssd:Clock needs a name)
            if e.get(a) is None:
                out.append(f"{where}: {name} {e.get('name', '')!r} lacks the required attribute {a}")
        if name in ("SystemStructureDescription", "ParameterSet") and e.get("version") not in VERSIONS:
            out.append(f"{where}: version {e.get('version')!r} (allowed: 1.0, 2.0)")
        if name == "Connector" and e.get("kind") not in KINDS:
            out.append(f"{where}: connector {e.get('name')!r} kind {e.get('kind')!r} (allowed: {', '.join(KINDS)})")
        if name == "Component" and e.get("implementation", "any") not in IMPLEMENTATIONS:
            out.append(f"{where}: component {e.get('name')!r} implementation {e.get('implementation')!r}")
        if name == "Connector":
            types = [ch for ch in e if ch.tag.startswith(f"{{{SSC}}}") and _local(ch.tag) in TYPES]
            if len(types) > 1:
                out.append(f"{where}: connector {e.get('name')!r} has {len(types)} types (at most one)")
            for t in types:
                iv = t.get("intervalVariability")
                if _local(t.tag) == "Clock" and iv is not None and iv not in INTERVAL_VARIABILITY:
                    out.append(f"{where}: clock {e.get('name')!r} intervalVariability {iv!r}")
        if name == "Dimension" and (e.get("size") is None) == (e.get("sizeConnector") is None):
            out.append(f"{where}: a Dimension takes exactly one of size and sizeConnector")
        if name == "Parameter":
            vals = [ch for ch in e if _local(ch.tag) in TYPES]
            if len(vals) != 1 or vals[0].get("value") is None:
                out.append(f"{where}: parameter {e.get('name')!r} needs exactly one typed value")
        out += _order_problems(e, where)
    return out


def structure_problems(path: str | Path) -> list[str]:
    """What the SSP 2.0 schemas require of the elements this package writes, checked on the archive at
    ``path`` without the schemas: the root elements with version 2.0, required attributes, allowed values
    (connector kinds, implementations, clock interval variabilities), one type per connector and the order
    of the children. Empty when nothing is wrong."""
    out = []
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        if "SystemStructure.ssd" not in names:
            return ["no SystemStructure.ssd at the archive root"]
        for n in names:
            if not n.endswith((".ssd", ".ssv")):
                continue
            root = ET.fromstring(z.read(n))
            want = f"{{{SSD}}}SystemStructureDescription" if n.endswith(".ssd") else f"{{{SSV}}}ParameterSet"
            if root.tag != want:
                out.append(f"{n}: root element {root.tag}, expected {want}")
                continue
            if root.get("version") != "2.0":
                out.append(f"{n}: version {root.get('version')!r}, expected 2.0")
            out += _elem_problems(root, n)
    return out


def schema_dir() -> Path | None:
    """The folder holding the official SSP 2.0 schemas (``SystemStructureDescription.xsd``, …), from
    ``SCFMU_SSP2_SCHEMA``; None when unset or without them."""
    d = os.environ.get("SCFMU_SSP2_SCHEMA")
    if d and (Path(d) / "SystemStructureDescription.xsd").is_file():
        return Path(d)
    return None


def xsd_problems(path: str | Path, folder: str | Path) -> list[str]:
    """Validates the archive's ``.ssd`` and ``.ssv`` files against the SSP 2.0 schemas in ``folder``
    (lxml); empty when valid."""
    from lxml import etree
    folder = Path(folder)
    schemas = {ext: etree.XMLSchema(file=str(folder / f)) for ext, f in
               ((".ssd", "SystemStructureDescription.xsd"), (".ssv", "SystemStructureParameterValues.xsd"))}
    out = []
    with zipfile.ZipFile(path) as z:
        for n in z.namelist():
            ext = Path(n).suffix
            if ext in schemas:
                if not schemas[ext].validate(etree.fromstring(z.read(n))):
                    out += [f"{n}:{e.line}: {e.message}" for e in schemas[ext].error_log]
    return out
