"""Lean fixed-step Gauss–Seidel master: the same algorithm as ``master.CoSimulation``, without per-step
Python object churn.

Set-up (once per run): every FMU is instantiated and initialized through fmpy (``master.Fmu``), the
scenario's wiring is resolved by port name to value references, and for every destination instance
the master preallocates one ctypes ``double`` buffer for its connected inputs and the value-reference
arrays of each source group. Per communication point t_k = t0 + k·Δ it calls, in Gauss–Seidel order,
``fmi2GetReal`` of each source group into a slice of the destination's buffer and one ``fmi2SetReal``
of the whole buffer; logged variables are read with one ``fmi2GetReal`` per instance straight into a
preallocated NumPy row; then ``fmi2DoStep(t_k, Δ)`` on every instance. The FMI functions are called as
raw ctypes function pointers taken from the FMU's shared library (arguments are plain ints: handles
and buffer addresses), and their status codes are checked once per step.

The value sequence seen by the FMUs is the one of ``master.CoSimulation`` (same reads, same writes, same
order, same communication points), so results are bit-identical (tests/test_campaign.py checks it).
"""

from __future__ import annotations

import ctypes
from ctypes import c_double, c_int, c_size_t, c_uint, c_void_p

import numpy as np

from ..fmu import Fmu, fmu_path, unpacked
from ..scenario.model import Scenario
from ..scenario.resolve import resolve

_STATUS = {0: "OK", 1: "Warning", 2: "Discard", 3: "Error", 4: "Fatal", 5: "Pending"}


class SimulationError(RuntimeError):
    """A run that failed: FMU error status, or a non-finite logged value. ``status`` is a short code."""

    def __init__(self, status: str, message: str, time: float | None = None):
        super().__init__(message)
        self.status = status
        self.time = time


def _raw(slave, name: str, argtypes, restype=c_int):
    f = slave.dll[name]  # a fresh function pointer: fmpy's own (cached) one keeps its argtypes
    f.argtypes = argtypes
    f.restype = restype
    return f


def build_fmus(scenario: Scenario, path_of=None, reuse: bool = False, model_exchange=frozenset()) -> dict[str, Fmu]:
    """Instantiates and initializes every instance of the scenario (parameters in initialization mode),
    then writes the fixed ``inputs``. Returns {instance name: Fmu} in Gauss–Seidel order. With ``reuse``
    the FMUs are unpacked once per process (``master.unpacked``). Instances named in ``model_exchange``
    run as Model Exchange units under SciPy's solver (:class:`scfmu.fmu.Fmu`; the reference master only)."""
    unknown = set(model_exchange) - {c.name for c in scenario.components}
    if unknown:
        raise KeyError(f"model_exchange names no instance of {scenario.name}: {sorted(unknown)}")
    fmus: dict[str, Fmu] = {}
    try:
        for c in scenario.components:
            p = path_of(c.model) if path_of else fmu_path(c.model)
            # the same calls as Fmu(initialize=True), keeping the instance to report its log messages
            fmus[c.name] = Fmu(c.model, name=c.name, start_time=scenario.start_time, path=p, initialize=False,
                               unpacked=unpacked(p) if reuse else None,
                               interface="me" if c.name in model_exchange else "cs")
        initialize_fmus(fmus, scenario)
    except Exception:
        for f in fmus.values():
            f.close()
        raise
    return fmus


def initialize_fmus(fmus: dict[str, Fmu], scenario: Scenario) -> None:
    """Initializes instantiated (or reset) FMUs for the scenario: set-up, parameters in initialization
    mode, then the fixed ``inputs``. Raises SimulationError when an FMU refuses to initialize."""
    for c in scenario.components:
        f = fmus[c.name]
        f.slave.setupExperiment(tolerance=None, startTime=scenario.start_time, stopTime=None)
        f.slave.enterInitializationMode()
        for k, v in c.params.items():
            f.set(k, v)
        try:
            f.exit_initialization_mode()
        except Exception:
            msgs = "; ".join(m[2] for m in f.messages if m[0] >= 2)
            raise SimulationError("fmu_error", f"{c.name} ({c.model}): fmi2ExitInitializationMode failed"
                                  + (f": {msgs}" if msgs else "")) from None
    for q, value in scenario.inputs.items():
        inst, _, var = q.partition(".")
        fmus[inst].set(var, value)


def ports_of(fmus: dict[str, Fmu]) -> dict[str, tuple[list[str], list[str]]]:
    return {name: (f.inputs(), f.outputs()) for name, f in fmus.items()}


class LeanMaster:
    """Runs a Scenario (see module docstring). Use as a context manager or call ``close()``."""

    def __init__(self, scenario: Scenario, path_of=None, reuse: bool = True):
        scenario = resolve(scenario)
        self.scenario = scenario
        self.fmus = build_fmus(scenario, path_of, reuse)
        try:
            self._prepare()
        except Exception:
            self.close()
            raise

    def _prepare(self) -> None:
        sc = self.scenario
        fmus = self.fmus
        links = sc.wiring(ports_of(fmus))
        self.links = links
        vr = {name: {v.name: v.valueReference for v in f.md.modelVariables} for name, f in fmus.items()}
        types = {name: {v.name: v.type for v in f.md.modelVariables} for name, f in fmus.items()}
        for d, di, s, so in links:
            if types[d][di] != "Real" or types[s][so] != "Real":
                raise TypeError(f"{d}.{di} <- {s}.{so}: only Real connections are supported")
        self._keep = []  # ctypes objects that must live as long as the master
        self._get, self._set, self._step, self._comp = {}, {}, {}, {}
        for name, f in fmus.items():
            sl = f.slave
            self._comp[name] = sl.component if isinstance(sl.component, int) else ctypes.cast(sl.component, c_void_p).value
            self._get[name] = _raw(sl, "fmi2GetReal", [c_void_p, c_void_p, c_size_t, c_void_p])
            self._set[name] = _raw(sl, "fmi2SetReal", [c_void_p, c_void_p, c_size_t, c_void_p])
            self._step[name] = _raw(sl, "fmi2DoStep", [c_void_p, c_double, c_double, c_int])
        # The plan, by instance name (also executed by the compiled engine, scfmu/engines/compiled.py):
        # per destination one buffer; per (destination, source) group a get into a slice of it, in
        # Gauss–Seidel order; then the set of the whole buffer.
        self.plan_ops = []  # ("get", source, [vr], buffer index, offset) / ("set", destination, [vr], buffer index, 0)
        self.plan_buffers = []  # buffer sizes
        by_dst: dict[str, list] = {}
        for d, di, s, so in links:
            by_dst.setdefault(d, []).append((s, so, di))
        for d, items in by_dst.items():
            b = len(self.plan_buffers)
            self.plan_buffers.append(len(items))
            i = 0
            while i < len(items):  # consecutive items of the same source form one get
                s = items[i][0]
                j = i
                while j < len(items) and items[j][0] == s:
                    j += 1
                self.plan_ops.append(("get", s, [vr[s][so] for _, so, _ in items[i:j]], b, i))
                i = j
            self.plan_ops.append(("set", d, [vr[d][di] for _, _, di in items], b, 0))
        # logging: per instance one get into a row of a (n + 1, m) array
        groups: dict[str, list[tuple[str, str]]] = {}
        for key, inst, var in sc.log_items():
            if inst not in fmus:
                raise KeyError(f"log {key!r}: unknown instance {inst!r}")
            if var not in vr[inst]:
                raise KeyError(f"log {key!r}: {fmus[inst].model} has no variable {var!r}")
            if types[inst][var] != "Real":
                raise TypeError(f"log {key!r}: {inst}.{var} is not Real")
            groups.setdefault(inst, []).append((key, var))
        self.plan_log = [(inst, [k for k, _ in items], [vr[inst][v] for _, v in items]) for inst, items in groups.items()]
        self.n = sc.n_steps
        self._build_calls()

    def _build_calls(self) -> None:
        """The plan as ctypes calls for :meth:`run`."""
        bufs = [(c_double * m)() for m in self.plan_buffers]
        self._keep.extend(bufs)

        def vr_array(vals):
            a = (c_uint * len(vals))(*vals)
            self._keep.append(a)
            return ctypes.addressof(a)

        self._ops = []  # (fn, component, vr array address, n, buffer address at the offset)
        for kind, inst, vrs, b, off in self.plan_ops:
            fn = self._get[inst] if kind == "get" else self._set[inst]
            self._ops.append((fn, self._comp[inst], vr_array(vrs), len(vrs), ctypes.addressof(bufs[b]) + 8 * off))
        self._log_keys = []
        self._log_arrays = []
        self._log_ops = []
        for inst, keys, vrs in self.plan_log:
            arr = np.empty((self.n + 1, len(keys)))
            self._log_arrays.append(arr)
            self._log_keys.append(keys)
            self._log_ops.append((self._get[inst], self._comp[inst], vr_array(vrs), len(vrs), arr.ctypes.data,
                                  arr.strides[0]))
        self._steps = [(self._step[name], self._comp[name]) for name in self.fmus]

    # ------------------------------------------------------------------------------------------------
    def run(self) -> dict[str, np.ndarray]:
        """Runs from start_time to stop_time; returns {"time", log keys...} sampled at every t_k."""
        sc = self.scenario
        n, dt, t0 = self.n, sc.step, sc.start_time
        ops, log_ops, steps = self._ops, self._log_ops, self._steps
        for k in range(n + 1):
            t = t0 + k * dt
            st = 0
            for fn, comp, vrs, m, buf in ops:
                st |= fn(comp, vrs, m, buf)
            for fn, comp, vrs, m, base, stride in log_ops:
                st |= fn(comp, vrs, m, base + k * stride)
            if k < n:
                for fn, comp in steps:
                    st |= fn(comp, t, dt, 1)
            if st > 1:
                self._fail(t)
        return self._result()

    def _result(self) -> dict[str, np.ndarray]:
        sc = self.scenario
        out = {"time": sc.start_time + np.arange(self.n + 1) * sc.step}
        for keys, arr in zip(self._log_keys, self._log_arrays):
            for i, key in enumerate(keys):
                out[key] = arr[:, i].copy()
        order = ["time"] + [k for k in sc.log]
        return {k: out[k] for k in order}

    def _fail(self, t: float):
        msgs = []
        for name, f in self.fmus.items():
            for status, _cat, text in f.messages:
                if status >= 2:
                    msgs.append(f"{name}: {text}")
        raise SimulationError("fmu_error", "; ".join(msgs) or f"an FMI call returned an error status at t = {t}", t)

    def close(self) -> None:
        for f in self.fmus.values():
            f.close()
        self.fmus = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class OpenLoop:
    """One FMU driven open loop by a table of inputs held over each communication step, every run from
    the same initial state: instantiated and initialized once (``params`` in initialization mode), its
    state saved (``fmi2GetFMUstate``) and restored before every run (``fmi2SetFMUstate``). The FMI calls
    are raw ctypes calls as in :class:`LeanMaster` (value references resolved once, one ``fmi2SetReal`` of
    all inputs per step straight from the table's row).

    ``run(u, dt)``: for k < len(u), sets ``inputs`` to ``u[k]`` and steps from t0 + k·dt to t0 + (k+1)·dt;
    returns the ``outputs`` at the end (a NumPy array). Any FMI status other than OK raises
    :class:`SimulationError`. Use as a context manager or call ``close()``."""

    def __init__(self, model: str, params: dict, inputs: list[str], outputs: list[str], start_time: float = 0.0,
                 stop_time: float | None = None):
        self.fmu = Fmu(model, params, start_time=start_time, stop_time=stop_time)
        try:
            sl = self.fmu.slave
            self._comp = sl.component if isinstance(sl.component, int) else ctypes.cast(sl.component, c_void_p).value
            self._get = _raw(sl, "fmi2GetReal", [c_void_p, c_void_p, c_size_t, c_void_p])
            self._set = _raw(sl, "fmi2SetReal", [c_void_p, c_void_p, c_size_t, c_void_p])
            self._step = _raw(sl, "fmi2DoStep", [c_void_p, c_double, c_double, c_int])
            self.inputs, self.outputs = list(inputs), list(outputs)
            self._vr_in = (c_uint * len(inputs))(*[self.fmu.var(n).valueReference for n in inputs])
            self._vr_out = (c_uint * len(outputs))(*[self.fmu.var(n).valueReference for n in outputs])
            self.t0 = start_time
            self.state0 = sl.getFMUstate()
        except Exception:
            self.fmu.close()
            raise
        self.runs = 0

    def _fail(self, what: str, t: float | None = None):
        msgs = "; ".join(m[2] for m in self.fmu.messages[-3:])
        raise SimulationError("fmu_error", f"{self.fmu.model}: {what}" + (f": {msgs}" if msgs else ""), t)

    def run(self, u: np.ndarray, dt: float) -> np.ndarray:
        u = np.ascontiguousarray(u, dtype=np.float64)
        n_in = len(self.inputs)
        if u.ndim != 2 or u.shape[1] != n_in:
            raise ValueError(f"input table of shape {u.shape}: expected (steps, {n_in})")
        self.fmu.slave.setFMUstate(self.state0)
        comp, setr, step = self._comp, self._set, self._step
        vr_in = ctypes.addressof(self._vr_in)
        base, stride, t0 = u.ctypes.data, u.strides[0], self.t0
        for k in range(len(u)):
            if setr(comp, vr_in, n_in, base + k * stride) != 0:
                self._fail(f"fmi2SetReal failed at t = {t0 + k * dt}", t0 + k * dt)
            if step(comp, t0 + k * dt, dt, 1) != 0:
                self._fail(f"fmi2DoStep failed at t = {t0 + k * dt}", t0 + k * dt)
        y = np.empty(len(self.outputs))
        if self._get(comp, ctypes.addressof(self._vr_out), len(self.outputs), y.ctypes.data) != 0:
            self._fail("fmi2GetReal failed")
        self.runs += 1
        return y

    def close(self) -> None:
        if self.fmu is None:
            return
        try:
            self.fmu.slave.freeFMUstate(self.state0)
        finally:
            self.fmu.close()
            self.fmu = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
