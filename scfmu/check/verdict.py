"""The verdicts and shared steps of the dynamic checks of ``scfmu check`` (scfmu.check.gauntlet,
scfmu.check.misuse): :class:`Fail` (kind, detail), :class:`NotApplicable`, the status expectations, stepping
with checked outputs, the input sequence. Runs in the child process."""

from __future__ import annotations

import struct

from .fmi import DISCARD, OK, WARNING
from .unit import Unit, s_name

NOT_OK = "a status other than OK/Warning"


class Fail(Exception):
    """A finding: `kind` (what happened), `detail`, and `rule` (a key of scfmu.check.rules.RULES; by default
    the rule of the kind)."""

    def __init__(self, kind: str, detail: str, rule: str | None = None):
        super().__init__(detail)
        self.kind, self.detail, self.rule = kind, detail, rule


class NotApplicable(Exception):
    pass


def _rss() -> int:
    """Resident set size of this process in bytes (Linux /proc; elsewhere the peak from getrusage)."""
    try:
        with open("/proc/self/statm") as f:
            import os
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        import resource
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _need(u: Unit, h, what: str):
    if h is None:
        raise Fail("error_status", f"{what}: instantiation returned NULL")
    return h


def _expect_refused(u: Unit, s: int, what: str, kind: str = "wrong_status", rule: str | None = None):
    if s in (OK, WARNING):
        why = "the standard prescribes an error status" if rule and rule != "invalid_argument" else \
            "an invalid argument must be refused with an error status"
        raise Fail(kind, f"{what} returned {s_name(u.v, s)}; {why}", rule)


def _expect_ok(u: Unit, s: int, what: str, rule: str | None = None):
    if s > WARNING:
        raise Fail("error_status", f"{what} returned {s_name(u.v, s)} ({last_message(u)})", rule)


def last_message(u: Unit) -> str:
    """The last message the unit logged during its last call (an earlier call's message is not quoted)."""
    mine = u.messages[u.lib.mark:] if u.lib.log is u.messages else []
    return f'its message: "{mine[-1][1]}"' if mine else "no log message during that call"


def _check_status_valid(u: Unit, s: int, what: str):
    if not 0 <= s <= (5 if u.v == 2 else 4):
        raise Fail("invalid_status", f"{what} returned the invalid status value {s}")


def _steps(u: Unit, h, t: float, n: int, inputs=None) -> tuple[float, list]:
    """Up to n steps of u.dt with the outputs checked after each; returns (time, outputs after each step).
    The run ends early, as a master's would, when the unit asks to end the simulation (terminateSimulation,
    or fmi2Discard from a Co-Simulation step: u.ended[h] says which)."""
    outs = []
    for k in range(n):
        if h in u.ended:
            break
        if inputs is not None:
            _expect_ok(u, u.set(h, u.inputs, inputs(k)), "setting the inputs")
        s = u.step(h, t, u.dt)
        _check_status_valid(u, s, "a step")
        if s == DISCARD and not u.me:
            u.ended[h] = f"the step from t = {t!r} returned {s_name(u.v, s)}"
            break
        _expect_ok(u, s, f"the step from t = {t!r}")
        t = u.now.pop(h, t + u.dt)
        s, vals, problem = u.outputs_ok(h)
        _expect_ok(u, s, "reading the outputs")
        if problem:
            raise Fail("nonfinite", problem)
        outs.append(vals)
    return t, outs


def _bits(rows) -> bytes:
    return b"".join(struct.pack(f"<{len(r)}d", *[float(x) for x in r]) for r in rows)


def _inputs_fn(u: Unit, seed: int):
    """The input sequence of the nominal, FMU-state and thread runs: the inputs' start values (an operating
    point the modelDescription promises; perturbing them could break a unit's input contract, e.g. a unit
    quaternion). `seed` is kept for the signature: the sequence is the same for every seed."""
    base = u.nominal_inputs()
    return lambda k: base
