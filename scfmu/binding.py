"""The package's one C binding: every C function signature the Python code calls, declared once.

* **FMI 2.0 and FMI 3.0**: the status codes, the callback types and structs, and :data:`SIGNATURES` (return
  type and argument types of every FMI function the checker, the lean master, the compiled loop and the
  engines call). :func:`bind` gives a function of a loaded library with its signature: ``typed`` (pointer
  arguments as typed pointers, arrays or ``byref``; the checker) or ``raw`` (every pointer a plain
  ``void *``: handles and buffer addresses as ints, the engines' fast path). Both come from the same table.
* **Libraries**: :func:`load` opens the shared library of an unpacked FMU (its own symbols, resolved at once),
  :func:`unload` closes it; :func:`address` is the address of an exported function.
* **The compiled loop's own C API** (``scfmu_loop_version``, ``scfmu_loop_run``): :func:`load_loop`.
* **libc**: ``calloc``/``free`` for FMI 2.0's memory callbacks (:func:`callbacks2`) and
  ``prctl(PR_SET_PDEATHSIG)`` for processes that must end with their parent (:func:`die_with_parent`).

fmpy keeps reading model descriptions and instantiating units for the engines; only the calls on the hot
path (and the checker's deliberately wrong ones, which fmpy's wrappers refuse to make) go through here.
Other modules use ctypes only for buffers and addresses passed to these functions.
"""

from __future__ import annotations

import ctypes
import os
import sys
from ctypes import (CFUNCTYPE, POINTER, Structure, c_bool, c_char_p, c_double, c_float, c_int, c_int32, c_int64,
                    c_size_t, c_uint8, c_uint32, c_void_p)

STATUS2 = ("fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending")
STATUS3 = ("fmi3OK", "fmi3Warning", "fmi3Discard", "fmi3Error", "fmi3Fatal")
STATUS = {0: "OK", 1: "Warning", 2: "Discard", 3: "Error", 4: "Fatal", 5: "Pending"}
OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4


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


# ----------------------------------------------------------------------------------------- FMI 3.0 types
LOG3 = CFUNCTYPE(None, c_void_p, c_int, c_char_p, c_char_p)
CLOCK_UPDATE3 = CFUNCTYPE(None, c_void_p)  # Scheduled Execution: an output or countdown clock ticked
LOCK_PREEMPTION3 = CFUNCTYPE(None)  # Scheduled Execution: the FMU enters / leaves a critical section
UNLOCK_PREEMPTION3 = CFUNCTYPE(None)

# ----------------------------------------------------------------------------------------- signatures
P = c_void_p
VRS = POINTER(c_uint32)
B = c_bool
PB = POINTER(c_bool)
PD = POINTER(c_double)
SIGNATURES = {  # name: (return type, argument types)
    "fmi2Instantiate": (P, [c_char_p, c_int, c_char_p, c_char_p, POINTER(Callbacks2), c_int, c_int]),
    "fmi2FreeInstance": (None, [P]),
    "fmi2SetupExperiment": (c_int, [P, c_int, c_double, c_double, c_int, c_double]),
    "fmi2EnterInitializationMode": (c_int, [P]),
    "fmi2ExitInitializationMode": (c_int, [P]),
    "fmi2Terminate": (c_int, [P]),
    "fmi2Reset": (c_int, [P]),
    "fmi2GetReal": (c_int, [P, VRS, c_size_t, PD]),
    "fmi2SetReal": (c_int, [P, VRS, c_size_t, PD]),
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
    "fmi2SetContinuousStates": (c_int, [P, PD, c_size_t]),
    "fmi2GetDerivatives": (c_int, [P, PD, c_size_t]),
    "fmi2GetContinuousStates": (c_int, [P, PD, c_size_t]),
    "fmi2GetEventIndicators": (c_int, [P, PD, c_size_t]),
    "fmi3InstantiateCoSimulation": (P, [c_char_p, c_char_p, c_char_p, B, B, B, B, VRS, c_size_t, c_void_p, LOG3,
                                        c_void_p]),
    "fmi3InstantiateModelExchange": (P, [c_char_p, c_char_p, c_char_p, B, B, c_void_p, LOG3]),
    "fmi3InstantiateScheduledExecution": (P, [c_char_p, c_char_p, c_char_p, B, B, c_void_p, LOG3, CLOCK_UPDATE3,
                                              LOCK_PREEMPTION3, UNLOCK_PREEMPTION3]),
    "fmi3FreeInstance": (None, [P]),
    "fmi3EnterInitializationMode": (c_int, [P, B, c_double, c_double, B, c_double]),
    "fmi3ExitInitializationMode": (c_int, [P]),
    "fmi3Terminate": (c_int, [P]),
    "fmi3Reset": (c_int, [P]),
    "fmi3GetFloat64": (c_int, [P, VRS, c_size_t, PD, c_size_t]),
    "fmi3SetFloat64": (c_int, [P, VRS, c_size_t, PD, c_size_t]),
    "fmi3GetFloat32": (c_int, [P, VRS, c_size_t, POINTER(c_float), c_size_t]),
    "fmi3SetFloat32": (c_int, [P, VRS, c_size_t, POINTER(c_float), c_size_t]),
    "fmi3GetInt32": (c_int, [P, VRS, c_size_t, POINTER(c_int32), c_size_t]),
    "fmi3SetInt32": (c_int, [P, VRS, c_size_t, POINTER(c_int32), c_size_t]),
    "fmi3GetInt64": (c_int, [P, VRS, c_size_t, POINTER(c_int64), c_size_t]),
    "fmi3SetInt64": (c_int, [P, VRS, c_size_t, POINTER(c_int64), c_size_t]),
    "fmi3GetBoolean": (c_int, [P, VRS, c_size_t, PB, c_size_t]),
    "fmi3SetBoolean": (c_int, [P, VRS, c_size_t, PB, c_size_t]),
    "fmi3DoStep": (c_int, [P, c_double, c_double, B, PB, PB, PB, PD]),
    "fmi3GetFMUState": (c_int, [P, POINTER(c_void_p)]),
    "fmi3SetFMUState": (c_int, [P, c_void_p]),
    "fmi3FreeFMUState": (c_int, [P, POINTER(c_void_p)]),
    "fmi3SerializedFMUStateSize": (c_int, [P, c_void_p, POINTER(c_size_t)]),
    "fmi3SerializeFMUState": (c_int, [P, c_void_p, POINTER(c_uint8), c_size_t]),
    "fmi3DeserializeFMUState": (c_int, [P, POINTER(c_uint8), c_size_t, POINTER(c_void_p)]),
    "fmi3EnterEventMode": (c_int, [P]),
    "fmi3EnterStepMode": (c_int, [P]),
    "fmi3SetClock": (c_int, [P, VRS, c_size_t, PB]),
    "fmi3GetIntervalDecimal": (c_int, [P, VRS, c_size_t, PD, POINTER(c_int)]),
    "fmi3GetShiftDecimal": (c_int, [P, VRS, c_size_t, PD]),
    "fmi3ActivateModelPartition": (c_int, [P, c_uint32, c_double]),
    "fmi3UpdateDiscreteStates": (c_int, [P, PB, PB, PB, PB, PB, PD]),
    "fmi3EnterContinuousTimeMode": (c_int, [P]),
    "fmi3CompletedIntegratorStep": (c_int, [P, B, PB, PB]),
    "fmi3SetTime": (c_int, [P, c_double]),
    "fmi3SetContinuousStates": (c_int, [P, PD, c_size_t]),
    "fmi3GetContinuousStateDerivatives": (c_int, [P, PD, c_size_t]),
    "fmi3GetContinuousStates": (c_int, [P, PD, c_size_t]),
    "fmi3GetEventIndicators": (c_int, [P, PD, c_size_t]),
}

# the checker's typed getters/setters by FMI type name: (function suffix, element type)
TYPES2 = {"Real": ("Real", c_double), "Integer": ("Integer", c_int), "Boolean": ("Boolean", c_int)}
TYPES3 = {"Float64": ("Float64", c_double), "Float32": ("Float32", c_float), "Int32": ("Int32", c_int32),
          "Int64": ("Int64", c_int64), "Boolean": ("Boolean", c_bool)}
# the engines' getters/setters by scenario type, per FMI version, and their CS step
ACCESSORS = {2: {"get": {"Real": "fmi2GetReal", "Integer": "fmi2GetInteger", "Boolean": "fmi2GetBoolean"},
                 "set": {"Real": "fmi2SetReal", "Integer": "fmi2SetInteger", "Boolean": "fmi2SetBoolean"},
                 "step": "fmi2DoStep"},
             3: {"get": {"Real": "fmi3GetFloat64", "Integer": "fmi3GetInt32", "Boolean": "fmi3GetBoolean"},
                 "set": {"Real": "fmi3SetFloat64", "Integer": "fmi3SetInt32", "Boolean": "fmi3SetBoolean"},
                 "step": "fmi3DoStep"}}


def _raw_type(t):
    """A pointer argument as ``void *`` (anything else unchanged)."""
    return c_void_p if isinstance(t, type) and issubclass(t, ctypes._Pointer) else t


def signature(name: str, raw: bool = False) -> tuple:
    """(restype, argtypes) of an FMI function; ``raw``: every pointer argument is ``void *``."""
    res, args = SIGNATURES[name]
    return res, [_raw_type(a) for a in args] if raw else list(args)


def bind(lib, name: str, raw: bool = False):
    """A fresh function object for ``name`` of a loaded library (a ``ctypes.CDLL``, e.g. fmpy's
    ``slave.dll``) with its signature (:func:`signature`); AttributeError when the library lacks it.
    Fresh: fmpy's own cached functions keep their argument types and error checks."""
    f = lib[name]
    f.restype, f.argtypes = signature(name, raw)
    return f


def address(lib, name: str) -> int | None:
    """The address of an exported function, or None when the library exports none by that name."""
    try:
        return ctypes.cast(lib[name], c_void_p).value
    except AttributeError:
        return None


def function_address(f) -> int:
    """The address of a ctypes function object (a bound function or a callback)."""
    return ctypes.cast(f, c_void_p).value


def instance_address(slave) -> int:
    """The instance pointer of an fmpy slave/model as an int."""
    c = slave.component
    return c if isinstance(c, int) else ctypes.cast(c, c_void_p).value


def as_doubles(a):
    """A ``double *`` to the data of a contiguous float64 NumPy array (for fmpy's typed wrappers)."""
    return a.ctypes.data_as(PD)


def load(path: str):
    """The shared library of an unpacked FMU, its symbols resolved at once and kept to itself."""
    return ctypes.CDLL(path, mode=os.RTLD_NOW | os.RTLD_LOCAL)


def unload(lib) -> None:
    """Closes a library opened by :func:`load` (nothing of it may be called afterwards)."""
    import _ctypes
    _ctypes.dlclose(lib._handle)


# ----------------------------------------------------------------------------------------- compiled loop
LOOP_RUN = (c_int, [c_size_t, c_void_p, c_void_p, c_void_p, c_void_p,  # FMUs
                    c_size_t, c_void_p, c_size_t, c_void_p, c_size_t, c_size_t,  # ops, buffers
                    c_size_t, c_void_p, c_void_p, c_void_p,  # logged triples
                    c_size_t, c_double, c_double, c_void_p, c_size_t,  # steps, time, output
                    c_int, POINTER(c_int64)])


def load_loop(path: str, abi_version: int):
    """The compiled loop library with ``scfmu_loop_run`` declared, or None when its ``scfmu_loop_version``
    is not ``abi_version`` (or it cannot be loaded)."""
    try:
        lib = ctypes.CDLL(str(path))
        lib.scfmu_loop_version.restype = c_uint32
        lib.scfmu_loop_version.argtypes = []
        if lib.scfmu_loop_version() != abi_version:
            return None
        f = lib.scfmu_loop_run
        f.restype, f.argtypes = LOOP_RUN
        return lib
    except (OSError, AttributeError):
        return None


# ----------------------------------------------------------------------------------------- libc
_LIBC: list = []


def _libc():
    if not _LIBC:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.calloc.restype, libc.calloc.argtypes = c_void_p, [c_size_t, c_size_t]
        libc.free.restype, libc.free.argtypes = None, [c_void_p]
        _LIBC.append(libc)
    return _LIBC[0]


def callbacks2(log) -> Callbacks2:
    """FMI 2.0 callbacks: ``log(status, message)`` for the logger, libc's calloc/free for memory, no
    stepFinished. Keep the returned struct alive as long as an instance uses it."""
    libc = _libc()

    def logger(_env, _name, status, _category, message):
        log(int(status), (message or b"").decode(errors="replace"))

    cb = Callbacks2()
    cb.logger = LOGGER2(logger)
    cb.allocateMemory = ALLOC2(lambda n, s: libc.calloc(n, s))
    cb.freeMemory = FREE2(lambda p: libc.free(p))
    cb.stepFinished = STEPFINISHED2(0)
    cb.componentEnvironment = None
    return cb


def logger3(log):
    """An FMI 3.0 ``logMessage`` callback calling ``log(status, message)`` (keep it alive)."""
    def f(_env, status, _category, message):
        log(int(status), (message or b"").decode(errors="replace"))
    return LOG3(f)


def die_with_parent() -> bool:
    """On Linux, asks for SIGKILL when the parent process ends, however it ends (prctl PR_SET_PDEATHSIG).
    False where that is not available (then the caller decides what to do)."""
    if not sys.platform.startswith("linux"):
        return False
    import signal
    try:
        _libc().prctl(1, int(signal.SIGKILL), 0, 0, 0)
        return True
    except (OSError, AttributeError):
        return False
