"""Fixed-step Gauss-Seidel co-simulation master on fmpy's FMU2Slave.

Connections are made by port name: every input of an FMU is fed from the output of the same name of
another FMU in the loop (exactly one must have it, unless the input is listed in ``unconnected``).
At each communication point t_k the master walks the FMUs in the given order, sets each one's inputs
from the current outputs of its sources, logs the requested variables, then calls doStep on every
FMU from t_k to t_k + dt. Give the order so that an FMU whose outputs depend directly on its inputs
comes after its sources (e.g. command, controller, plant, metrics): plant state outputs have no
direct feed-through, so reading them first is exact (spec README, master section).
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

ROOT = Path(__file__).resolve().parents[2]
FMU_DIR = Path(os.environ.get("SCFMU_FMU_DIR", ROOT / "fmus"))


def fmu_path(model: str) -> Path:
    p = FMU_DIR / f"{model}.fmu"
    if not p.exists():
        raise FileNotFoundError(f"{p} not found: run scripts/build_fmus.sh first")
    return p


_UNPACKED: dict = {}


def unpacked(path: Path) -> tuple:
    """(model description, unzip directory) of an FMU, extracted once per process and kept until exit
    (for runs that instantiate the same FMUs many times, e.g. campaigns)."""
    path = Path(path).resolve()
    st = path.stat()
    key = (str(path), st.st_mtime_ns, st.st_size)
    hit = _UNPACKED.get(key)
    if hit is None:
        import atexit
        hit = (read_model_description(str(path)), extract(str(path)))
        atexit.register(shutil.rmtree, hit[1], True)
        _UNPACKED[key] = hit
    return hit


_DIGESTS: dict = {}


def fmu_digest(path: Path) -> str:
    """SHA-256 of an FMU file (cached per process by path, modification time and size)."""
    import hashlib
    path = Path(path).resolve()
    st = path.stat()
    key = (str(path), st.st_mtime_ns, st.st_size)
    if key not in _DIGESTS:
        _DIGESTS[key] = hashlib.sha256(path.read_bytes()).hexdigest()
    return _DIGESTS[key]


def recording_callbacks(messages: list) -> fmi2CallbackFunctions:
    """fmi2CallbackFunctions whose logger appends (status, category, message) to `messages`."""

    def log(_env, _name, status, category, message):
        messages.append((int(status), (category or b"").decode(), (message or b"").decode().replace("%%", "%")))

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(log)
    cb.allocateMemory = defaultCallbacks.allocateMemory
    cb.freeMemory = defaultCallbacks.freeMemory
    cb._keep = cb.logger  # keep the ctypes thunk alive as long as the struct
    return cb


class Fmu:
    """One instantiated co-simulation FMU with name-based access. With `initialize=True` (default) it
    is set up, given `params` in initialization mode, and ready to step at `start_time`. Every
    logger message is kept in `messages` as (status, category, text)."""

    def __init__(self, model: str, params: dict | None = None, name: str | None = None,
                 start_time: float = 0.0, stop_time: float | None = None, tolerance: float | None = None,
                 path: Path | None = None, initialize: bool = True, logging_on: bool = False,
                 unpacked: tuple | None = None):
        self.model = model
        self.path = Path(path) if path else fmu_path(model)
        if unpacked is None:  # (model description, unzip directory) shared by instances; kept on close
            self.md = read_model_description(str(self.path))
            self.unzipdir = extract(str(self.path))
            self._owns_dir = True
        else:
            self.md, self.unzipdir = unpacked
            self._owns_dir = False
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.messages: list[tuple[int, str, str]] = []
        self.callbacks = recording_callbacks(self.messages)
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                               modelIdentifier=self.md.coSimulation.modelIdentifier,
                               instanceName=name or model)
        self.slave.instantiate(callbacks=self.callbacks, loggingOn=logging_on)
        self.time = start_time
        if initialize:
            self.slave.setupExperiment(tolerance=tolerance, startTime=start_time, stopTime=stop_time)
            self.slave.enterInitializationMode()
            for k, v in (params or {}).items():
                self.set(k, v)
            self.slave.exitInitializationMode()

    # ----- name-based access -------------------------------------------------------------
    def var(self, name: str):
        try:
            return self.vars[name]
        except KeyError:
            raise KeyError(f"{self.model} has no variable {name!r}") from None

    def inputs(self) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == "input"]

    def outputs(self) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == "output"]

    def set(self, name: str, value) -> None:
        v = self.var(name)
        if v.type == "Real":
            self.slave.setReal([v.valueReference], [float(value)])
        elif v.type == "Integer":
            self.slave.setInteger([v.valueReference], [int(value)])
        elif v.type == "Boolean":
            self.slave.setBoolean([v.valueReference], [bool(value)])
        else:
            raise TypeError(f"{name}: unsupported type {v.type}")

    def get(self, name: str):
        v = self.var(name)
        if v.type == "Real":
            return self.slave.getReal([v.valueReference])[0]
        if v.type == "Integer":
            return self.slave.getInteger([v.valueReference])[0]
        if v.type == "Boolean":
            return self.slave.getBoolean([v.valueReference])[0]
        raise TypeError(f"{name}: unsupported type {v.type}")

    def get_reals(self, names: list[str]) -> list[float]:
        return self.slave.getReal([self.var(n).valueReference for n in names])

    def set_reals(self, names: list[str], values) -> None:
        self.slave.setReal([self.var(n).valueReference for n in names], [float(x) for x in values])

    def do_step(self, t: float, dt: float) -> None:
        self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
        self.time = t + dt

    def close(self) -> None:
        try:
            self.slave.terminate()
        except Exception:
            pass
        try:
            self.slave.freeInstance()
        finally:
            if self._owns_dir:
                shutil.rmtree(self.unzipdir, ignore_errors=True)


@dataclass
class _Link:
    dst: Fmu
    dst_names: list[str]
    src: Fmu
    src_names: list[str]


@dataclass
class CoSimulation:
    """FMUs in Gauss-Seidel order, wired by port name."""

    fmus: list[Fmu]
    unconnected: set[str] = field(default_factory=set)
    links: list[_Link] = field(init=False)

    def __post_init__(self):
        self.links = []
        for dst in self.fmus:
            by_src: dict[int, _Link] = {}
            for name in dst.inputs():
                sources = [s for s in self.fmus if s is not dst and name in s.outputs()]
                if len(sources) > 1:
                    raise ValueError(f"input {dst.model}.{name} has several sources: {[s.model for s in sources]}")
                if not sources:
                    if name in self.unconnected or not self._required(name):
                        continue
                    raise ValueError(f"input {dst.model}.{name} has no source; list it in unconnected=")
                src = sources[0]
                link = by_src.setdefault(id(src), _Link(dst, [], src, []))
                link.dst_names.append(name)
                link.src_names.append(name)
            self.links.extend(by_src.values())

    @staticmethod
    def _required(name: str) -> bool:
        # Disturbance and optional extra inputs may stay at their start value.
        return not (name.startswith("torque_dist") or name.startswith("dist_") or name.startswith("h_wheel")
                    or name.startswith("q_ref_dot") or name.startswith("q_ref_ddot") or name == "leader_true_anomaly")

    def propagate(self) -> None:
        for dst in self.fmus:
            for link in self.links:
                if link.dst is dst:
                    dst.set_reals(link.dst_names, link.src.get_reals(link.src_names))

    def run(self, t_end: float, dt: float, log: dict[str, tuple[Fmu, str]] | None = None,
            t0: float = 0.0, on_step=None) -> dict[str, np.ndarray]:
        """Runs from t0 to t_end with step dt; returns logged signals at every t_k (incl. t_end)."""
        n = int(round((t_end - t0) / dt))
        if abs(n * dt - (t_end - t0)) > 1e-9 * max(1.0, abs(t_end)):
            raise ValueError(f"t_end - t0 = {t_end - t0} is not a multiple of dt = {dt}")
        log = log or {}
        out = {"time": np.empty(n + 1)}
        for k in log:
            out[k] = np.empty(n + 1)
        groups: dict[int, tuple[Fmu, list[str], list[str]]] = {}
        for key, (f, name) in log.items():
            g = groups.setdefault(id(f), (f, [], []))
            g[1].append(key)
            g[2].append(name)
        for k in range(n + 1):
            t = t0 + k * dt
            self.propagate()
            out["time"][k] = t
            for f, keys, names in groups.values():
                for key, val in zip(keys, f.get_reals(names)):
                    out[key][k] = val
            if on_step is not None:
                on_step(k, t)
            if k < n:
                for f in self.fmus:
                    f.do_step(t, dt)
        return out

    def close(self) -> None:
        for f in self.fmus:
            f.close()
