"""The dynamic checks of ``scfmu check`` (they run in a child process: see scfmu.check.runner).

Each check takes a :class:`~scfmu.check.unit.Unit` and the options and returns a result dict
(status "pass" | "fail" | "n/a", kind, detail, reproducer, metrics). A failure raises :class:`Fail`; the
reproducer is the call list of the scenario that failed (the current :class:`~scfmu.check.fmi.Trace`).
A crash or a hang is seen by the parent, which has the same call list from the child's output. The
verdicts and shared steps are in scfmu.check.verdict, the misuse checks (bad arguments, random call
sequences) in scfmu.check.misuse."""

from __future__ import annotations

import random
import threading
import time

from .fmi import OK, WARNING, Lib
from .hostile import stale_handles, start_times, state_nan
from .misuse import bad_arguments, random_sequences
from .unit import Unit, s_name
from .verdict import (Fail, NotApplicable, _bits, _check_status_valid, _expect_ok, _expect_refused, _inputs_fn,
                      _need, _rss, _steps)

# ============================================================================================ checks
def nominal_run(u: Unit, o: dict) -> dict:
    """The default experiment (capped at `steps`): every call OK, every output finite."""
    u.trace.start("nominal run")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    n = max(1, min(o["steps"], int(round((u.spec["stop_time"] - u.start_time) / u.dt)) or o["steps"]))
    t, outs = _steps(u, h, u.start_time, n, _inputs_fn(u, o["seed"]))
    ended = u.ended.get(h)
    _expect_ok(u, u.terminate(h), "terminate")
    u.free(h)
    return {"detail": f"{len(outs)} steps of {u.dt:g} s from t = {u.start_time:g} to {t:g}: every call OK, outputs "
                      "finite" + (f"; the unit ended the simulation ({ended})" if ended else ""),
            "metrics": {"steps": len(outs), "ended": bool(ended)}}


def _cs_forbidden(u: Unit):
    """(title, reach, call): a call the standard forbids in the state `reach` leads to."""
    p = u.p
    init = lambda h: u.enter_init(h)  # noqa: E731
    ready = lambda h: u.start(h)  # noqa: E731

    def term(h):
        u.start(h)
        return u.terminate(h)
    inp = u.real_inputs[:1]
    step = lambda h: u.step(h, u.start_time, u.dt)  # noqa: E731
    items = [
        ("step in Instantiated", None, step),
        ("step in Initialization Mode", init, step),
        ("step after terminate", term, lambda h: u.step(h, u.start_time + u.dt, u.dt)),
        (f"{p}ExitInitializationMode in Instantiated", None, lambda h: u.exit_init(h)),
        (f"{p}EnterInitializationMode twice", init, lambda h: u.enter_init(h)),
        (f"{p}EnterInitializationMode after initialization", ready, lambda h: u.enter_init(h)),
        (f"{p}ExitInitializationMode after initialization", ready, lambda h: u.exit_init(h)),
        (f"{p}Terminate in Instantiated", None, lambda h: u.terminate(h)),
    ]
    if u.v == 2:  # FMI 2.0's tables (the FMI 3.0 ones differ in detail here; not judged there)
        items.append(("fmi2SetupExperiment after initialization", ready,
                      lambda h: u.lib.call("fmi2SetupExperiment", h, 0, 0.0, 0.0, 0, 0.0)))
        items.append(("fmi2Terminate in Initialization Mode", init, lambda h: u.terminate(h)))
        items.append(("fmi2Terminate after terminate", term, lambda h: u.terminate(h)))
        if u.outputs:
            items.append(("reading the outputs in Instantiated", None, lambda h: u.get(h, u.outputs[:1])[0]))
    if inp and u.v == 2:  # FMI 3.0 allows setting variables in Terminated (as the Reference-FMUs do)
        items.append((f"setting input {inp[0]['name']} after terminate", term,
                      lambda h: u.set(h, inp, [inp[0].get("start") or 0.0])))
    if u.me:
        p = u.p
        n = u.nx
        from ctypes import c_double

        def set_states(h):
            xs = (c_double * max(n, 1))()
            return u.lib.call(f"{p}SetContinuousStates", h, xs, n, shown=[u.lib.handle_name(h), "x", str(n)])

        def derivs(h):
            dx = (c_double * max(n, 1))()
            name = "fmi2GetDerivatives" if u.v == 2 else "fmi3GetContinuousStateDerivatives"
            return u.lib.call(name, h, dx, n, shown=[u.lib.handle_name(h), "dx", str(n)])

        def event_mode(h):
            s = u.enter_init(h)
            return max(s, u.exit_init(h))
        items = [it for it in items if not it[0].startswith("step")]
        items += [
            (f"{p}SetTime in Instantiated", None, lambda h: u.lib.call(f"{p}SetTime", h, 0.0)),
            (f"{p}EnterContinuousTimeMode in Instantiated", None, lambda h: u.lib.call(f"{p}EnterContinuousTimeMode", h)),
            (f"{p}EnterContinuousTimeMode in Continuous-Time Mode", ready,
             lambda h: u.lib.call(f"{p}EnterContinuousTimeMode", h)),
            (f"{p}CompletedIntegratorStep in Event Mode", event_mode, lambda h: _completed(u, h)),
            (f"{p}EnterEventMode in Instantiated", None, lambda h: u.lib.call(f"{p}EnterEventMode", h)),
            ("event update in Continuous-Time Mode", ready, lambda h: u.event_iteration(h, limit=1)),
        ]
        if n:
            items += [(f"{p}SetContinuousStates in Instantiated", None, set_states),
                      (f"{p}SetContinuousStates in Event Mode", event_mode, set_states),
                      ("the derivatives in Instantiated", None, derivs)]
    return items


def _completed(u: Unit, h):
    from ctypes import byref, c_bool, c_int
    if u.v == 2:
        a, b = c_int(), c_int()
        return u.lib.call("fmi2CompletedIntegratorStep", h, 1, byref(a), byref(b),
                          shown=[u.lib.handle_name(h), "fmi2True", "&enterEventMode", "&terminateSimulation"])
    a, b = c_bool(), c_bool()
    return u.lib.call("fmi3CompletedIntegratorStep", h, True, byref(a), byref(b),
                      shown=[u.lib.handle_name(h), "true", "&enterEventMode", "&terminateSimulation"])


def state_machine(u: Unit, o: dict) -> dict:
    """Calls the standard forbids in a state must be refused (an error status); calls it allows must work:
    the outputs in Initialization Mode, after a step and after terminate, Reset from every state and after
    an error, free in every state."""
    failures, first = [], None
    n_calls = 0
    for title, reach, call in _cs_forbidden(u):
        u.trace.start(f"state machine: {title}")
        h = _need(u, u.new(), "instantiate")
        if reach is not None:
            s = reach(h)
            if s > WARNING:
                raise Fail("error_status", f"reaching the state for '{title}' failed: "
                                           f"{u.trace.lines[-1] if u.trace.lines else ''}", "allowed_call")
        s = call(h)
        n_calls += 1
        _check_status_valid(u, s, title)
        if s <= WARNING:
            failures.append(f"{title} returned {s_name(u.v, s)}")
            if first is None:
                first = list(u.trace.lines)
        u.free(h)
    # allowed calls
    u.trace.start("state machine: allowed calls")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.enter_init(h), "initialization", rule="allowed_call")
    if u.outputs:
        _expect_ok(u, u.outputs_ok(h)[0], "reading the outputs in Initialization Mode", rule="allowed_call")
    _expect_ok(u, u.exit_init(h), "exit initialization", rule="allowed_call")
    u.free(h)
    for where in ("after a step", "after terminate", "after an error"):
        u.trace.start(f"state machine: Reset {where}")
        h = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h), "initialization", rule="allowed_call")
        _expect_ok(u, u.step(h, u.start_time, u.dt), "a step", rule="allowed_call")
        if where == "after terminate":
            _expect_ok(u, u.terminate(h), "terminate", rule="allowed_call")
            if u.outputs:
                s, _, problem = u.outputs_ok(h)
                _expect_ok(u, s, "reading the outputs after terminate", rule="allowed_call")
        if where == "after an error":
            u.lib.call(f"{u.p}ExitInitializationMode", h)  # forbidden here: an error (checked above)
        _expect_ok(u, u.reset(h), f"{u.p}Reset {where}", rule="allowed_call")
        _expect_ok(u, u.start(h), f"initialization after {u.p}Reset", rule="allowed_call")
        _steps(u, h, u.start_time, 3)
        u.free(h)
    u.trace.start("state machine: free in every state")
    for reach in (None, lambda h: u.enter_init(h), lambda h: u.start(h)):
        h = _need(u, u.new(), "instantiate")
        if reach:
            reach(h)
        u.free(h)
    if failures:
        u.trace.lines = first
        raise Fail("wrong_state", f"{len(failures)} of {n_calls} calls in a forbidden state were accepted: "
                   + "; ".join(failures[:4]) + (" ..." if len(failures) > 4 else ""))
    return {"detail": f"{n_calls} calls in forbidden states refused; outputs readable in Initialization Mode and "
                      "after terminate; Reset works after a step, terminate and an error",
            "metrics": {"forbidden_calls": n_calls}}


def _corrupted_states(u: Unit, o: dict, data: bytes, t: float) -> tuple[int, int, int]:
    """Corrupted serialized states (empty, truncated, garbage, NULL, random byte changes) deserialized and
    set into fresh instances: refused, or usable with finite outputs; returns (cases, refused, usable)."""
    rng = random.Random(o["seed"] * 31 + 7)
    refused = usable = 0
    cases = [("empty", b""), ("truncated", data[: len(data) // 2]), ("one byte short", data[:-1]),
             ("garbage", bytes(rng.randrange(256) for _ in range(len(data)))), ("NULL", None)]
    for i in range(o["mutations"]):
        b = bytearray(data)
        for _ in range(rng.choice([1, 1, 2, 4, 16])):
            pos = rng.randrange(len(b))
            b[pos] = rng.randrange(256)
        cases.append((f"mutation {i}", bytes(b)))
    h3 = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h3), "initialization")
    for label, bad in cases:
        u.trace.start(f"FMU state: deserialize a corrupted state ({label})")
        s, st3 = u.deserialize(h3, bad, label=label)
        _check_status_valid(u, s, "deserialize")
        if s > WARNING or not st3:
            if label in ("empty", "NULL") and s <= WARNING:
                raise Fail("wrong_status", f"deserializing a {label} state returned {s_name(u.v, s)}")
            refused += 1
            if s > WARNING:
                u.reset(h3)
                u.free(h3)
                h3 = _need(u, u.new(), "instantiate")
                _expect_ok(u, u.start(h3), "initialization")
            continue
        s = u.set_state(h3, st3)
        if s <= WARNING:
            u.forget(h3)
            s = u.step(h3, t, u.dt)
            if s <= WARNING:
                _, _, problem = u.outputs_ok(h3)
                if problem:
                    raise Fail("nonfinite", f"a corrupted state ({label}) was accepted, then {problem}")
            usable += 1
        else:
            refused += 1
        u.free_state(h3, st3)
        u.free(h3)
        h3 = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h3), "initialization")
    u.free(h3)
    return len(cases), refused, usable


def fmu_state(u: Unit, o: dict) -> dict:
    """Get/set FMU state round trip (bit-identical continuation), serialize/deserialize into another
    instance, and corrupted serialized states (random byte changes, truncation, empty, NULL): refused or
    usable (finite outputs), never a crash."""
    if not u.spec["can_get_set_state"]:
        raise NotApplicable("canGetAndSetFMUstate is false")
    inputs = _inputs_fn(u, o["seed"])
    u.trace.start("FMU state: get, step, set, step again")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    t, _ = _steps(u, h, u.start_time, 5, inputs)
    s, st = u.get_state(h)
    _expect_ok(u, s, "getting the FMU state")
    x_saved, te_saved = list(u.x.get(h, [])), u.next_event.get(h)
    n = 10
    _, y1 = _steps(u, h, t, n, lambda k: inputs(k + 5))
    _expect_ok(u, u.set_state(h, st), "setting the FMU state")
    u.forget(h)
    if u.me:  # the checker's own integrator state goes back with the unit's
        u.x[h], u.next_event[h] = list(x_saved), te_saved
    _, y2 = _steps(u, h, t, n, lambda k: inputs(k + 5))
    if _bits(y1) != _bits(y2):
        raise Fail("nondeterministic", "the steps after restoring the FMU state differ from the first ones")
    metrics = {"round_trip": "bit-identical"}
    detail = "get/set round trip bit-identical"
    if u.spec["can_serialize_state"] and u.spec["only_once"]:
        detail += "; serialization not checked (canBeInstantiatedOnlyOncePerProcess: no second instance)"
    elif u.spec["can_serialize_state"]:
        u.trace.start("FMU state: serialize, deserialize into a second instance")
        s, data = u.serialize(h, st)
        _expect_ok(u, s, "serializing the FMU state")
        h2 = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h2), "initialization")
        s, st2 = u.deserialize(h2, data)
        _expect_ok(u, s, "deserializing the FMU state")
        _expect_ok(u, u.set_state(h2, st2), "setting the deserialized FMU state")
        u.forget(h2)
        if u.me:
            u.x[h2], u.next_event[h2] = list(x_saved), te_saved
        _, y3 = _steps(u, h2, t, n, lambda k: inputs(k + 5))
        if _bits(y1) != _bits(y3):
            raise Fail("nondeterministic", "a second instance restored from the serialized state steps differently")
        u.free_state(h2, st2)
        u.free(h2)
        n_cases, refused, usable = _corrupted_states(u, o, data, t)
        detail += (f"; serialized ({len(data)} bytes) and restored in a second instance bit-identical; "
                   f"{n_cases} corrupted states: {refused} refused, {usable} usable with finite outputs")
        metrics.update(serialized_bytes=len(data), corrupted=n_cases, refused=refused, usable=usable)
    u.trace.start("FMU state: set a NULL state")
    _expect_refused(u, u.set_state(h, None), "setting a NULL FMU state", rule="invalid_argument")
    u.free_state(h, st)
    u.free(h)
    return {"detail": detail, "metrics": metrics}


def memory(u: Unit, o: dict) -> dict:
    """Repeated instantiate/initialize/step/free cycles and library load/unload cycles with the resident
    memory measured: the growth over the second half of the cycles must stay below the limit."""
    cycles, loads = o["cycles"], o["loads"]
    limit = o["memory_limit"]

    def one(unit):
        h = _need(unit, unit.new(), "instantiate")
        _expect_ok(unit, unit.start(h), "initialization")
        _steps(unit, h, unit.start_time, 3)
        s, st = (unit.get_state(h) if unit.spec["can_get_set_state"] else (OK, None))
        if st:
            unit.free_state(h, st)
        unit.terminate(h)
        unit.free(h)

    u.trace.start("memory: instantiate/free cycles")
    warm = max(10, cycles // 10)
    for _ in range(warm):
        one(u)
        u.trace.lines.clear()
    r0 = _rss()
    for i in range(cycles):
        if i == cycles // 2:
            r_half = _rss()
        one(u)
        u.trace.lines.clear()
    r1 = _rss()
    per_cycle = (r1 - r_half) / max(1, cycles - cycles // 2)
    u.trace.start("memory: instantiate/free cycles")
    one(u)
    if r1 - r_half > limit:
        raise Fail("leak", f"resident memory grew by {(r1 - r_half) / 1024:.0f} kB over the last "
                   f"{cycles - cycles // 2} instantiate/free cycles ({per_cycle / 1024:.1f} kB per instance; "
                   f"limit {limit / 1024:.0f} kB)")
    # load / unload
    u.trace.start("memory: load/unload cycles")
    r2 = _rss()
    rl = None
    for i in range(loads):
        if i == loads // 2:
            rl = _rss()
        lib = Lib(u.spec["library"], u.v, u.trace)
        u2 = Unit(u.spec, u.trace, lib)
        one(u2)
        lib.unload()
        u.trace.lines.clear()
    r3 = _rss()
    load_growth = r3 - (rl if rl is not None else r2)
    if load_growth > 4 * limit:
        raise Fail("leak", f"resident memory grew by {load_growth / 1024:.0f} kB over the last "
                   f"{loads - loads // 2} load/unload cycles (limit {4 * limit / 1024:.0f} kB)")
    return {"detail": f"{cycles} instantiate/free cycles: {(r1 - r0) / 1024:+.0f} kB in all, "
                      f"{per_cycle:+.0f} B per instance over the second half; {loads} load/unload cycles: "
                      f"{load_growth / 1024:+.0f} kB over the second half",
            "metrics": {"cycles": cycles, "rss_growth_bytes": r1 - r0, "bytes_per_instance_second_half": per_cycle,
                        "loads": loads, "load_growth_bytes": load_growth}}


def _join_announcing(u: Unit, ts: list, traces: list) -> None:
    """Waits for the threads, announcing their progress (the calls their traces record) as a call that
    returns whenever a call of any thread has returned: the parent's per-call time bound then sees a thread
    that hangs as a call that does not return."""
    line = f"(the calls of {len(ts)} threads)"
    done = -1
    while any(th.is_alive() for th in ts):
        n = sum(len(t.lines) for t in traces)
        if n != done:
            if done >= 0:
                u.trace.done(line)
            u.trace.add(line + " ...")
            done = n
        time.sleep(0.05)
    if done >= 0:
        u.trace.done(line)


def threads(u: Unit, o: dict) -> dict:
    """The same inputs on N threads at once (one instance each): every thread's outputs bit-identical to
    a run on the main thread."""
    if u.spec["only_once"]:
        raise NotApplicable("canBeInstantiatedOnlyOncePerProcess is true")
    nt, n = o["threads"], o["thread_steps"]
    inputs = _inputs_fn(u, o["seed"])
    u.trace.start("threads: reference run on the main thread")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    _, ref = _steps(u, h, u.start_time, n, inputs)
    u.free(h)
    ref_bits = _bits(ref)
    results: list = [None] * nt
    barrier = threading.Barrier(nt)
    from .fmi import Trace
    tu = []
    for _ in range(nt):
        tr = Trace(None)
        tu.append(Unit(u.spec, tr, Lib(u.spec["library"], u.v, tr)))

    def work(i):
        try:
            w = tu[i]
            w._counter = 100 * (i + 1)
            hh = w.new()
            if hh is None:
                results[i] = "instantiation returned NULL"
                barrier.abort()  # the others must not wait for this thread
                return
            s = w.start(hh)
            barrier.wait(timeout=60)
            if s > WARNING:
                results[i] = f"initialization returned {s_name(u.v, s)}"
                return
            _, outs = _steps(w, hh, w.start_time, n, inputs)
            w.free(hh)
            results[i] = _bits(outs)
        except Fail as e:
            results[i] = e.detail
        except threading.BrokenBarrierError:
            results[i] = "another thread failed before the common start"
        except Exception as e:  # e.g. a function missing from the binary
            results[i] = f"{type(e).__name__}: {e}"

    u.trace.start(f"threads: {nt} threads, {n} steps each, the same inputs")
    u.trace.note(f"{nt} threads each: instantiate, initialize, {n} x (set inputs, step, get outputs), free")
    ts = [threading.Thread(target=work, args=(i,)) for i in range(nt)]
    for th in ts:
        th.start()
    _join_announcing(u, ts, [w.trace for w in tu])
    bad = [i for i, r in enumerate(results) if r != ref_bits]
    if bad:
        r = results[bad[0]]
        why = r if isinstance(r, str) else "outputs differ from the main thread's run"
        raise Fail("nondeterministic", f"{len(bad)} of {nt} threads: {why}")
    return {"detail": f"{nt} threads x {n} steps: outputs bit-identical to the main thread's run",
            "metrics": {"threads": nt, "steps": n}}


CHECKS = {"nominal_run": nominal_run, "state_machine": state_machine, "bad_arguments": bad_arguments,
          "random_sequences": random_sequences, "fmu_state": fmu_state, "memory": memory, "threads": threads,
          "start_times": start_times, "stale_handles": stale_handles, "state_nan": state_nan}
