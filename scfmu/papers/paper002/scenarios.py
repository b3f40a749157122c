"""Paper 002 scenarios: ``paper002/<PD|PID|FOPD|FOPID>``, the single-axis loop with the tuned gains."""

from __future__ import annotations

import json

from ...scenario.model import Scenario
from . import model as p2
from .data import data_file

def paper002(controller: str = "FOPID", theta_ref_deg: float = 30.0, stop_time: float = 20.0,
             step: float = 0.001) -> Scenario:
    """Paper 002 single-axis loop (:func:`model.loop_scenario`): PidController or FopidController (PD, PID,
    FOPD, FOPID with the committed PSO-tuned gains of the package data file paper002/data/gains.json) →
    SingleAxisPlant (explicit Euler, internal step = communication step = the controller's sample time),
    step command theta_ref."""
    tuned = json.loads(data_file("gains.json").read_text())
    sc = p2.loop_scenario(controller, tuned["controllers"][controller]["gains"],
                          p2.Scenario(theta_ref_deg=theta_ref_deg, t_end=stop_time, h=step))
    sc.description = f"paper 002 single-axis loop, {controller} with the tuned gains, {theta_ref_deg:g} deg step"
    return sc


def build(name: str, **kw) -> Scenario:
    parts = name.split("/")
    if len(parts) != 2 or parts[1] not in p2.CONTROLLERS:
        raise KeyError(f"unknown scenario {name!r}: expected paper002/<{'|'.join(p2.CONTROLLERS)}>")
    return paper002(parts[1], **kw)


def names() -> list[tuple[str, str]]:
    return [(f"paper002/{c}", f"paper 002 single-axis loop, {c} with the tuned gains, 30 deg step")
            for c in p2.CONTROLLERS]


EXPORTED = ("paper002/FOPID",)
