"""The hostile-master checks of ``scfmu check`` (run in the child process, see scfmu.check.gauntlet):
extreme start times, stale instance and FMU-state handles after their address was reused, and NaN written
into a serialized FMU state. Every finding here is of the robustness class (scfmu.check.rules): the
standard leaves these cases undefined or unmentioned.

A call that never returns is seen by the parent (the per-call time bound of scfmu.check.runner), which
fails the check as a hang with the call in progress; a crash likewise."""

from __future__ import annotations

import math
import struct

from .fmi import WARNING
from .unit import Unit, s_name
from .verdict import Fail, NotApplicable, _check_status_valid, _expect_ok, _need

START_TIMES = [s * 10.0 ** e for e in (6, 9, 12, 15, 17, 18, 20, 50, 100, 300) for s in (1, -1)]
NAN_BYTES = struct.pack("<d", math.nan)


def start_times(u: Unit, o: dict) -> dict:
    """For start times ±1e6 ... ±1e300: instantiate, initialise at that time and make 5 steps of the default
    step. Each call must return within the call bound (the parent's); a time the unit accepts must give
    finite outputs with OK, or be refused with an error status (at initialisation or at a step)."""
    accepted, refused = [], []
    for t0 in START_TIMES:
        u.trace.start(f"start times: t0 = {t0:g}")
        h = _need(u, u.new(), "instantiate")
        s = u.start(h, t0)
        _check_status_valid(u, s, f"initialisation at t0 = {t0:g}")
        where = "initialisation"
        if s <= WARNING:
            t = t0
            for _ in range(5):
                if h in u.ended:
                    break
                s = u.step(h, t, u.dt)
                _check_status_valid(u, s, "a step")
                if s > WARNING:
                    where = f"the step from {t!r}"
                    break
                t = u.now.pop(h, t + u.dt)
                s2, _, problem = u.outputs_ok(h)
                if problem:
                    raise Fail("nonfinite", f"start time {t0:g} accepted, then {problem}", "start_time")
        (accepted if s <= WARNING else refused).append(f"{t0:g}" + ("" if s <= WARNING else f" ({where})"))
        u.free(h)
    return {"detail": f"{len(START_TIMES)} start times from ±1e6 to ±1e300, every call returned: "
                      f"{len(accepted)} run 5 steps with finite outputs"
                      + (f", {len(refused)} refused: {', '.join(refused[:6])}" + (" ..." if len(refused) > 6
                                                                                   else "") if refused else ""),
            "metrics": {"accepted": len(accepted), "refused": len(refused)}}


def _same_address(u: Unit, stale: int, tries: int) -> tuple[int | None, list]:
    """Instantiates until an instance has the freed handle's value (or `tries` times); (that instance or
    None, the other instances, still live: freed by the caller)."""
    others = []
    for _ in range(tries):
        h = u.new()
        if h is None:
            break
        if h == stale:
            return h, others
        if u.spec["only_once"]:
            u.free(h)
        else:
            others.append(h)
    return None, others


def _stale_instance(u: Unit, o: dict) -> str:
    u.trace.start("stale handles: a freed instance called after its address was reused")
    a = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(a), "initialization")
    u.free(a)
    b, others = _same_address(u, a, o["reuse_tries"])
    reused = b is not None
    if reused:
        u.lib.names[a] = u.lib.names[b] = "b"
        u.trace.note(f"the new instance b has the freed instance's address 0x{a:x}; the stale handle is that value")
        _expect_ok(u, u.start(b), "initialization of the new instance")
    else:
        u.lib.names[a] = "stale"
        u.trace.note(f"no new instance got the freed address in {o['reuse_tries']} tries; calling the freed handle")
    s = u.step(a, u.start_time, u.dt)  # a Model Exchange unit: SetTime and the Euler step's calls
    _check_status_valid(u, s, "a call on a freed instance")
    for h in others + ([b] if reused else []):
        u.free(h)
    if s <= WARNING:
        how = "its address was given to a new instance, which the call then acted on" if reused else \
            "the freed handle was used as if it were live"
        raise Fail("stale_handle", f"a step on a freed instance returned {s_name(u.v, s)} ({how})", "stale_handle")
    return f"a freed instance {'whose address was reused ' if reused else ''}refused ({s_name(u.v, s)})"


def _stale_state(u: Unit) -> str:
    u.trace.start("stale handles: a freed FMU state set after a new one was taken")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    s, s1 = u.get_state(h)
    _expect_ok(u, s, "getting the FMU state")
    _expect_ok(u, u.free_state(h, s1), "freeing the FMU state")
    s, s2 = u.get_state(h)
    _expect_ok(u, s, "getting a second FMU state")
    reused = s2 == s1
    u.trace.note(f"the second state {'has' if reused else 'does not have'} the freed state's address")
    s = u.set_state(h, s1)
    _check_status_valid(u, s, "setting a freed FMU state")
    u.free_state(h, s2)
    u.free(h)
    if s <= WARNING:
        raise Fail("stale_handle", f"setting a freed FMU state returned {s_name(u.v, s)}"
                   + (" (its address was reused by a new state)" if reused else ""), "stale_handle")
    return f"a freed FMU state {'whose address was reused ' if reused else ''}refused ({s_name(u.v, s)})"


def stale_handles(u: Unit, o: dict) -> dict:
    """Free an instance, instantiate until a new instance has the same address (up to `reuse_tries`), then
    call the stale handle: it must be refused, not act on the new instance. The same for a freed FMU state
    (where the unit can get FMU states). A crash is reported by the parent."""
    parts = [_stale_instance(u, o)]
    if u.spec["can_get_set_state"]:
        parts.append(_stale_state(u))
    return {"detail": "; ".join(parts)}


def _nan_offsets(n_bytes: int, most: int) -> list[int]:
    """The 8-byte-aligned offsets to write NaN at: all of them, or `most` spread evenly over the state."""
    words = n_bytes // 8
    if words <= most:
        return [8 * k for k in range(words)]
    return sorted({8 * (k * words // most) for k in range(most)})


def state_nan(u: Unit, o: dict) -> dict:
    """Where the unit can serialize its FMU state: NaN written over each 8-byte-aligned word of a serialized
    state (the layout of a foreign unit is unknown: every word is tried, or `nan_words` spread evenly), then
    deserialize, set and 3 steps: the unit must refuse the state (at deserialize, set or the step) or step
    with finite outputs. Reports how many were refused and how many restored states still hold the NaN
    when serialized again (a dormant NaN: noted, not failed, since the word may not be a float)."""
    if not u.spec["can_serialize_state"]:
        raise NotApplicable("canSerializeFMUstate is false")
    if u.spec["only_once"]:
        raise NotApplicable("canBeInstantiatedOnlyOncePerProcess: no second instance to restore into")
    u.trace.start("NaN in a state: the state to corrupt")
    h = _need(u, u.new(), "instantiate")
    _expect_ok(u, u.start(h), "initialization")
    t = u.start_time
    for _ in range(3):
        _expect_ok(u, u.step(h, t, u.dt), "a step")
        t = u.now.pop(h, t + u.dt)
    s, st = u.get_state(h)
    _expect_ok(u, s, "getting the FMU state")
    s, data = u.serialize(h, st)
    _expect_ok(u, s, "serializing the FMU state")
    u.free_state(h, st)
    u.free(h)
    offsets = _nan_offsets(len(data), o["nan_words"])
    refused = usable = dormant = 0
    for off in offsets:
        u.trace.start(f"NaN in a state: bytes {off}..{off + 7} of {len(data)}")
        bad = data[:off] + NAN_BYTES + data[off + 8:]
        h = _need(u, u.new(), "instantiate")
        _expect_ok(u, u.start(h), "initialization")
        s, st = u.deserialize(h, bad, label=f"state with NaN at byte {off}")
        _check_status_valid(u, s, "deserialize")
        if s > WARNING or not st:
            refused += 1
            u.free(h)
            continue
        s = u.set_state(h, st)
        _check_status_valid(u, s, "set the deserialized state")
        ok = s <= WARNING
        if ok:
            u.forget(h)
            s = u.step(h, t, u.dt)
            _check_status_valid(u, s, "a step")
            ok = s <= WARNING
            if ok:
                _, _, problem = u.outputs_ok(h)
                if problem:
                    raise Fail("nonfinite", f"a state with NaN at byte {off} was accepted, then {problem}",
                               "finite_outputs")
                s2, st2 = u.get_state(h)
                if s2 <= WARNING and st2:
                    s3, again = u.serialize(h, st2)
                    if s3 <= WARNING and again is not None and NAN_BYTES in again and NAN_BYTES not in data:
                        dormant += 1
                    u.free_state(h, st2)
        usable += ok
        refused += not ok
        u.free_state(h, st)
        u.free(h)
    return {"detail": f"NaN written over {len(offsets)} of {len(data) // 8} 8-byte words of a {len(data)}-byte "
                      f"state: {refused} refused, {usable} restored and stepped with finite outputs"
                      + (f" ({dormant} of them still hold a NaN when serialized again)" if dormant else ""),
            "metrics": {"words": len(offsets), "refused": refused, "usable": usable, "dormant": dormant}}
