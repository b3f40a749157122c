"""pytest configuration: the FMU tests drive the built FMUs in fmus/ through fmpy and the installed
scfmu package (scripts/setup.sh installs it, editable, into .venv).

fmpy's ``extract(path)`` without a target folder makes a temporary folder and never removes it (its own
``simulate_fmu`` does remove the one it makes). Tests call it directly in a dozen places, and a full run
used to leave about 50 unpacked units (0.9 GB) in the temporary folder. Here every folder it makes for a
test in this process is recorded and removed when the session ends (not earlier: module fixtures keep
theirs across tests)."""

import shutil

import fmpy

_made: list[str] = []
_extract = fmpy.extract


def _recorded_extract(filename, unzipdir=None, include=None):
    d = _extract(filename, unzipdir, include)
    if unzipdir is None:
        _made.append(d)
    return d


fmpy.extract = _recorded_extract  # before the test modules run `from fmpy import extract`


def pytest_sessionfinish(session, exitstatus):
    for d in _made:
        shutil.rmtree(d, ignore_errors=True)
