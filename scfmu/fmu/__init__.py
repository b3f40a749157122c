"""FMU access: where the FMUs are, unpacking, digests, and :class:`Fmu`, one instantiated FMU with
name-based access: FMI 2.0 or FMI 3.0, Co-Simulation (fmpy's FMU2Slave / FMU3Slave underneath) or Model
Exchange (FMU2Model / FMU3Model, integrated by SciPy's solve_ivp between communication points).

Where the FMUs are is decided in scfmu.fmu.locate and nowhere else (:func:`fmu_dir`), first match wins:

1. the environment variable ``SCFMU_FMU_DIR``;
2. a folder set by the program (:func:`set_fmu_dir`, the ``--fmus`` option of the ``scfmu`` command);
3. the FMUs shipped inside the installed package (``scfmu/fmus/``, filled by ``scripts/build_wheel.sh``);
4. the ``fmus/`` folder of the source checkout the package is imported from (an editable install).

A component's model may also be a path to any ``.fmu`` file (:func:`fmu_path`).

Every FMU this package unpacks (ours, a user's, one shipped to a Dask worker, the units nested in a loop
FMU) goes through :func:`safe_extract`, which inspects the whole archive before it writes anything (the
limits: scfmu.fmu.archive). A unit that runs is unpacked once per content, with the running platform's
binaries only, into the unit cache that every scfmu process of the user shares (:func:`unpacked`,
scfmu.fmu.units); what must stay private or writable (a container's work folder, an isolated run, a unit
under ``scfmu check``) is unpacked whole into the process's scratch folder (scfmu.fmu.scratch). The Model
Exchange integration of :class:`Fmu` is in scfmu.fmu.model_exchange.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Model, FMU3ScheduledExecution, FMU3Slave

from .locate import UnknownModel, fmu_dir, fmu_path, is_path, models, set_fmu_dir
from .archive import ArchiveError, ArchiveLimits, archive_limits, inspect_archive, safe_extract, set_archive_limits
from .model_exchange import ModelExchange

__all__ = ["ArchiveError", "ArchiveLimits", "archive_limits", "inspect_archive", "safe_extract", "set_archive_limits",
           "UnknownModel", "fmu_dir", "fmu_path", "is_path", "models", "set_fmu_dir"]

INT32 = (-(2 ** 31), 2 ** 31 - 1)  # the range of an FMI 2.0 Integer (fmi2Integer is a C int)


def file_key(path: str | Path) -> tuple:
    """(resolved path, modification time, size) of a file: the key of the per-process caches of what is
    read from an FMU file (a rebuilt file is read again)."""
    path = Path(path).resolve()
    st = path.stat()
    return str(path), st.st_mtime_ns, st.st_size


_DESCRIBED: dict = {}
_UNPACKED: dict = {}


def described(path: str | Path):
    """fmpy's model description of an FMU file (validated against the schema), read from the archive after
    :func:`inspect_archive`, without unpacking anything; cached per process by path, modification time and
    size (:func:`file_key`); an oversized ``modelDescription.xml`` is never inflated in memory. Planning,
    resolving and recording a run need no more than this."""
    key = file_key(path)
    hit = _DESCRIBED.get(key)
    if hit is None:
        inspect_archive(key[0])
        hit = _DESCRIBED[key] = read_model_description(key[0])
    return hit


def unpacked(path: Path) -> tuple:
    """(model description, unzip directory) of an FMU: its entry in the unit cache shared by processes
    (scfmu.fmu.units: the running platform's binaries only, unpacked once per content, then found by every
    later call of any process), or, with ``SCFMU_UNIT_CACHE=off``, a whole extraction into the process's
    scratch folder (scfmu.fmu.scratch), kept until the process ends. Copies of one file at other paths share
    one folder (keyed by the file's SHA-256). Nothing may write into the folder: it is shared."""
    from . import units
    md = described(path)
    digest = fmu_digest(path)
    key = (digest, str(units.cache_root()))
    d = _UNPACKED.get(key)
    if d is None or not os.path.isdir(d):
        d = _UNPACKED[key] = units.unpack(path, digest)
    return md, d


def once_per_process(md) -> bool:
    """True when a model description declares canBeInstantiatedOnlyOncePerProcess for an interface it has."""
    return any(getattr(i, "canBeInstantiatedOnlyOncePerProcess", False)
               for i in (getattr(md, "coSimulation", None), getattr(md, "modelExchange", None)) if i is not None)


def _cached(path: Path) -> tuple:
    return unpacked(path)  # (Fmu's argument of the same name hides this function there)


_DIGESTS: dict = {}


def fmu_digest(path: Path) -> str:
    """SHA-256 of an FMU file (cached per process by path, modification time and size)."""
    import hashlib
    key = file_key(path)
    if key not in _DIGESTS:
        _DIGESTS[key] = hashlib.sha256(Path(key[0]).read_bytes()).hexdigest()
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


# FMI 3.0 scalar types that stand for the scenario's (FMI 2.0) types; every other FMI 3.0 type is refused
FMI3_TYPES = {"Float64": "Real", "Int32": "Integer", "Boolean": "Boolean"}


class FmuError(FMICallException):
    """An FMI call that returned error or fatal, with the unit's own log messages (fmpy's
    ``FMICallException`` names only the function and the status). Still an ``FMICallException``."""

    def __init__(self, fmu: "Fmu", exc: FMICallException):
        Exception.__init__(self)
        self.function = getattr(exc, "function", "?")
        self.status = getattr(exc, "status", None)
        self.model = fmu.model
        self.instance = getattr(fmu, "_instance_name", fmu.model)
        self.log = fmu.last_errors()
        self.call = str(exc).rstrip(".")  # fmpy's text: "fmi2DoStep failed with status 3 (error)"
        self.args = (str(self),)

    def __str__(self) -> str:
        head = f"{self.instance} ({Path(str(self.model)).name}): {self.call}"
        return head + (": " + " | ".join(self.log) if self.log else " (the unit logged no message)")


def scalar_type(v) -> str | None:
    """The scenario type (``"Real"``, ``"Integer"``, ``"Boolean"``) of a model variable of either FMI version,
    or None for any other type (strings, enumerations, FMI 3.0 Float32/Int8/..., and arrays)."""
    if getattr(v, "dimensions", None):
        return None
    t = FMI3_TYPES.get(v.type, v.type)
    return t if t in ("Real", "Integer", "Boolean") else None


class Fmu(ModelExchange):
    """One instantiated FMU (FMI 2.0 or 3.0) with name-based access. With `initialize=True` (default) it is
    set up, given `params` in initialization mode, and ready to step at `start_time`. Every logger message
    is kept in `messages` as (status, category, text).

    ``interface="cs"`` (default) runs the unit as Co-Simulation. ``interface="me"`` runs a unit that
    offers Model Exchange under SciPy's ``solve_ivp`` instead: :meth:`do_step` integrates its continuous
    states from t to t + dt with the inputs held (like a co-simulation step), stops at the unit's time
    events and at its state events (a sign change of an event indicator, located by solve_ivp's event
    detection), and runs the event iteration where the unit asks for it (after
    ``completedIntegratorStep``, e.g. a quaternion renormalisation). ``me_method`` and
    ``me_rtol``/``me_atol`` choose the solver (default DOP853, 1e-10/1e-12); ``me_method="RK4"`` is the
    classic Runge–Kutta 4 with a fixed step (the communication step, or ``me_max_step`` when smaller; state
    events located by bisection on re-integrated partial steps). ``fmi`` is the FMI major version (2 or 3)."""

    def __init__(self, model: str, params: dict | None = None, name: str | None = None,
                 start_time: float = 0.0, stop_time: float | None = None, tolerance: float | None = None,
                 path: Path | None = None, initialize: bool = True, logging_on: bool = False,
                 unpacked: tuple | None = None, interface: str = "cs", me_method: str = "DOP853",
                 me_rtol: float = 1e-10, me_atol: float = 1e-12, me_max_step: float = 0.0, clocking: str = "",
                 preemption=None):
        self.model = model
        self.clocking = clocking  # FMI 3.0 clocks: "" none; "event": eventModeUsed; "scheduled": Scheduled Execution
        self.preemption = preemption  # Scheduled Execution: (lockPreemption, unlockPreemption) Python callables
        self.path = Path(path) if path else fmu_path(model)
        self._owns_dir = False
        if unpacked is None:  # the unit cache's entry (shared, kept), else a folder of this instance's own
            from . import units
            # a unit that may be instantiated only once per process gets a library file of its own per
            # instance (a second dlopen of the same file would share its globals), as before the cache
            if units.cache_root() is None or once_per_process(described(self.path)):
                self.unzipdir = safe_extract(self.path)
                self._owns_dir = True
            else:
                unpacked = _cached(self.path)
        if unpacked is not None:
            self.md, self.unzipdir = unpacked
        self.slave = None
        try:
            self._open(model, unpacked, params, name, start_time, stop_time, tolerance, initialize, logging_on,
                       interface, me_method, me_rtol, me_atol, me_max_step)
        except BaseException:  # nothing of a unit that failed to open stays behind (instance, folder)
            self.close()
            raise

    def _open(self, model, unpacked, params, name, start_time, stop_time, tolerance, initialize, logging_on,
              interface, me_method, me_rtol, me_atol, me_max_step) -> None:
        clocking = self.clocking
        if unpacked is None:
            self.md = read_model_description(self.unzipdir)
        self.fmi = int(str(self.md.fmiVersion).split(".")[0])
        if self.fmi not in (2, 3):
            raise ValueError(f"{model}: FMI {self.md.fmiVersion} is not supported (FMI 2.0 or 3.0)")
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.messages: list[tuple[int, str, str]] = []
        if interface not in ("cs", "me"):
            raise ValueError(f"{model}: interface {interface!r} is neither 'cs' nor 'me'")
        self.interface = interface
        iname = name or model
        if interface == "me":
            if self.md.modelExchange is None:
                raise ValueError(f"{model} offers no Model Exchange interface (Co-Simulation only)")
            cls = FMU2Model if self.fmi == 2 else FMU3Model
            slave = cls(guid=self.md.guid, unzipDirectory=self.unzipdir,
                        modelIdentifier=self.md.modelExchange.modelIdentifier, instanceName=iname)
            self.nx = sum(1 for v in self.md.modelVariables if v.derivative is not None)
            self.nz = int(self.md.numberOfEventIndicators or 0)
            self.me_method, self.me_rtol, self.me_atol = me_method, me_rtol, me_atol
            self.me_max_step = me_max_step
            self.next_event: float | None = None
        else:
            if self.md.coSimulation is None:
                raise ValueError(f"{model} offers no Co-Simulation interface (Model Exchange only): run it as "
                                 f"Model Exchange")
            if clocking and (self.fmi != 3 or clocking not in ("event", "scheduled")):
                raise ValueError(f"{model}: clocking {clocking!r}: 'event' or 'scheduled', FMI 3.0 only")
            if clocking == "scheduled" and self.md.scheduledExecution is None:
                raise ValueError(f"{model} offers no Scheduled Execution interface")
            cls = FMU2Slave if self.fmi == 2 else FMU3ScheduledExecution if clocking == "scheduled" else FMU3Slave
            slave = cls(guid=self.md.guid, unzipDirectory=self.unzipdir,
                        modelIdentifier=(self.md.scheduledExecution if clocking == "scheduled"
                                         else self.md.coSimulation).modelIdentifier, instanceName=iname)
        self._instance_name = iname
        with self._fmu_errors():
            if self.fmi == 2:
                self.callbacks = recording_callbacks(self.messages)
                slave.instantiate(callbacks=self.callbacks, loggingOn=logging_on)
            else:
                msgs = self.messages

                def log3(_env, status, category, message):
                    msgs.append((int(status), (category or b"").decode(), (message or b"").decode()))

                self.callbacks = log3
                if clocking == "scheduled":
                    self._instantiate_se(slave, log3, logging_on)
                elif clocking == "event":
                    slave.instantiate(loggingOn=logging_on, logMessage=log3, eventModeUsed=True)
                else:
                    slave.instantiate(loggingOn=logging_on, logMessage=log3)
        self.slave = slave
        self.time = start_time
        if initialize:
            self.enter_initialization_mode(start_time, tolerance, stop_time)
            for k, v in (params or {}).items():
                self.set(k, v)
            self.exit_initialization_mode()

    def _instantiate_se(self, slave, log3, logging_on: bool) -> None:
        """``fmi3InstantiateScheduledExecution`` with the importer's own preemption callbacks (fmpy's class
        installs no-ops), through :mod:`scfmu.binding`; the callbacks live as long as this object."""
        from .. import binding
        lock, unlock = self.preemption or (lambda: None, lambda: None)
        cbs = (binding.LOG3(log3), binding.CLOCK_UPDATE3(lambda _env: None), binding.LOCK_PREEMPTION3(lock),
               binding.UNLOCK_PREEMPTION3(unlock))
        slave._se_callbacks = cbs
        f = binding.bind(slave.dll, "fmi3InstantiateScheduledExecution")
        res = os.path.join(self.unzipdir, "resources") + os.path.sep
        slave.component = f(slave.instanceName.encode(), slave.guid.encode(), res.encode(), False, logging_on,
                            None, *cbs)
        if not slave.component:
            raise ValueError(f"{self.model}: fmi3InstantiateScheduledExecution returned NULL: "
                             + " | ".join(m[2] for m in self.messages[-3:]))

    def enter_initialization_mode(self, start_time: float = 0.0, tolerance: float | None = None,
                                  stop_time: float | None = None) -> None:
        """Sets up the experiment (FMI 2.0 ``setupExperiment``) and enters initialization mode."""
        self.time = start_time
        with self._fmu_errors():
            if self.fmi == 2:
                self.slave.setupExperiment(tolerance=tolerance, startTime=start_time, stopTime=stop_time)
                self.slave.enterInitializationMode()
            else:
                self.slave.enterInitializationMode(tolerance=tolerance, startTime=start_time, stopTime=stop_time)

    def last_errors(self, n: int = 3) -> list[str]:
        """The last ``n`` messages the unit logged with status error or fatal (else warning or discard)."""
        for least in (3, 1):
            msgs = [m[2] for m in self.messages if m[0] >= least]
            if msgs:
                return msgs[-n:]
        return []

    def _fmu_errors(self):
        """A context that turns fmpy's ``FMICallException`` (status only) into :class:`FmuError` carrying
        the unit's own last log messages."""
        import contextlib

        @contextlib.contextmanager
        def ctx():
            try:
                yield
            except FmuError:
                raise
            except FMICallException as e:
                raise FmuError(self, e) from None
        return ctx()

    def exit_initialization_mode(self) -> None:
        """Leaves initialization mode; a Model Exchange unit then runs its first event iteration and
        enters continuous-time mode."""
        with self._fmu_errors():
            self.slave.exitInitializationMode()
            if self.interface == "me":
                self._event_iteration()
                self.slave.enterContinuousTimeMode()

    # ----- name-based access -------------------------------------------------------------
    def var(self, name: str):
        try:
            return self.vars[name]
        except KeyError:
            raise KeyError(f"{self.model} has no variable {name!r}") from None

    def inputs(self) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == "input" and v.type != "Clock"]

    def outputs(self) -> list[str]:  # (FMI 3.0 clocks are no ports)
        return [v.name for v in self.md.modelVariables if v.causality == "output" and v.type != "Clock"]

    def set(self, name: str, value) -> None:
        v = self.var(name)
        t = scalar_type(v)
        with self._fmu_errors():
            if t == "Real":
                self.set_reals([name], [value])
            elif t == "Integer" or (self.fmi == 2 and v.type == "Enumeration"):
                if isinstance(value, bool) or not (isinstance(value, int) or float(value).is_integer()):
                    raise ValueError(f"{self.model}: {name} = {value!r}: an {v.type} needs a whole number")
                if not INT32[0] <= int(value) <= INT32[1]:  # never wrapped by ctypes
                    raise ValueError(f"{self.model}: {name} = {value!r} is outside the {v.type} range "
                                     f"[{INT32[0]}, {INT32[1]}]")
                (self.slave.setInteger if self.fmi == 2 else self.slave.setInt32)([v.valueReference], [int(value)])
            elif t == "Boolean":
                if isinstance(value, str) or value not in (0, 1):
                    raise ValueError(f"{self.model}: {name} = {value!r}: a Boolean needs true or false")
                self.slave.setBoolean([v.valueReference], [bool(value)])
            else:
                raise TypeError(f"{name}: unsupported type {v.type}" + (" (an array)" if v.dimensions else ""))

    def set_refs(self, fmi_type: str, vrs: list[int], values) -> None:
        """Sets variables of one scenario type (Real, Integer, Boolean) by value reference: a plan's settings,
        whose names, types and C ranges :func:`scfmu.scenario.plan.apply_params` checked."""
        with self._fmu_errors():
            if fmi_type == "Real":
                (self.slave.setReal if self.fmi == 2 else self.slave.setFloat64)(vrs, [float(x) for x in values])
            elif fmi_type == "Integer":
                (self.slave.setInteger if self.fmi == 2 else self.slave.setInt32)(vrs, [int(x) for x in values])
            elif fmi_type == "Boolean":
                self.slave.setBoolean(vrs, [bool(x) for x in values])
            else:
                raise TypeError(f"value references {vrs}: unsupported type {fmi_type}")

    def get(self, name: str):
        v = self.var(name)
        t = scalar_type(v)
        if t == "Real":
            return self.get_reals([name])[0]
        if t == "Integer":
            return (self.slave.getInteger if self.fmi == 2 else self.slave.getInt32)([v.valueReference])[0]
        if t == "Boolean":
            return self.slave.getBoolean([v.valueReference])[0]
        raise TypeError(f"{name}: unsupported type {v.type}" + (" (an array)" if v.dimensions else ""))

    def get_values(self, names: list[str]) -> list:
        """Values of variables of one scenario type (all Real, all Integer or all Boolean)."""
        if names and scalar_type(self.var(names[0])) == "Real":
            return self.get_reals(names)
        return [self.get(n) for n in names]

    def set_values(self, names: list[str], values) -> None:
        if names and scalar_type(self.var(names[0])) == "Real":
            self.set_reals(names, values)
            return
        for n, x in zip(names, values):
            self.set(n, x)

    def get_reals(self, names: list[str]) -> list[float]:
        vrs = [self.var(n).valueReference for n in names]
        return self.slave.getReal(vrs) if self.fmi == 2 else self.slave.getFloat64(vrs)

    def set_reals(self, names: list[str], values) -> None:
        vrs = [self.var(n).valueReference for n in names]
        vals = [float(x) for x in values]
        if self.fmi == 2:
            self.slave.setReal(vrs, vals)
        else:
            self.slave.setFloat64(vrs, vals)

    def do_step(self, t: float, dt: float) -> None:
        with self._fmu_errors():
            if self.interface == "me":
                self._me_step(t, dt)
            elif self.fmi == 2:
                self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
            else:
                _, terminate, early, _ = self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
                if terminate:
                    raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t + dt}")
        self.time = t + dt

    def reset(self) -> None:
        """Terminates and resets the instance (back to its start values, ready for initialization)."""
        self.slave.terminate()
        self.slave.reset()

    def close(self) -> None:
        try:
            if self.slave is not None:
                try:
                    self.slave.terminate()
                except Exception:
                    pass
                self.slave.freeInstance()
                self.slave = None
        finally:
            if self._owns_dir:
                shutil.rmtree(self.unzipdir, ignore_errors=True)

