"""The ``mission/*`` scenarios (plain data): the 6U CubeSat of ``leo/*`` (same orbit, epoch, environment,
spacecraft, wheels and magnetorquers) with its whole ADCS in one loop under a ``ModeManager``. Every number
is a project choice, stated here and in docs/mission.md.

The loop, in Gauss–Seidel order:

* ``environment``, ``orbit``: IGRF-14, sun, shadow, atmosphere; J2 + drag (as ``leo/*``);
* sensors: ``gyro`` (10 Hz), ``sun_sensor`` (10 Hz, whole sky: the coarse sun sensors a safe mode needs on
  every face, 0.1° noise, nothing in the shadow), ``magnetometer`` (1 Hz, for B-dot and the Triad),
  ``star_tracker`` (2 Hz, looking at the zenith in nadir pointing: body −z), ``ephemeris`` (on-board mean sun
  and axial dipole at the Orbit's position);
* ``coarse`` (Triad, anchored on the sun): the coarse attitude that initialises the filter;
* ``estimator`` (Mekf on gyro + star tracker; re-initialised from ``coarse`` while the manager's
  ``estimator_init`` is 1);
* ``manager`` (ModeManager, 1 Hz): the mode from the gyro's rate, the sun sensor, the filter's covariance and
  NIS, the plant's actuator health flag; its selection signals drive the gate and the switch;
* ``command`` (AttitudeCommand, nadir: LVLH from the Orbit's r, v);
* ``gate`` (EstimateGate): the pointing controller sees the estimate in FINE_POINTING, its reference (a zero
  error) before — so a controller with internal state starts its mode from its initial state;
* ``controller`` (the FINE_POINTING law; PdController with rate feed-forward by default; any attitude
  controller swaps in with ``--fmu controller=…``);
* ``safe`` (SunSafeController): body +x on the measured sun, rate damping on the gyro (SAFE, SUN_ACQUISITION,
  DETERMINATION);
* ``bdot`` (BDot on the magnetometer, DETUMBLE);
* ``switch`` (CommandSwitch): which torque and which dipole reach the plant;
* ``plant`` (AttitudePlant, reaction wheels; magnetorquers: the switch's dipole plus the wheels' momentum
  dumping, ``mtq_mode = 2``).

* ``mission/tipoff``: separation at 3 deg/s about each axis (5.2 deg/s) in a random-looking attitude, all the
  way to fine pointing (two orbits).
* ``mission/wheel-fault``: fine pointing from the start; the x wheel fails at t = 600 s (its torque goes to
  zero and its telemetry flag to 1), the manager enters SAFE and the sun-safe law holds +x on the sun with the
  y and z wheels (pointing one axis needs torque only across it); the ground resets the wheel at 1 800 s and
  commands recovery at 2 400 s; back to fine pointing through SUN_ACQUISITION and DETERMINATION.
"""

from __future__ import annotations

import math

from ...scenario.model import Component, Scenario, log_of
from ...scenario.templates import GYRO_DEFAULT, MAGNETOMETER_DEFAULT, STAR_TRACKER_NOISE, mekf_params
from ..leo import scenarios as leo

STEP = 0.1
MODES = {0: "SAFE", 1: "DETUMBLE", 2: "SUN_ACQUISITION", 3: "DETERMINATION", 4: "FINE_POINTING"}
SAFE, DETUMBLE, SUN_ACQUISITION, DETERMINATION, FINE_POINTING = range(5)
TIPOFF_DEG_S = 3.0
TIPOFF_ATTITUDE = (0.7, -0.4, 2.1)  # 321 angles at separation [rad]
# the manager's thresholds over its defaults: the tumbling threshold above the sun-safe law's largest slew rate
# (wn sin(θ/2) / ζ ≤ 0.033 rad/s = 1.9 deg/s, the balance of its two terms), so that acquiring the sun from behind
# does not read as tumbling; a fault flag held 2 s before it counts
MANAGER = {"sample_period": 1.0, "sun_axis_x": 1.0, "sun_axis_y": 0.0, "sun_axis_z": 0.0,
           "rate_tumbling": math.radians(3.0), "fault_confirm_time": 2.0, "nis_source": 1}
SAFE_LAW = {"wn": 0.03, "zeta": 0.9, "sun_axis_x": 1.0, "sun_axis_y": 0.0, "sun_axis_z": 0.0}
GYRO = {**GYRO_DEFAULT, "sample_period": STEP}
SUN_SENSOR = {"sample_period": STEP, "noise": 1.745e-3, "fov": math.pi, "shadow": 1, "mount_y": math.pi / 2,
              "environment_inputs": 1}
MAGNETOMETER = {**MAGNETOMETER_DEFAULT, "sample_period": 1.0, "environment_inputs": 1}
STAR_TRACKER = {"sample_period": 0.5, "latency": 0.0, "mount_x": math.pi}
BDOT = {"sample_period": 1.0, "filter_time_constant": 1.0, "dipole_max": 0.2, "orbit_rate": leo.ORBIT_RATE,
        "field_inclination": leo.INCLINATION, "inertia_min": min(leo.INERTIA.values()), "gain_rule": 1}
SIGMA_COARSE = 0.35  # the Triad's error: the on-board axial dipole is up to 26° off IGRF-14 about the sun line
# the power model of docs/mission.md (a metric, not a unit): a body-mounted array on +x, 30 % cells
ARRAY_AREA = leo.BOX[1] * leo.BOX[2]
ARRAY_POWER = 1361.0 * ARRAY_AREA * 0.30  # W at normal incidence, 1 au
SAFE_LOAD = 10.0  # W, the spacecraft's consumption in safe mode

MANAGER_LOG = ["mode", "time_in_mode", "mode_changes", "torque_select", "dipole_select", "estimator_init",
               "controller_enable", "rate", "sigma_att", "nis_avg", "sun_angle", "last_reason"]


def _mekf() -> dict:
    est = mekf_params(GYRO, {**STAR_TRACKER_NOISE, **STAR_TRACKER}, SUN_SENSOR, MAGNETOMETER,
                      {"orbit_radius": leo.SMA})
    return {**est, "use_star_tracker": 1, "init_from_star_tracker": 0, "use_sun": 0, "use_mag": 0,
            "st_mount_x": math.pi, "sigma_att_init": 3.0, "sigma_att_coarse": SIGMA_COARSE}


def loop(name: str, plant: dict, manager: dict, mekf: dict, stop: float, description: str) -> Scenario:
    """The whole ADCS loop (module docstring) with the plant's, the manager's and the filter's parameters."""
    truth = {f"{unit}.q_{a}": f"plant.q_{a}" for unit in ("sun_sensor", "magnetometer", "star_tracker")
             for a in "wxyz"}
    comps = [*leo.orbit_units(),
             Component("gyro", "Gyro", dict(GYRO)),
             Component("sun_sensor", "SunSensor", dict(SUN_SENSOR)),
             Component("magnetometer", "Magnetometer", dict(MAGNETOMETER)),
             Component("star_tracker", "StarTracker", dict(STAR_TRACKER)),
             Component("ephemeris", "Ephemeris", {"environment_inputs": 1}),
             Component("coarse", "Triad", {}),
             Component("estimator", "Mekf", {**_mekf(), **mekf}),
             Component("manager", "ModeManager", {**MANAGER, **manager}),
             Component("command", "AttitudeCommand", {"reference": 1}),
             Component("gate", "EstimateGate", {}),
             Component("controller", "PdController", dict(leo.PD_GAINS), slot=dict(leo.INERTIA)),
             Component("safe", "SunSafeController", dict(SAFE_LAW), slot=dict(leo.INERTIA)),
             Component("bdot", "BDot", dict(BDOT)),
             Component("switch", "CommandSwitch", {}),
             Component("plant", "AttitudePlant", leo.plant_params(mtq_mode=2, mtq_enable=1, **plant))]
    connections = {
        **truth, **{f"gyro.w_{a}": f"plant.w_{a}" for a in "xyz"},
        **{f"estimator.q_coarse_{a}": f"coarse.q_est_{a}" for a in "wxyz"},
        "estimator.init_request": "manager.estimator_init",
        **{f"gate.q_est_{a}": f"estimator.q_est_{a}" for a in "wxyz"},
        **{f"gate.w_est_{a}": f"estimator.w_est_{a}" for a in "xyz"},
        "gate.enable": "manager.controller_enable",
        **{f"controller.q_{a}": f"gate.q_{a}" for a in "wxyz"},
        **{f"controller.w_{a}": f"gate.w_{a}" for a in "xyz"},
        **{f"switch.torque_safe_{a}": f"safe.torque_cmd_{a}" for a in "xyz"},
        **{f"switch.torque_fine_{a}": f"controller.torque_cmd_{a}" for a in "xyz"},
        **{f"switch.m_bdot_{a}": f"bdot.m_cmd_{a}" for a in "xyz"},
        **{f"plant.torque_cmd_{a}": f"switch.torque_cmd_{a}" for a in "xyz"},
        **{f"plant.m_cmd_{a}": f"switch.m_cmd_{a}" for a in "xyz"},
    }
    log = {**log_of("plant", [*leo.PLANT_LOG, "actuator_fault", "wheel_speed_x", "wheel_speed_y", "wheel_speed_z",
                              "torque_applied_x", "torque_applied_y", "torque_applied_z"]),
           **log_of("command", ["q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"]),
           **log_of("manager", MANAGER_LOG),
           **log_of("estimator", ["q_est_w", "q_est_x", "q_est_y", "q_est_z", "p_att_x", "p_att_y", "p_att_z"]),
           "sun_valid": "sun_sensor.valid", **leo.ORBIT_LOG}
    return Scenario(
        name=name, components=comps, stop_time=stop, step=STEP, log=log, connections=connections,
        unconnected=[*leo.UNCONNECTED, "manager.recover", "manager.safe_request", "command.sun_eci_*",
                     "controller.w_ref_dot_*", "estimator.sun_*", "estimator.b_meas_*", "estimator.b_ref_*"],
        seed_params=["gyro.seed", "sun_sensor.seed", "magnetometer.seed", "star_tracker.seed",
                     "plant.dist_noise_seed"],
        metrics="mission", description=description)


def tipoff() -> Scenario:
    rate = math.radians(TIPOFF_DEG_S)
    roll, pitch, yaw = TIPOFF_ATTITUDE
    plant = {"init_euler321_roll": roll, "init_euler321_pitch": pitch, "init_euler321_yaw": yaw,
             **{f"init_w_{a}": s * rate for a, s in zip("xyz", (1.0, -1.0, 1.0))}}
    return loop("mission/tipoff", plant, {"initial_mode": DETUMBLE}, {}, float(round(2 * leo.ORBIT_PERIOD)),
                f"6U, 500 km SSO: separation at {TIPOFF_DEG_S:g} deg/s per axis to nadir fine pointing under the "
                "ModeManager (B-dot, sun-safe law, Triad + Mekf, PD on the estimate), two orbits")


FAULT_TIME, CLEAR_TIME, RECOVER_TIME = 600.0, 1800.0, 2400.0


def wheel_fault() -> Scenario:
    start = leo.lvlh_start()
    q0 = leo.quat_from_euler321(start["init_euler321_roll"], start["init_euler321_pitch"],
                                start["init_euler321_yaw"])
    plant = {**start, "fault_time": FAULT_TIME, "fault_clear_time": CLEAR_TIME, "effectiveness_x": 0.0}
    mekf = {**{f"q_init_{c}": q0[i] for i, c in enumerate("wxyz")}, "sigma_att_init": 1e-3}
    return loop("mission/wheel-fault", plant, {"initial_mode": FINE_POINTING, "recover_time": RECOVER_TIME}, mekf,
                float(round(leo.ORBIT_PERIOD)),
                f"6U, 500 km SSO, nadir fine pointing: the x wheel fails at {FAULT_TIME:g} s, SAFE (sun-safe law on "
                f"the y and z wheels), wheel reset at {CLEAR_TIME:g} s, recovery commanded at {RECOVER_TIME:g} s, "
                "back to fine pointing; one orbit")


# the mission campaign's dispersions (``scfmu campaign mission/tipoff --runs N``): CLI distribution specs
DISPERSIONS = {
    **{f"plant.init_w_{a}": f"uniform:{-math.radians(5):.6g}:{math.radians(5):.6g}" for a in "xyz"},
    **{f"plant.inertia_scale_{a}": "uniform:0.9:1.1" for a in "xyz"},
    "plant.init_euler321_roll": f"uniform:{-math.pi:.6g}:{math.pi:.6g}",
    "plant.init_euler321_pitch": f"uniform:{-math.pi / 2:.6g}:{math.pi / 2:.6g}",
    "plant.init_euler321_yaw": f"uniform:{-math.pi:.6g}:{math.pi:.6g}",
    "sun_sensor.noise": "uniform:0.00087:0.0035",
}

BUILDERS = {"mission/tipoff": tipoff, "mission/wheel-fault": wheel_fault}
EXPORTED = ("mission/tipoff", "mission/wheel-fault")


def build(name: str, stop_time: float | None = None, **_kw) -> Scenario:
    """The scenario ``name``; ``stop_time``: a shorter (or longer) run of the same loop."""
    return leo.built(BUILDERS, name, stop_time)


def names() -> list[tuple[str, str]]:
    return [("mission/tipoff", "6U, 500 km SSO: tip-off to nadir fine pointing under the ModeManager (two orbits)"),
            ("mission/wheel-fault", "6U, 500 km SSO: wheel fault in fine pointing, SAFE on the sun, recovery on "
                                    "command (one orbit)")]
