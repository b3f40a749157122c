"""The static checks of ``scfmu check`` (in the parent process) and the plain-data description of each FMU
interface that the child's dynamic checks work from.

- ``schema``: modelDescription.xml against the standard's XML schema (the XSD files fmpy ships);
- ``archive`` (in scfmu.check): the FMU unpacks whole, into a private folder, through the package's extraction
  (scfmu.fmu.safe_extract: the archive limits);
- ``units``, ``start_values``, ``model_structure``, ``value_references``, ``variables``: the standard's
  rules beyond the schema, as fmpy's validation states them (units defined, required start values and
  none where forbidden, ModelStructure complete and consistent, unique value references in FMI 3.0,
  legal causality/variability/initial combinations, variable names), each problem filed under its rule;
- ``binaries``: the binary of every interface the FMU declares exists for this platform."""

from __future__ import annotations

import os
import platform
import zipfile
from pathlib import Path

MD_LIMIT = 64 * 1024 * 1024  # bytes of modelDescription.xml read for the schema check


def _read_md_xml(path: Path) -> bytes:
    if path.is_dir():
        return (path / "modelDescription.xml").read_bytes()
    with zipfile.ZipFile(path) as z:
        info = z.getinfo("modelDescription.xml")
        if info.file_size > MD_LIMIT:
            raise ValueError(f"modelDescription.xml is {info.file_size} bytes (limit {MD_LIMIT})")
        return z.read(info)


def _row(name, problems, ok_detail, na=None):
    if na:
        return {"check": name, "status": "n/a", "detail": na}
    if problems:
        return {"check": name, "status": "fail", "kind": "model_description",
                "detail": f"{len(problems)} problem(s): " + "; ".join(problems[:5]) + (" ..." if len(problems) > 5 else ""),
                "problems": problems}
    return {"check": name, "status": "pass", "detail": ok_detail}


def schema_check(path: Path) -> tuple[dict, str | None]:
    """(result row, fmiVersion or None)."""
    from lxml import etree
    import fmpy
    try:
        xml = _read_md_xml(path)
        root = etree.fromstring(xml, parser=etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False))
    except (KeyError, OSError, ValueError, zipfile.BadZipFile, etree.XMLSyntaxError) as e:
        return {"check": "schema", "status": "fail", "kind": "model_description",
                "detail": f"modelDescription.xml cannot be read: {e}"}, None
    version = root.get("fmiVersion", "")
    schema_dir = Path(fmpy.__file__).parent / "schema"
    if version == "2.0":
        xsd = schema_dir / "fmi2" / "fmi2ModelDescription.xsd"
    elif version.startswith("3."):
        xsd = schema_dir / "fmi3" / "fmi3ModelDescription.xsd"
    else:
        return {"check": "schema", "status": "fail", "kind": "model_description",
                "detail": f"fmiVersion {version!r} is neither 2.0 nor 3.x (scfmu check covers FMI 2.0 and 3.0)"}, None
    schema = etree.XMLSchema(file=str(xsd))
    if schema.validate(root):
        return {"check": "schema", "status": "pass",
                "detail": f"valid against the FMI {version} schema ({xsd.name})"}, version
    problems = [f"line {e.line}: {e.message}" for e in schema.error_log]
    return _row("schema", problems, ""), version


RULES = (("units", ("unit",)), ("start_values", ("start value",)),
         ("model_structure", ("ModelStructure", "model structure", "dependenc", "derivative", "initial unknown",
                              "InitialUnknown", "output", "Output")),
         ("value_references", ("value reference",)))


def rule_checks(md) -> list[dict]:
    from fmpy.validation import validate_model_description
    try:
        problems = validate_model_description(md, validate_variable_names=True, validate_model_structure=True)
    except Exception as e:  # fmpy's validation itself failed on this description
        problems = [f"the rules could not be evaluated: {type(e).__name__}: {e}"]
    buckets = {name: [] for name, _ in RULES}
    other = []
    for p in problems:
        for name, keys in RULES:
            if any(k in p for k in keys):
                buckets[name].append(p)
                break
        else:
            other.append(p)
    vs = md.modelVariables
    n_units = sum(1 for v in vs if getattr(v, "unit", None))
    rows = [
        _row("units", buckets["units"], f"{n_units} variables with a unit; every unit is defined in UnitDefinitions"),
        _row("start_values", buckets["start_values"],
             "every input and exact/approx variable has a start value; none where the standard forbids one"),
        _row("model_structure", buckets["model_structure"],
             f"{len(md.outputs)} outputs, {len(md.derivatives)} derivatives, {len(md.initialUnknowns)} initial "
             "unknowns listed with valid dependencies"),
    ]
    vr_problems = list(buckets["value_references"])
    if md.fmiVersion == "2.0":  # the same value reference for the same type is an alias; aliases must agree
        seen: dict = {}
        for v in vs:
            key = (v.type, v.valueReference)
            if key in seen:
                a = seen[key]
                if v.variability != a.variability:
                    vr_problems.append(f'the aliases "{a.name}" and "{v.name}" (value reference {v.valueReference}) '
                                       f"differ in variability")
                if v.start is not None and a.start is not None and v.causality != "independent":
                    vr_problems.append(f'the aliases "{a.name}" and "{v.name}" (value reference {v.valueReference}) '
                                       f"both have a start value")
            else:
                seen[key] = v
    rows.append(_row("value_references", vr_problems,
                     f"{len({v.valueReference for v in vs})} distinct value references for {len(vs)} variables"
                     + ("" if md.fmiVersion == "2.0" else ", all unique")))
    rows.append(_row("variables", other, "variable names unique and well formed; legal causality/variability/initial"))
    return rows


def platform_folder(version: str) -> str:
    import fmpy
    return fmpy.platform if version == "2.0" else fmpy.platform_tuple


def shared_lib_ext() -> str:
    s = platform.system()
    return ".dll" if s == "Windows" else ".dylib" if s == "Darwin" else ".so"


def binaries_check(md, unzipdir: Path) -> tuple[dict, dict]:
    """(row, {interface: library path}) for the interfaces the FMU declares."""
    folder = platform_folder(md.fmiVersion)
    libs, missing = {}, []
    for itf, elem in (("cs", md.coSimulation), ("me", md.modelExchange)):
        if elem is None:
            continue
        lib = Path(unzipdir) / "binaries" / folder / (elem.modelIdentifier + shared_lib_ext())
        if lib.is_file():
            libs[itf] = lib
        else:
            missing.append(f"{itf.upper()}: binaries/{folder}/{lib.name}")
    if md.coSimulation is None and md.modelExchange is None:
        if getattr(md, "scheduledExecution", None) is not None:  # FMI 3.0: a legal kind this checker does not drive
            return {"check": "binaries", "status": "n/a",
                    "detail": "the FMU offers only Scheduled Execution, which scfmu check does not drive"}, libs
        return {"check": "binaries", "status": "fail", "kind": "model_description",
                "detail": "the FMU declares neither Co-Simulation nor Model Exchange"}, libs
    if missing:
        present = sorted(p.name for p in (Path(unzipdir) / "binaries").iterdir()) if (Path(unzipdir) / "binaries").is_dir() else []
        return {"check": "binaries", "status": "fail", "kind": "no_binary",
                "detail": f"no binary for this platform ({folder}): {', '.join(missing)}; platforms present: "
                          f"{', '.join(present) or 'none'}"}, libs
    return {"check": "binaries", "status": "pass",
            "detail": "binary present for this platform: " + ", ".join(f"binaries/{folder}/{p.name}" for p in
                                                                       sorted(set(libs.values())))}, libs


DEFAULT_STEP = 0.01  # s: the checker's step when the default experiment gives no stepSize


def _num(x):
    try:
        return float(x) if x is not None else None
    except (TypeError, ValueError):
        return None


def _size(v) -> int:
    """The number of scalars of variable v: the product of its dimensions (FMI 3.0 arrays; a dimension given
    by a structural parameter takes that parameter's start value), 1 for a scalar."""
    n = 1
    for d in getattr(v, "dimensions", None) or []:
        if d.start is not None and str(d.start).strip():
            n *= int(d.start)
        else:
            ref = d.variable
            n *= int(float(ref.start)) if ref is not None and ref.start is not None else 1
    return n


def n_states(md) -> int:
    """The number of continuous states: one per scalar of every derivative (an array state counts its
    elements)."""
    return sum(_size(d.variable) for d in md.derivatives)


def unit_spec(md, unzipdir: Path, interface: str, library: Path) -> dict:
    """The plain-data description of one interface for the child process."""
    v2 = md.fmiVersion == "2.0"
    elem = md.coSimulation if interface == "cs" else md.modelExchange
    numeric = ("Real", "Integer", "Boolean") if v2 else ("Float64", "Float32", "Int32", "Int64", "Boolean")

    def var(v):
        start = v.start
        if start is not None:
            if v.type == "Boolean":
                start = 1 if str(start).lower() in ("true", "1") else 0
            elif v.type in ("Integer", "Int32", "Int64"):
                start = int(float(start))
            else:
                start = _num(start)
        return {"name": v.name, "vr": int(v.valueReference), "type": v.type, "start": start,
                "variability": v.variability or "continuous",
                "min": _num(getattr(v, "min", None)), "max": _num(getattr(v, "max", None))}

    scalar = [v for v in md.modelVariables if v.type in numeric and not getattr(v, "dimensions", None)]
    de = md.defaultExperiment
    t0 = _num(de.startTime) if de and de.startTime is not None else 0.0
    t1 = _num(de.stopTime) if de and de.stopTime is not None else t0 + 1.0
    step = _num(de.stepSize) if de and de.stepSize is not None else None
    if not step or step <= 0:  # no stepSize: a hundredth of the experiment, at most DEFAULT_STEP (a unit with
        # its own fixed internal step, e.g. 1e-6 s, is not asked for 1e6 s in one call)
        step = min((t1 - t0) / 100.0, DEFAULT_STEP) if t1 > t0 else DEFAULT_STEP
    res = Path(unzipdir) / "resources"
    resources = res.as_uri() if v2 else str(res) + os.sep
    if v2:
        can_state, can_ser = elem.canGetAndSetFMUstate, elem.canSerializeFMUstate
    else:
        can_state = getattr(elem, "canGetAndSetFMUstate", False) or getattr(elem, "canGetAndSetFMUState", False)
        can_ser = getattr(elem, "canSerializeFMUstate", False) or getattr(elem, "canSerializeFMUState", False)
    return {
        "version": 2 if v2 else 3, "interface": interface, "library": str(library),
        "token": md.guid if v2 else (getattr(md, "instantiationToken", None) or md.guid),
        "resources": resources, "model": md.modelName, "identifier": elem.modelIdentifier,
        "nx": n_states(md) if interface == "me" else 0,
        "start_time": t0, "stop_time": t1, "step": step,
        "can_get_set_state": bool(can_state), "can_serialize_state": bool(can_ser and can_state),
        "only_once": bool(getattr(elem, "canBeInstantiatedOnlyOncePerProcess", False)),
        "inputs": [var(v) for v in scalar if v.causality == "input"],
        "outputs": [var(v) for v in scalar if v.causality == "output"],
        "parameters": [var(v) for v in scalar if v.causality == "parameter" and v.variability in ("fixed", "tunable")],
        "all_vrs": sorted({int(v.valueReference) for v in md.modelVariables}),
    }
