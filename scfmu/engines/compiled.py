"""Compiled engine: the lean master's Gauss–Seidel loop, logging included, run by a small compiled
library (the Rust crate ``scfmu/engines/native_loop``), so a whole run with every step logged needs no
Python call per communication step.

How. :class:`CompiledLoop` instantiates and initializes the FMUs of the scenario's plan
(:mod:`scfmu.scenario.plan`) exactly as :class:`~scfmu.engines.lean.LeanMaster` (whose flat operations
it reuses: the same gets and sets, grouped and ordered the same way, the same logged groups), then
hands them to ``scfmu_loop_run`` as flat arrays: per FMU its instance pointer, FMI version (2.0 or
3.0), interface and a table of function pointers taken from its loaded shared library with ctypes
(typed get/set for Real, Integer and Boolean, ``doStep``, and for a Model Exchange unit the functions
of its continuous-time interface), the propagation operations, the logged (FMU, value reference, type)
triples, n_steps, t0, Δ and the output array of (n_steps + 1) rows. The library makes, for
k = 0..n_steps, the calls ``LeanMaster.run`` makes at t_k = t0 + k·Δ (propagate, log row k, step every
FMU from t_k to t_k + Δ; at t_end log only) and stops at the first status above Warning, so results
of Co-Simulation units are bit-identical to the lean and reference masters (tests/test_campaign.py).

Model Exchange units are integrated inside the library by its embedded Dormand–Prince 5(4) solver
with the instance's ``rtol``/``atol`` (``Component.solver``; the ``method`` applies to the Python
engines only), stopping at time events and located state events, calling ``completedIntegratorStep``
after every accepted step and running the event iteration where the unit asks for it.

Reuse. With ``reuse`` (default), after a successful run every FMU is reset (terminate + reset) and the
instances are kept (up to two sets per structure: components, models and FMU files with their
modification times and sizes, interfaces) for the next run, which only sets them up and initializes
them again; results do not depend on it (tested). Instances of a failed run are freed.

The library: :func:`library_path` (the package's shipped binary, else a source checkout's
``target/release``); :func:`available` says whether it can be loaded. ``simulate(..., "auto")`` and
campaigns (engine ``"auto"``, their default) use this engine when it is available and the native one
otherwise.
"""

from __future__ import annotations

import platform
import sys
from importlib import resources
from ctypes import c_double, c_int64, c_size_t, c_uint, c_void_p
from pathlib import Path

import numpy as np

from .. import binding
from .calls import SimulationError, fmu_messages
from .instances import as_plan, build_fmus, initialize_fmus
from .lean import LeanMaster

ABI_VERSION = 2
_PHASES = ("get (propagation)", "set (propagation)", "get (logging)", "step", "a request to terminate",
           "the Model Exchange solver (step size too small, or too many steps)")
FN_SLOTS = 16
_FN_NAMES = {
    2: ["fmi2GetReal", "fmi2SetReal", "fmi2GetInteger", "fmi2SetInteger", "fmi2GetBoolean", "fmi2SetBoolean",
        "fmi2DoStep", "fmi2SetTime", "fmi2SetContinuousStates", "fmi2GetContinuousStates", "fmi2GetDerivatives",
        "fmi2GetEventIndicators", "fmi2CompletedIntegratorStep", "fmi2EnterEventMode", "fmi2NewDiscreteStates",
        "fmi2EnterContinuousTimeMode"],
    3: ["fmi3GetFloat64", "fmi3SetFloat64", "fmi3GetInt32", "fmi3SetInt32", "fmi3GetBoolean", "fmi3SetBoolean",
        "fmi3DoStep", "fmi3SetTime", "fmi3SetContinuousStates", "fmi3GetContinuousStates",
        "fmi3GetContinuousStateDerivatives", "fmi3GetEventIndicators", "fmi3CompletedIntegratorStep",
        "fmi3EnterEventMode", "fmi3UpdateDiscreteStates", "fmi3EnterContinuousTimeMode"]}
_KINDS = {("get", "Real"): 0, ("set", "Real"): 1, ("get", "Integer"): 2, ("set", "Integer"): 3,
          ("get", "Boolean"): 4, ("set", "Boolean"): 5}
_LOG_TYPES = {"Real": 0, "Integer": 1, "Boolean": 2}


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
            lib = binding.load_loop(str(path), ABI_VERSION)
        _LIB.append(lib)
    return _LIB[0]


def available() -> bool:
    """True when the compiled loop library is found and has the expected calling convention."""
    return _lib() is not None


_POOL: dict[tuple, list[dict]] = {}  # reset FMU instance sets ready for the next run, per structure


def _identity(name: str, model: str, path: Path, interface: str) -> tuple:
    st = path.stat()  # a rebuilt FMU file is another structure: its old instances are not reused
    return name, model, str(path), st.st_mtime_ns, st.st_size, interface


_SLOT_KEYS = ("get:Real", "set:Real", "get:Integer", "set:Integer", "get:Boolean", "set:Boolean", "step")


def _fn_address(calls, slot: int, name: str) -> int | None:
    """Address of the function of a slot: the instance's raw calls (:class:`~scfmu.engines.calls.RawCalls`)
    for get/set/step, else the unit's exported function (None when it exports none by that name)."""
    if slot < len(_SLOT_KEYS):
        f = calls.fn.get(_SLOT_KEYS[slot])
        return None if f is None else binding.function_address(f)
    return binding.address(calls.fmu.slave.dll, name)  # None e.g. for event indicators a unit does not have


class CompiledLoop(LeanMaster):
    """Runs a Scenario (or a plan) in the compiled loop (see module docstring). Use as a context manager or
    call ``close()``. ``run()`` returns what ``LeanMaster.run`` returns."""

    def __init__(self, scenario, path_of=None, reuse: bool = True, model_exchange=frozenset()):
        lib = _lib()
        if lib is None:
            raise RuntimeError("the compiled loop library is not available (cargo build --release in a source "
                               "checkout, or a wheel that ships it): use the 'native' engine")
        self._lib = lib
        self.plan = as_plan(scenario, path_of, model_exchange)
        self.scenario = self.plan.scenario
        self.reuse = reuse
        self._ok = False
        self._key = tuple(_identity(u.name, u.model, u.path, u.interface) + (tuple(sorted(u.solver.items())),)
                          for u in self.plan.units)
        pool = _POOL.get(self._key) if reuse else None
        if pool:
            fmus = pool.pop()
            for f in fmus.values():
                f.messages.clear()
            self.fmus = fmus
            try:
                initialize_fmus(fmus, self.plan)
            except Exception:
                self.reuse = False  # not back into the pool
                self.close()
                raise
        else:
            self.fmus = build_fmus(self.plan, reuse=reuse)
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
        comps = (c_void_p * nf)(*[self.calls[n].comp for n in names])
        info, fns, me = [], [], []
        for n in names:
            f, u = self.fmus[n], self.plan.unit(n)
            me_unit = u.interface == "me"
            info += [f.fmi, 1 if me_unit else 0, f.nx if me_unit else 0, f.nz if me_unit else 0]
            table = getattr(f, "_fn_table", None)
            if table is None:  # per instance, once (kept across reset and reuse)
                names_ = _FN_NAMES[f.fmi] if me_unit else _FN_NAMES[f.fmi][:7]
                table = [_fn_address(self.calls[n], i, fn) for i, fn in enumerate(names_)]
                table += [None] * (FN_SLOTS - len(table))
                if me_unit:
                    table[6] = None
                f._fn_table = table
            fns += table
            nxt = f.next_event if me_unit and f.next_event is not None else float("nan")
            me += ([u.solver["rtol"], u.solver["atol"], nxt, 1.0 if u.solver["method"] == "RK4" else 0.0,
                    u.solver["max_step"]] if me_unit else [0.0, 0.0, float("nan"), 0.0, 0.0])
        base = {}
        n_real = n_int = 0
        for b, (t, m) in enumerate(self.plan_buffers):
            if t == "Real":
                base[b], n_real = n_real, n_real + m
            else:
                base[b], n_int = n_int, n_int + m
        ops, vrs = [], []
        for kind, t, inst, v, b, off in self.plan_ops:
            ops += [_KINDS[(kind, t)], index[inst], len(vrs), len(v), base[b] + off]
            vrs += v
        log_fmu, log_vr, log_type = [], [], []
        self._log_keys, self._log_arrays = [], []
        n_log = sum(len(keys) for _, _, keys, _ in self.plan_log)
        self._out = np.empty((self.n + 1, n_log))
        col = 0
        for inst, t, keys, v in self.plan_log:
            log_fmu += [index[inst]] * len(keys)
            log_vr += v
            log_type += [_LOG_TYPES[t]] * len(keys)
            self._log_keys.append(keys)
            self._log_arrays.append(self._out[:, col:col + len(keys)])  # views: LeanMaster._result copies columns
            col += len(keys)
        arrays = (comps, (c_size_t * len(info))(*info), (c_void_p * len(fns))(*fns), (c_double * len(me))(*me),
                  (c_size_t * max(1, len(ops)))(*ops), (c_uint * max(1, len(vrs)))(*vrs),
                  (c_size_t * max(1, n_log))(*log_fmu), (c_uint * max(1, n_log))(*log_vr),
                  (c_size_t * max(1, n_log))(*log_type))
        self._keep.extend(arrays)
        self._names = names
        self._fail_at = (c_int64 * 3)()
        self._args = (nf, *arrays[:4], len(ops) // 5, arrays[4], len(vrs), arrays[5], n_real, n_int, n_log,
                      *arrays[6:])

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
            self._fail(t, f"{self._names[i]}: {_PHASES[phase]} returned status {st} at t = {t}"
                       if phase < 4 else f"{self._names[i]}: {_PHASES[phase]} at t = {t}")
        self._ok = True
        return self._result()

    def _result(self) -> dict[str, np.ndarray]:
        """``LeanMaster._result`` in one copy: the row-major output block transposed once, each logged signal
        a contiguous row of that copy (the same values as a copy per column, at a third of the cost)."""
        sc = self.scenario
        cols = np.ascontiguousarray(self._out.T)
        out = {"time": sc.start_time + np.arange(self.n + 1) * sc.step}
        i = 0
        for keys in self._log_keys:
            for key in keys:
                out[key] = cols[i]
                i += 1
        return {k: out[k] for k in ["time", *sc.log]}

    def _fail(self, t: float, what: str | None = None):
        msgs = fmu_messages(self.fmus)
        raise SimulationError("fmu_error", "; ".join(msgs) or what or f"an FMI call failed at t = {t}", t)

    def close(self) -> None:
        fmus, self.fmus = self.fmus, {}
        if not fmus:
            return
        if self.reuse and self._ok:
            try:
                for f in fmus.values():
                    f.reset()
                pool = _POOL.setdefault(self._key, [])
                if len(pool) < 2:
                    pool.append(fmus)
                    return
            except Exception:
                pass
        for f in fmus.values():
            f.close()
