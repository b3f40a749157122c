"""The misuse checks of ``scfmu check`` (run in the child process, see scfmu.check.gauntlet): bad arguments
(wrong and NULL tokens, NULL instances and arrays, unknown value references, non-finite inputs, bad steps)
and seeded random call sequences over the unit's state machine."""

from __future__ import annotations

import math
import random

from .fmi import OK, WARNING
from .unit import Unit, s_name
from .verdict import Fail, _check_status_valid, _expect_ok, _expect_refused, _need


def _bad_instantiation(u: Unit, notes: list) -> None:
    """A wrong and a NULL GUID/instantiation token are refused; NULL callbacks (FMI 2.0) noted if accepted."""
    u.trace.start("bad arguments: wrong GUID / instantiation token")
    h = u.new(token="{00000000-0000-0000-0000-000000000000}")
    if h is not None:
        u.free(h)
        raise Fail("wrong_status", "instantiation with a wrong GUID/instantiationToken returned an instance", "guid")
    u.trace.start("bad arguments: NULL GUID / instantiation token")
    h = u.new(null_token=True)
    if h is not None:
        u.free(h)
        raise Fail("wrong_status", "instantiation with a NULL GUID/instantiationToken returned an instance", "guid")
    if u.v == 2:
        u.trace.start("bad arguments: NULL callback functions")
        h = u.new(null_callbacks=True)
        if h is not None:
            u.free(h)
            notes.append("NULL callbacks accepted")


def _null_instance(u: Unit) -> None:
    """Every call on a NULL instance is refused."""
    p = u.p
    u.trace.start("bad arguments: NULL instance")
    calls = [(f"{p}EnterInitializationMode(NULL)", lambda: u.enter_init(None)),
             (f"{p}ExitInitializationMode(NULL)", lambda: u.exit_init(None)),
             (f"{p}Terminate(NULL)", lambda: u.terminate(None)),
             (f"{p}Reset(NULL)", lambda: u.reset(None))]
    if u.outputs:
        calls.append(("reading the outputs of NULL", lambda: u.get(None, u.outputs[:1])[0]))
    if u.real_inputs:
        calls.append(("setting an input of NULL", lambda: u.set(None, u.real_inputs[:1], [0.0])))
    if not u.me:
        calls.append(("a step of NULL", lambda: u.step(None, 0.0, u.dt)))
    for what, f in calls:
        _expect_refused(u, f(), what)
    u.lib.call(f"{p}FreeInstance", None)


def _null_arrays_and_unknown_reference(u: Unit) -> int:
    """NULL value-reference and value arrays and an unknown value reference (get and set) are refused;
    returns that value reference."""
    from ctypes import c_double, c_uint32
    v = u.v
    u.trace.start("bad arguments: NULL arrays and unknown value references")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    getter = "fmi2GetReal" if v == 2 else "fmi3GetFloat64"
    setter = "fmi2SetReal" if v == 2 else "fmi3SetFloat64"
    ext = [] if v == 2 else [1]
    real_out = [x for x in u.outputs if x["type"] in ("Real", "Float64")]
    if real_out:
        vr1 = (c_uint32 * 1)(real_out[0]["vr"])
        val = (c_double * 1)()
        hn = u.lib.handle_name(h)
        sh = [] if v == 2 else ["1"]
        _expect_refused(u, u.lib.call(getter, h, None, 1, val, *ext, shown=[hn, "NULL", "1", "values", *sh]),
                        f"{getter} with a NULL value-reference array")
        _expect_refused(u, u.lib.call(getter, h, vr1, 1, None, *ext, shown=[hn, f"{{{real_out[0]['vr']}}}", "1",
                                                                              "NULL", *sh]),
                        f"{getter} with a NULL value array")
    used = set(u.spec["all_vrs"])
    unknown = max(used, default=0) + 1000
    while unknown in used:
        unknown += 1
    vr = (c_uint32 * 1)(unknown)
    val = (c_double * 1)(0.0)
    hn = u.lib.handle_name(h)
    sh = [] if v == 2 else ["1"]
    s = u.lib.call(getter, h, vr, 1, val, *ext, shown=[hn, f"{{{unknown}}}", "1", "values", *sh])
    _expect_refused(u, s, f"{getter} of the unknown value reference {unknown}", rule="unknown_vr")
    u.free(h)
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    hn = u.lib.handle_name(h)
    s = u.lib.call(setter, h, vr, 1, val, *ext, shown=[hn, f"{{{unknown}}}", "1", "{0.0}", *sh])
    _expect_refused(u, s, f"{setter} of the unknown value reference {unknown}", rule="unknown_vr")
    u.free(h)
    return unknown


def _nonfinite_inputs(u: Unit) -> list:
    """Non-finite inputs, each on a fresh instance, then a step and the outputs: the unit may refuse them or
    accept them (a non-finite output with OK is then a NaN passed through, which the standard allows); what
    is checked is that every call returns and nothing crashes. Returns the inputs that accepted one."""
    accepted = []
    for var in u.real_inputs:
        for bad in (math.nan, math.inf, -math.inf):
            u.trace.start(f"bad arguments: input {var['name']} = {bad}")
            h = _need(u, u.new(), "instantiate")
            _expect_ok(u, u.start(h), "initialization")
            s = u.set(h, [var], [bad])
            if s <= WARNING:
                s = u.step(h, u.start_time, u.dt)
                if s <= WARNING:
                    u.outputs_ok(h)
                    accepted.append(var["name"])
            u.free(h)
    return accepted


def _bad_steps(u: Unit) -> bool:
    """Zero, negative and non-finite steps (Model Exchange: times) and a NaN communication point; returns
    whether a zero step was accepted."""
    p, v = u.p, u.v
    bad_steps = [(0.0, None), (-u.dt, "negative"), (math.nan, "NaN"), (math.inf, "infinite"), (-math.inf, "negative")]
    zero_ok = None
    for dt, must in bad_steps:
        u.trace.start(f"bad arguments: step size {dt}")
        h = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h), "initialization")
        if u.me:
            s = u.lib.call(f"{p}SetTime", h, u.start_time + dt if math.isfinite(dt) else dt)
            label = f"{p}SetTime to start time + {dt}"
            must = "NaN" if math.isnan(dt) else None  # time may be set back in Model Exchange
        else:
            s = u.step(h, u.start_time, dt)
            label = f"a step of size {dt}"
        _check_status_valid(u, s, label)
        if must and s <= WARNING:
            if must == "infinite":
                _, _, problem = u.outputs_ok(h)
                if problem:
                    raise Fail("nonfinite", f"{label} accepted, then {problem}")
            else:
                raise Fail("wrong_status", f"{label} returned {s_name(v, s)}; a {must} step must be refused "
                                           "(the standard does not say so; this project's rule does)")
        if dt == 0.0:
            zero_ok = s <= WARNING
        u.free(h)
    if not u.me:
        u.trace.start("bad arguments: NaN communication point")
        h = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h), "initialization")
        s = u.step(h, math.nan, u.dt)
        if s <= WARNING:
            raise Fail("wrong_status", f"a step from t = NaN returned {s_name(v, s)}; a NaN time must be refused")
        u.free(h)
    return zero_ok


def bad_arguments(u: Unit, o: dict) -> dict:
    """NULL pointers, a wrong GUID/token, unknown value references, NaN/Inf inputs, zero, negative and
    non-finite steps: refused (or, for values the unit accepts, no non-finite output with OK); never a crash."""
    notes = []
    _bad_instantiation(u, notes)
    _null_instance(u)
    unknown = _null_arrays_and_unknown_reference(u)
    accepted = _nonfinite_inputs(u)
    zero_ok = _bad_steps(u)
    detail = (f"wrong and NULL GUID refused, NULL instance and arrays refused, unknown value reference {unknown} "
              f"refused, non-finite inputs {'accepted by ' + ', '.join(sorted(set(accepted))[:3]) if accepted else 'refused'}, "
              f"negative/NaN steps refused, zero step {'accepted' if zero_ok else 'refused'}")
    if notes:
        detail += "; " + "; ".join(notes)
    return {"detail": detail, "metrics": {"nonfinite_inputs_accepted": len(accepted)}}


# ----------------------------------------------------------------------------------- random sequences
# the modelled states
INST, INIT, READY, TERM = "instantiated", "initialization", "ready", "terminated"
ACTIONS = ("set", "get", "step", "step", "step", "bad_step", "enter_init", "exit_init", "terminate", "reset",
           "state", "free_new", "extreme")


# the calls a well-behaved master makes in each state (three quarters of the calls; the rest are any call)
LEGAL = {INST: ("enter_init", "set", "state"), INIT: ("set", "get", "exit_init", "exit_init"),
         READY: ("set", "get", "step", "step", "step", "step", "state", "extreme", "terminate"),
         TERM: ("get", "reset", "free_new")}


class _Sequence:
    """One random call sequence: the instance, its modelled state `st`, its time and a saved FMU state."""

    def __init__(self, u: Unit, rng: random.Random, k: int):
        self.u, self.rng, self.k = u, rng, k
        self.h = _need(u, u.new(), "instantiate")
        self.st, self.t = INST, u.start_time
        self.saved = None
        self.tainted = False  # a non-finite or extreme input was accepted: non-finite outputs may follow

    def next_action(self) -> str:
        rng = self.rng
        return rng.choice(ACTIONS) if rng.random() < 0.25 else rng.choice(LEGAL[self.st] if self.st in LEGAL
                                                                           else ACTIONS)

    def _set(self, a: str) -> tuple[int, bool] | None:
        u, rng = self.u, self.rng
        if a == "set":
            if not u.inputs:
                return None
            base = u.nominal_inputs()
            scale = rng.choice([0.0, 0.0, 1e-3, 0.1])  # mostly the start values, sometimes perturbed
            vals = [b + rng.gauss(0, scale * (1 + abs(b))) if var["type"] in ("Real", "Float64") else b
                    for var, b in zip(u.inputs, base)]
            vals = [min(max(x, var["min"]), var["max"]) if var["type"] in ("Real", "Float64") and
                    var.get("min") is not None and var.get("max") is not None else x
                    for var, x in zip(u.inputs, vals)]
            return u.set(self.h, u.inputs, vals), self.st == TERM and u.v == 2  # FMI 3.0 allows it
        if not u.real_inputs:  # "extreme"
            return None
        var = rng.choice(u.real_inputs)
        x = rng.choice([math.nan, math.inf, -math.inf, 1e300, -1e300, 5e-324])
        s = u.set(self.h, [var], [x])
        if s <= WARNING:
            self.tainted = True
        return s, self.st == TERM and u.v == 2

    def _step(self, a: str) -> tuple[int, bool]:
        u, rng, h, t, st = self.u, self.rng, self.h, self.t, self.st
        if st == READY and h in u.ended:  # the unit asked to end the simulation: a master terminates
            return self._mode("terminate")
        forbidden = False
        dt = u.dt * rng.choice([1, 1, 1, 0.5, 2, 10]) if a == "step" else \
            rng.choice([0.0, -u.dt, math.nan, 1e9 * u.dt])
        if u.me and st == READY:
            s = u.me_step(h, t, dt) if math.isfinite(dt) and dt > 0 else \
                u.lib.call(f"{u.p}SetTime", h, t + dt if not math.isnan(dt) else dt)
            if s <= WARNING and math.isnan(dt):
                forbidden, self.why = True, "invalid_argument"
        else:
            forbidden = st != READY or (a == "bad_step" and (math.isnan(dt) or dt < 0))
            self.why = "state_machine" if st != READY else "invalid_argument"
            s = u.step(h, t, dt)
        if s <= WARNING and st == READY and math.isfinite(dt) and dt > 0:
            self.t = u.now.pop(h, self.t + dt)
        if s <= WARNING and dt > 1e6 * u.dt:
            self.tainted = True  # a huge step may overflow a state: not a finding of finite inputs
        return s, forbidden

    def _mode(self, a: str) -> tuple[int, bool]:
        u, h, st = self.u, self.h, self.st
        if a == "enter_init":
            s = u.enter_init(h, self.t) if st == INST or self.rng.random() < 0.5 else \
                u.lib.call(f"{u.p}EnterInitializationMode", h) if u.v == 2 else u.enter_init(h, self.t)
            if s <= WARNING:
                self.st = INIT
            return s, st != INST
        if a == "exit_init":
            s = u.exit_init(h)
            if s <= WARNING and st == INIT:
                self.st = READY
                if u.me:
                    s = max(s, u.event_iteration(h))
                    if s <= WARNING:
                        s = max(s, u.lib.call(f"{u.p}EnterContinuousTimeMode", h))
            return s, st != INIT
        if a == "terminate":
            s = u.terminate(h)
            if s <= WARNING and st != INST:
                self.st = TERM
            return s, st == INST
        s = u.reset(h)  # "reset"
        if s <= WARNING:
            self.st, self.t, self.tainted = INST, u.start_time, False
        return s, False

    def _state(self) -> tuple[int, bool] | None:
        u, h = self.u, self.h
        if not u.spec["can_get_set_state"]:
            return None
        s = OK
        if self.saved is None or self.rng.random() < 0.5:
            if self.saved is not None:
                u.free_state(h, self.saved)
            s, self.saved = u.get_state(h)
            if s > WARNING:
                self.saved = None
        else:
            s = u.set_state(h, self.saved)
            if s <= WARNING:
                self.st = "unknown"  # the restored state's mode is not modelled: re-initialise
                u.forget(h)
        return s, False

    why = "state_machine"  # the rule a forbidden call of the last action breaks

    def call(self, a: str) -> tuple[int, bool] | None:
        """Makes the call `a`: (status, whether the call is forbidden in the modelled state), or None when
        the call was not made (nothing to set, no outputs yet, no FMU states, a new instance)."""
        u = self.u
        if a in ("set", "extreme"):
            return self._set(a)
        if a == "get":
            if not u.outputs or self.st == INST:
                return None
            s, _, problem = u.outputs_ok(self.h)
            if problem and not self.tainted:
                raise Fail("nonfinite", f"random sequence {self.k}: {problem}")
            return s, False
        if a in ("step", "bad_step"):
            return self._step(a)
        if a in ("enter_init", "exit_init", "terminate", "reset"):
            self.why = "state_machine"
            return self._mode(a)
        if a == "state":
            return self._state()
        self.drop_state()  # "free_new"
        u.free(self.h)
        self.h = _need(u, u.new(), "instantiate")
        self.st, self.t, self.tainted = INST, u.start_time, False
        return None

    def drop_state(self) -> None:
        if self.saved is not None:
            self.u.free_state(self.h, self.saved)
            self.saved = None

    def reinitialise(self) -> None:
        """After an error: reset (or a new instance) and initialise again."""
        u = self.u
        self.drop_state()
        s = u.reset(self.h)
        if s > WARNING:
            u.free(self.h)
            self.h = _need(u, u.new(), "instantiate")
        s = u.start(self.h)
        self.tainted = False
        self.st, self.t = (READY, u.start_time) if s <= WARNING else (INST, u.start_time)


def random_sequences(u: Unit, o: dict) -> dict:
    """`sequences` seeded random call sequences of `length` calls from the unit's state machine (legal calls,
    forbidden calls, extreme values, bad steps, FMU states), re-initialised after every error so that
    sequences reach deep states. Fails on a forbidden call accepted, a non-finite output returned with OK, an
    invalid status or (seen by the parent) a crash or hang. Reports the share of calls that succeeded."""
    rng = random.Random(o["seed"] * 7919 + 11)
    n_seq, length = o["sequences"], o["length"]
    total = ok = reinit = 0
    for k in range(n_seq):
        u.trace.start(f"random sequence {k} (seed {o['seed']})")
        q = _Sequence(u, rng, k)
        for _ in range(length):
            a = q.next_action()
            r = q.call(a)
            if r is None:
                continue
            s, forbidden = r
            total += 1
            _check_status_valid(u, s, a)
            if forbidden and s <= WARNING and q.st != "unknown":
                last = u.trace.lines[-1] if u.trace.lines else a
                raise Fail("wrong_state" if q.why == "state_machine" else "wrong_status",
                           f"random sequence {k}: {last.split(' -> ')[0]} is forbidden in state '{q.st}' but "
                           f"returned {s_name(u.v, s)}", q.why)
            if s <= WARNING:
                ok += 1
            if s > WARNING or q.st == "unknown":
                reinit += 1
                q.reinitialise()
        q.drop_state()
        u.free(q.h)
    share = ok / total if total else 0.0
    return {"detail": f"{n_seq} sequences x {length} calls (seed {o['seed']}): {ok} of {total} calls succeeded "
                      f"({100 * share:.1f} %), {reinit} re-initialisations after errors",
            "metrics": {"sequences": n_seq, "calls": total, "succeeded": ok, "share_succeeded": share,
                        "reinitialisations": reinit}}
