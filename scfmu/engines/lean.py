"""Lean fixed-step Gauss–Seidel master: the same algorithm as ``reference.CoSimulation``, without per-step
Python object churn.

Set-up (once per run): every FMU of the plan (:mod:`scfmu.scenario.plan`; FMI 2.0 or 3.0, Co-Simulation
or Model Exchange) is instantiated and initialized through fmpy (:class:`scfmu.fmu.Fmu`), and the plan's
link groups become flat operations (:func:`flat_ops`): per destination and type one preallocated ctypes
buffer (Real ``double``, Integer and Boolean ``int32``) for its connected inputs and the value-reference
arrays of each source group. Per communication point t_k = t0 + k·Δ it calls, in Gauss–Seidel order, the
get of each source group into a slice of the destination's buffer and one set of each of the
destination's buffers; logged variables are read with one get per instance and type straight into a
preallocated NumPy row; then every instance steps from t_k to t_k + Δ (``doStep``, or for a Model Exchange
instance its solver). The FMI functions are raw ctypes function pointers taken from the FMU's shared
library (:class:`scfmu.engines.calls.RawCalls`: arguments are plain ints, handles and buffer addresses),
and their status codes are checked once per step.

The value sequence seen by the FMUs is the one of ``reference.CoSimulation`` (same reads, same writes, same
order, same communication points), so results are bit-identical (tests/test_campaign.py checks it).
"""

from __future__ import annotations

import ctypes
from ctypes import c_uint

import numpy as np

from ..fmu import Fmu
from ..scenario.plan import Plan
from .calls import C_TYPES, STATUS as _STATUS, RawCalls, SimulationError, fmu_messages, raw_calls  # noqa: F401
from .instances import as_plan, build_fmus, initialize_fmus, ports_of  # noqa: F401


def flat_ops(plan: Plan) -> tuple[list, list]:
    """The propagation of a plan as flat operations, executed by the lean master and the compiled loop:
    ``ops`` = [(kind "get"/"set", type, instance, [vr], buffer index, offset)], ``buffers`` = [(type,
    size)]. Per destination and type one buffer; each link group's get fills a slice of it, in Gauss–Seidel
    order; then one set of each of the destination's buffers."""
    ops, buffers = [], []
    for dst, groups in plan.by_destination():
        bufs: dict[str, list] = {}  # type -> [buffer index, filled]
        for g in groups:
            b = bufs.get(g.type)
            if b is None:
                b = bufs[g.type] = [len(buffers), 0, []]
                buffers.append([g.type, 0])
            ops.append(("get", g.type, g.src, list(g.src_vrs), b[0], b[1]))
            b[1] += len(g.src_vrs)
            b[2] += g.dst_vrs
            buffers[b[0]][1] = b[1]
        for t, (bi, _n, dvrs) in bufs.items():
            ops.append(("set", t, dst, dvrs, bi, 0))
    return ops, [tuple(b) for b in buffers]


class LeanMaster:
    """Runs a Scenario (or a :class:`~scfmu.scenario.plan.Plan`; see module docstring). Use as a context
    manager or call ``close()``."""

    def __init__(self, scenario, path_of=None, reuse: bool = True, model_exchange=frozenset()):
        self.plan = as_plan(scenario, path_of, model_exchange)
        self.scenario = self.plan.scenario
        self.fmus = build_fmus(self.plan, reuse=reuse)
        try:
            self._prepare()
        except Exception:
            self.close()
            raise

    def _prepare(self) -> None:
        plan = self.plan
        self.links = plan.links
        self.calls = {name: raw_calls(f) for name, f in self.fmus.items()}
        self._keep = []  # ctypes objects that must live as long as the master
        self.plan_ops, self.plan_buffers = flat_ops(plan)
        self.plan_log = [(g.inst, g.type, g.keys, g.vrs) for g in plan.log]
        for kind, t, inst, _v, _b, _o in self.plan_ops:
            if t not in getattr(self.calls[inst], kind):
                raise SimulationError("fmu_error", f"{inst}: the unit's library has no {kind} function for {t}")
        self.n = plan.n_steps
        self._build_calls()

    def _build_calls(self) -> None:
        """The plan as ctypes calls for :meth:`run`."""
        bufs = [(C_TYPES[t] * max(1, m))() for t, m in self.plan_buffers]
        self._keep.extend(bufs)

        def vr_array(vals):
            a = (c_uint * len(vals))(*vals)
            self._keep.append(a)
            return ctypes.addressof(a)

        self._ops = []  # (fn, vr array address, n, buffer address at the offset)
        for kind, t, inst, vrs, b, off in self.plan_ops:
            fn = getattr(self.calls[inst], kind)[t]
            self._ops.append((fn, vr_array(vrs), len(vrs), ctypes.addressof(bufs[b]) + ctypes.sizeof(C_TYPES[t]) * off))
        self._log_keys = []
        self._log_arrays = []
        self._log_ops = []
        for inst, t, keys, vrs in self.plan_log:
            arr = np.empty((self.n + 1, len(keys)), dtype=np.float64 if t == "Real" else np.int32)
            self._log_arrays.append(arr)
            self._log_keys.append(keys)
            self._log_ops.append((self.calls[inst].get[t], vr_array(vrs), len(vrs), arr.ctypes.data, arr.strides[0]))
        self._steps = [self.calls[name].step for name in self.fmus]

    # ------------------------------------------------------------------------------------------------
    def run(self) -> dict[str, np.ndarray]:
        """Runs from start_time to stop_time; returns {"time", log keys...} sampled at every t_k."""
        sc = self.scenario
        n, dt, t0 = self.n, sc.step, sc.start_time
        ops, log_ops, steps = self._ops, self._log_ops, self._steps
        for k in range(n + 1):
            t = t0 + k * dt
            st = 0
            for fn, vrs, m, buf in ops:
                st |= fn(vrs, m, buf)
            for fn, vrs, m, base, stride in log_ops:
                st |= fn(vrs, m, base + k * stride)
            if k < n:
                for fn in steps:
                    st |= fn(t, dt)
            if st > 1:
                self._fail(t)
        return self._result()

    def _result(self) -> dict[str, np.ndarray]:
        sc = self.scenario
        out = {"time": sc.start_time + np.arange(self.n + 1) * sc.step}
        for keys, arr in zip(self._log_keys, self._log_arrays):
            for i, key in enumerate(keys):
                out[key] = arr[:, i].astype(np.float64)  # a copy (Integer, Boolean: as numbers)
        order = ["time"] + [k for k in sc.log]
        return {k: out[k] for k in order}

    def _fail(self, t: float):
        msgs = fmu_messages(self.fmus)
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
            calls = RawCalls(self.fmu)
            self._get, self._set, self._step = calls.get["Real"], calls.set["Real"], calls.step
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
        setr, step = self._set, self._step
        vr_in = ctypes.addressof(self._vr_in)
        base, stride, t0 = u.ctypes.data, u.strides[0], self.t0
        for k in range(len(u)):
            if setr(vr_in, n_in, base + k * stride) != 0:
                self._fail(f"fmi2SetReal failed at t = {t0 + k * dt}", t0 + k * dt)
            if step(t0 + k * dt, dt) != 0:
                self._fail(f"fmi2DoStep failed at t = {t0 + k * dt}", t0 + k * dt)
        y = np.empty(len(self.outputs))
        if self._get(ctypes.addressof(self._vr_out), len(self.outputs), y.ctypes.data) != 0:
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
