"""Raw ctypes access to an FMI 2.0 or 3.0 binary for the gauntlet (runs in the child process).

Every call goes through :meth:`Lib.call`, which records it as one line of a C-like call list
(``fmi2DoStep(c1, 0.0, 0.01, fmi2True) -> fmi2OK``) in the current :class:`Trace`; the trace is also
written, unbuffered, to a file descriptor so that the parent still has the calls when the FMU kills the
child. The signatures are declared here from the standards' C headers (fmpy's wrappers raise on error
statuses and cannot pass NULL pointers, which the gauntlet needs)."""

from __future__ import annotations

import ctypes
import math
import os
from ctypes import (CFUNCTYPE, POINTER, Structure, c_bool, c_char_p, c_double, c_float, c_int, c_int32, c_int64,
                    c_size_t, c_uint8, c_uint32, c_void_p)

STATUS2 = ("fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending")
STATUS3 = ("fmi3OK", "fmi3Warning", "fmi3Discard", "fmi3Error", "fmi3Fatal")
OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4


class Trace:
    """The call list of the current scenario; each line is also written to `fd` (if given) at once."""

    def __init__(self, fd: int | None = None):
        self.fd = fd
        self.lines: list[str] = []

    def start(self, title: str) -> None:
        self.lines = []
        self._emit("S " + title)

    def add(self, line: str) -> None:
        self.lines.append(line)
        self._emit("C " + line)

    def note(self, line: str) -> None:
        self.add("// " + line)

    def done(self, line: str) -> None:
        """Replaces the last line (a call written before it was made) by its completed form."""
        self.lines[-1] = line
        self._emit("R " + line)

    def _emit(self, text: str) -> None:
        if self.fd is not None:
            os.write(self.fd, (text.replace("\n", " ") + "\n").encode())


def fmt(v) -> str:
    """A C-like rendering of one argument."""
    if v is None:
        return "NULL"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "NAN"
        if math.isinf(v):
            return "INFINITY" if v > 0 else "-INFINITY"
        return repr(v)
    if isinstance(v, (list, tuple)):
        return "{" + ", ".join(fmt(x) for x in v) + "}"
    if isinstance(v, bytes):
        return '"' + v.decode(errors="replace") + '"'
    return str(v)


# ----------------------------------------------------------------------------------------- FMI 2.0 types
class EventInfo2(Structure):
    _fields_ = [("newDiscreteStatesNeeded", c_int), ("terminateSimulation", c_int),
                ("nominalsOfContinuousStatesChanged", c_int), ("valuesOfContinuousStatesChanged", c_int),
                ("nextEventTimeDefined", c_int), ("nextEventTime", c_double)]


LOGGER2 = CFUNCTYPE(None, c_void_p, c_char_p, c_int, c_char_p, c_char_p)
ALLOC2 = CFUNCTYPE(c_void_p, c_size_t, c_size_t)
FREE2 = CFUNCTYPE(None, c_void_p)
STEPFINISHED2 = CFUNCTYPE(None, c_void_p, c_int)


class Callbacks2(Structure):
    _fields_ = [("logger", LOGGER2), ("allocateMemory", ALLOC2), ("freeMemory", FREE2),
                ("stepFinished", STEPFINISHED2), ("componentEnvironment", c_void_p)]


LOG3 = CFUNCTYPE(None, c_void_p, c_int, c_char_p, c_char_p)

P = c_void_p
VRS = POINTER(c_uint32)
SIGS2 = {
    "fmi2Instantiate": (P, [c_char_p, c_int, c_char_p, c_char_p, POINTER(Callbacks2), c_int, c_int]),
    "fmi2FreeInstance": (None, [P]),
    "fmi2SetupExperiment": (c_int, [P, c_int, c_double, c_double, c_int, c_double]),
    "fmi2EnterInitializationMode": (c_int, [P]),
    "fmi2ExitInitializationMode": (c_int, [P]),
    "fmi2Terminate": (c_int, [P]),
    "fmi2Reset": (c_int, [P]),
    "fmi2GetReal": (c_int, [P, VRS, c_size_t, POINTER(c_double)]),
    "fmi2SetReal": (c_int, [P, VRS, c_size_t, POINTER(c_double)]),
    "fmi2GetInteger": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2SetInteger": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2GetBoolean": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2SetBoolean": (c_int, [P, VRS, c_size_t, POINTER(c_int)]),
    "fmi2DoStep": (c_int, [P, c_double, c_double, c_int]),
    "fmi2GetFMUstate": (c_int, [P, POINTER(c_void_p)]),
    "fmi2SetFMUstate": (c_int, [P, c_void_p]),
    "fmi2FreeFMUstate": (c_int, [P, POINTER(c_void_p)]),
    "fmi2SerializedFMUstateSize": (c_int, [P, c_void_p, POINTER(c_size_t)]),
    "fmi2SerializeFMUstate": (c_int, [P, c_void_p, POINTER(c_uint8), c_size_t]),
    "fmi2DeSerializeFMUstate": (c_int, [P, POINTER(c_uint8), c_size_t, POINTER(c_void_p)]),
    "fmi2EnterEventMode": (c_int, [P]),
    "fmi2NewDiscreteStates": (c_int, [P, POINTER(EventInfo2)]),
    "fmi2EnterContinuousTimeMode": (c_int, [P]),
    "fmi2CompletedIntegratorStep": (c_int, [P, c_int, POINTER(c_int), POINTER(c_int)]),
    "fmi2SetTime": (c_int, [P, c_double]),
    "fmi2SetContinuousStates": (c_int, [P, POINTER(c_double), c_size_t]),
    "fmi2GetDerivatives": (c_int, [P, POINTER(c_double), c_size_t]),
    "fmi2GetContinuousStates": (c_int, [P, POINTER(c_double), c_size_t]),
}
B = c_bool
PB = POINTER(c_bool)
SIGS3 = {
    "fmi3InstantiateCoSimulation": (P, [c_char_p, c_char_p, c_char_p, B, B, B, B, VRS, c_size_t, c_void_p, LOG3,
                                        c_void_p]),
    "fmi3InstantiateModelExchange": (P, [c_char_p, c_char_p, c_char_p, B, B, c_void_p, LOG3]),
    "fmi3FreeInstance": (None, [P]),
    "fmi3EnterInitializationMode": (c_int, [P, B, c_double, c_double, B, c_double]),
    "fmi3ExitInitializationMode": (c_int, [P]),
    "fmi3Terminate": (c_int, [P]),
    "fmi3Reset": (c_int, [P]),
    "fmi3GetFloat64": (c_int, [P, VRS, c_size_t, POINTER(c_double), c_size_t]),
    "fmi3SetFloat64": (c_int, [P, VRS, c_size_t, POINTER(c_double), c_size_t]),
    "fmi3GetFloat32": (c_int, [P, VRS, c_size_t, POINTER(c_float), c_size_t]),
    "fmi3SetFloat32": (c_int, [P, VRS, c_size_t, POINTER(c_float), c_size_t]),
    "fmi3GetInt32": (c_int, [P, VRS, c_size_t, POINTER(c_int32), c_size_t]),
    "fmi3SetInt32": (c_int, [P, VRS, c_size_t, POINTER(c_int32), c_size_t]),
    "fmi3GetInt64": (c_int, [P, VRS, c_size_t, POINTER(c_int64), c_size_t]),
    "fmi3SetInt64": (c_int, [P, VRS, c_size_t, POINTER(c_int64), c_size_t]),
    "fmi3GetBoolean": (c_int, [P, VRS, c_size_t, PB, c_size_t]),
    "fmi3SetBoolean": (c_int, [P, VRS, c_size_t, PB, c_size_t]),
    "fmi3DoStep": (c_int, [P, c_double, c_double, B, PB, PB, PB, POINTER(c_double)]),
    "fmi3GetFMUState": (c_int, [P, POINTER(c_void_p)]),
    "fmi3SetFMUState": (c_int, [P, c_void_p]),
    "fmi3FreeFMUState": (c_int, [P, POINTER(c_void_p)]),
    "fmi3SerializedFMUStateSize": (c_int, [P, c_void_p, POINTER(c_size_t)]),
    "fmi3SerializeFMUState": (c_int, [P, c_void_p, POINTER(c_uint8), c_size_t]),
    "fmi3DeserializeFMUState": (c_int, [P, POINTER(c_uint8), c_size_t, POINTER(c_void_p)]),
    "fmi3EnterEventMode": (c_int, [P]),
    "fmi3UpdateDiscreteStates": (c_int, [P, PB, PB, PB, PB, PB, POINTER(c_double)]),
    "fmi3EnterContinuousTimeMode": (c_int, [P]),
    "fmi3CompletedIntegratorStep": (c_int, [P, B, PB, PB]),
    "fmi3SetTime": (c_int, [P, c_double]),
    "fmi3SetContinuousStates": (c_int, [P, POINTER(c_double), c_size_t]),
    "fmi3GetContinuousStateDerivatives": (c_int, [P, POINTER(c_double), c_size_t]),
    "fmi3GetContinuousStates": (c_int, [P, POINTER(c_double), c_size_t]),
}

# the typed getters/setters by (version, type name): (suffix, ctypes element type)
TYPES2 = {"Real": ("Real", c_double), "Integer": ("Integer", c_int), "Boolean": ("Boolean", c_int)}
TYPES3 = {"Float64": ("Float64", c_double), "Float32": ("Float32", c_float), "Int32": ("Int32", c_int32),
          "Int64": ("Int64", c_int64), "Boolean": ("Boolean", c_bool)}


class Lib:
    """One loaded FMU binary with traced calls. `version` is 2 or 3."""

    def __init__(self, path: str, version: int, trace: Trace):
        self.path, self.version, self.trace = path, version, trace
        self.cdll = ctypes.CDLL(path, mode=os.RTLD_NOW | os.RTLD_LOCAL)
        self.sigs = SIGS2 if version == 2 else SIGS3
        self.status_names = STATUS2 if version == 2 else STATUS3
        self._fns: dict = {}
        self.names: dict = {}  # instance pointer -> c1, c2, ...
        self.log: list[tuple[int, str]] = []  # the unit's log messages (filled by scfmu.check.unit's logger)
        self.mark = 0  # len(self.log) when the last call began
        self._keep = []

    def has(self, name: str) -> bool:
        try:
            self.fn(name)
            return True
        except AttributeError:
            return False

    def fn(self, name: str):
        f = self._fns.get(name)
        if f is None:
            f = getattr(self.cdll, name)
            res, args = self.sigs[name]
            f.restype, f.argtypes = res, args
            self._fns[name] = f
        return f

    def handle_name(self, h) -> str:
        if h is None:
            return "NULL"
        return self.names.get(h, f"0x{h:x}")

    def call(self, name: str, *args, shown=None):
        """Calls `name` with ctypes arguments; `shown` is the rendering of the arguments for the trace."""
        f = self.fn(name)
        if shown is None:
            shown = [self.handle_name(args[0]) if i == 0 else fmt(a) for i, a in enumerate(args)]
        text = f"{name}({', '.join(shown)})"
        self.mark = len(self.log)
        self.trace.add(text + " ...")  # written before the call: a crash or a hang leaves the call in the trace
        r = f(*args)
        if f.restype is None:
            self.trace.done(text)
        elif f.restype is c_int:
            s = self.status_names[r] if 0 <= r < len(self.status_names) else f"<invalid status {r}>"
            self.trace.done(f"{text} -> {s}")
        else:
            self.trace.done(f"{text} -> {'NULL' if not r else 'instance'}")
        return r

    def unload(self) -> None:
        import _ctypes
        handle = self.cdll._handle
        self._fns.clear()
        self.cdll = None
        _ctypes.dlclose(handle)
