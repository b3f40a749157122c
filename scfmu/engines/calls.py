"""What the engines share below the plan: the one :class:`SimulationError`, the one helper that takes raw
FMI functions from a unit's shared library (:func:`raw_fn`), and :class:`RawCalls`, one instance's typed
get/set/step functions for either FMI version with the scenario's value representation.

Value representation in the engines' buffers: Real as C ``double``, Integer as ``int32``, Boolean as
``int32`` 0/1 (FMI 2.0's ``fmi2Boolean``). FMI 3.0's ``fmi3Boolean`` is one byte: :class:`RawCalls`
converts through a small scratch array, so buffers never depend on the version of the unit at their
other end. FMI 3.0 getters and setters take the number of values as an extra argument (equal to the
number of value references for scalars).
"""

from __future__ import annotations

import ctypes
import functools
from ctypes import c_bool, c_double, c_int32

from .. import binding
from ..binding import STATUS  # noqa: F401

C_TYPES = {"Real": c_double, "Integer": c_int32, "Boolean": c_int32}  # buffer element per scenario type


class SimulationError(RuntimeError):
    """A run that failed: FMU error status, or a non-finite logged value. ``status`` is a short code."""

    def __init__(self, status: str, message: str, time: float | None = None):
        super().__init__(message)
        self.status = status
        self.time = time


def raw_fn(slave, name: str):
    """A fresh function object for ``name`` of the unit's library with its raw signature
    (:func:`scfmu.binding.bind`: pointers as ints; fmpy's own, cached ones keep their argtypes and error
    checks)."""
    return binding.bind(slave.dll, name, raw=True)


def fmu_messages(fmus: dict, min_status: int = 2) -> list[str]:
    """``"instance: message"`` for every logged message of at least ``min_status`` (Discard)."""
    return [f"{name}: {text}" for name, f in fmus.items() for status, _c, text in f.messages if status >= min_status]


def raw_calls(fmu) -> "RawCalls":
    """The instance's :class:`RawCalls`, made once per instance (kept across reset and reuse: the library,
    its functions and the instance pointer do not change)."""
    rc = getattr(fmu, "_raw_calls", None)
    if rc is None:
        rc = fmu._raw_calls = RawCalls(fmu)
    return rc


class RawCalls:
    """Raw typed calls of one instance (an :class:`scfmu.fmu.Fmu`), made once per instance:

    * ``get[t](vrs_addr, n, buf_addr)`` / ``set[t](...)`` for t in Real, Integer, Boolean, reading or
      writing ``n`` values in the buffer representation (module docstring); they return the FMI status;
    * ``step(t, h)``: ``doStep`` of a Co-Simulation instance (FMI 3.0: a request to terminate is
      reported as status 3, Error, with a message in the unit's log);
    * ``fn[kind]``: the bare function pointers (``"get:Real"``, ..., ``"step"``) for the compiled loop.
    """

    def __init__(self, fmu):
        sl = fmu.slave
        self.fmu = fmu
        self.fmi = fmu.fmi
        self.comp = binding.instance_address(sl)
        names = binding.ACCESSORS[self.fmi]
        self.fn = {}
        for kind in ("get", "set"):
            for t, n in names[kind].items():
                try:
                    self.fn[f"{kind}:{t}"] = raw_fn(sl, n)
                except AttributeError:  # a unit without Integer/Boolean functions (never linked to)
                    pass
        if fmu.interface == "cs":
            self.fn["step"] = raw_fn(sl, names["step"])
        self.get = {t: self._accessor("get", t) for t in C_TYPES if f"get:{t}" in self.fn}
        self.set = {t: self._accessor("set", t) for t in C_TYPES if f"set:{t}" in self.fn}
        self.step = self._stepper() if fmu.interface == "cs" else self._me_stepper()

    def _accessor(self, kind: str, t: str):
        f, comp = self.fn[f"{kind}:{t}"], self.comp
        if self.fmi == 2:
            return functools.partial(f, comp)  # a C-level partial: no Python frame per call
        if t != "Boolean":
            return lambda vrs, n, buf: f(comp, vrs, n, buf, n)
        scratch = {}

        def conv(vrs, n, buf):  # fmi3Boolean (1 byte) <-> int32 buffer
            s = scratch.get(n)
            if s is None:
                s = scratch[n] = (c_bool * n)()
            b = (c_int32 * n).from_address(buf)
            if kind == "set":
                for i in range(n):
                    s[i] = bool(b[i])
                return f(comp, vrs, n, ctypes.addressof(s), n)
            st = f(comp, vrs, n, ctypes.addressof(s), n)
            for i in range(n):
                b[i] = int(s[i])
            return st
        return conv

    def _stepper(self):
        f, comp = self.fn["step"], self.comp
        if self.fmi == 2:
            return lambda t, h: f(comp, t, h, 1)
        flags = (c_bool * 3)()
        last = c_double()
        # the unit writes into both at every step: they live as long as this instance's calls (a buffer
        # known only by its address would be freed when this function returns, and the unit would write
        # lastSuccessfulTime into freed memory)
        self._step_outputs = (flags, last)
        a_ev, a_term, a_early = (ctypes.addressof(flags) + i for i in range(3))
        a_last = ctypes.addressof(last)
        fmu = self.fmu

        def step3(t, h):
            st = f(comp, t, h, True, a_ev, a_term, a_early, a_last)
            if st <= 1 and flags[1]:
                fmu.messages.append((3, "", f"fmi3DoStep: the unit asked to terminate the simulation at t = {t + h}"))
                return 3
            return st
        return step3

    def _me_stepper(self):
        fmu = self.fmu

        def step_me(t, h):  # the unit's solver (scfmu.fmu.Fmu._me_step); a failure is an Error status
            try:
                fmu.do_step(t, h)
                return 0
            except Exception as e:
                fmu.messages.append((3, "", f"Model Exchange step from t = {t}: {e}"))
                return 3
        return step_me
