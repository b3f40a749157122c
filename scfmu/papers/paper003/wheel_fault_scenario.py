"""The ``wheel_fault`` scenario: the paper 003 plant with reaction-wheel saturation and an actuator fault."""

from __future__ import annotations

import math

from ...scenario.model import Component, Scenario, log_of
from ...scenario.templates import nominal_inertia

D = math.radians
WHEEL_FAULT_COMMAND = (D(30.0), D(-20.0), D(45.0))
I003 = {"inertia_xx": 4.0, "inertia_yy": 5.0, "inertia_zz": 3.5, "inertia_xy": 0.05, "inertia_xz": -0.03,
        "inertia_yz": 0.02}


def wheel_fault(stop_time: float = 120.0, step: float = 0.1, fault_time: float = 4.0, effectiveness_x: float = 0.3,
                bias_z: float = 0.01) -> Scenario:
    """Paper 003 plant with three reaction wheels, magnetorquer dumping, gravity gradient and a constant
    disturbance; PD retuned (ω_n = 0.3 rad/s, ξ = 0.9); x wheel loses 70 % at fault_time, z wheel biased."""
    names = ["roll", "pitch", "yaw"] + [f"{v}_{a}" for v in ["torque_applied", "h_wheel", "wheel_speed", "dipole", "w"]
                                        for a in "xyz"]
    c = WHEEL_FAULT_COMMAND
    return Scenario(
        name="wheel_fault",
        components=[
            Component("command", "AttitudeCommand", {"ref_euler321_roll": c[0], "ref_euler321_pitch": c[1],
                                                     "ref_euler321_yaw": c[2]}),
            Component("controller", "PdController", {"wn": 0.3, "zeta": 0.9},
                      slot=nominal_inertia(I003)),
            Component("plant", "AttitudePlant", dict(I003, actuator_mode=1, mtq_enable=1, gg_enable=1,
                                                     dist_const_x=5e-4, dist_const_y=5e-4, dist_const_z=5e-4,
                                                     effectiveness_x=effectiveness_x, fault_bias_z=bias_z,
                                                     fault_time=fault_time)),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", names), **log_of("controller", [f"torque_cmd_{a}" for a in "xyz"]),
             **log_of("command", ["roll_ref", "pitch_ref", "yaw_ref"])},
        metrics="attitude_nometrics",
        description="reaction-wheel saturation and actuator fault (paper 003 plant)",
    )
