"""Sensor-in-the-loop variants of registered attitude scenarios, declared once: ``sensing/<name>`` is the
scenario ``<name>`` (looked up in the registry, so no paper is imported) passed through
:func:`scfmu.scenario.templates.with_sensors` — gyro 100 Hz, star tracker 5 Hz with 0.1 s latency, the
controller sampled at 10 Hz with a 0.05 s computation delay. Any attitude loop with ``controller`` and
``plant`` instances works (``sensing/paper000/000-4``); the listed ones are paper 000's large slews (one per
controller) and paper 003's cases."""

from __future__ import annotations

import functools

from ...registry import REGISTRY
from ...scenario import get
from ...scenario.model import Scenario
from ...scenario.templates import with_estimation, with_sensors

PAPER000_LARGE = {"default": "PD (quaternion)", "paper000/000-7L": "LQR", "paper000/000-8L": "pole placement",
                  "paper000/000-9L": "MRAC (linear coordinates)", "paper000/000-10L": "fuzzy PD",
                  "paper000/000-11L": "adaptive fuzzy"}
PAPER003 = {f"paper003/{c}/{k}": f"paper 003 case 003-{k}, {c}" for c in ("SMC", "T2FSMC") for k in "NCSWU"}
EXPORTED = ("sensing/default", "sensing/paper003/T2FSMC/N")


def build(name: str, **kw) -> Scenario:
    """``sensing/<registered attitude scenario>``; keyword arguments go to that scenario's builder."""
    inner = name.partition("/")[2]
    if not inner:
        raise KeyError(f"unknown scenario {name!r}: expected sensing/<attitude scenario>, e.g. sensing/default")
    return with_sensors(get(inner, **kw), name=name)


def names() -> list[tuple[str, str]]:
    out = [(f"sensing/{n}", f"{'paper 000 large slew, ' + label if n != 'default' else 'paper 000 run 000-6 (PD, large slew)'}"
                            f" with gyro, star tracker, 10 Hz flight computer") for n, label in PAPER000_LARGE.items()]
    out += [(f"sensing/{n}", f"{text} with gyro, star tracker, 10 Hz flight computer") for n, text in PAPER003.items()]
    return out


# ----- the estimator in the loop (issue 37) ----------------------------------------------------------------
EST_PREFIX = "sensing+estimation"
DERIVED = ("sensing", EST_PREFIX)  # prefixes of variants, not attitude scenarios of their own


def build_estimation(name: str, **kw) -> Scenario:
    """``sensing+estimation/<registered attitude scenario>``: its sensing variant with the sun sensor,
    magnetometer, on-board ephemeris and the Mekf between the sensors and the controller
    (:func:`scfmu.scenario.templates.with_estimation`); keyword arguments go to that scenario's builder."""
    inner = name.partition("/")[2]
    if not inner or inner.split("/")[0] in DERIVED:
        raise KeyError(f"unknown scenario {name!r}: expected {EST_PREFIX}/<attitude scenario>, e.g. "
                       f"{EST_PREFIX}/default")
    return with_estimation(get(inner, **kw), name=name)


@functools.cache
def attitude_scenarios() -> tuple:
    """(name, description) of every registered three-axis attitude loop (an ``AttitudePlant`` with a
    ``controller``) that has no estimator yet, the variants excluded: the scenarios that take the estimator."""
    out = []
    for src in list(REGISTRY.scenario_sources.values()):
        if src.prefix in DERIVED:
            continue
        for n, d in src.names():
            sc = get(n)
            names = {c.name for c in sc.components}
            if ({"plant", "controller"} <= names and "estimator" not in names
                    and sc.component("plant").model == "AttitudePlant"):
                out.append((n, d))
    return tuple(out)


def names_estimation() -> list[tuple[str, str]]:
    return [(f"{EST_PREFIX}/{n}", f"{d} with gyro, star tracker, sun sensor, magnetometer, Mekf, 10 Hz flight computer")
            for n, d in attitude_scenarios()]
