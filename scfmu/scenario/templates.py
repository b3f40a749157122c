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


# ----- estimator in the loop (issue 37) -------------------------------------------------------------------
# Project choice, completing the sensor suite above: a sun sensor (10 Hz, 0.1 deg, 60 deg half-angle field of
# view about body +x, the face that sees the sun at the start of the papers' runs; no measurement in the
# Earth's shadow), a magnetometer (10 Hz, 100 nT per axis) and the
# flight computer's on-board Ephemeris (sun direction and dipole field in R) feed a Mekf at the gyro's rate,
# whose estimated attitude and rate replace the raw measurements at the controller's inputs.
ORBIT_KEYS = ("mu", "orbit_radius", "orbit_inclination", "orbit_arg_lat0", "earth_dipole", "sun_ecliptic_longitude")
SUN_SENSOR_DEFAULT = {"sample_period": 0.1, "noise": 1.745e-3, "fov": 1.0471975511965976, "shadow": 1,
                      "mount_y": 1.5707963267948966}  # boresight (sensor z) on body +x
MAGNETOMETER_DEFAULT = {"sample_period": 0.1, "noise_x": 1e-7, "noise_y": 1e-7, "noise_z": 1e-7}
# the sensors' declared defaults the Mekf's noise model is matched to (tests/test_estimation_loop.py reads
# them back from the packaged FMUs): gyro ARW N² [rad²/s], bias instability B [rad/s] with correlation time
# tau_c [s]; star tracker 1-sigma cross / about the boresight [rad]
GYRO_NOISE = {"arw_psd": 1.9e-9, "bias_instability": 4.85e-6, "bias_corr_time": 300.0, "rrw_psd": 0.0}
STAR_TRACKER_NOISE = {"noise_cross": 2.5e-5, "noise_about": 2.0e-4}
GM_STD_PER_B = 0.664_282_470_267_960_1 / 0.617_364_283_144_441_4  # the Gyro's σ_b / B (FLICKER_FLOOR / GM_ADEV_PEAK)
STAR_TRACKER_EST = {"latency": 0.0}  # the star tracker of the estimator variant: as the sensing one, without latency
EST_LOG = ["q_est_w", "q_est_x", "q_est_y", "q_est_z", "w_est_x", "w_est_y", "w_est_z", "bias_est_x", "bias_est_y",
           "bias_est_z", "p_att_x", "p_att_y", "p_att_z", "nis", "nis_dim"]


def _axis(d: dict, stem: str, a: str) -> float:
    """Component ``a`` of a vector parameter given per axis (``stem_x``) or as one value for all (``stem``)."""
    return float(d.get(f"{stem}_{a}", d.get(stem, 0.0)))


def mekf_params(gyro: dict, star_tracker: dict, sun_sensor: dict, magnetometer: dict, orbit: dict) -> dict:
    """The Mekf's parameters matched to the sensors it is fed by (their parameters over the defaults above):
    its sample period is the gyro's, its ARW is the gyro's; the gyro's bias instability B, realised as a
    Gauss–Markov bias of stationary sigma σ_b = 0.664 B / 0.6174 and correlation time tau_c, is modelled as
    the random walk driven by the same white noise, K² = rrw_psd + 2 σ_b² / tau_c (exact for times short
    against tau_c); the star tracker's and the sun sensor's 1-sigma angles are the filter's; the
    magnetometer's angular noise is its per-axis noise over the weakest field on the orbit, M_E / r³; the
    initial bias sigma is twice the largest turn-on bias (at least 1e-4 rad/s)."""
    g = {**GYRO_NOISE, **gyro}
    st = {**STAR_TRACKER_NOISE, **star_tracker}
    b_min = float(orbit.get("earth_dipole", 7.96e15)) / float(orbit.get("orbit_radius", 7078137.0)) ** 3
    rrw = [_axis(g, "rrw_psd", a) + 2.0 * (GM_STD_PER_B * _axis(g, "bias_instability", a)) ** 2
           / float(g["bias_corr_time"]) for a in "xyz"]
    turn_on = max(abs(_axis(g, "bias_const", a)) for a in "xyz")
    mag_noise = max(float(magnetometer[f"noise_{a}"]) for a in "xyz") / b_min
    return {"sample_period": float(g["sample_period"]),
            **{f"arw_psd_{a}": _axis(g, "arw_psd", a) for a in "xyz"},
            **{f"rrw_psd_{a}": rrw[i] for i, a in enumerate("xyz")},
            "sigma_bias_init": max(1e-4, 2.0 * turn_on),
            "st_noise_cross": float(st["noise_cross"]), "st_noise_about": float(st["noise_about"]),
            "sun_noise": float(sun_sensor["noise"]), "mag_noise": mag_noise,
            "use_star_tracker": 1, "use_sun": 1, "use_mag": 1, "init_from_star_tracker": 1}


def with_estimation(sc: Scenario, name: str | None = None, mekf: dict | None = None, sun_sensor: dict | None = None,
                    magnetometer: dict | None = None, star_tracker: dict | None = None, vectors: bool = True,
                    description: str = "") -> Scenario:
    """``sc`` (an attitude loop, with or without sensors) with the estimator between the sensors and the
    controller: AttitudePlant → Gyro, StarTracker, SunSensor, Magnetometer (+ Ephemeris) → Mekf → controller
    → SampleHold → AttitudePlant. The controller's ``q_*`` ← ``estimator.q_est_*`` and ``w_*`` ←
    ``estimator.w_est_*``; the filter is fed, by name, the gyro's rate, the star tracker's quaternion and
    validity (``w_meas_*``, ``q_meas_*``, ``st_valid``) and, with ``vectors``, the sun sensor's direction with
    its validity (``sun_meas_*``, ``sun_valid``: sun in its field of view and the spacecraft lit: the sensor
    decides, sample by sample) and the magnetometer's field (``b_meas_*``), each with its reference direction
    from the Ephemeris (``sun_ref_*``, ``b_ref_*``). The plant's orbit parameters go to every environment-reading unit, so
    sensors, ephemeris and plant see one environment. ``mekf``: parameters over :func:`mekf_params`.
    ``star_tracker``: parameters over :data:`STAR_TRACKER_EST` (no latency, and the Mekf's ``st_latency`` left
    at 0: a quaternion is taken as measured at its arrival. With a latency τ and no compensation the estimate
    lags by about |ω| τ: with τ = 0.1 s, an RMS error of ~1.2° during paper 000's large slew and ~0.08° over
    its pointing phase, against a filter sigma of ~0.005°. To model a late star tracker, give it ``latency``
    and the filter the same ``st_latency``, a whole number of its sample periods: docs/estimation.md)."""
    s = copy.deepcopy(sc) if any(c.name == "gyro" for c in sc.components) else with_sensors(sc, name=sc.name)
    if any(c.name == "estimator" for c in s.components):
        raise KeyError(f"with_estimation: scenario {sc.name!r} already has an estimator")
    plant = s.component("plant").params
    orbit = {k: plant[k] for k in ORBIT_KEYS if k in plant}
    gyro = {**GYRO_DEFAULT, **s.component("gyro").params}
    st = {**s.component("star_tracker").params, **STAR_TRACKER_EST, **(star_tracker or {})}
    s.component("star_tracker").params = st
    ss = {**SUN_SENSOR_DEFAULT, **orbit, **(sun_sensor or {})}
    mg = {**MAGNETOMETER_DEFAULT, **{k: v for k, v in orbit.items() if k != "sun_ecliptic_longitude"},
          **(magnetometer or {})}
    est = {**mekf_params(gyro, st, ss, mg, orbit), **(mekf or {})}
    if not vectors:
        est.update(use_sun=0, use_mag=0)
    comps = []
    for c in s.components:
        if c.name == "controller":
            if vectors:
                comps += [Component("sun_sensor", "SunSensor", ss), Component("magnetometer", "Magnetometer", mg),
                          Component("ephemeris", "Ephemeris", dict(orbit))]
            comps.append(Component("estimator", "Mekf", est))
        comps.append(c)
    s.components = comps
    # the filter's inputs carry its sources' output names (w_meas, q_meas, st_valid, sun_meas, sun_valid,
    # b_meas; sun_ref, b_ref of the Ephemeris): they connect by name; only the controller is rewired
    s.connections = {**s.connections,
                     **{f"controller.q_{a}": f"estimator.q_est_{a}" for a in "wxyz"},
                     **{f"controller.w_{a}": f"estimator.w_est_{a}" for a in "xyz"}}
    if not vectors:
        s.unconnected = [*s.unconnected, "estimator.sun_*", "estimator.b_meas_*", "estimator.b_ref_*"]
    s.seed_params = [*s.seed_params, *(["sun_sensor.seed", "magnetometer.seed"] if vectors else [])]
    s.log = {**s.log, **log_of("estimator", EST_LOG), **({"sun_valid": "sun_sensor.valid"} if vectors else {})}
    inner = sc.name.removeprefix("sensing/")
    s.name = name or f"sensing+estimation/{inner}"
    s.description = description or (f"{sc.description} — gyro, star tracker"
                                    f"{', sun sensor, magnetometer' if vectors else ''}, Mekf, 10 Hz flight computer")
    return s
