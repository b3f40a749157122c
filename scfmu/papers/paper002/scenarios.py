"""Paper 002 scenarios: ``paper002/<PD|PID|FOPD|FOPID>``, the single-axis loop with the tuned gains."""

from __future__ import annotations

import json
import math

from ...scenario.model import DEFAULT_UNCONNECTED, Component, Scenario, log_of
from . import model as p2
from .data import data_file

def paper002(controller: str = "FOPID", theta_ref_deg: float = 30.0, stop_time: float = 20.0,
             step: float = 0.001) -> Scenario:
    """Paper 002 single-axis loop: PidController or FopidController (PD, PID, FOPD, FOPID with the
    committed PSO-tuned gains of the package data file paper002/data/gains.json) → SingleAxisPlant (explicit Euler, internal
    step = communication step = the controller's sample time), step command theta_ref."""
    tuned = json.loads(data_file("gains.json").read_text())
    sc = p2.Scenario(theta_ref_deg=theta_ref_deg, t_end=stop_time, h=step)
    model, cparams = p2.controller_params(controller, tuned["controllers"][controller]["gains"], sc)
    return Scenario(
        name=f"paper002/{controller}",
        components=[
            Component("controller", model, cparams),
            Component("plant", "SingleAxisPlant", {"integrator": 1, "max_internal_step": step}),
        ],
        stop_time=stop_time, step=step,
        log=log_of("plant", ["theta", "omega", "applied_torque", "theta_deg"]) | log_of("controller", ["u", "theta_ref"]),
        inputs={"controller.theta_ref": math.radians(theta_ref_deg)},
        unconnected=[*DEFAULT_UNCONNECTED, "torque_dist"],
        metrics="paper002",  # single-axis step metrics + the PSO cost terms (mae_deg, late_max_deg, cost)
        description=f"paper 002 single-axis loop, {controller} with the tuned gains, {theta_ref_deg:g} deg step",
    )


def build(name: str, **kw) -> Scenario:
    parts = name.split("/")
    if len(parts) != 2 or parts[1] not in p2.CONTROLLERS:
        raise KeyError(f"unknown scenario {name!r}: expected paper002/<{'|'.join(p2.CONTROLLERS)}>")
    return paper002(parts[1], **kw)


def names() -> list[tuple[str, str]]:
    return [(f"paper002/{c}", f"paper 002 single-axis loop, {c} with the tuned gains, 30 deg step")
            for c in p2.CONTROLLERS]


EXPORTED = ("paper002/FOPID",)
