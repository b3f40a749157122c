"""Scenarios: a closed loop declared once as plain data (:class:`Scenario`), looked up by name in the
registry that the paper plug-ins fill (:func:`get`, :func:`names`), read from and written to files
(:mod:`scfmu.scenario.ssp` for SSP 1.0 and 2.0)."""

from __future__ import annotations

from ..registry import REGISTRY
from .model import DEFAULT_UNCONNECTED, Component, Scenario, load, log_of, matches_input

__all__ = ["DEFAULT_UNCONNECTED", "Component", "Scenario", "get", "load", "log_of", "matches_input", "names",
           "describe"]


def get(name: str, **kw) -> Scenario:
    """A registered scenario by name (``"default"``, ``"paper000/000-6"``, ``"paper003/SMC/N"``, ...);
    keyword arguments go to its builder."""
    return REGISTRY.scenario(name, **kw)


def names(pattern: str = "*") -> list[str]:
    """Names of the standard scenarios (optionally a glob pattern)."""
    return [n for n, _ in REGISTRY.scenario_names(pattern)]


def describe(pattern: str = "*") -> list[tuple[str, str]]:
    """(name, description) of the standard scenarios."""
    return REGISTRY.scenario_names(pattern)
