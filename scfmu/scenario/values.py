"""Values a user gives (``--set``, ``--params``, scenario files, campaign axes) parsed strictly and checked
against what they reach, before they reach an FMU or an allocator.

* :func:`parse_cli`: a command-line value: an integer (digits only), a number (``1.5``, ``2e-3``, also
  ``nan``/``inf``, which the check then refuses with the field's name), ``true``/``false``, else the text;
* :func:`value_problem`: why a value does not fit a model variable: its type (Real: a finite number;
  Integer and Enumeration: a whole number within the FMI 2.0 ``fmi2Integer`` range, −2147483648 …
  2147483647, never wrapped; Boolean: true or false; String: text) and its declared ``min``/``max``;
* :func:`timing_problems`: the start and stop time and the communication step of a run: finite, the step
  positive, at most ``max_steps()`` steps (default 10⁹, ``SCFMU_MAX_STEPS``) and at most ``max_rows()``
  logged rows (default 5,000,000, ``SCFMU_MAX_LOG_ROWS``; ``--log-every`` keeps every n-th step);
* :func:`did_you_mean`: the closest known name (difflib) for an unknown one;
* :class:`UsageError`: a user's mistake on the command line; ``scfmu`` prints its one line and exits 2.
"""

from __future__ import annotations

import difflib
import math
import os
import re

INT32 = (-(2 ** 31), 2 ** 31 - 1)  # fmi2Integer (a C int)
MAX_STEPS_DEFAULT = 10 ** 9
MAX_ROWS_DEFAULT = 5_000_000


class UsageError(SystemExit):
    """A user's mistake (a bad value, an unknown name): one line for the user, exit status 2. A SystemExit,
    so that a command run outside ``scfmu.cli`` still stops with status 2 (the line is in ``message``)."""

    def __init__(self, message: str):
        super().__init__(2)
        self.message = message

    def __str__(self) -> str:
        return self.message


def did_you_mean(name: str, known, what: str = "") -> str:
    """``"; did you mean 'x'?"`` for the closest of ``known`` (empty when none is close)."""
    close = difflib.get_close_matches(str(name), [str(k) for k in known], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


def parse_cli(text: str):
    """A command-line value: int (``[+-]digits``), float (anything ``float()`` reads), ``true``/``false``
    (any case), else the text itself (a String parameter, or a mistake the check names)."""
    t = text.strip()
    if re.fullmatch(r"[+-]?\d+", t):
        return int(t)
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    if re.fullmatch(r"[+-]?(\d+\.?\d*([eE][+-]?\d+)?|\.\d+([eE][+-]?\d+)?|nan|inf|infinity)", t, re.I):
        return float(t)
    return text


def _num(x):
    if x is None:
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _fmt(v) -> str:
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    return repr(v) if isinstance(v, str) else str(v).lower() if isinstance(v, bool) else str(v)


def bounds(var) -> tuple[float | None, float | None]:
    """The declared (min, max) of a model variable (its own, else its declared type's), as numbers."""
    dt = getattr(var, "declaredType", None)
    lo = _num(getattr(var, "min", None))
    hi = _num(getattr(var, "max", None))
    if lo is None and dt is not None:
        lo = _num(getattr(dt, "min", None))
    if hi is None and dt is not None:
        hi = _num(getattr(dt, "max", None))
    return lo, hi


def allowed(var) -> str:
    """What a variable accepts, in words: 'a finite Real in [0, 1] (1/s)', 'an Integer in [0, 2]', ..."""
    t = var.type
    lo, hi = bounds(var)
    if t == "Boolean":
        return "true or false"
    if t == "String":
        return "a text"
    if t in ("Integer", "Enumeration"):
        lo = INT32[0] if lo is None else max(lo, INT32[0])
        hi = INT32[1] if hi is None else min(hi, INT32[1])
        return f"an {t} in [{int(lo)}, {int(hi)}]"
    rng = "" if lo is None and hi is None else \
        f" ≥ {lo:g}" if hi is None else f" ≤ {hi:g}" if lo is None else f" in [{lo:g}, {hi:g}]"
    unit = getattr(var, "unit", None) or getattr(getattr(var, "declaredType", None), "unit", None)
    return f"a finite Real{rng}" + (f" [{unit}]" if unit else "")


def value_problem(qualified: str, var, value) -> str | None:
    """Why ``value`` cannot be given to the model variable ``var`` (named ``qualified`` in the message:
    field, value, what is allowed), or None when it can."""
    t = var.type
    head = f"{qualified} = {_fmt(value)}"
    if t == "Real":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            try:  # numpy scalars
                import numpy as np
                if isinstance(value, np.number) and not isinstance(value, np.bool_):
                    value = float(value)
                else:
                    raise TypeError
            except TypeError:
                return f"{head}: not a number; allowed: {allowed(var)}"
        if isinstance(value, int) and abs(value) > 2 ** 1023:
            return f"{head}: too large for a Real; allowed: {allowed(var)}"
        if not math.isfinite(float(value)):
            return f"{head}: not finite; allowed: {allowed(var)}"
    elif t in ("Integer", "Enumeration"):
        if isinstance(value, bool) or isinstance(value, str):
            return f"{head}: not a whole number; allowed: {allowed(var)}"
        if isinstance(value, float):
            if not (math.isfinite(value) and value.is_integer()):
                return f"{head}: not a whole number; allowed: {allowed(var)}"
            value = int(value)
        try:
            value = int(value)
        except (TypeError, ValueError):
            return f"{head}: not a whole number; allowed: {allowed(var)}"
        if not INT32[0] <= value <= INT32[1]:
            return f"{head}: outside the {t} range (never wrapped); allowed: {allowed(var)}"
    elif t == "Boolean":
        if not isinstance(value, bool):
            return f"{head}: not a Boolean; allowed: true or false"
        return None
    elif t == "String":
        return None if isinstance(value, str) else f"{head}: not a text; allowed: a text"
    lo, hi = bounds(var)
    v = float(value)
    if lo is not None and v < lo:
        return f"{head}: below the declared minimum {lo:g}; allowed: {allowed(var)}"
    if hi is not None and v > hi:
        return f"{head}: above the declared maximum {hi:g}; allowed: {allowed(var)}"
    return None


def _env_int(var: str, default: int) -> int:
    text = os.environ.get(var)
    if not text:
        return default
    try:
        v = int(float(text))
    except ValueError:
        raise UsageError(f"{var} = {text!r}: expected a positive integer") from None
    if v <= 0:
        raise UsageError(f"{var} = {text!r}: expected a positive integer")
    return v


def max_steps() -> int:
    """The most communication steps one run may take (``SCFMU_MAX_STEPS``, default 10⁹)."""
    return _env_int("SCFMU_MAX_STEPS", MAX_STEPS_DEFAULT)


def max_rows() -> int:
    """The most rows one run may log (``SCFMU_MAX_LOG_ROWS``, default 5,000,000: about 1 GB for 25 signals)."""
    return _env_int("SCFMU_MAX_LOG_ROWS", MAX_ROWS_DEFAULT)


def timing_problems(start_time, stop_time, step, log_every: int | None = 1, log_hint: bool = True) -> list[str]:
    """Why a run from ``start_time`` to ``stop_time`` with communication ``step`` cannot run (empty when it
    can); each message names the field, its value and what is allowed. ``log_every``: the run logs every
    n-th step (0: the first and last only; None: the logged rows are not counted)."""
    out = []
    for name, v in (("start_time", start_time), ("stop_time", stop_time), ("step", step)):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            out.append(f"{name} = {_fmt(v)}: not a number; allowed: a finite number of seconds")
        elif not math.isfinite(float(v)):
            out.append(f"{name} = {_fmt(v)}: not finite; allowed: a finite number of seconds")
    if out:
        return out
    start_time, stop_time, step = float(start_time), float(stop_time), float(step)
    if not step > 0:
        return [f"step = {step:g}: allowed: a positive number of seconds"]
    if not stop_time > start_time:
        return [f"stop_time = {stop_time:g}: allowed: a time after start_time = {start_time:g}"]
    n = (stop_time - start_time) / step
    if not n <= max_steps():
        return [f"stop_time = {stop_time:g} with step = {step:g}: {n:.3g} steps; allowed: at most {max_steps()} "
                f"steps per run (SCFMU_MAX_STEPS)"]
    if log_every is None:
        return []
    rows = 2 if int(log_every) <= 0 else math.ceil(n / int(log_every)) + 1
    if rows > max_rows():
        hint = (f"; use --log-every {math.ceil(n / (max_rows() - 1))} or more (native engine), a larger step or an "
                f"earlier stop_time" if log_hint else "")
        return [f"stop_time = {stop_time:g} with step = {step:g}: {rows} logged rows; allowed: at most {max_rows()} "
                f"rows per run (SCFMU_MAX_LOG_ROWS){hint}"]
    return []


def bounded_int(name: str, value, lo: int, hi: int) -> int:
    """``value`` as an int in [lo, hi], else :class:`UsageError` naming the option."""
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise UsageError(f"{name} {_fmt(value)}: allowed: a whole number in [{lo}, {hi}]")
    return value


def bounded_float(name: str, value, lo: float, hi: float) -> float:
    """``value`` as a finite float in (lo, hi], else :class:`UsageError` naming the option."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (lo < float(value) <= hi):
        raise UsageError(f"{name} {_fmt(value)}: allowed: a number > {lo:g} and ≤ {hi:g}")
    return float(value)
