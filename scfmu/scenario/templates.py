"""Scenario templates of a family that several plug-ins share (plain builders; no paper is named here).

``attitude_loop``: AttitudeCommand → <controller> → AttitudePlant → AttitudeMetrics, the standard
three-axis closed loop (plant defaults: inertia diag(1000, 500, 700) kg·m², no torque limit, RK4 with
internal step 0.01 s).

``with_sensors``: the same loop with the controller fed by sensors instead of the plant's truth, and run
by a flight computer: AttitudePlant → Gyro, StarTracker → <controller> → SampleHold → AttitudePlant
(issue 26). The sensors read the plant's ``q_*``, ``w_*`` by name; explicit connections feed the
controller's ``q_*`` ← ``star_tracker.q_meas_*``, ``w_*`` ← ``gyro.w_meas_*`` and pass its ``torque_cmd_*``
through the hold (``u_1…3`` → ``y_1…3``) to the plant. The metrics still read the true attitude.
"""

from __future__ import annotations

import copy

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


# ----- sensors in the loop (issue 26) ---------------------------------------------------------------------
# Project choice, a small-satellite sensor suite: gyro 100 Hz, ARW 0.15 deg/sqrt(h), bias instability
# 1 deg/h (tau_c 300 s), turn-on bias (5, -3, 2) deg/h; star tracker 5 Hz, 5 / 41 arcsec (cross / about
# boresight), 0.1 s latency, 30 deg sun exclusion; flight computer 10 Hz with a 0.05 s computation delay.
_DEG_H = 3.141592653589793 / 180.0 / 3600.0
GYRO_DEFAULT = {"sample_period": 0.01, "bias_const_x": 5 * _DEG_H, "bias_const_y": -3 * _DEG_H,
                "bias_const_z": 2 * _DEG_H}
STAR_TRACKER_DEFAULT = {"sample_period": 0.2, "latency": 0.1}
HOLD_DEFAULT = {"sample_period": 0.1, "delay": 0.05}
SENSOR_LOG = {**{f"w_meas_{a}": f"gyro.w_meas_{a}" for a in "xyz"},
              **{f"q_meas_{a}": f"star_tracker.q_meas_{a}" for a in ("w", "x", "y", "z")},
              "st_valid": "star_tracker.valid",
              **{f"torque_cmd_{a}": f"hold.y_{i}" for i, a in enumerate("xyz", 1)}}


def with_sensors(sc: Scenario, name: str | None = None, gyro: dict | None = None, star_tracker: dict | None = None,
                 hold: dict | None = None, description: str = "") -> Scenario:
    """``sc`` (an attitude loop with instances ``controller`` and ``plant``) with a Gyro and a StarTracker
    between the plant and the controller and a SampleHold between the controller and the plant.
    ``gyro``, ``star_tracker``, ``hold``: parameters over the defaults above. The sensors' seeds join the
    scenario's seed parameters, so a campaign over seeds is a Monte Carlo over sensor noise."""
    s = copy.deepcopy(sc)
    names = [c.name for c in s.components]
    if "controller" not in names or "plant" not in names:
        raise KeyError(f"with_sensors: scenario {sc.name!r} needs instances 'controller' and 'plant' (has {names})")
    if s.component("plant").model != "AttitudePlant":
        raise KeyError(f"with_sensors: scenario {sc.name!r} is not a three-axis attitude loop "
                       f"(its plant is {s.component('plant').model!r}, not AttitudePlant)")
    sun = {k: v for k, v in s.component("plant").params.items() if k == "sun_ecliptic_longitude"}
    comps = []
    for c in s.components:
        if c.name == "controller":
            comps.append(Component("gyro", "Gyro", {**GYRO_DEFAULT, **(gyro or {})}))
            comps.append(Component("star_tracker", "StarTracker", {**STAR_TRACKER_DEFAULT, **sun, **(star_tracker or {})}))
            comps.append(c)
            comps.append(Component("hold", "SampleHold", {**HOLD_DEFAULT, **(hold or {})}))
        else:
            comps.append(c)
    s.components = comps
    s.connections = {**s.connections,
                     **{f"controller.q_{a}": f"star_tracker.q_meas_{a}" for a in ("w", "x", "y", "z")},
                     **{f"controller.w_{a}": f"gyro.w_meas_{a}" for a in "xyz"},
                     **{f"hold.u_{i}": f"controller.torque_cmd_{a}" for i, a in enumerate("xyz", 1)},
                     **{f"plant.torque_cmd_{a}": f"hold.y_{i}" for i, a in enumerate("xyz", 1)}}
    s.unconnected = [*s.unconnected, "hold.u_*"]
    s.seed_params = [*s.seed_params, "gyro.seed", "star_tracker.seed"]
    s.log = {**s.log, **SENSOR_LOG}
    s.name = name or f"sensing/{sc.name}"
    s.description = description or f"{sc.description} — with gyro, star tracker and a 10 Hz flight computer"
    return s
