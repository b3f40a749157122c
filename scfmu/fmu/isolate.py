"""A call into a foreign unit, made in a forked child with a wall-time limit: a unit that crashes, hangs
or ends its process costs that call only, never the caller (a campaign worker, the pre-flight check).

:func:`in_child` is the one way scfmu does this. The child, before it runs anything:

* starts a session (and process group) of its own, so no signal that a crashing unit's process sends to
  its group reaches the caller;
* puts the crash signals back at the kernel's default action: no fault handler inherited from the caller
  (Python's faulthandler, which pytest and ``python -X faulthandler`` turn on, would print a 'Fatal Python
  error' dump for what is a reported result, and re-raise the signal from user space);
* on Linux, is killed with its parent (``PR_SET_PDEATHSIG``), so a unit that hangs cannot spin on after a
  killed campaign;
* writes its temporary files (the FMUs it unpacks, a unit's own) into a folder of its own, which the
  caller removes afterwards: a child that crashes, hangs or ends with ``os._exit`` never runs its cleanup,
  and a campaign of thousands of isolated runs must not leave thousands of unpacked units behind.

The caller kills the child on every way out: the limit, an exception, Ctrl-C.
"""

from __future__ import annotations

import os
import pickle
import select
import shutil
import signal
import tempfile
import time
from typing import Any, Callable

# the signals by which a crashing unit ends its process
FATAL_SIGNALS = ("SIGSEGV", "SIGBUS", "SIGILL", "SIGFPE", "SIGABRT")


def available() -> bool:
    """Whether this platform can fork (not Windows): elsewhere the callers run the call in-process."""
    return hasattr(os, "fork")


def in_child(fn: Callable[[], Any], timeout: float) -> tuple[str, Any]:
    """``fn()`` in a forked child; its result comes back pickled through a pipe. Returns ("ok", result),
    ("crash", the signal's name or "exit code N") or ("timeout", None) when no result came within
    ``timeout`` seconds of wall time (the child is killed)."""
    parent = os.getpid()
    from .scratch import mkdtemp
    scratch = mkdtemp(prefix="scfmu_isolated_")  # in the caller's scratch folder: gone with a killed caller too
    try:
        return _fork_and_wait(fn, timeout, parent, scratch)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _fork_and_wait(fn: Callable[[], Any], timeout: float, parent: int, scratch: str) -> tuple[str, Any]:
    rfd, wfd = os.pipe()
    pid = os.fork()
    if pid == 0:  # child: run, send, exit without running the caller's cleanup handlers
        code = 0
        try:
            os.close(rfd)
            _detach(parent, scratch)
            data = pickle.dumps(fn())
            with os.fdopen(wfd, "wb") as w:
                w.write(data)
        except BaseException:
            code = 3
        finally:
            os._exit(code)
    os.close(wfd)
    chunks, deadline = [], time.monotonic() + float(timeout)
    timed_out, reaped, status = False, False, 0
    try:
        with os.fdopen(rfd, "rb") as r:
            while True:
                left = deadline - time.monotonic()
                if left <= 0:
                    timed_out = True
                    break
                ready, _, _ = select.select([r], [], [], min(left, 1.0))
                if ready:
                    b = os.read(r.fileno(), 1 << 20)
                    if not b:
                        break
                    chunks.append(b)
        if not timed_out:
            _, status = os.waitpid(pid, 0)
            reaped = True
    finally:
        if not reaped:  # timed out, or the caller is leaving (an exception, Ctrl-C): the child goes too
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            os.waitpid(pid, 0)
    if timed_out:
        return "timeout", None
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        return "crash", signal.Signals(sig).name if sig in signal.Signals._value2member_map_ else f"signal {sig}"
    try:
        return "ok", pickle.loads(b"".join(chunks))
    except Exception:
        return "crash", f"exit code {os.WEXITSTATUS(status)}"


def _detach(parent: int, scratch: str) -> None:
    """The child's set-up (the module's opening comment says why)."""
    import faulthandler
    os.setsid()
    tempfile.tempdir = scratch  # Python's temporary files (fmpy's unpacking included)
    os.environ["TMPDIR"] = scratch  # a unit's native code
    faulthandler.disable()
    for name in FATAL_SIGNALS:  # after a fork the forking thread is the child's main thread: allowed
        signal.signal(getattr(signal, name), signal.SIG_DFL)
    from ..binding import die_with_parent
    die_with_parent()  # Linux: SIGKILL when the parent ends (prctl PR_SET_PDEATHSIG)
    if os.getppid() != parent:  # the parent died before the line above took effect
        os._exit(3)
