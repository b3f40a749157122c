"""FMU access: where the FMUs are, unpacking, digests, and :class:`Fmu`, one instantiated FMU with
name-based access: FMI 2.0 or FMI 3.0, Co-Simulation (fmpy's FMU2Slave / FMU3Slave underneath) or Model
Exchange (FMU2Model / FMU3Model, integrated by SciPy's solve_ivp between communication points).

Where the FMUs are is decided here and nowhere else (:func:`fmu_dir`), first match wins:

1. the environment variable ``SCFMU_FMU_DIR``;
2. a folder set by the program (:func:`set_fmu_dir`, the ``--fmus`` option of the ``scfmu`` command);
3. the FMUs shipped inside the installed package (``scfmu/fmus/``, filled by ``scripts/build_wheel.sh``);
4. the ``fmus/`` folder of the source checkout the package is imported from (an editable install).

A component's model may also be a path to any ``.fmu`` file (:func:`fmu_path`).

Every FMU this package unpacks (ours, a user's, one shipped to a Dask worker, the units nested in a loop
FMU) goes through :func:`safe_extract`, which inspects the whole archive before it writes anything and
refuses (:class:`ArchiveError`):

* more than ``max_files`` entries (default 10,000; ``SCFMU_FMU_MAX_FILES``);
* more than ``max_bytes`` uncompressed in total (default 1 GiB; ``SCFMU_FMU_MAX_BYTES``);
* an entry larger than 1 MiB that is more than ``max_ratio`` times its compressed size (default 200;
  ``SCFMU_FMU_MAX_RATIO``; our own FMUs compress at most about 16:1, a zip bomb about 1000:1);
* symbolic links and other special files, encrypted entries, and paths that would leave the extraction
  folder: absolute paths, drive letters (``C:``), backslashes, ``..`` components, NUL bytes.

While writing it counts the bytes again (an entry that inflates past its declared size stops there), and on
any failure it removes the folder it created. :func:`inspect_archive` runs the same checks without
extracting (the pre-flight check uses it before reading a unit's model description).
"""

from __future__ import annotations

import functools
import os
import shutil
import stat
import tempfile
import zipfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from ctypes import POINTER, c_double

import numpy as np
from fmpy.fmi2 import FMU2Model, FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Model, FMU3Slave

_FMU_DIR_OVERRIDE: Path | None = None
INT32 = (-(2 ** 31), 2 ** 31 - 1)  # the range of an FMI 2.0 Integer (fmi2Integer is a C int)


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


class UnknownModel(FileNotFoundError):
    """A model name that names no FMU of the FMU folder (the message suggests the closest names)."""


def models() -> list[str]:
    """The model names of the FMU folder (``<name>.fmu``), sorted."""
    try:
        return sorted(p.stem for p in fmu_dir().glob("*.fmu"))
    except OSError:
        return []


def fmu_path(model: str) -> Path:
    """The FMU file of ``model``: a path to an ``.fmu`` file as given, else ``<fmu_dir()>/<model>.fmu``."""
    if is_path(model):
        p = Path(model).expanduser()
        if p.is_dir():
            raise FileNotFoundError(f"FMU {p} is a directory, not an FMU file (give the .fmu archive)")
        if not p.is_file():
            raise FileNotFoundError(f"FMU {p} not found")
        return p.resolve()
    p = fmu_dir() / f"{model}.fmu"
    if not p.is_file():
        import difflib
        close = difflib.get_close_matches(str(model), models(), n=1)
        if close:
            raise UnknownModel(f"unknown model {model!r}; did you mean {close[0]!r}? (the models are the .fmu files "
                               f"of {fmu_dir()})")
        raise UnknownModel(f"{p} not found: build the FMUs (scripts/build_fmus.sh in a checkout), set "
                           f"SCFMU_FMU_DIR or pass --fmus DIR")
    return p


# ----- archive limits ----------------------------------------------------------------------------------
class ArchiveError(ValueError):
    """An FMU (or SSP) archive refused by :func:`inspect_archive`/:func:`safe_extract`; the message names
    the file, the entry and the limit."""


@dataclass(frozen=True)
class ArchiveLimits:
    """Limits of one extraction (see the module docstring). ``ratio_floor``: entries up to this size
    [bytes] are not held to ``max_ratio`` (small files of repeated text compress well and cost nothing)."""
    max_bytes: int = 1 << 30
    max_files: int = 10_000
    max_ratio: float = 200.0
    ratio_floor: int = 1 << 20

    ENV = {"max_bytes": "SCFMU_FMU_MAX_BYTES", "max_files": "SCFMU_FMU_MAX_FILES", "max_ratio": "SCFMU_FMU_MAX_RATIO"}

    @classmethod
    def from_env(cls) -> "ArchiveLimits":
        """The defaults, each replaced by its environment variable when set (a positive number)."""
        kw = {}
        for field_, var in cls.ENV.items():
            text = os.environ.get(var)
            if text is None or not text.strip():
                continue
            try:
                v = float(text) if field_ == "max_ratio" else int(text)
            except ValueError:
                v = None
            if v is None or not v > 0 or v != v or v == float("inf"):
                raise ArchiveError(f"{var} = {text!r}: expected a positive "
                                   f"{'number' if field_ == 'max_ratio' else 'integer'}")
            kw[field_] = v
        return cls(**kw)

    def to_dict(self) -> dict:
        return {"max_bytes": self.max_bytes, "max_files": self.max_files, "max_ratio": self.max_ratio,
                "ratio_floor": self.ratio_floor}


_LIMITS_OVERRIDE: ArchiveLimits | None = None


def set_archive_limits(limits: ArchiveLimits | dict | None) -> None:
    """Uses ``limits`` for every extraction of this process (a campaign's workers get the client's);
    None restores the environment's/defaults."""
    global _LIMITS_OVERRIDE
    _LIMITS_OVERRIDE = ArchiveLimits(**limits) if isinstance(limits, dict) else limits


def archive_limits() -> ArchiveLimits:
    """The limits in force: :func:`set_archive_limits`, else the environment variables, else the defaults."""
    return _LIMITS_OVERRIDE if _LIMITS_OVERRIDE is not None else ArchiveLimits.from_env()


def _entry_problem(name: str) -> str | None:
    """Why an entry name is not a safe relative path (None when it is)."""
    if "\0" in name:
        return "a NUL byte in the name"
    if "\\" in name:
        return "a backslash in the path (entries use forward slashes)"
    if name.startswith("/"):
        return "an absolute path"
    if len(name) >= 2 and name[1] == ":" and name[0].isalpha():
        return "a drive letter"
    if ":" in name.split("/")[0]:
        return "a device or drive prefix"
    if any(part == ".." for part in name.split("/")):
        return "a '..' component (outside the extraction folder)"
    return None


def inspect_archive(path: str | Path, limits: ArchiveLimits | None = None) -> list[zipfile.ZipInfo]:
    """The entries of a zip archive after every check of :func:`safe_extract` (nothing is written);
    raises :class:`ArchiveError` naming the file, the entry and the limit."""
    limits = limits or archive_limits()
    path = Path(path)
    if path.is_dir():
        raise ArchiveError(f"{path} is a directory, not an FMU file (give the .fmu archive)")
    try:
        size = path.stat().st_size
    except OSError as e:
        raise ArchiveError(f"{path}: {e.strerror or e}") from None
    if size > limits.max_bytes:  # before its directory (which could list millions of entries) is read
        raise ArchiveError(f"{path}: {size} bytes; the limit is {limits.max_bytes} bytes (SCFMU_FMU_MAX_BYTES)")
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
    except zipfile.BadZipFile as e:
        raise ArchiveError(f"{path}: not a zip archive ({e})") from None
    except OSError as e:
        raise ArchiveError(f"{path}: {e.strerror or e}") from None
    if len(infos) > limits.max_files:
        raise ArchiveError(f"{path}: {len(infos)} entries; at most {limits.max_files} are extracted "
                           f"(SCFMU_FMU_MAX_FILES)")
    total = 0
    for i in infos:
        why = _entry_problem(i.filename)
        if why:
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: {why}")
        mode = i.external_attr >> 16
        if stat.S_ISLNK(mode):
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: a symbolic link")
        if stat.S_IFMT(mode) not in (0, stat.S_IFREG, stat.S_IFDIR):
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: a special file (mode {oct(mode)})")
        if i.flag_bits & 0x1:
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: encrypted")
        total += i.file_size
        if total > limits.max_bytes:
            raise ArchiveError(f"{path}: more than {limits.max_bytes} bytes uncompressed (at entry {i.filename!r}); "
                               f"the limit is {limits.max_bytes} bytes (SCFMU_FMU_MAX_BYTES)")
        if i.file_size > limits.ratio_floor and i.file_size > limits.max_ratio * max(i.compress_size, 1):
            raise ArchiveError(f"{path}: entry {i.filename!r} inflates {i.compress_size} bytes to {i.file_size} "
                               f"(ratio {i.file_size / max(i.compress_size, 1):.0f}); at most {limits.max_ratio:g} "
                               f"is allowed (SCFMU_FMU_MAX_RATIO): a zip bomb?")
    return infos


def safe_extract(path: str | Path, dest: str | Path | None = None, limits: ArchiveLimits | None = None) -> str:
    """Extracts a zip archive (an FMU or SSP) into ``dest`` (a new temporary folder by default; created when
    absent) after :func:`inspect_archive`; returns the folder. On any failure the folder is removed (when this
    call created it) and :class:`ArchiveError` is raised."""
    limits = limits or archive_limits()
    infos = inspect_archive(path, limits)
    if dest is None:
        root = Path(tempfile.mkdtemp(prefix="scfmu_fmu_"))
        created = root
    else:
        root = Path(dest)
        created = None if root.exists() else root
        root.mkdir(parents=True, exist_ok=True)
    base = root.resolve()
    written = 0
    try:
        with zipfile.ZipFile(path) as z:
            for i in infos:
                target = (base / i.filename).resolve()
                if target != base and base not in target.parents:  # a second line of defence
                    raise ArchiveError(f"{path}: entry {i.filename!r} refused: outside the extraction folder")
                if i.is_dir():
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                n = 0
                with z.open(i) as src, open(target, "wb") as out:
                    while True:
                        block = src.read(1 << 20)
                        if not block:
                            break
                        n += len(block)
                        written += len(block)
                        if n > i.file_size or written > limits.max_bytes:
                            raise ArchiveError(f"{path}: entry {i.filename!r} inflates past its declared size "
                                               f"({i.file_size} bytes)")
                        out.write(block)
    except BaseException as e:
        if created is not None:
            shutil.rmtree(created, ignore_errors=True)
        if isinstance(e, ArchiveError):
            raise
        if isinstance(e, (zipfile.BadZipFile, OSError, EOFError, RuntimeError, ValueError)):
            raise ArchiveError(f"{path}: extraction failed: {e}") from None
        raise
    return str(root)


def model_description(path: str | Path):
    """fmpy's model description of an FMU file, after :func:`inspect_archive` (so that no oversized
    ``modelDescription.xml`` is inflated in memory)."""
    inspect_archive(path)
    return read_model_description(str(path), validate=False)


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
        d = safe_extract(path)
        try:
            hit = (read_model_description(d), d)
        except Exception:
            shutil.rmtree(d, ignore_errors=True)
            raise
        atexit.register(shutil.rmtree, d, True)
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


class Fmu:
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
                 me_rtol: float = 1e-10, me_atol: float = 1e-12, me_max_step: float = 0.0):
        self.model = model
        self.path = Path(path) if path else fmu_path(model)
        if unpacked is None:  # (model description, unzip directory) shared by instances; kept on close
            self.unzipdir = safe_extract(self.path)
            self._owns_dir = True
        else:
            self.md, self.unzipdir = unpacked
            self._owns_dir = False
        self.slave = None
        try:
            self._open(model, unpacked, params, name, start_time, stop_time, tolerance, initialize, logging_on,
                       interface, me_method, me_rtol, me_atol, me_max_step)
        except BaseException:  # nothing of a unit that failed to open stays behind (instance, folder)
            self.close()
            raise

    def _open(self, model, unpacked, params, name, start_time, stop_time, tolerance, initialize, logging_on,
              interface, me_method, me_rtol, me_atol, me_max_step) -> None:
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
            cls = FMU2Slave if self.fmi == 2 else FMU3Slave
            slave = cls(guid=self.md.guid, unzipDirectory=self.unzipdir,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=iname)
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
                slave.instantiate(loggingOn=logging_on, logMessage=log3)
        self.slave = slave
        self.time = start_time
        if initialize:
            self.enter_initialization_mode(start_time, tolerance, stop_time)
            for k, v in (params or {}).items():
                self.set(k, v)
            self.exit_initialization_mode()

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

    # ----- Model Exchange ------------------------------------------------------------------
    def _event_iteration(self) -> None:
        while True:
            if self.fmi == 2:
                needed, terminate, _, _, defined, t_next = self.slave.newDiscreteStates()
            else:
                needed, terminate, _, _, defined, t_next = self.slave.updateDiscreteStates()
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
        if self.fmi == 2:
            self.slave.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), self.nx)
        else:
            self.slave.getContinuousStateDerivatives(dx.ctypes.data_as(POINTER(c_double)), self.nx)
        return dx

    def _indicators(self) -> np.ndarray:
        z = np.zeros(self.nz)
        if self.nz:
            self.slave.getEventIndicators(z.ctypes.data_as(POINTER(c_double)), self.nz)
        return z

    def _state_events(self):
        """solve_ivp event functions, one per event indicator: a sign change stops the integration."""
        def ev(i):
            def f(t, x):
                self._rhs(t, x)
                return self._indicators()[i]
            f.terminal = True
            return f
        return [ev(i) for i in range(self.nz)]

    def _rk4(self, t: float, x: np.ndarray, h: float, k1: np.ndarray) -> np.ndarray:
        k2 = self._rhs(t + 0.5 * h, x + 0.5 * h * k1)
        k3 = self._rhs(t + 0.5 * h, x + 0.5 * h * k2)
        k4 = self._rhs(t + h, x + h * k3)
        return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    def _rk4_interval(self, t: float, t_stop: float, dt: float, eps: float) -> tuple[float, bool]:
        """Fixed-step RK4 from t towards t_stop; stops early at a state event or when the unit asks for an
        event after ``completedIntegratorStep``. Returns (time reached, event to handle)."""
        h_fix = min(self.me_max_step, dt) if self.me_max_step > 0 else dt
        x = self._states()
        z = self._indicators() if self.nz else None
        while t < t_stop - eps:
            h = min(h_fix, t_stop - t)
            if t + h > t_stop - eps:
                h = t_stop - t
            k1 = self._rhs(t, x)
            xn = self._rk4(t, x, h, k1)
            tn = t_stop if abs(t + h - t_stop) <= eps else t + h
            self._rhs(tn, xn)
            crossed = False
            if self.nz:
                zn = self._indicators()
                crossed = bool(np.any((z > 0) != (zn > 0)))
                if crossed:  # bisection on the step size
                    lo, hi, x_hi = 0.0, 1.0, xn
                    while (hi - lo) * h > eps:
                        mid = 0.5 * (lo + hi)
                        xm = self._rk4(t, x, mid * h, k1)
                        self._rhs(t + mid * h, xm)
                        if np.any((z > 0) != (self._indicators() > 0)):
                            hi, x_hi = mid, xm
                        else:
                            lo = mid
                    tn, xn = t + hi * h, x_hi
                    self._rhs(tn, xn)
                else:
                    z = zn
            t, x = tn, xn
            enter, terminate = self.slave.completedIntegratorStep()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t}")
            if crossed or enter:
                return t, True
        return t, False

    def _me_step(self, t: float, dt: float) -> None:
        t_end = t + dt
        eps = 1e-12 * max(1.0, abs(t_end))
        events = self._state_events() if self.nz else None
        while t < t_end - eps:
            t_stop = t_end if self.next_event is None or self.next_event >= t_end - eps else self.next_event
            state_event = False
            if self.me_method == "RK4" and self.nx:
                t_stop, event = self._rk4_interval(t, t_stop, dt, eps)
                at_event = self.next_event is not None and abs(t_stop - self.next_event) <= eps
                if event or at_event:
                    self.time = t_stop
                    self.slave.enterEventMode()
                    self._event_iteration()
                    self.slave.enterContinuousTimeMode()
                t = t_stop
                continue
            if self.nx:
                from scipy.integrate import solve_ivp  # imported here: SciPy costs ~1 s at start-up
                sol = solve_ivp(self._rhs, (t, t_stop), self._states(), method=self.me_method,
                                rtol=self.me_rtol, atol=self.me_atol, events=events)
                if not sol.success:
                    raise RuntimeError(f"{self.model}: solve_ivp failed from t = {t} to {t_stop}: {sol.message}")
                if sol.status == 1:  # an event indicator changed sign: stop there
                    state_event, t_stop = True, float(sol.t[-1])
                self._rhs(t_stop, sol.y[:, -1])  # leaves the unit at (t_stop, x(t_stop))
            else:
                self.slave.setTime(t_stop)
            enter, terminate = self.slave.completedIntegratorStep()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t_stop}")
            at_event = self.next_event is not None and abs(t_stop - self.next_event) <= eps
            if enter or at_event or state_event:
                self.time = t_stop
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
