"""Raw ctypes access to an FMI 2.0 or 3.0 binary for the gauntlet (runs in the child process).

Every call goes through :meth:`Lib.call`, which records it as one line of a C-like call list
(``fmi2DoStep(c1, 0.0, 0.01, fmi2True) -> fmi2OK``) in the current :class:`Trace`; the trace is also
written, unbuffered, to a file descriptor so that the parent still has the calls when the FMU kills the
child. The signatures come from :mod:`scfmu.binding` (fmpy's wrappers raise on error statuses and cannot
pass NULL pointers, which the gauntlet needs)."""

from __future__ import annotations

import math
import os

from .. import binding
from ..binding import (DISCARD, ERROR, FATAL, OK, STATUS2, STATUS3, TYPES2, TYPES3, WARNING,  # noqa: F401
                       Callbacks2, EventInfo2)


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


class Lib:
    """One loaded FMU binary with traced calls. `version` is 2 or 3."""

    def __init__(self, path: str, version: int, trace: Trace):
        self.path, self.version, self.trace = path, version, trace
        self.library = binding.load(path)
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
            if not name.startswith(f"fmi{self.version}"):
                raise AttributeError(f"{name} is not an FMI {self.version}.0 function")
            f = self._fns[name] = binding.bind(self.library, name)
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
        res = binding.SIGNATURES[name][0]
        if res is None:
            self.trace.done(text)
        elif res is not binding.P:  # a status
            s = self.status_names[r] if 0 <= r < len(self.status_names) else f"<invalid status {r}>"
            self.trace.done(f"{text} -> {s}")
        else:
            self.trace.done(f"{text} -> {'NULL' if not r else 'instance'}")
        return r

    def unload(self) -> None:
        lib, self.library = self.library, None
        self._fns.clear()
        binding.unload(lib)
