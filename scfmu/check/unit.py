"""One FMU interface (FMI 2.0 or 3.0, Co-Simulation or Model Exchange) driven through raw, traced calls:
the vocabulary of the gauntlet's checks (runs in the child process).

`spec` is the plain dict the parent derives from the modelDescription (see scfmu.check.static.unit_spec):
version, interface, library, token, resource location, instance limits, continuous-state count, default
experiment and the numeric variables (inputs, outputs, parameters) with value reference, type, start, min, max."""

from __future__ import annotations

import ctypes
import math
from ctypes import byref, c_bool, c_double, c_int, c_size_t, c_uint8, c_uint32, c_void_p

from .. import binding
from ..binding import LOG3, EventInfo2
from .fmi import ERROR, OK, WARNING, Lib, TYPES2, TYPES3, Trace


MAX_SUBSTEPS = 50  # Euler sub-steps per Model Exchange step of the checker


class Unit:
    def __init__(self, spec: dict, trace: Trace, lib: Lib | None = None):
        self.spec = spec
        self.v = spec["version"]
        self.me = spec["interface"] == "me"
        self.trace = trace
        self.lib = lib or Lib(spec["library"], self.v, trace)
        self.p = "fmi2" if self.v == 2 else "fmi3"
        self.nx = int(spec.get("nx", 0))
        inputs = [x for x in spec["inputs"] if x["type"] in self._types()]
        # Model Exchange: only continuous inputs may be set in Continuous-Time Mode (FMI 2.0.4 §3.2.3, FMI 3.0
        # Model Exchange state machine); the discrete ones keep their start values
        self.inputs = [x for x in inputs if not self.me or x.get("variability", "continuous") == "continuous"]
        self.outputs = [x for x in spec["outputs"] if x["type"] in self._types()]
        self.real_inputs = [x for x in self.inputs if x["type"] in ("Real", "Float64")]
        self.real_params = [x for x in spec["parameters"] if x["type"] in ("Real", "Float64")]
        self.messages: list[tuple[int, str]] = self.lib.log  # Lib.mark: where the last call's messages begin
        self.x: dict = {}       # instance -> continuous states (Model Exchange)
        self.now: dict = {}     # instance -> the time a Model Exchange step reached (Unit.me_step)
        self.ended: dict = {}   # instance -> why the unit asked to end the simulation (terminateSimulation)
        self.next_event: dict = {}
        self._counter = 0
        self._make_callbacks()

    def _types(self):
        return TYPES2 if self.v == 2 else TYPES3

    # ------------------------------------------------------------------ callbacks
    def _make_callbacks(self):
        def log(status, message):
            self.messages.append((status, message))

        self.callbacks = binding.callbacks2(log) if self.v == 2 else binding.logger3(log)

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
        self.forget(h)

    def forget(self, h) -> None:
        """Drops what the checker holds of instance h (after free, reset or a restored FMU state)."""
        self.x.pop(h, None)
        self.now.pop(h, None)
        self.ended.pop(h, None)
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
        self.forget(h)
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
                term = ei.terminateSimulation
            else:
                b = [c_bool() for _ in range(5)]
                tn = c_double()
                s = self.lib.call("fmi3UpdateDiscreteStates", h, *[byref(x) for x in b], byref(tn),
                                  shown=[self.lib.handle_name(h), "&needUpdate", "&terminate", "&nominalsChanged",
                                         "&valuesChanged", "&nextEventTimeDefined", "&nextEventTime"])
                needed, defined, t_next = b[0].value, b[4].value, tn.value
                term = b[1].value
            worst = max(worst, s)
            if s > WARNING:
                return worst
            if term:
                self.ended[h] = "terminateSimulation from the event update"
                return worst
            if not needed:
                self.next_event[h] = t_next if defined else None
                return worst
        self.trace.note(f"the event iteration did not converge in {limit} iterations")
        return ERROR

    def me_step(self, h, t: float, dt: float) -> int:
        """Explicit Euler from t towards t + dt with the events the unit asks for, in sub-steps that change no
        state by more than a tenth of its size (plus 1e-6): a stiff unit or one without a stepSize in its
        default experiment is not driven into the checker's own divergence. At most MAX_SUBSTEPS sub-steps:
        the time reached is left in self.now[h]."""
        worst, t1, tk = OK, t + dt, t
        for _ in range(MAX_SUBSTEPS):
            s, tk = self._euler(h, tk, t1)
            worst = max(worst, s)
            if s > WARNING:
                return worst
            if tk >= t1 or h in self.ended:
                break
        self.now[h] = tk
        return worst

    def _euler(self, h, t: float, t_end: float) -> tuple[int, float]:
        """One Euler sub-step from t (to t_end at most, and not past a time event); (status, time reached)."""
        worst = OK
        n = self.nx
        hn = self.lib.handle_name(h)
        t1 = t_end
        te = self.next_event.get(h)
        if te is not None and t < te < t1:
            t1 = te
        if n:
            x = self.x.get(h)
            if x is None or len(x) != n:
                xs = (c_double * n)()
                s = self.lib.call(f"{self.p}GetContinuousStates", h, xs, n, shown=[hn, "x", str(n)])
                if s > WARNING:
                    return s, t
                x = list(xs)
            dx = (c_double * n)()
            name = "fmi2GetDerivatives" if self.v == 2 else "fmi3GetContinuousStateDerivatives"
            s = self.lib.call(name, h, dx, n, shown=[hn, "dx", str(n)])
            worst = max(worst, s)
            if s > WARNING:
                return worst, t
            rate = max((abs(d) / (0.1 * abs(a) + 1e-6) for a, d in zip(x, dx) if math.isfinite(a) and
                        math.isfinite(d)), default=0.0)
            if rate * (t1 - t) > 1.0:
                t1 = t + 1.0 / rate
            x = [a + (t1 - t) * b for a, b in zip(x, dx)]
            self.x[h] = x
        s = self.lib.call(f"{self.p}SetTime", h, t1)
        worst = max(worst, s)
        if s > WARNING:
            return worst, t
        if n:
            xs = (c_double * n)(*self.x[h])
            s = self.lib.call(f"{self.p}SetContinuousStates", h, xs, n, shown=[hn, fmt_list(self.x[h]), str(n)])
            worst = max(worst, s)
            if s > WARNING:
                return worst, t1
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
            return worst, t1
        if term.value:
            self.ended[h] = f"terminateSimulation from CompletedIntegratorStep at t = {t1!r}"
            return worst, t1
        if enter.value or (te is not None and t1 >= te - 1e-12 * max(1.0, abs(te))):
            s = self.lib.call(f"{self.p}EnterEventMode", h)
            worst = max(worst, s)
            if s > WARNING:
                return worst, t1
            s = self.event_iteration(h)
            worst = max(worst, s)
            if s > WARNING or h in self.ended:
                return worst, t1
            s = self.lib.call(f"{self.p}EnterContinuousTimeMode", h)
            worst = max(worst, s)
            if n and s <= WARNING:
                xs = (c_double * n)()
                s2 = self.lib.call(f"{self.p}GetContinuousStates", h, xs, n, shown=[hn, "x", str(n)])
                worst = max(worst, s2)
                self.x[h] = list(xs)
        return worst, t1

    # ------------------------------------------------------------------ stepping
    def step(self, h, t: float, dt: float) -> int:
        if self.me:
            return self.me_step(h, t, dt)
        if self.v == 2:
            return self.lib.call("fmi2DoStep", h, t, dt, 1)
        flags = [c_bool() for _ in range(3)]
        last = c_double()
        s = self.lib.call("fmi3DoStep", h, t, dt, True, *[byref(f) for f in flags], byref(last),
                          shown=[self.lib.handle_name(h), fmt_num(t), fmt_num(dt), "true", "&eventHandlingNeeded",
                                 "&terminateSimulation", "&earlyReturn", "&lastSuccessfulTime"])
        if s <= WARNING and flags[1].value:
            self.ended[h] = f"terminateSimulation from the step from t = {t!r}"
        return s

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
