"""The verdicts and shared steps of the dynamic checks of ``scfmu check`` (scfmu.check.gauntlet,
scfmu.check.misuse): :class:`Fail` (kind, detail), :class:`NotApplicable`, the status expectations, stepping
with checked outputs, the input sequence. Runs in the child process."""

from __future__ import annotations

import struct

from .fmi import OK, WARNING
from .unit import Unit, s_name

NOT_OK = "a status other than OK/Warning"


class Fail(Exception):
    def __init__(self, kind: str, detail: str):
        super().__init__(detail)
        self.kind, self.detail = kind, detail


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


def _expect_refused(u: Unit, s: int, what: str, kind: str = "wrong_status"):
    if s in (OK, WARNING):
        raise Fail(kind, f"{what} returned {s_name(u.v, s)}; the standard prescribes an error status")


def _expect_ok(u: Unit, s: int, what: str):
    if s > WARNING:
        msg = u.messages[-1][1] if u.messages else "no log message"
        raise Fail("error_status", f"{what} returned {s_name(u.v, s)} ({msg})")


def _check_status_valid(u: Unit, s: int, what: str):
    if not 0 <= s <= (5 if u.v == 2 else 4):
        raise Fail("invalid_status", f"{what} returned the invalid status value {s}")


def _steps(u: Unit, h, t: float, n: int, inputs=None) -> tuple[float, list]:
    """n steps of u.dt with the outputs checked after each; returns (time, outputs after each step)."""
    outs = []
    for k in range(n):
        if inputs is not None:
            _expect_ok(u, u.set(h, u.inputs, inputs(k)), "setting the inputs")
        s = u.step(h, t, u.dt)
        _check_status_valid(u, s, "a step")
        _expect_ok(u, s, f"the step from t = {t!r}")
        t += u.dt
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
