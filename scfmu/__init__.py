"""scfmu: spacecraft guidance and control units as FMUs (FMI 2.0 and 3.0; Co-Simulation, and Model Exchange
where a model is continuous or static), their closed-loop scenarios, engines, campaigns and the papers'
experiments.

The public API (imported lazily, so ``import scfmu`` stays cheap and pulls in no layer it does not need):

* :func:`simulate` — run a scenario (or a scenario name) on the native engine (lean or reference on request);
* :class:`Scenario`, :class:`Component`, :func:`get_scenario`, :func:`scenario_names` — scenarios as data;
* :class:`Fmu`, :func:`fmu_path`, :func:`fmu_dir`, :func:`set_fmu_dir` — FMU access;
* :class:`SimulationError` — the error a failing run raises;
* :mod:`scfmu.campaign` — many runs on Dask; :mod:`scfmu.metrics` — metrics of a run.
"""

from __future__ import annotations

from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("scfmu")
except _metadata.PackageNotFoundError:  # imported from a source tree that is not installed
    __version__ = "0+unknown"

_LAZY = {
    "simulate": ("scfmu.engines", "simulate"),
    "Result": ("scfmu.engines", "Result"),
    "SimulationError": ("scfmu.engines.calls", "SimulationError"),
    "Scenario": ("scfmu.scenario.model", "Scenario"),
    "Component": ("scfmu.scenario.model", "Component"),
    "get_scenario": ("scfmu.scenario", "get"),
    "scenario_names": ("scfmu.scenario", "names"),
    "Fmu": ("scfmu.fmu", "Fmu"),
    "fmu_path": ("scfmu.fmu", "fmu_path"),
    "fmu_dir": ("scfmu.fmu", "fmu_dir"),
    "set_fmu_dir": ("scfmu.fmu", "set_fmu_dir"),
}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    if name in _LAZY:
        import importlib
        mod, attr = _LAZY[name]
        value = getattr(importlib.import_module(mod), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'scfmu' has no attribute {name!r}")
