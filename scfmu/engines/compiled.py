"""Compiled engine: the lean master's Gauss–Seidel loop, logging included, run by a small compiled
library (the Rust crate ``scfmu/engines/native_loop``), so a whole run with every step logged needs no
Python call per communication step.

How. :class:`CompiledLoop` instantiates and initializes the FMUs and resolves the wiring exactly as
:class:`~scfmu.engines.lean.LeanMaster` (whose plan it reuses: the same gets and sets, grouped and
ordered the same way, the same logged groups), then hands the plan to ``scfmu_loop_run`` as flat
arrays: per FMU its component pointer and its ``fmi2GetReal`` / ``fmi2SetReal`` / ``fmi2DoStep``
function pointers (taken from the FMU's loaded shared library with ctypes), the propagation operations,
the logged (FMU, value reference) pairs, n_steps, t0, Δ and the output array of (n_steps + 1) rows.
The library makes, for k = 0..n_steps, the calls ``LeanMaster.run`` makes at t_k = t0 + k·Δ
(propagate, log row k, ``fmi2DoStep(t_k, Δ)`` of every FMU; at t_end log only) and stops at the first
status above fmi2Warning, so results are bit-identical to the lean and reference masters
(tests/test_campaign.py).

Reuse. With ``reuse`` (default), after a successful run every FMU is reset (``fmi2Terminate`` +
``fmi2Reset``) and the instances are kept (up to two sets per structure: components, models and FMU
files with their modification times and sizes) for the next run, which only sets them up and
initializes them again; results do not depend on it (tested). Instances of a failed run are freed.

The library: :func:`library_path` (the package's shipped binary, else a source checkout's
``target/release``); :func:`available` says whether it can be loaded. ``simulate(..., "auto")`` and
campaigns (engine ``"auto"``, their default) use this engine when it is available and the native one
otherwise.
"""

from __future__ import annotations

import ctypes
import platform
import sys
from importlib import resources
from ctypes import POINTER, c_double, c_int, c_int64, c_size_t, c_uint, c_uint32, c_void_p
from pathlib import Path

import numpy as np

from ..fmu import fmu_path
from ..scenario.model import Scenario
from ..scenario.resolve import resolve
from .lean import LeanMaster, SimulationError, build_fmus, initialize_fmus

ABI_VERSION = 1
_PHASES = ("fmi2GetReal (propagation)", "fmi2SetReal (propagation)", "fmi2GetReal (logging)", "fmi2DoStep")


def _platform() -> tuple[str, str] | None:
    """(FMI platform folder, library file name) of this machine, or None when not x86-64/aarch64."""
    m = platform.machine().lower()
    if m not in ("x86_64", "amd64", "arm64", "aarch64"):
        return None
    if sys.platform.startswith("linux"):
        return "linux64", "libscfmu_native_loop.so"
    if sys.platform == "win32":
        return "win64", "scfmu_native_loop.dll"
    if sys.platform == "darwin":
        return "darwin64", "libscfmu_native_loop.dylib"
    return None


def library_path() -> Path | None:
    """The compiled loop library: the package's binary ``scfmu/engines/native_loop/bin/<platform>/<lib>``
    (a wheel carries it, scripts/build_wheel.sh), else ``target/release/<lib>`` of the source checkout
    this package lives in (``cargo build --release`` at the root builds it), else None."""
    p = _platform()
    if p is None:
        return None
    pkg = Path(str(resources.files("scfmu")))
    shipped = pkg / "engines" / "native_loop" / "bin" / p[0] / p[1]
    if shipped.is_file():
        return shipped
    root = pkg.parent  # the source checkout holding this package (editable install), if it is one
    built = root / "target" / "release" / p[1]
    if (root / "Cargo.toml").is_file() and built.is_file():
        return built
    return None


_LIB: list = []  # [loaded library or None], once per process


def _lib():
    if not _LIB:
        lib = None
        path = library_path()
        if path is not None:
            try:
                cand = ctypes.CDLL(str(path))
                cand.scfmu_loop_version.restype = c_uint32
                cand.scfmu_loop_version.argtypes = []
                if cand.scfmu_loop_version() == ABI_VERSION:
                    f = cand.scfmu_loop_run
                    f.restype = c_int
                    f.argtypes = ([c_size_t, c_void_p, c_void_p, c_void_p, c_void_p,  # FMUs
                                   c_size_t, c_void_p, c_size_t, c_void_p, c_size_t,  # ops, vrs, buffer
                                   c_size_t, c_void_p, c_void_p,  # logged pairs
                                   c_size_t, c_double, c_double, c_void_p, c_size_t,  # steps, time, output
                                   c_int, POINTER(c_int64)])
                    lib = cand
            except (OSError, AttributeError):
                lib = None
        _LIB.append(lib)
    return _LIB[0]


def available() -> bool:
    """True when the compiled loop library is found and has the expected calling convention."""
    return _lib() is not None


_POOL: dict[tuple, list[dict]] = {}  # reset FMU instance sets ready for the next run, per structure


def _identity(name: str, model: str, path: Path) -> tuple:
    st = path.stat()  # a rebuilt FMU file is another structure: its old instances are not reused
    return name, model, str(path.resolve()), st.st_mtime_ns, st.st_size


class CompiledLoop(LeanMaster):
    """Runs a Scenario in the compiled loop (see module docstring). Use as a context manager or call
    ``close()``. ``run()`` returns what ``LeanMaster.run`` returns."""

    def __init__(self, scenario: Scenario, path_of=None, reuse: bool = True):
        lib = _lib()
        if lib is None:
            raise RuntimeError("the compiled loop library is not available (cargo build --release in a source "
                               "checkout, or a wheel that ships it): use the 'native' engine")
        self._lib = lib
        scenario = resolve(scenario)
        self.scenario = scenario
        self.reuse = reuse
        self._ok = False
        self._key = tuple(_identity(c.name, c.model, Path(path_of(c.model) if path_of else fmu_path(c.model)))
                          for c in scenario.components)
        pool = _POOL.get(self._key) if reuse else None
        if pool:
            fmus = pool.pop()
            for f in fmus.values():
                f.messages.clear()
            self.fmus = fmus
            try:
                initialize_fmus(fmus, scenario)
            except Exception:
                self.reuse = False  # not back into the pool
                self.close()
                raise
        else:
            self.fmus = build_fmus(scenario, path_of, reuse)
        try:
            self._prepare()
        except Exception:
            self.reuse = False
            self.close()
            raise

    def _build_calls(self) -> None:
        """The plan as the flat arrays of ``scfmu_loop_run``."""
        names = list(self.fmus)
        index = {n: i for i, n in enumerate(names)}
        nf = len(names)

        def fn_ptr(f):
            return ctypes.cast(f, c_void_p).value

        comps = (c_void_p * nf)(*[self._comp[n] for n in names])
        gets = (c_void_p * nf)(*[fn_ptr(self._get[n]) for n in names])
        sets = (c_void_p * nf)(*[fn_ptr(self._set[n]) for n in names])
        steps = (c_void_p * nf)(*[fn_ptr(self._step[n]) for n in names])
        base = np.concatenate([[0], np.cumsum(self.plan_buffers)]).astype(int) if self.plan_buffers else [0]
        ops, vrs = [], []
        for kind, inst, v, b, off in self.plan_ops:
            ops += [0 if kind == "get" else 1, index[inst], len(vrs), len(v), int(base[b]) + off]
            vrs += v
        n_buf = int(base[-1])
        log_fmu, log_vr = [], []
        self._log_keys, self._log_arrays = [], []
        n_log = sum(len(keys) for _, keys, _ in self.plan_log)
        self._out = np.empty((self.n + 1, n_log))
        col = 0
        for inst, keys, v in self.plan_log:
            log_fmu += [index[inst]] * len(keys)
            log_vr += v
            self._log_keys.append(keys)
            self._log_arrays.append(self._out[:, col:col + len(keys)])  # views: LeanMaster._result copies columns
            col += len(keys)
        arrays = (comps, gets, sets, steps, (c_size_t * max(1, len(ops)))(*ops), (c_uint * max(1, len(vrs)))(*vrs),
                  (c_size_t * max(1, n_log))(*log_fmu), (c_uint * max(1, n_log))(*log_vr))
        self._keep.extend(arrays)
        self._names = names
        self._fail_at = (c_int64 * 3)()
        self._args = (nf, *arrays[:4], len(ops) // 5, arrays[4], len(vrs), arrays[5], n_buf, n_log, arrays[6],
                      arrays[7])

    def run(self) -> dict[str, np.ndarray]:
        """Runs from start_time to stop_time in the compiled loop; returns {"time", log keys...} at every t_k."""
        sc = self.scenario
        out = self._out
        st = self._lib.scfmu_loop_run(*self._args, self.n, sc.start_time, sc.step, out.ctypes.data, out.size, 1,
                                      self._fail_at)
        if st < 0:
            raise SimulationError("engine_error", f"compiled loop: invalid plan (code {st})")
        if st > 1:
            k, phase, i = self._fail_at
            t = sc.start_time + k * sc.step
            self._fail(t, f"{self._names[i]}: {_PHASES[phase]} returned status {st} at t = {t}")
        self._ok = True
        return self._result()

    def _fail(self, t: float, what: str | None = None):
        msgs = [f"{name}: {text}" for name, f in self.fmus.items() for status, _c, text in f.messages if status >= 2]
        raise SimulationError("fmu_error", "; ".join(msgs) or what or f"an FMI call failed at t = {t}", t)

    def close(self) -> None:
        fmus, self.fmus = self.fmus, {}
        if not fmus:
            return
        if self.reuse and self._ok:
            try:
                for f in fmus.values():
                    f.slave.terminate()
                    f.slave.reset()
                pool = _POOL.setdefault(self._key, [])
                if len(pool) < 2:
                    pool.append(fmus)
                    return
            except Exception:
                pass
        for f in fmus.values():
            f.close()
