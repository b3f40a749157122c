"""Scenarios as files: TOML (``.toml``) or JSON (``.json``) with the same fields as the Python declaration,
validated with messages that name the field. Relative FMU paths in ``model`` are taken relative to the
file's folder. ``scfmu scenarios --show NAME`` prints any registered scenario in this format.

    name = "my_loop"
    stop_time = 30.0
    step = 0.01
    metrics = "attitude"              # a registered metric set (optional)
    [[components]]                    # in Gauss–Seidel order
    name = "controller"
    model = "fmus/MyController.fmu"   # a model name or a path to an FMI 2.0 or 3.0 FMU
    interface = "me"                  # optional: "cs" or "me" (default: Co-Simulation when offered)
    [components.solver]               # optional, Model Exchange: method, rtol, atol
    rtol = 1e-8
    [components.params]               # parameters of this model
    k = 2.0
    [components.slot]                 # given to any unit in this place that declares them
    inertia_xx = 1000.0
    [components.ports]                # the unit's port name = the scenario's port name
    tau_x = "torque_cmd_x"
    [log]                             # key = "instance.variable"
    alpha_deg = "metrics.alpha_deg"
"""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import fields
from pathlib import Path

from .model import Component, Scenario
from .values import timing_problems

_FIELDS = {f.name for f in fields(Scenario)}
_COMPONENT = {"name", "model", "params", "slot", "ports", "bind", "unused", "interface", "solver"}
_TYPES = {"name": str, "stop_time": (int, float), "step": (int, float), "start_time": (int, float), "log": dict,
          "connections": dict, "terminals": dict, "unconnected": list, "inputs": dict, "auto_connect": bool, "seed_params": list,
          "metrics": str, "description": str, "components": list}


class ScenarioFileError(ValueError):
    pass


def from_data(data: dict, where: str = "scenario", base: Path | None = None) -> Scenario:
    """A Scenario from plain data (as read from TOML or JSON), validated."""
    if not isinstance(data, dict):
        raise ScenarioFileError(f"{where}: expected a table of fields")
    unknown = sorted(set(data) - _FIELDS)
    if unknown:
        raise ScenarioFileError(f"{where}: unknown field(s) {unknown}; known: {sorted(_FIELDS)}")
    for req in ("components", "stop_time", "step"):
        if req not in data:
            raise ScenarioFileError(f"{where}: missing field {req!r}")
    for k, t in _TYPES.items():
        if k in data and not (isinstance(data[k], t) and not (t is not bool and isinstance(data[k], bool))):
            raise ScenarioFileError(f"{where}: field {k!r} must be {t.__name__ if isinstance(t, type) else 'a number'}, "
                                    f"not {type(data[k]).__name__}")
    comps = []
    for i, c in enumerate(data["components"]):
        w = f"{where}: components[{i}]"
        if not isinstance(c, dict):
            raise ScenarioFileError(f"{w}: expected a table with name and model")
        bad = sorted(set(c) - _COMPONENT)
        if bad:
            raise ScenarioFileError(f"{w}: unknown field(s) {bad}; known: {sorted(_COMPONENT)}")
        for req in ("name", "model"):
            if not isinstance(c.get(req), str) or not c[req]:
                raise ScenarioFileError(f"{w}: {req!r} must be a non-empty string")
        for k in ("params", "slot", "ports", "bind", "solver"):
            if k in c and not isinstance(c[k], dict):
                raise ScenarioFileError(f"{w} ({c['name']}): {k!r} must be a table")
        if not isinstance(c.get("unused", []), list):
            raise ScenarioFileError(f"{w} ({c['name']}): 'unused' must be a list of slot names")
        if c.get("interface", "") not in ("", "cs", "me"):
            raise ScenarioFileError(f"{w} ({c['name']}): interface = {c['interface']!r}; allowed: \"cs\" "
                                    f"(Co-Simulation), \"me\" (Model Exchange)")
        model = _model(c["model"], f"{w} ({c['name']})", base)
        for k in ("params", "slot"):
            for name, v in c.get(k, {}).items():
                if isinstance(v, bool) or isinstance(v, (int, str)):
                    continue
                if isinstance(v, float):
                    if not math.isfinite(v):
                        raise ScenarioFileError(f"{w} ({c['name']}): {k}.{name} = {v}: not finite; allowed: a "
                                                f"finite number")
                    continue
                raise ScenarioFileError(f"{w} ({c['name']}): {k}.{name} = {v!r}: a {type(v).__name__}; allowed: "
                                        f"a number, true/false or a text")
        for theirs, ours in c.get("ports", {}).items():
            if not isinstance(ours, str) or not ours:
                raise ScenarioFileError(f"{w} ({c['name']}): ports.{theirs} = {ours!r}: allowed: a port name (text)")
        comps.append(Component(c["name"], model, dict(c.get("params", {})), dict(c.get("slot", {})),
                               dict(c.get("ports", {})), dict(c.get("bind", {})), list(c.get("unused", [])),
                               c.get("interface", ""), dict(c.get("solver", {}))))
    d = {k: v for k, v in data.items() if k != "components"}
    d.setdefault("name", where)
    for k, v in d.get("inputs", {}).items():
        if isinstance(v, float) and not math.isfinite(v) or not isinstance(v, (bool, int, float, str)):
            raise ScenarioFileError(f"{where}: inputs.{k} = {v!r}: allowed: a finite number, true/false or a text")
    sc = Scenario(components=comps, **d)
    problems = timing_problems(sc.start_time, sc.stop_time, sc.step, log_every=None)
    if problems:
        raise ScenarioFileError(f"{where}: {problems[0]}")
    try:
        sc.n_steps
    except ValueError as e:
        raise ScenarioFileError(f"{where}: {e}") from None
    for key, q in sc.log.items():
        if not isinstance(q, str) or "." not in q:
            raise ScenarioFileError(f"{where}: log entry {key!r} must be 'instance.variable'")
    names = [c.name for c in comps]
    if len(set(names)) != len(names):
        raise ScenarioFileError(f"{where}: duplicate instance names in {names}")
    return sc


def _model(model: str, where: str, base: Path | None) -> str:
    """A component's model: a model name (letters, digits, '_', '-', '.'), or a path to an ``.fmu`` file,
    taken relative to the scenario file's folder, that must exist as a file."""
    if not (model.endswith(".fmu") or "/" in model or "\\" in model):
        if not all(ch.isalnum() or ch in "_-." for ch in model) or model.startswith("."):
            raise ScenarioFileError(f"{where}: model = {model!r}: allowed: a model name (letters, digits, '_') "
                                    f"or a path to an .fmu file")
        return model
    p = Path(model).expanduser()
    if base is not None and not p.is_absolute():
        p = base / p
    p = p.resolve()
    if p.suffix.lower() != ".fmu":
        raise ScenarioFileError(f"{where}: model = {model!r} (resolved to {p}): allowed: a path to an .fmu file")
    if p.is_dir():
        raise ScenarioFileError(f"{where}: model = {model!r} (resolved to {p}): a directory, not an FMU file")
    if not p.is_file():
        raise ScenarioFileError(f"{where}: model = {model!r}: no such file {p} (paths are taken relative to the "
                                f"scenario file's folder)")
    return str(p)


def load_ssp(path: str | Path) -> Scenario:
    """Reads an SSP 1.0 or 2.0 file (:func:`scfmu.scenario.ssp.read_ssp`) into a scenario whose units are the
    FMUs unpacked from it (a temporary folder removed when the program ends), so any engine runs it."""
    import atexit
    import shutil
    import tempfile
    import zipfile
    from xml.etree.ElementTree import ParseError
    from .ssp import read_ssp
    work = tempfile.mkdtemp(prefix="scfmu-ssp-")
    atexit.register(shutil.rmtree, work, True)
    try:
        sc, fmus = read_ssp(path, work)
    except (ValueError, KeyError, AttributeError, TypeError, OSError, ParseError, zipfile.BadZipFile) as e:
        raise ScenarioFileError(f"{path}: not an SSP file this package reads ({type(e).__name__}: {e})") from None
    for c in sc.components:
        c.model = str(fmus[c.model])
    return sc


def load(path: str | Path) -> Scenario:
    """Reads a scenario file (``.toml`` or ``.json``; an ``.ssp`` file: :func:`load_ssp`)."""
    path = Path(path)
    if path.suffix.lower() == ".ssp":
        return load_ssp(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise ScenarioFileError(f"{path}: {e.strerror}") from None
    except UnicodeDecodeError:
        raise ScenarioFileError(f"{path}: not a text file (expected TOML or JSON in UTF-8)") from None
    try:
        data = tomllib.loads(text) if path.suffix.lower() == ".toml" else json.loads(text)
    except (tomllib.TOMLDecodeError, json.JSONDecodeError) as e:
        raise ScenarioFileError(f"{path}: not valid {path.suffix.lstrip('.').upper() or 'JSON'}: {e}") from None
    if not isinstance(data, dict):
        raise ScenarioFileError(f"{path}: expected a table of fields, not a {type(data).__name__}")
    data.setdefault("name", path.stem)
    return from_data(data, str(path), path.parent)


def to_data(sc: Scenario) -> dict:
    """Plain data of a scenario, empty optional tables left out (the form the files use)."""
    d = sc.to_dict()
    for c in d["components"]:
        for k in ("params", "slot", "ports", "interface", "solver"):
            if not c[k]:
                del c[k]
    for k in ("connections", "inputs", "log", "seed_params", "swapped"):
        if not d[k]:
            del d[k]
    comps = d.pop("components")
    d["components"] = comps  # tables after scalars (TOML)
    return d


def dumps_toml(sc: Scenario) -> str:
    import tomli_w
    return tomli_w.dumps(to_data(sc))


def dumps_json(sc: Scenario) -> str:
    return json.dumps(to_data(sc), indent=1)


def is_scenario_file(text: str) -> bool:
    return text.lower().endswith((".toml", ".json", ".ssp")) and Path(text).is_file()
