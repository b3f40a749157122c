"""Native fast path: the whole closed loop runs inside fmpy's container FMU (a compiled co-simulation
loop shipped with fmpy), so a run needs no Python call per communication step.

How. ``build_container(scenario)`` packs the scenario's FMUs into one FMI 2.0 co-simulation FMU
(``fmpy.container_fmu``): its configuration lists the instances, the scenario's connections (value
references resolved by port name), and one container variable ``"<instance>.<variable>"`` for every
parameter, calculated parameter, input and output of every instance. The container's ``fmi2DoStep(t, h)`` runs h/Δ fixed
steps of Δ = scenario.step in compiled code; each fixed step is: ``doStep`` of every instance from
t_k to t_k + Δ, then, connection by connection in the listed order, ``fmi2GetReal`` of the source
outputs and ``fmi2SetReal`` of the destination inputs.

Coupling. The connections are listed in the scenario's Gauss–Seidel order (grouped by destination in
component order, exactly as ``master.CoSimulation.propagate``). Because an FMU's outputs are read only
after its own inputs have been written at the same communication point, a controller's torque
computed from the plant state at t_k reaches the plant at t_k, the same step: this is the reference
master's Gauss–Seidel scheme (not the Jacobi scheme of a parallel master), and the FMUs see the same
values at the same communication points t0 + kΔ. The container's own propagation at the end of
``fmi2ExitInitializationMode`` happens before its instances leave initialization mode, so
``NativeLoop`` repeats the propagation once through container variables after initialization; from
then on, results are bit-identical to the reference master (tests/test_campaign.py).

Logging. ``log_every = m`` (default 1) reads the logged variables with one container ``fmi2GetReal``
every m communication steps (one ``fmi2DoStep(t, mΔ)`` in between); ``log_every = 0`` runs the whole
interval in one ``fmi2DoStep`` call and returns only the initial and final samples.

Model Exchange units. fmpy's container nests Co-Simulation units only: a Model Exchange instance is
nested as its Co-Simulation face (:mod:`scfmu.engines.cs_face`: the unit's FMU with scfmu's wrapper library,
which integrates it over each fixed step with the instance's solver, events included).

Containers are cached on disk by a hash of their configuration (FMU GUIDs and file SHA-256, wiring,
step), in ``$SCFMU_CONTAINER_DIR`` or ``~/.cache/scfmu/containers``, a cache bounded in size
(:mod:`scfmu.engines.cache`).
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import shutil
import zipfile
from ctypes import c_int32, c_uint
from dataclasses import replace
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from ..fmu import Fmu, fmu_digest, safe_extract, scalar_type, scratch, unpacked
from ..scenario.model import Scenario
from ..scenario.plan import Plan
from . import cache
from .cache import CACHE
from .calls import SimulationError, raw_calls
from .cs_face import cs_face, wrapper_identity
from .instances import apply_params, as_plan, fmu_setter

_KINDS = ("parameter", "calculatedParameter", "input", "output")
LAYOUT = 5  # version of the container layout below (part of the cache key)
_KEYS: dict = {}  # structure of a plan (+ FMU file identities) -> hash, per process


def _structure(plan: Plan, starts: dict | None) -> tuple:
    """What the container of a plan depends on, cheaply: instances and models with their FMU files'
    identity (path, modification time, size), the wiring, the step and the start values."""
    files = []
    for u in plan.units:
        st = u.path.stat()
        files.append((u.name, u.model, str(u.path), st.st_mtime_ns, st.st_size, u.interface,
                      tuple(sorted((k, repr(v)) for k, v in u.solver.items())) if u.interface == "me" else ()))
    return (tuple(files), repr(plan.scenario.step), tuple(plan.links),
            tuple(sorted((k, repr(v)) for k, v in starts.items())) if starts else ())


def container_key(plan: Plan, starts: dict | None = None) -> str:
    sig = _structure(plan, starts)
    hit = _KEYS.get(sig)
    if hit is not None:
        return hit
    key = {"components": [(u.name, u.model, u.md.guid, fmu_digest(u.path)) for u in plan.units],
           "links": plan.links, "step": repr(plan.scenario.step), "layout": LAYOUT}
    if starts:
        key["starts"] = sorted((k, repr(v)) for k, v in starts.items())
    me = [(u.name, sorted((k, repr(v)) for k, v in u.solver.items())) for u in plan.units if u.interface == "me"]
    if me:  # Model Exchange units run through their Co-Simulation face (scfmu.engines.cs_face)
        key["me"] = [me, wrapper_identity()]  # every platform's wrapper library the faces may carry
    h = hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:20]
    _KEYS[sig] = h
    return h


def scenario_starts(scenario: Scenario) -> dict:
    """``{"instance.variable": value}`` of the scenario's parameters and fixed inputs: the start values a
    stand-alone closed-loop FMU carries, so that it reproduces the scenario with no value set."""
    out = {f"{c.name}.{k}": v for c in scenario.components for k, v in c.params.items()}
    out.update(scenario.inputs)
    return out


def _start_text(vtype: str, value) -> str:
    if vtype == "Real":
        return repr(float(value))
    if vtype == "Integer":
        return str(int(value))
    return "true" if value in (True, 1, "true") else "false"


def build_container(scenario, starts: dict | None = None) -> Path:
    """Path of the container FMU for a plan's (or a scenario's) structure (built once, then cached): the
    one container builder, used by the native engine and the loop-FMU export. Nested units may be
    FMI 2.0 or FMI 3.0 Co-Simulation FMUs (fmpy's container runtime loads both), or Model Exchange units,
    nested as their Co-Simulation face (:mod:`scfmu.engines.cs_face`); ``starts``
    (``"instance.variable" -> value``, e.g. :func:`scenario_starts`) replaces the nested FMUs' start
    values of those container variables (the container applies them at instantiation)."""
    from fmpy.container_fmu.config import Configuration, Connection

    plan = as_plan(scenario)
    starts = dict(starts or {})
    h = container_key(plan, starts)
    path = CACHE / f"loop_{h}.fmu"
    if path.exists():
        return cache.used(path)
    units = _nested_units(plan)
    comps, cvars, container_vars, mappings, cv_of = _container_variables(units, starts)
    # one connection per link group of the plan (destination, source, type), in Gauss–Seidel order
    connections = [Connection(comps[g.src], [cvars[g.src][so] for so in g.src_names],
                              comps[g.dst], [cvars[g.dst][di] for di in g.dst_names]) for g in plan.groups]
    md = _container_description(plan.scenario, units, h, container_vars, cv_of)
    config = Configuration(parallelDoStep=False, modelDescription=md, components=list(comps.values()),
                           connections=connections, variableMappings=mappings)
    _write_container(config, h, path)
    cache.prune()
    return path


def _nested_units(plan: Plan) -> list:
    """The plan's units as the container nests them: a Model Exchange unit as its Co-Simulation face (the
    unit's FMU with scfmu's wrapper library added, :mod:`scfmu.engines.cs_face`)."""
    out = []
    for u in plan.units:
        if u.interface == "me":
            face = cs_face(u, CACHE / "faces")
            u = replace(u, path=face, md=read_model_description(str(face)))
        out.append(u)
    return out


def _container_variables(units: list, starts: dict):
    """The container's components and variables: one container variable ``"<instance>.<variable>"`` per
    parameter, calculated parameter, input and output of every instance (``starts`` consumed: an unknown
    name or a start value of another kind of variable is a KeyError). Returns ``(components, nested
    variables by instance and name, container variables, mappings, container variable by (instance, name))``."""
    from fmpy.container_fmu.config import Component as CComponent
    from fmpy.model_description import ModelVariable

    comps, cvars = {}, {}
    container_vars = [ModelVariable(type="Real", variability="continuous", causality="independent", name="time")]
    mappings = {}
    cv_of = {}  # (instance, nested variable name) -> container variable
    for u in units:
        comp = CComponent(name=u.name, filename=u.path, modelDescription=u.md)
        comps[u.name] = comp
        cvars[u.name] = {v.name: v for v in u.md.modelVariables}
        for v in u.md.modelVariables:
            vt = scalar_type(v)  # FMI 3.0 Float64/Int32/Boolean are the container's Real/Integer/Boolean
            if v.causality not in _KINDS or vt is None:
                continue
            q = f"{u.name}.{v.name}"
            cv = _container_variable(v, vt, q)
            if q in starts:
                if v.causality not in ("parameter", "input"):
                    raise KeyError(f"start value for {q}: not a parameter or input")
                cv.start = _start_text(vt, starts.pop(q))
            container_vars.append(cv)
            mappings[cv] = [(comp, v)]
            cv_of[(u.name, v.name)] = cv
    if starts:
        raise KeyError(f"start values for unknown variables {sorted(starts)}")
    return comps, cvars, container_vars, mappings, cv_of


def _container_variable(v, vt: str, q: str):
    """The container variable ``q`` of nested variable ``v`` (scalar type ``vt``), same causality."""
    from fmpy.model_description import ModelVariable

    if v.causality == "parameter":
        cv = ModelVariable(type=vt, variability="tunable" if v.variability == "tunable" else "fixed",
                           causality="parameter", name=q, start=v.start)
        cv.initial = "exact"
    elif v.causality == "calculatedParameter":
        cv = ModelVariable(type=vt, variability=v.variability, causality="calculatedParameter", name=q)
    elif v.causality == "input":
        cv = ModelVariable(type=vt, variability=v.variability, causality="input", name=q, start=v.start)
    else:
        cv = ModelVariable(type=vt, variability=v.variability, causality="output", name=q)
    cv.description = v.description
    return cv


def _container_description(scenario: Scenario, units: list, h: str, container_vars: list, cv_of: dict):
    """The container's FMI 2.0 Co-Simulation model description, with its ModelStructure."""
    from fmpy.model_description import CoSimulation, DefaultExperiment, ModelDescription, Unknown

    mds = {u.name: u.md for u in units}
    md = ModelDescription(fmiVersion="2.0", modelName=f"scfmu_loop_{h}", instantiationToken="{scfmu-" + h + "}",
                          description=f"closed loop of {[Path(c.model).stem for c in scenario.components]} "
                                      f"(scfmu native path)",
                          generationTool="scfmu.native",
                          defaultExperiment=DefaultExperiment(startTime=str(scenario.start_time),
                                                              stopTime=str(scenario.stop_time),
                                                              stepSize=str(scenario.step)),
                          coSimulation=CoSimulation(modelIdentifier="container_fmu",
                                                    fixedInternalStepSize=scenario.step,
                                                    # fmpy's container steps in multiples of its fixed
                                                    # internal step only: a constant step (issue 22)
                                                    canHandleVariableCommunicationStepSize=False),
                          modelVariables=container_vars)
    # ModelStructure: a container variable reads or writes its nested variable directly (connections are
    # propagated only inside doStep), so each container output depends on exactly the container variables
    # its nested output depends on, at communication points and at initialization.
    order = {id(v): i for i, v in enumerate(container_vars)}
    for attr in ("outputs", "initialUnknowns"):
        unknowns = []
        for c in scenario.components:
            for u in getattr(mds[c.name], attr):
                cv = cv_of.get((c.name, u.variable.name))
                if cv is None:
                    continue
                # a dependency on a nested continuous state (a local of a Model Exchange capable FMU) is
                # internal to the container: only container variables are listed
                deps = None if u.dependencies is None else sorted(
                    (cv_of[(c.name, d.name)] for d in u.dependencies if (c.name, d.name) in cv_of),
                    key=lambda x: order[id(x)])
                unknowns.append(Unknown(variable=cv, dependencies=deps))
        unknowns.sort(key=lambda u: order[id(u.variable)])
        setattr(md, attr, unknowns)
    for i, v in enumerate(md.modelVariables):
        v.valueReference = i  # "time" is 0; container variable i maps to mappings[i - 1]
    return md


def _write_container(config, h: str, path: Path) -> None:
    """Writes the container FMU ``path`` (atomically): model description, ``resources/container.json``,
    the nested FMUs unpacked under ``resources/<file stem>`` and fmpy's container binaries."""
    from fmpy.container_fmu import write_configuration
    from fmpy.model_description import write_model_description

    CACHE.mkdir(parents=True, exist_ok=True)
    work = Path(scratch.mkdtemp(prefix="scfmu_container_"))
    try:
        for c in config.components:  # nested FMUs unpacked under resources/<file stem>
            safe_extract(c.filename, work / "resources" / Path(c.filename).stem)  # archive limits (scfmu.fmu)
        write_model_description(config.modelDescription, work / "modelDescription.xml")
        cfg = work / "resources" / "container.json"
        write_configuration(config, cfg)
        data = json.loads(cfg.read_text())
        for conn in data["connections"]:  # fmpy writes FMI 2 type names here; the container wants FMI 3 ones
            conn["variableType"] = {"Real": "Float64", "Integer": "Int32"}.get(conn["variableType"], conn["variableType"])
        for comp in data["components"]:  # an FMI 3.0 unit without a Co-Simulation element cannot be nested
            comp["fmiMajorVersion"] = str(comp["fmiMajorVersion"])
        cfg.write_text(json.dumps(data, indent=1))
        import fmpy.container_fmu as cf
        for tuple_, fmi2_platform, lib in (("x86_64-linux", "linux64", "container_fmu.so"),
                                           ("x86_64-windows", "win64", "container_fmu.dll"),
                                           ("x86_64-darwin", "darwin64", "container_fmu.dylib")):
            src = Path(cf.__file__).parent / "binaries" / tuple_ / lib
            if src.exists():
                (work / "binaries" / fmi2_platform).mkdir(parents=True, exist_ok=True)
                shutil.copyfile(src, work / "binaries" / fmi2_platform / lib)
        tmp = CACHE / f".loop_{h}.{os.getpid()}.fmu"
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(work.rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(work).as_posix())
        os.replace(tmp, path)  # atomic: concurrent workers may build the same container
    finally:
        shutil.rmtree(work, ignore_errors=True)


_POOL: dict[str, list[Fmu]] = {}  # reset container instances ready for the next run, per container file
_PLANS: dict[str, dict] = {}  # per container file: value references and the propagation's link list


class NativeLoop:
    """Runs a Scenario (or a plan) inside its container FMU. ``log_every``: see module docstring.

    With ``reuse`` (default) the container is unpacked once per process and, after a run, its instance
    is reset (``fmi2Terminate`` + ``fmi2Reset``: every nested FMU back to its start values) and kept for
    the next run of a scenario with the same structure, which saves the instantiation of every nested
    FMU; an instance whose reset fails is freed. Results do not depend on reuse (tested)."""

    def __init__(self, scenario, log_every: int = 1, reuse: bool = True):
        self.plan = as_plan(scenario)
        self.scenario = scenario = self.plan.scenario
        self.log_every = int(log_every)
        self.reuse = reuse
        path = build_container(self.plan)
        self._path = str(path)
        pool = _POOL.get(self._path) if reuse else None
        if pool:
            self.fmu = pool.pop()
            self.fmu.messages.clear()
        else:
            self.fmu = Fmu("loop", path=path, name="loop", start_time=scenario.start_time,
                           initialize=False, unpacked=unpacked(path) if reuse else None)
        try:
            self._init()
        except Exception:
            self.close()
            raise

    def _fail(self, where: str, t: float | None = None):
        msgs = [m[2] for m in self.fmu.messages if m[0] >= 2]
        raise SimulationError("fmu_error", f"{where}: " + ("; ".join(msgs) or "error status"), t)

    def _init(self):
        sc, f = self.scenario, self.fmu
        sl = f.slave
        f.enter_initialization_mode(sc.start_time)
        # the container knows each unit's variable as "instance.name", under a value reference of its own
        def ref(inst):
            return lambda s: f.var(f"{inst}.{s.name}").valueReference
        for c in sc.components:
            apply_params(self.plan.params[c.name], fmu_setter(f), ref(c.name))
        try:
            sl.exitInitializationMode()
        except Exception:
            self._fail("exitInitializationMode")
        for c in sc.components:
            apply_params(self.plan.inputs[c.name], fmu_setter(f), ref(c.name))
        # repeat the Gauss–Seidel propagation now that every instance has left initialization mode
        plan = _PLANS.get(self._path)
        if plan is None:  # the same for every run of this container (its key includes the wiring)
            vr = {n: v.valueReference for n, v in f.vars.items()}
            pairs = [(g.type, vr[f"{g.src}.{so}"], vr[f"{g.dst}.{di}"])
                     for g in self.plan.groups for so, di in zip(g.src_names, g.dst_names)]
            vrs = (c_uint * (2 * len(pairs)))(*[x for p in pairs for x in p[1:]])
            plan = _PLANS[self._path] = {"vr": vr, "pairs": vrs, "types": [p[0] for p in pairs]}
        vr = plan["vr"]
        raw = getattr(f, "_scfmu_raw", None)
        if raw is None:  # the container's raw calls, kept with the instance
            raw = f._scfmu_raw = raw_calls(f)
        # one link at a time, in order: get the source output, set the destination input
        one = (c_int32 * 2)()  # room for a double or an int32
        pv, addr = ctypes.addressof(plan["pairs"]), ctypes.addressof(one)
        for i, t in enumerate(plan["types"]):
            if raw.get[t](pv + 8 * i, 1, addr) > 1 or raw.set[t](pv + 8 * i + 4, 1, addr) > 1:
                self._fail("propagation after initialization")
        self._raw = raw
        self._get, self._step = raw.get["Real"], raw.step
        items = [(g.type, key, g.inst, var) for g in self.plan.log for key, var in zip(g.keys, g.names)]
        for _t, key, inst, var in items:
            if f"{inst}.{var}" not in vr:
                raise KeyError(f"log {key!r}: no variable {inst}.{var}")
        real = [x for x in items if x[0] == "Real"]
        other = [x for x in items if x[0] != "Real"]
        self._log_vrs = (c_uint * max(1, len(real)))(*[vr[f"{i}.{v}"] for _, _, i, v in real])
        self._log_keys = [k for _, k, _, _ in real]
        # Integer and Boolean signals: one read per type after each logged Real row
        self._log_other = [(t, [k for tt, k, _, _ in other if tt == t],
                            (c_uint * sum(1 for x in other if x[0] == t))(*[vr[f"{i}.{v}"] for tt, _, i, v in other if tt == t]))
                           for t in dict.fromkeys(x[0] for x in other)]

    def get(self, name: str):
        """Current value of ``"instance.variable"`` (a parameter, calculated parameter, input or output)."""
        return self.fmu.get(name)

    def run(self) -> dict[str, np.ndarray]:
        sc = self.scenario
        n, dt, t0 = self.plan.n_steps, sc.step, sc.start_time
        m = self.log_every
        if m <= 0:
            ks = [0, n]
        else:
            ks = list(range(0, n + 1, m))
            if ks[-1] != n:
                ks.append(n)
        nl = len(self._log_keys)
        arr = np.empty((len(ks), nl))
        base, stride = arr.ctypes.data, arr.strides[0]
        vrs = ctypes.addressof(self._log_vrs)
        get, step = self._get, self._step
        times = t0 + np.asarray(ks, dtype=float) * dt
        other = [(self._raw.get[t], keys, ctypes.addressof(v), len(keys), np.empty((len(ks), len(keys)), np.int32))
                 for t, keys, v in self._log_other]
        if m == 1 and nl and not other:  # the same calls as the general loop below, with less Python per step
            for k in range(n):
                if get(vrs, nl, base + k * stride) > 1:
                    self._fail(f"getReal at t = {t0 + k * dt}", t0 + k * dt)
                if step(t0 + k * dt, dt) > 1:
                    self._fail(f"doStep at t = {t0 + k * dt}", t0 + k * dt)
            ks = [n]
        prev = ks[0]
        for j, k in enumerate(ks, len(arr) - len(ks)):
            if k > prev:
                t = t0 + prev * dt
                if step(t, (k - prev) * dt) > 1:
                    self._fail(f"doStep at t = {t}", t)
                prev = k
            if nl and get(vrs, nl, base + j * stride) > 1:
                self._fail(f"getReal at t = {t0 + k * dt}", t0 + k * dt)
            for fn, _keys, v, cnt, a in other:
                if fn(v, cnt, a.ctypes.data + j * a.strides[0]) > 1:
                    self._fail(f"get at t = {t0 + k * dt}", t0 + k * dt)
        out = {"time": times}
        for i, key in enumerate(self._log_keys):
            out[key] = arr[:, i].copy()
        for _fn, keys, _v, _c, a in other:
            for i, key in enumerate(keys):
                out[key] = a[:, i].astype(np.float64)
        return {k: out[k] for k in ["time"] + list(self.scenario.log)}

    def close(self):
        f = getattr(self, "fmu", None)
        if f is None:
            return
        self.fmu = None
        if self.reuse:
            try:
                f.slave.terminate()
            except Exception:
                pass
            try:
                f.slave.reset()
                pool = _POOL.setdefault(self._path, [])
                if len(pool) < 2:
                    pool.append(f)
                    return
            except Exception:
                pass
        f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
