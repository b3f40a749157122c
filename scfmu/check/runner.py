"""Runs the dynamic checks of one FMU interface in isolated child processes (scfmu.check.child) with a
time limit per check and one per FMI call: a crash, an abort or a hang of the FMU ends only the child; the
check that was running is failed with the call list it was making, and a fresh child continues with the
next checks.

A hang is a call that has not returned after ``call_timeout`` seconds (the child announces each call before
making it; the threads check announces its threads' progress the same way), or a check still running after
``timeout``. Once the unit has hung, a call of the later checks gets AFTER_HANG_CALL seconds at most: a unit
that hangs in every check is reported in well under a minute instead of one full time limit per check,
while a check that is long but progressing keeps its whole time limit."""

from __future__ import annotations

import json
import os
import selectors
import signal
import subprocess
import sys
import tempfile
import time

from ..fmu import scratch


def _signame(rc: int) -> str:
    try:
        return signal.Signals(-rc).name
    except (ValueError, AttributeError):
        return f"signal {-rc}"


AFTER_HANG_CALL = 2.0  # s a call may take once the unit has hung


def run_checks(spec: dict, checks: list[str], options: dict, timeout: float, seen: dict | None = None) -> dict:
    """{check name: result dict} for `checks` on the interface `spec`; each check gets `timeout` seconds and
    each call options["call_timeout"] seconds. `seen` ({"hung": bool}) carries over from one interface to
    the next whether the unit has hung."""
    results: dict = {}
    todo = list(checks)
    seen = {"hung": False} if seen is None else seen
    while todo:
        results.update(_one_child(spec, todo, options, timeout, seen))
        todo = [c for c in todo if c not in results]
    return results


def _one_child(spec, checks, options, timeout, seen) -> dict:
    job = json.dumps({"spec": spec, "checks": checks, "options": options}).encode()
    results: dict = {}
    with tempfile.TemporaryDirectory(prefix="scfmu_check_", dir=scratch.process_folder()) as tmp, \
            tempfile.TemporaryFile(dir=tmp) as err:
        env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
        env.pop("PYTHONFAULTHANDLER", None)  # the FMU's signal is reported from the exit status
        env["SCFMU_CHECK_PARENT"] = str(os.getpid())  # the child ends with this process (scfmu.check.child)
        proc = subprocess.Popen([sys.executable, "-m", "scfmu.check.child"], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, stderr=err, cwd=tmp, env=env, start_new_session=True)
        try:
            return _watch(proc, job, err, checks, (timeout, float(options.get("call_timeout", 5.0))), results, seen)
        except BaseException:  # Ctrl-C, SIGTERM (scfmu.cli), any error: no child outlives the check
            _kill(proc)
            raise


def _kill(proc) -> None:
    """Kills the child's process group (the child and anything it started) and waits for the child."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        pass


def _bounds(limits, seen) -> tuple[float, float]:
    check_t, call_t = limits
    return check_t, (min(call_t, AFTER_HANG_CALL) if seen["hung"] else call_t)


def _watch(proc, job: bytes, err, checks, limits, results: dict, seen: dict) -> dict:
    """Feeds the child its job and reads its events until it ends or hangs; the results of its checks."""
    proc.stdin.write(job)
    proc.stdin.close()
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    current, lines, buf = None, [], b""
    deadline = time.monotonic() + limits[0] + 60.0  # starting Python is not the FMU's time
    call_since = None  # when the call in progress began (None: no call in progress)
    hung = None  # "check" or "call"
    timeout, call_timeout = _bounds(limits, seen)
    fd = proc.stdout.fileno()
    while True:
        now = time.monotonic()
        if deadline - now <= 0:
            hung = "check"
            break
        if call_since is not None and current is not None and now - call_since > call_timeout:
            hung = "call"
            break
        wait = deadline - now if call_since is None else min(deadline - now, call_since + call_timeout - now)
        if not sel.select(timeout=max(0.01, min(wait, 0.25))):
            continue
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            break
        buf += chunk
        *complete, buf = buf.split(b"\n")
        for raw in complete:
            line = raw.decode(errors="replace")
            tag, _, rest = line.partition(" ")
            if tag == "B":
                current, lines, call_since = rest, [], None
                timeout, call_timeout = _bounds(limits, seen)
                deadline = time.monotonic() + timeout
            elif tag == "S":
                lines = []
            elif tag == "C":
                lines.append(rest)
                call_since = None if rest.startswith("//") else time.monotonic()
            elif tag == "R" and lines:
                lines[-1] = rest
                call_since = None
            elif tag == "E" and current:
                results[current] = json.loads(rest)
                current = None
    sel.close()
    return _finish(proc, err, checks, results, seen, (current, lines, hung, timeout, call_timeout))


def _finish(proc, err, checks, results: dict, seen: dict, where: tuple) -> dict:
    """Ends the child and turns a check it left unfinished into a hang or crash result."""
    current, lines, hung, timeout, call_timeout = where
    if hung:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    try:
        rc = proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        rc = proc.wait()
    try:  # what the FMU may have started in the child's group ends with it
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    err.seek(0)
    stderr = err.read()[-4000:].decode(errors="replace").strip()
    if current is not None and current not in results:
        last = lines[-1] if lines else "(no call yet)"
        if hung:
            seen["hung"] = True
            what = f"a call did not return within {call_timeout:g} s" if hung == "call" else \
                f"the check did not end within {timeout:g} s"
            results[current] = {"status": "fail", "kind": "hang",
                                "detail": f"{what}; the call in progress: {last}", "reproducer": lines}
        else:
            how = f"killed by {_signame(rc)}" if rc < 0 else f"exited with status {rc}"
            tail = " | ".join(stderr.splitlines()[-3:])
            results[current] = {"status": "fail", "kind": "crash",
                                "detail": f"the process was {how} during {last}" + (f" (stderr: {tail})" if tail else ""),
                                "reproducer": lines}
    elif not results and rc != 0:  # the child died before its first check (e.g. cannot start)
        tail = " | ".join(stderr.splitlines()[-3:])
        results[checks[0]] = {"status": "fail", "kind": "crash",
                              "detail": f"the check process exited with status {rc} before the check began: {tail}",
                              "reproducer": []}
    return results
