"""The child process of ``scfmu check``: runs the dynamic checks the parent names on one FMU interface.

Protocol (stdin: one JSON object {"spec", "checks", "options"}; stdout: one line per event, written
unbuffered so that nothing is lost when the FMU kills the process):

  B <check>      a check begins          S <title>   a scenario begins (the reproducer restarts)
  C <call> ...   a call is being made    R <call>    the call returned (replaces the C line)
  E <json>       the check's result

Run as ``python -m scfmu.check.child``; it imports nothing but the standard library and this package's
ctypes layer, and sets its own resource limits (no core file, bounded address space and file size)."""

from __future__ import annotations

import json
import os
import sys
import traceback


def _limits(opts: dict) -> None:
    try:
        import resource
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        cap = int(opts.get("address_space", 0))
        if cap:
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        fs = int(opts.get("file_size", 0))
        if fs:
            resource.setrlimit(resource.RLIMIT_FSIZE, (fs, fs))
    except (ImportError, ValueError, OSError):
        pass


def _die_with_parent() -> None:
    """On Linux, SIGKILL when the ``scfmu check`` process ends, however it ends (even by SIGKILL, which it
    cannot act on): a check never runs on after its command (PR_SET_PDEATHSIG, as scfmu.fmu.isolate)."""
    parent = os.environ.get("SCFMU_CHECK_PARENT", "")
    if not parent.isdigit() or not sys.platform.startswith("linux"):
        return
    from ..binding import die_with_parent
    if not die_with_parent():
        return
    if os.getppid() != int(parent):  # the parent ended before the line above took effect
        os._exit(3)


def main() -> int:
    _die_with_parent()
    job = json.loads(sys.stdin.read())
    opts = job["options"]
    _limits(opts)
    from .fmi import Trace
    from .gauntlet import CHECKS
    from .verdict import Fail, NotApplicable
    from .unit import Unit
    out = sys.stdout.fileno()
    trace = Trace(out)

    def emit(text):
        os.write(out, (text + "\n").encode())

    unit = None
    import time
    for name in job["checks"]:
        emit("B " + name)
        t0 = time.monotonic()
        trace.lines = []
        try:
            if unit is None:
                unit = Unit(job["spec"], trace)
            res = CHECKS[name](unit, opts)
            res["status"] = "pass"
        except Fail as e:
            res = {"status": "fail", "kind": e.kind, "detail": e.detail, "reproducer": list(trace.lines)}
            if e.rule:
                res["rule"] = e.rule
        except NotApplicable as e:
            res = {"status": "n/a", "detail": str(e)}
        except AttributeError as e:  # a function the standard requires is not exported
            res = {"status": "fail", "kind": "missing_function", "detail": str(e).splitlines()[0],
                   "reproducer": list(trace.lines)}
        except OSError as e:
            res = {"status": "fail", "kind": "load", "detail": f"the binary cannot be loaded: {e}",
                   "reproducer": []}
        except MemoryError:
            res = {"status": "fail", "kind": "memory", "detail": "the address-space limit of the child was reached",
                   "reproducer": list(trace.lines)[-20:]}
        except Exception as e:  # a bug of the checker: reported, not hidden
            res = {"status": "fail", "kind": "checker_error",
                   "detail": f"{type(e).__name__}: {e} ({traceback.format_exc().splitlines()[-3].strip()})",
                   "reproducer": list(trace.lines)}
        res["seconds"] = round(time.monotonic() - t0, 3)
        emit("E " + json.dumps(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
