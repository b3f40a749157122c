"""Paper 004 scenarios: ``paper004/<1|2|3>``, fault-tolerant control by reference correction."""

from __future__ import annotations

import json

import numpy as np

from ...scenario.model import Component, Scenario, log_of
from . import model as p4
from .data import data_file

NODES_FOR_SCALE = {1.0: "nodes.json", p4.INIT_SCALE_CALIBRATED: "nodes_calibrated.json"}


def committed_nodes(scale: float) -> tuple[np.ndarray, dict]:
    """The committed optimised spline nodes (3 × N_NODES, N·m) for a start scale and the optimiser report."""
    if scale not in NODES_FOR_SCALE:
        raise KeyError(f"no committed spline for initial-attitude scale {scale:g} (committed: "
                       f"{', '.join(f'{k:g}' for k in NODES_FOR_SCALE)}; `scfmu paper 004 optimize`)")
    rep = json.loads(data_file(NODES_FOR_SCALE[scale]).read_text())
    return np.array([rep["nodes_N_m"][a] for a in p4.AXES], dtype=float), rep


def paper004(case: str = "1", stop_time: float = 20.0, step: float = 0.01,
             scale: float = p4.INIT_SCALE_CALIBRATED) -> Scenario:
    """Paper 004 closed loop ReferenceCorrector → FeedbackLinearizingController → AttitudePlant:
    case "1" healthy actuators, "2" 90 % loss of effectiveness, "3" the same fault with the reference
    corrected by the committed optimised spline for that start (package data paper004/data/nodes*.json); at
    rest at the 321 angles (yaw, pitch, roll) = scale × (6, −4, 8) deg, by default the report's calibrated start
    (model.INIT_SCALE_CALIBRATED; scale 1 is the earlier default)."""
    eff = 1.0 if case == "1" else p4.A_FAULT
    init = p4.init_deg_scaled(scale)
    nodes = committed_nodes(scale)[0] if case == "3" else None
    mode = 1 if case == "3" else 0
    names = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
             "torque_applied_x", "torque_applied_y", "torque_applied_z"]
    return Scenario(
        name=f"paper004/{case}",
        components=[
            Component("corrector", "ReferenceCorrector", p4.corrector_params(mode, nodes, eff, init)),
            Component("controller", "FeedbackLinearizingController",
                      {k: v for k, v in p4.controller_params().items() if not k.startswith("inertia_")},
                      slot={k: v for k, v in p4.controller_params().items() if k.startswith("inertia_")}),
            Component("plant", "AttitudePlant", p4.plant_params(eff, init)),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", names), **log_of("controller", [f"torque_cmd_{a}" for a in "xyz"])},
        metrics="paper004",
        description=f"paper 004 case 004-{case}, start scale {scale:g} × (6, −4, 8) deg",
    )


def build(name: str, **kw) -> Scenario:
    parts = name.split("/")
    if len(parts) != 2 or parts[1] not in ("1", "2", "3"):
        raise KeyError(f"unknown scenario {name!r}: expected paper004/<1|2|3>")
    return paper004(parts[1], **kw)


def names() -> list[tuple[str, str]]:
    return [("paper004/1", "paper 004 case 004-1: healthy actuators, feedback-linearising control"),
            ("paper004/2", "paper 004 case 004-2: 90 % loss of effectiveness, no correction"),
            ("paper004/3", "paper 004 case 004-3: the same fault, reference corrected by the optimised spline")]


EXPORTED = ("paper004/3",)
