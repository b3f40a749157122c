"""Sensor-in-the-loop variants of registered attitude scenarios, declared once: ``sensing/<name>`` is the
scenario ``<name>`` (looked up in the registry, so no paper is imported) passed through
:func:`scfmu.scenario.templates.with_sensors` — gyro 100 Hz, star tracker 5 Hz with 0.1 s latency, the
controller sampled at 10 Hz with a 0.05 s computation delay. Any attitude loop with ``controller`` and
``plant`` instances works (``sensing/paper000/000-4``); the listed ones are paper 000's large slews (one per
controller) and paper 003's cases."""

from __future__ import annotations

from ...scenario import get
from ...scenario.model import Scenario
from ...scenario.templates import with_sensors

PAPER000_LARGE = {"default": "PD (quaternion)", "paper000/000-7L": "LQR", "paper000/000-8L": "pole placement",
                  "paper000/000-9L": "MRAC (quaternion)", "paper000/000-10L": "fuzzy PD",
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
