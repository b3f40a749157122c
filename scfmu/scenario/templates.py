"""Scenario templates of a family that several plug-ins share (plain builders; no paper is named here).

``attitude_loop``: AttitudeCommand → <controller> → AttitudePlant → AttitudeMetrics, the standard
three-axis closed loop (plant defaults: inertia diag(1000, 500, 700) kg·m², no torque limit, RK4 with
internal step 0.01 s).
"""

from __future__ import annotations

from .model import Component, Scenario, log_of

ATTITUDE_LOG = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
                "torque_applied_x", "torque_applied_y", "torque_applied_z"]
METRICS_LOG = ["alpha_deg", "eulerint_deg_s", "effort_abs", "effort_sq", "ise", "isf"]
PLANT_INERTIA_DEFAULT = {"inertia_xx": 1000.0, "inertia_yy": 500.0, "inertia_zz": 700.0}
INERTIA_KEYS = ("inertia_xx", "inertia_yy", "inertia_zz", "inertia_xy", "inertia_xz", "inertia_yz")


def nominal_inertia(plant_params: dict) -> dict:
    """The controller slot's nominal inertia: the plant's inertia parameters (its defaults where unset).
    Any attitude controller in that place that declares ``inertia_*`` parameters is given them."""
    out = dict(PLANT_INERTIA_DEFAULT)
    out.update({k: plant_params[k] for k in INERTIA_KEYS if k in plant_params})
    return out


def attitude_loop(name: str, controller: str, command, ctrl_params: dict | None = None,
                  plant_params: dict | None = None, stop_time: float = 30.0, step: float = 0.01,
                  kinematics: int = 0, description: str = "") -> Scenario:
    """AttitudeCommand → <controller> → AttitudePlant → AttitudeMetrics (inertia diag(1000, 500, 700) kg·m²
    from the plant's defaults, no torque limit, RK4 with internal step 0.01 s); ``command`` = 321 angles [rad]."""
    pp = {"max_internal_step": 0.01}
    if kinematics != 0:  # only set when not the default, so plants without the option still load
        pp["kinematics"] = kinematics
    pp.update(plant_params or {})
    return Scenario(
        name=name,
        components=[
            Component("command", "AttitudeCommand", {"ref_euler321_roll": command[0], "ref_euler321_pitch": command[1],
                                                     "ref_euler321_yaw": command[2]}),
            Component("controller", controller, dict(ctrl_params or {}), slot=nominal_inertia(pp)),
            Component("plant", "AttitudePlant", pp),
            Component("metrics", "AttitudeMetrics", {}),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", ATTITUDE_LOG), **log_of("metrics", METRICS_LOG),
             **log_of("command", ["roll_ref", "pitch_ref", "yaw_ref"])},
        metrics="attitude",
        seed_params=["plant.dist_noise_seed"],
        description=description,
    )
