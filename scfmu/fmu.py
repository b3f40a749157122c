"""FMU access: where the FMUs are, unpacking, digests, and :class:`Fmu`, one instantiated FMU with
name-based access (fmpy's FMU2Slave underneath, or FMU2Model with SciPy's solve_ivp for a unit run as
Model Exchange).

Where the FMUs are is decided here and nowhere else (:func:`fmu_dir`), first match wins:

1. the environment variable ``SCFMU_FMU_DIR``;
2. a folder set by the program (:func:`set_fmu_dir`, the ``--fmus`` option of the ``scfmu`` command);
3. the FMUs shipped inside the installed package (``scfmu/fmus/``, filled by ``scripts/build_wheel.sh``);
4. the ``fmus/`` folder of the source checkout the package is imported from (an editable install).

A component's model may also be a path to any ``.fmu`` file (:func:`fmu_path`).
"""

from __future__ import annotations

import functools
import os
import shutil
from importlib import resources
from pathlib import Path

from fmpy import extract, read_model_description
from ctypes import POINTER, c_double

import numpy as np
from fmpy.fmi2 import FMU2Model, FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from scipy.integrate import solve_ivp

_FMU_DIR_OVERRIDE: Path | None = None


def set_fmu_dir(path: str | Path | None) -> None:
    """Uses ``path`` as the FMU folder (unless ``SCFMU_FMU_DIR`` is set); None restores the default."""
    global _FMU_DIR_OVERRIDE
    _FMU_DIR_OVERRIDE = None if path is None else Path(path).resolve()


@functools.cache  # where the installed package lies does not change while it runs
def _package_fmus() -> Path | None:
    d = resources.files("scfmu") / "fmus"
    if d.is_dir() and any(p.name.endswith(".fmu") for p in d.iterdir()):
        return Path(str(d))
    return None


@functools.cache
def _checkout_fmus() -> Path | None:
    """``fmus/`` of the source checkout that holds this package (editable install), if it is one."""
    pkg = Path(str(resources.files("scfmu")))
    root = pkg.parent
    if (root / "Cargo.toml").is_file() and (root / "fmus").is_dir():
        return root / "fmus"
    return None


def fmu_dir() -> Path:
    """The folder holding ``<Model>.fmu`` (see the module docstring for the order)."""
    env = os.environ.get("SCFMU_FMU_DIR")
    if env:
        return Path(env)
    if _FMU_DIR_OVERRIDE is not None:
        return _FMU_DIR_OVERRIDE
    for d in (_package_fmus(), _checkout_fmus()):
        if d is not None:
            return d
    raise FileNotFoundError("no FMU folder: set SCFMU_FMU_DIR or pass --fmus DIR (this installation ships no "
                            "FMUs and is not a source checkout with fmus/)")


def is_path(model: str) -> bool:
    """True when a component's model is given as a path to an FMU file rather than a model name."""
    return str(model).endswith(".fmu") or "/" in str(model) or os.sep in str(model)


def fmu_path(model: str) -> Path:
    """The FMU file of ``model``: a path to an ``.fmu`` file as given, else ``<fmu_dir()>/<model>.fmu``."""
    if is_path(model):
        p = Path(model).expanduser()
        if not p.is_file():
            raise FileNotFoundError(f"FMU {p} not found")
        return p.resolve()
    p = fmu_dir() / f"{model}.fmu"
    if not p.exists():
        raise FileNotFoundError(f"{p} not found: build the FMUs (scripts/build_fmus.sh in a checkout), set "
                                f"SCFMU_FMU_DIR or pass --fmus DIR")
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
    """One instantiated FMU with name-based access. With `initialize=True` (default) it is set up,
    given `params` in initialization mode, and ready to step at `start_time`. Every logger message is
    kept in `messages` as (status, category, text).

    ``interface="cs"`` (default) runs the unit as FMI 2.0 Co-Simulation. ``interface="me"`` runs a
    unit that offers Model Exchange under SciPy's ``solve_ivp`` instead: :meth:`do_step` integrates its
    continuous states from t to t + dt with the inputs held (like a co-simulation step), stops at the
    unit's time events, and runs the event iteration where the unit asks for it (after
    ``fmi2CompletedIntegratorStep``, e.g. a quaternion renormalisation). ``me_method`` and
    ``me_rtol``/``me_atol`` choose the solver (default DOP853, 1e-10/1e-12)."""

    def __init__(self, model: str, params: dict | None = None, name: str | None = None,
                 start_time: float = 0.0, stop_time: float | None = None, tolerance: float | None = None,
                 path: Path | None = None, initialize: bool = True, logging_on: bool = False,
                 unpacked: tuple | None = None, interface: str = "cs", me_method: str = "DOP853",
                 me_rtol: float = 1e-10, me_atol: float = 1e-12):
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
        if interface not in ("cs", "me"):
            raise ValueError(f"{model}: interface {interface!r} is neither 'cs' nor 'me'")
        self.interface = interface
        if interface == "me":
            if self.md.modelExchange is None:
                raise ValueError(f"{model} offers no Model Exchange interface (Co-Simulation only)")
            self.slave = FMU2Model(guid=self.md.guid, unzipDirectory=self.unzipdir,
                                   modelIdentifier=self.md.modelExchange.modelIdentifier, instanceName=name or model)
            self.nx = sum(1 for v in self.md.modelVariables if v.derivative is not None)
            self.me_method, self.me_rtol, self.me_atol = me_method, me_rtol, me_atol
            self.next_event: float | None = None
        else:
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
            self.exit_initialization_mode()

    def exit_initialization_mode(self) -> None:
        """Leaves initialization mode; a Model Exchange unit then runs its first event iteration and
        enters continuous-time mode."""
        self.slave.exitInitializationMode()
        if self.interface == "me":
            self._event_iteration()
            self.slave.enterContinuousTimeMode()

    # ----- Model Exchange ------------------------------------------------------------------
    def _event_iteration(self) -> None:
        while True:
            needed, terminate, _, _, defined, t_next = self.slave.newDiscreteStates()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {self.time}")
            if not needed:
                break
        self.next_event = t_next if defined else None

    def _states(self) -> np.ndarray:
        x = np.zeros(self.nx)
        if self.nx:
            self.slave.getContinuousStates(x.ctypes.data_as(POINTER(c_double)), self.nx)
        return x

    def _rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        x = np.ascontiguousarray(x, dtype=float)
        self.slave.setTime(t)
        self.slave.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), self.nx)
        dx = np.zeros(self.nx)
        self.slave.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), self.nx)
        return dx

    def _me_step(self, t: float, dt: float) -> None:
        t_end = t + dt
        eps = 1e-12 * max(1.0, abs(t_end))
        while t < t_end - eps:
            t_stop = t_end if self.next_event is None or self.next_event >= t_end - eps else self.next_event
            if self.nx:
                sol = solve_ivp(self._rhs, (t, t_stop), self._states(), method=self.me_method,
                                rtol=self.me_rtol, atol=self.me_atol)
                if not sol.success:
                    raise RuntimeError(f"{self.model}: solve_ivp failed from t = {t} to {t_stop}: {sol.message}")
                self._rhs(t_stop, sol.y[:, -1])  # leaves the unit at (t_stop, x(t_stop))
            else:
                self.slave.setTime(t_stop)
            enter, terminate = self.slave.completedIntegratorStep()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t_stop}")
            at_event = self.next_event is not None and abs(t_stop - self.next_event) <= eps
            if enter or at_event:
                self.slave.enterEventMode()
                self._event_iteration()
                self.slave.enterContinuousTimeMode()
            t = t_stop

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
        if self.interface == "me":
            self._me_step(t, dt)
        else:
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
