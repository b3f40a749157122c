"""pytest configuration: the FMU tests drive the built FMUs in fmus/ through fmpy and the installed
scfmu package (scripts/setup.sh installs it, editable, into .venv).

fmpy's ``extract(path)`` without a target folder makes a temporary folder and never removes it (its own
``simulate_fmu`` does remove the one it makes). Tests call it directly in a dozen places, and a full run
used to leave about 50 unpacked units (0.9 GB) in the temporary folder. Here every folder it makes for a
test in this process is recorded and removed when the session ends (not earlier: module fixtures keep
theirs across tests).

The unit cache (scfmu.fmu.units) of the session is a folder of its own, set in ``SCFMU_UNIT_CACHE`` before
any test imports scfmu (so every child process, Dask workers included, inherits it) and removed when the
session ends: the tests never write to ``~/.cache``. Tests of the cache itself give each case a folder
of its own."""

import os
import shutil
import tempfile

import fmpy

_unit_cache = tempfile.mkdtemp(prefix="pytest_scfmu_units_")
os.environ["SCFMU_UNIT_CACHE"] = _unit_cache

_made: list[str] = []
_extract = fmpy.extract


def _recorded_extract(filename, unzipdir=None, include=None):
    d = _extract(filename, unzipdir, include)
    if unzipdir is None:
        _made.append(d)
    return d


fmpy.extract = _recorded_extract  # before the test modules run `from fmpy import extract`


def pytest_sessionfinish(session, exitstatus):
    for d in _made + [_unit_cache]:
        shutil.rmtree(d, ignore_errors=True)
