"""One FMU interface (FMI 2.0 or 3.0, Co-Simulation or Model Exchange) driven through raw, traced calls:
the vocabulary of the gauntlet's checks (runs in the child process).

`spec` is the plain dict the parent derives from the modelDescription (see scfmu.check.static.unit_spec):
version, interface, library, token, resource location, instance limits, continuous-state count, default
experiment and the numeric variables (inputs, outputs, parameters) with value reference, type, start, min, max."""

from __future__ import annotations

import ctypes
import math
from ctypes import byref, c_bool, c_double, c_int, c_size_t, c_uint8, c_uint32, c_void_p

from .fmi import (ERROR, OK, WARNING, LOG3, LOGGER2, ALLOC2, FREE2, STEPFINISHED2, Callbacks2, EventInfo2,
                  Lib, TYPES2, TYPES3, Trace)

_libc = ctypes.CDLL(None)
_libc.calloc.restype = c_void_p
_libc.calloc.argtypes = [c_size_t, c_size_t]
_libc.free.argtypes = [c_void_p]
_libc.free.restype = None


class Unit:
    def __init__(self, spec: dict, trace: Trace, lib: Lib | None = None):
        self.spec = spec
        self.v = spec["version"]
        self.me = spec["interface"] == "me"
        self.trace = trace
        self.lib = lib or Lib(spec["library"], self.v, trace)
        self.p = "fmi2" if self.v == 2 else "fmi3"
        self.nx = int(spec.get("nx", 0))
        self.inputs = [x for x in spec["inputs"] if x["type"] in self._types()]
        self.outputs = [x for x in spec["outputs"] if x["type"] in self._types()]
        self.real_inputs = [x for x in self.inputs if x["type"] in ("Real", "Float64")]
        self.real_params = [x for x in spec["parameters"] if x["type"] in ("Real", "Float64")]
        self.messages: list[tuple[int, str]] = []
        self.x: dict = {}       # instance -> continuous states (Model Exchange)
        self.next_event: dict = {}
        self._counter = 0
        self._make_callbacks()

    def _types(self):
        return TYPES2 if self.v == 2 else TYPES3

    # ------------------------------------------------------------------ callbacks
    def _make_callbacks(self):
        def log2(_env, _name, status, category, message):
            self.messages.append((int(status), (message or b"").decode(errors="replace")))

        def log3(_env, status, category, message):
            self.messages.append((int(status), (message or b"").decode(errors="replace")))

        if self.v == 2:
            cb = Callbacks2()
            cb.logger = LOGGER2(log2)
            cb.allocateMemory = ALLOC2(lambda n, s: _libc.calloc(n, s))
            cb.freeMemory = FREE2(lambda p: _libc.free(p))
            cb.stepFinished = STEPFINISHED2(0)
            cb.componentEnvironment = None
            self.callbacks = cb
        else:
            self.callbacks = LOG3(log3)

    # ------------------------------------------------------------------ life cycle
    def new(self, token: str | None = None, name: str | None = None, null_callbacks: bool = False,
            null_token: bool = False, null_name: bool = False):
        """Instantiates; returns the instance pointer or None."""
        self._counter += 1
        nm = None if null_name else (name or f"check{self._counter}").encode()
        tok = None if null_token else (token if token is not None else self.spec["token"]).encode()
        res = self.spec["resources"].encode()
        if self.v == 2:
            kind = 1 if not self.me else 0  # fmi2CoSimulation = 1, fmi2ModelExchange = 0
            cbs = None if null_callbacks else byref(self.callbacks)
            shown = [f'"{nm.decode()}"' if nm else "NULL", "fmi2ModelExchange" if self.me else "fmi2CoSimulation",
                     f'"{tok.decode()}"' if tok else "NULL", '"<resources>"', "NULL" if null_callbacks else "&callbacks",
                     "fmi2False", "fmi2False"]
            h = self.lib.call("fmi2Instantiate", nm, kind, tok, res, cbs, 0, 0, shown=shown)
        else:
            logger = LOG3(0) if null_callbacks else self.callbacks
            if self.me:
                shown = [f'"{nm.decode()}"' if nm else "NULL", f'"{tok.decode()}"' if tok else "NULL",
                         '"<resources>"', "false", "false", "NULL", "NULL" if null_callbacks else "logMessage"]
                h = self.lib.call("fmi3InstantiateModelExchange", nm, tok, res, False, False, None, logger,
                                  shown=shown)
            else:
                shown = [f'"{nm.decode()}"' if nm else "NULL", f'"{tok.decode()}"' if tok else "NULL",
                         '"<resources>"', "false", "false", "false", "false", "NULL", "0", "NULL",
                         "NULL" if null_callbacks else "logMessage", "NULL"]
                h = self.lib.call("fmi3InstantiateCoSimulation", nm, tok, res, False, False, False, False, None, 0,
                                  None, logger, None, shown=shown)
        if h:
            self.lib.names[h] = f"c{self._counter}"
        return h or None

    def free(self, h) -> None:
        self.lib.call(f"{self.p}FreeInstance", h)
        self.x.pop(h, None)
        self.next_event.pop(h, None)

    def enter_init(self, h, t0: float | None = None) -> int:
        t0 = self.start_time if t0 is None else t0
        if self.v == 2:
            s = self.lib.call("fmi2SetupExperiment", h, 0, 0.0, t0, 0, 0.0)
            if s > WARNING:
                return s
            return self.lib.call("fmi2EnterInitializationMode", h)
        return self.lib.call("fmi3EnterInitializationMode", h, False, 0.0, t0, False, 0.0)

    def exit_init(self, h) -> int:
        return self.lib.call(f"{self.p}ExitInitializationMode", h)

    def start(self, h, t0: float | None = None) -> int:
        """Instantiated -> step mode (CS) or continuous-time mode (ME). Returns the worst status."""
        s = self.enter_init(h, t0)
        if s > WARNING:
            return s
        s = max(s, self.exit_init(h))
        if s > WARNING or not self.me:
            return s
        s = max(s, self.event_iteration(h))
        if s > WARNING:
            return s
        s = max(s, self.lib.call(f"{self.p}EnterContinuousTimeMode", h))
        if s <= WARNING and self.nx:
            xs = (c_double * self.nx)()
            s = max(s, self.lib.call(f"{self.p}GetContinuousStates", h, xs, self.nx,
                                     shown=[self.lib.handle_name(h), "x", str(self.nx)]))
            self.x[h] = list(xs)
        return s

    def terminate(self, h) -> int:
        return self.lib.call(f"{self.p}Terminate", h)

    def reset(self, h) -> int:
        self.x.pop(h, None)
        return self.lib.call(f"{self.p}Reset", h)

    @property
    def start_time(self) -> float:
        return float(self.spec["start_time"])

    @property
    def dt(self) -> float:
        return float(self.spec["step"])

    # ------------------------------------------------------------------ Model Exchange
    def event_iteration(self, h, limit: int = 100) -> int:
        worst = OK
        for _ in range(limit):
            if self.v == 2:
                ei = EventInfo2()
                s = self.lib.call("fmi2NewDiscreteStates", h, byref(ei), shown=[self.lib.handle_name(h), "&eventInfo"])
                needed, defined, t_next = ei.newDiscreteStatesNeeded, ei.nextEventTimeDefined, ei.nextEventTime
            else:
                b = [c_bool() for _ in range(5)]
                tn = c_double()
                s = self.lib.call("fmi3UpdateDiscreteStates", h, *[byref(x) for x in b], byref(tn),
                                  shown=[self.lib.handle_name(h), "&needUpdate", "&terminate", "&nominalsChanged",
                                         "&valuesChanged", "&nextEventTimeDefined", "&nextEventTime"])
                needed, defined, t_next = b[0].value, b[4].value, tn.value
            worst = max(worst, s)
            if s > WARNING:
                return worst
            if not needed:
                self.next_event[h] = t_next if defined else None
                return worst
        self.trace.note(f"the event iteration did not converge in {limit} iterations")
        return ERROR

    def me_step(self, h, t: float, dt: float) -> int:
        """One explicit Euler step from t to t + dt with the events the unit asks for."""
        worst = OK
        n = self.nx
        hn = self.lib.handle_name(h)
        t1 = t + dt
        if n:
            x = self.x.get(h)
            if x is None or len(x) != n:
                xs = (c_double * n)()
                s = self.lib.call(f"{self.p}GetContinuousStates", h, xs, n, shown=[hn, "x", str(n)])
                if s > WARNING:
                    return s
                x = list(xs)
            dx = (c_double * n)()
            name = "fmi2GetDerivatives" if self.v == 2 else "fmi3GetContinuousStateDerivatives"
            s = self.lib.call(name, h, dx, n, shown=[hn, "dx", str(n)])
            worst = max(worst, s)
            if s > WARNING:
                return worst
            x = [a + dt * b for a, b in zip(x, dx)]
            self.x[h] = x
        s = self.lib.call(f"{self.p}SetTime", h, t1)
        worst = max(worst, s)
        if s > WARNING:
            return worst
        if n:
            xs = (c_double * n)(*self.x[h])
            s = self.lib.call(f"{self.p}SetContinuousStates", h, xs, n, shown=[hn, fmt_list(self.x[h]), str(n)])
            worst = max(worst, s)
            if s > WARNING:
                return worst
        if self.v == 2:
            enter, term = c_int(), c_int()
            s = self.lib.call("fmi2CompletedIntegratorStep", h, 1, byref(enter), byref(term),
                              shown=[hn, "fmi2True", "&enterEventMode", "&terminateSimulation"])
        else:
            enter, term = c_bool(), c_bool()
            s = self.lib.call("fmi3CompletedIntegratorStep", h, True, byref(enter), byref(term),
                              shown=[hn, "true", "&enterEventMode", "&terminateSimulation"])
        worst = max(worst, s)
        if s > WARNING:
            return worst
        te = self.next_event.get(h)
        if enter.value or (te is not None and t1 >= te - 1e-12 * max(1.0, abs(te))):
            for fn in ("EnterEventMode",):
                s = self.lib.call(f"{self.p}{fn}", h)
                worst = max(worst, s)
                if s > WARNING:
                    return worst
            s = self.event_iteration(h)
            worst = max(worst, s)
            if s > WARNING:
                return worst
            s = self.lib.call(f"{self.p}EnterContinuousTimeMode", h)
            worst = max(worst, s)
            if n and s <= WARNING:
                xs = (c_double * n)()
                s2 = self.lib.call(f"{self.p}GetContinuousStates", h, xs, n, shown=[hn, "x", str(n)])
                worst = max(worst, s2)
                self.x[h] = list(xs)
        return worst

    # ------------------------------------------------------------------ stepping
    def step(self, h, t: float, dt: float) -> int:
        if self.me:
            return self.me_step(h, t, dt)
        if self.v == 2:
            return self.lib.call("fmi2DoStep", h, t, dt, 1)
        flags = [c_bool() for _ in range(3)]
        last = c_double()
        return self.lib.call("fmi3DoStep", h, t, dt, True, *[byref(f) for f in flags], byref(last),
                             shown=[self.lib.handle_name(h), fmt_num(t), fmt_num(dt), "true", "&eventHandlingNeeded",
                                    "&terminateSimulation", "&earlyReturn", "&lastSuccessfulTime"])

    # ------------------------------------------------------------------ values
    def get(self, h, variables: list) -> tuple[int, list]:
        """Reads `variables` (dicts with vr and type) grouped by type; returns (worst status, values)."""
        worst, out = OK, [None] * len(variables)
        groups: dict = {}
        for i, var in enumerate(variables):
            groups.setdefault(var["type"], []).append(i)
        for typ, idx in groups.items():
            suffix, ct = self._types()[typ]
            n = len(idx)
            vrs = (c_uint32 * n)(*[variables[i]["vr"] for i in idx])
            vals = (ct * n)()
            args = [h, vrs, n, vals] + ([] if self.v == 2 else [n])
            shown = [self.lib.handle_name(h), fmt_list([variables[i]["vr"] for i in idx]), str(n), "values"]
            if self.v == 3:
                shown.append(str(n))
            s = self.lib.call(f"{self.p}Get{suffix}", *args, shown=shown)
            worst = max(worst, s)
            for k, i in enumerate(idx):
                out[i] = vals[k] if not isinstance(vals[k], bool) else int(vals[k])
        return worst, out

    def set(self, h, variables: list, values: list) -> int:
        worst = OK
        groups: dict = {}
        for i, var in enumerate(variables):
            groups.setdefault(var["type"], []).append(i)
        for typ, idx in groups.items():
            suffix, ct = self._types()[typ]
            n = len(idx)
            vrs = (c_uint32 * n)(*[variables[i]["vr"] for i in idx])
            conv = float if ct in (c_double, ctypes.c_float) else (bool if ct is c_bool else int)
            vals = (ct * n)(*[conv(values[i]) for i in idx])
            args = [h, vrs, n, vals] + ([] if self.v == 2 else [n])
            shown = [self.lib.handle_name(h), fmt_list([variables[i]["vr"] for i in idx]), str(n),
                     fmt_list([values[i] for i in idx])]
            if self.v == 3:
                shown.append(str(n))
            s = self.lib.call(f"{self.p}Set{suffix}", *args, shown=shown)
            worst = max(worst, s)
            if s > WARNING:
                return worst
        return worst

    def outputs_ok(self, h) -> tuple[int, list, str | None]:
        """(status, output values, problem): the problem names a non-finite value returned with OK/Warning."""
        if not self.outputs:
            return OK, [], None
        s, vals = self.get(h, self.outputs)
        if s <= WARNING:
            for var, x in zip(self.outputs, vals):
                if isinstance(x, float) and not math.isfinite(x):
                    return s, vals, f"output {var['name']} = {x} returned with status {s_name(self.v, s)}"
        return s, vals, None

    def nominal_inputs(self) -> list:
        return [x["start"] if x.get("start") is not None else 0.0 for x in self.inputs]

    # ------------------------------------------------------------------ FMU state
    def get_state(self, h) -> tuple[int, int | None]:
        st = c_void_p()
        name = "fmi2GetFMUstate" if self.v == 2 else "fmi3GetFMUState"
        s = self.lib.call(name, h, byref(st), shown=[self.lib.handle_name(h), "&state"])
        return s, st.value

    def set_state(self, h, st) -> int:
        name = "fmi2SetFMUstate" if self.v == 2 else "fmi3SetFMUState"
        return self.lib.call(name, h, st, shown=[self.lib.handle_name(h), "state" if st else "NULL"])

    def free_state(self, h, st) -> int:
        name = "fmi2FreeFMUstate" if self.v == 2 else "fmi3FreeFMUState"
        p = c_void_p(st)
        return self.lib.call(name, h, byref(p), shown=[self.lib.handle_name(h), "&state"])

    def serialize(self, h, st) -> tuple[int, bytes | None]:
        p2 = self.v == 2
        n = c_size_t()
        s = self.lib.call("fmi2SerializedFMUstateSize" if p2 else "fmi3SerializedFMUStateSize", h, st, byref(n),
                          shown=[self.lib.handle_name(h), "state", "&size"])
        if s > WARNING:
            return s, None
        buf = (c_uint8 * n.value)()
        s = self.lib.call("fmi2SerializeFMUstate" if p2 else "fmi3SerializeFMUState", h, st, buf, n.value,
                          shown=[self.lib.handle_name(h), "state", "bytes", str(n.value)])
        return s, bytes(buf) if s <= WARNING else None

    def deserialize(self, h, data: bytes | None, size: int | None = None, label: str = "bytes") -> tuple[int, int | None]:
        st = c_void_p()
        n = (len(data) if data is not None else 16) if size is None else size
        buf = None if data is None else (c_uint8 * max(1, len(data))).from_buffer_copy(data or b"\0")
        name = "fmi2DeSerializeFMUstate" if self.v == 2 else "fmi3DeserializeFMUState"
        s = self.lib.call(name, h, buf, n, byref(st),
                          shown=[self.lib.handle_name(h), "NULL" if data is None else label, str(n), "&state"])
        return s, st.value


def s_name(version: int, s: int) -> str:
    from .fmi import STATUS2, STATUS3
    names = STATUS2 if version == 2 else STATUS3
    return names[s] if 0 <= s < len(names) else f"<invalid status {s}>"


def fmt_num(x: float) -> str:
    from .fmi import fmt
    return fmt(float(x))


def fmt_list(xs) -> str:
    from .fmi import fmt
    xs = list(xs)
    if len(xs) > 8:
        return "{" + ", ".join(fmt(x) for x in xs[:8]) + f", ... ({len(xs)} values)}}"
    return fmt(xs)
