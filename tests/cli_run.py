"""Running the `scfmu` command in a child process, and the shape of a refusal (tests/test_cli_errors.py,
tests/test_first_hour.py)."""

from __future__ import annotations

import os
import subprocess
import sys


def scfmu(*args, env=None, cwd=None, timeout=300):
    e = dict(os.environ, **(env or {}))
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=e, cwd=cwd)


def refused(r) -> str:
    """The one error line of a refused command: exit 2, one line (notices and warnings aside, and the import
    blocker's own lines of tests/test_first_hour.py), no traceback."""
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 2, (r.returncode, r.stdout[-1000:], r.stderr[-2000:])
    lines = [x for x in r.stderr.splitlines() if x.strip() and not x.startswith(("notice:", "warning:", "BLOCKED IMPORT"))]
    assert len(lines) == 1, r.stderr
    return lines[0]
