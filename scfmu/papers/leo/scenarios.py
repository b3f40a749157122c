"""The ``leo/*`` scenarios (plain data): a 6U CubeSat on a 500 km sun-synchronous orbit in the environment of
the environment family, every number a project choice stated here and in docs/leo.md.

* Orbit: circular, a = 6 878 137 m (500 km), i = 97.4° (sun-synchronous), RAAN 337.5° (the ascending node at
  10:30 local time at the epoch), epoch 2026-03-20 12:00:00 UTC; two-body + J2 + drag with the ballistic
  coefficient of the spacecraft's ram face.
* Environment: IGRF-14, the sun and the conical shadow, the exponential atmosphere.
* Spacecraft: 10 kg, a 0.100 × 0.2263 × 0.366 m box (x × y × z), inertia of the homogeneous box
  diag(0.1543, 0.1200, 0.0510) kg·m², centre of mass 5, 10, 20 mm off the box's centre, six facets (drag
  coefficient 2.2, specular 0.1, diffuse 0.3), residual dipole (0.02, -0.01, 0.015) A·m²; three reaction
  wheels (spin inertia 1.5e-5 kg·m², 2 mN·m, 680 rad/s: 10 mN·m·s), magnetorquers of 0.2 A·m² per axis.
* ``leo/detumble``: tip-off 5 deg/s per axis, the magnetometer on the IGRF field and B-dot (three orbits,
  1 s step).
* ``leo/sun-pointing``: body +x (the sun sensor's boresight) on the on-board sun, the Mekf on gyro and sun
  sensor (safe mode: no star tracker), through two orbits with their eclipses: the sun sensor's outage and the
  filter coasting on the gyro in the shadow.
* ``leo/nadir``: body z on the Earth's centre and x along-track (LVLH) for one day at 0.1 s, the PD law with
  rate feed-forward on the Mekf's estimate (gyro and a zenith star tracker), with the disturbance budget, the
  wheel momentum and the magnetorquers' dumping logged.
* ``leo/nadir-textbook``: the loop of ``leo/nadir`` in the plant's textbook environment (circular orbit,
  dipole, no Orbit or Environment unit), holding an inertial attitude: the cost baseline of the benchmark.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from ...scenario.model import DEFAULT_UNCONNECTED, Component, Scenario, log_of
from ...scenario.templates import with_estimation

# ----- orbit and epoch ---------------------------------------------------------------------------------------
MU = 3.986004418e14
EARTH_RADIUS = 6_378_137.0
SMA = EARTH_RADIUS + 500e3
INCLINATION = math.radians(97.4)
RAAN = math.radians(337.5)
EPOCH = (2026, 3, 20, 12, 0, 0.0)  # UTC
ORBIT_RATE = math.sqrt(MU / SMA**3)
ORBIT_PERIOD = 2 * math.pi / ORBIT_RATE
DAY = 86_400.0


def julian_date(year: int, month: int, day: int, hour: int, minute: int, second: float) -> float:
    """UTC Julian date of a Gregorian calendar date and time (Fliegel–Van Flandern day number)."""
    a = (14 - month) // 12
    y, m = year + 4800 - a, month + 12 * a - 3
    jdn = day + (153 * m + 2) // 5 + 365 * y + y // 4 - y // 100 + y // 400 - 32045
    return jdn - 0.5 + (hour * 3600 + minute * 60 + second) / DAY


EPOCH_JD = julian_date(*EPOCH)
EPOCH_PARAMS = dict(zip(("epoch_year", "epoch_month", "epoch_day", "epoch_hour", "epoch_minute", "epoch_second"),
                        EPOCH))

# ----- spacecraft --------------------------------------------------------------------------------------------
MASS = 10.0
BOX = (0.100, 0.2263, 0.366)
COM = (0.005, 0.010, 0.020)  # centre of mass from the box's centre
INERTIA = {f"inertia_{a}{a}": MASS / 12 * (BOX[(i + 1) % 3] ** 2 + BOX[(i + 2) % 3] ** 2) for i, a in enumerate("xyz")}
DRAG_COEFF, SPECULAR, DIFFUSE = 2.2, 0.1, 0.3
RESIDUAL_DIPOLE = (0.02, -0.01, 0.015)
BALLISTIC = MASS / (DRAG_COEFF * BOX[1] * BOX[2])  # the +x face flies into the flow in nadir pointing


def facets() -> dict:
    """The six faces of the box as the plant's facets 1–6 (+x, -x, +y, -y, +z, -z)."""
    out = {}
    for k, (axis, sign) in enumerate([(a, s) for a in range(3) for s in (1, -1)], 1):
        normal = [0.0] * 3
        normal[axis] = float(sign)
        centre = [(sign * BOX[axis] / 2 if i == axis else 0.0) - COM[i] for i in range(3)]
        area = BOX[(axis + 1) % 3] * BOX[(axis + 2) % 3]
        out[f"facet{k}_area"] = area
        for i, a in enumerate("xyz"):
            out[f"facet{k}_normal_{a}"] = normal[i]
            out[f"facet{k}_centre_{a}"] = centre[i]
        out.update({f"facet{k}_drag_coeff": DRAG_COEFF, f"facet{k}_specular": SPECULAR,
                    f"facet{k}_diffuse": DIFFUSE})
    return out


WHEELS = {"actuator_mode": 1, "wheel_inertia": 1.5e-5, "wheel_max_speed": 680.0, "wheel_torque_coeff": 0.002,
          "wheel_max_current": 1.0}
MTQ = {"mtq_turns": 500.0, "mtq_coil_area": 0.01, "mtq_max_current": 0.04}  # 0.2 A·m²
# the plant's own circular orbit at the same radius: read by the textbook twin, and by the Mekf's
# magnetometer noise (weakest dipole field on the orbit)
CIRCULAR = {"orbit_radius": SMA, "orbit_inclination": INCLINATION}


def plant_params(**extra) -> dict:
    return {**INERTIA, **facets(), **WHEELS, **MTQ, **CIRCULAR, "environment_inputs": 1, "gg_enable": 1,
            **{f"residual_dipole_{a}": RESIDUAL_DIPOLE[i] for i, a in enumerate("xyz")},
            "max_internal_step": 0.1, **extra}


def orbit_units() -> list[Component]:
    """``Environment`` (IGRF-14, sun, shadow, exponential atmosphere) and ``Orbit`` (J2 + drag) at the epoch. The
    Environment comes first in the Gauss–Seidel order: it reads the orbit's position of the communication point
    and is evaluated once per step, and the orbit's drag reads the density at that position."""
    return [Component("environment", "Environment", dict(EPOCH_PARAMS)),
            Component("orbit", "Orbit", {"semi_major_axis": SMA, "eccentricity": 0.0, "inclination": INCLINATION,
                                         "raan": RAAN, "epoch_jd_utc": EPOCH_JD, "ballistic_coeff": BALLISTIC,
                                         "tolerance": 1e-10})]


def initial_state() -> tuple[np.ndarray, np.ndarray]:
    """r, v at the epoch (circular orbit, argument of latitude 0: the ascending node)."""
    r = SMA * np.array([math.cos(RAAN), math.sin(RAAN), 0.0])
    v = math.sqrt(MU / SMA) * np.array([-math.sin(RAAN) * math.cos(INCLINATION),
                                        math.cos(RAAN) * math.cos(INCLINATION), math.sin(INCLINATION)])
    return r, v


def lvlh_start() -> dict:
    """The plant's initial attitude and rate on the LVLH frame at the epoch (321 angles of A = [x y z]ᵀ)."""
    r, v = initial_state()
    z = -r / np.linalg.norm(r)
    h = np.cross(r, v)
    y = -h / np.linalg.norm(h)
    x = np.cross(y, z)
    return {**euler321(np.vstack([x, y, z])),  # rows: the body axes in inertial components
            "init_w_x": 0.0, "init_w_y": float(-np.linalg.norm(h) / np.dot(r, r)), "init_w_z": 0.0}


def sun_direction(jd: float) -> np.ndarray:
    """Unit vector to the sun (equator and equinox of date) by the Astronomical Almanac's low-precision formula
    (about 0.01°); used only for the start of leo/sun-pointing, whose command reads Environment's sun."""
    n = jd - 2_451_545.0
    g = math.radians(357.528 + 0.985_600_3 * n)
    lam = math.radians(280.460 + 0.985_647_4 * n + 1.915 * math.sin(g) + 0.020 * math.sin(2 * g))
    eps = math.radians(23.439 - 4e-7 * n)
    return np.array([math.cos(lam), math.cos(eps) * math.sin(lam), math.sin(eps) * math.sin(lam)])


SUN_AXIS, SUN_SECONDARY = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)  # body +x (the sun sensor's boresight) on the sun


def sun_start() -> dict:
    """The plant's initial attitude on the sun-pointing attitude at the epoch (body +x on the sun, body z
    toward the inertial z axis), within the precession since 2000 (0.36°) of the command's."""
    s, z = sun_direction(EPOCH_JD), np.array([0.0, 0.0, 1.0])
    u2 = np.cross(s, z) / np.linalg.norm(np.cross(s, z))
    a1, b = np.array(SUN_AXIS), np.array(SUN_SECONDARY)
    a2 = np.cross(a1, b)
    a = np.column_stack([a1, a2, np.cross(a1, a2)]) @ np.column_stack([s, u2, np.cross(s, u2)]).T
    return euler321(a)


def euler321(a: np.ndarray) -> dict:
    """The plant's initial 321 angles of an attitude matrix A (inertial → body)."""
    return {"init_euler321_roll": math.atan2(a[1, 2], a[2, 2]), "init_euler321_pitch": -math.asin(a[0, 2]),
            "init_euler321_yaw": math.atan2(a[0, 1], a[0, 0])}


ENV_SENSOR = {"environment_inputs": 1}
SUN_MODEL_ERROR = math.radians(2.0)  # the on-board mean sun neglects the equation of centre (at most 1.9°)
FIELD_MODEL_ERROR = math.radians(15.0)  # the on-board axial dipole against IGRF-14 at 500 km
BUDGET_LOG = [f"{stem}_{a}" for stem in ("torque_gg", "torque_aero", "torque_srp", "torque_residual",
                                         "h_wheel", "dipole") for a in "xyz"]
ORBIT_LOG = {"altitude": "orbit.altitude", "eclipse": "environment.eclipse", "rho": "environment.rho",
             **log_of("orbit", ["r_x", "r_y", "r_z"]), **log_of("environment", ["b_eci_x", "b_eci_y", "b_eci_z", "sun_eci_x", "sun_eci_y", "sun_eci_z"])}
PLANT_LOG = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", *BUDGET_LOG, "torque_ext_x", "torque_ext_y",
             "torque_ext_z", "b_body_x", "b_body_y", "b_body_z", "h_total_ref_x", "h_total_ref_y", "h_total_ref_z"]
PD_GAINS = {"wn": 0.1, "zeta": 0.9, "rate_feedforward": 1}
UNCONNECTED = [*DEFAULT_UNCONNECTED, "plant.torque_dist_*"]


def detumble() -> Scenario:
    tip_off = math.radians(5.0)
    j_min = min(INERTIA.values())
    law = {"sample_period": 1.0, "filter_time_constant": 1.0, "dipole_max": 0.2, "orbit_rate": ORBIT_RATE,
           "field_inclination": INCLINATION, "inertia_min": j_min, "gain_rule": 1}
    plant = plant_params(mtq_mode=1, actuator_mode=0, **{f"init_w_{a}": tip_off for a in "xyz"})
    stop = round(3 * ORBIT_PERIOD)
    return Scenario(
        name="leo/detumble",
        components=[*orbit_units(),
                    Component("magnetometer", "Magnetometer", {"sample_period": 1.0, **ENV_SENSOR}),
                    Component("bdot", "BDot", law),
                    Component("plant", "AttitudePlant", plant)],
        stop_time=float(stop), step=1.0,
        log={**log_of("plant", ["w_x", "w_y", "w_z", *BUDGET_LOG, "b_body_x", "b_body_y", "b_body_z"]),
             **log_of("bdot", ["m_cmd_x", "m_cmd_y", "m_cmd_z"]), **ORBIT_LOG},
        unconnected=[*UNCONNECTED, "plant.torque_cmd_*"],
        seed_params=["magnetometer.seed"],
        description="6U, 500 km sun-synchronous orbit, IGRF-14: tip-off 5 deg/s per axis, B-dot on the "
                    "magnetometer driving 0.2 A·m² magnetorquers, three orbits")


def _pointing(name: str, command: dict, sensors: dict, stop: float, description: str,
              textbook: bool = False) -> Scenario:
    """Orbit, Environment → AttitudeCommand → PD (rate feed-forward) on the Mekf's estimate → plant."""
    start = {1: lvlh_start, 2: sun_start}.get(command.get("reference"), dict)()
    plant = plant_params(mtq_enable=1, **start)
    if textbook:
        plant.update(environment_inputs=0, gg_enable=1)
    base = Scenario(
        name=name,
        components=[*([] if textbook else orbit_units()),
                    Component("command", "AttitudeCommand", command),
                    Component("controller", "PdController", dict(PD_GAINS), slot=dict(INERTIA)),
                    Component("plant", "AttitudePlant", plant)],
        stop_time=stop, step=0.1,
        log={**log_of("plant", PLANT_LOG),
             **log_of("command", ["q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"]),
             **({} if textbook else ORBIT_LOG)},
        unconnected=list(UNCONNECTED),
        seed_params=["plant.dist_noise_seed"],
        description=description)
    env = {} if textbook else ENV_SENSOR
    sc = with_estimation(
        base, name=name, description=description,
        sun_sensor={**env, **sensors.get("sun_sensor", {})}, magnetometer={**env, **sensors.get("magnetometer", {})},
        star_tracker=sensors.get("star_tracker"), mekf=sensors.get("mekf"), vectors=sensors.get("vectors", True))
    for c in sc.components:
        if c.name == "ephemeris":
            c.params.update(env)
        if c.name == "gyro":
            c.params.update(sample_period=0.1)
        if c.name == "hold":
            c.params.update(sample_period=0.1, delay=0.0)
    est = sc.component("estimator").params
    est["sample_period"] = 0.1
    if not textbook and "sun_noise" in est:
        # the filter's vector noise includes the on-board models' error against the truth (measured along the
        # orbit: the mean sun 1.9°, the axial dipole 13° RMS and up to 26° against IGRF-14)
        est["sun_noise"] = math.hypot(est["sun_noise"], SUN_MODEL_ERROR)
        est["mag_noise"] = math.hypot(est["mag_noise"], FIELD_MODEL_ERROR)
    return sc


def sun_pointing() -> Scenario:
    start = sun_start()
    q0 = quat_from_euler321(start["init_euler321_roll"], start["init_euler321_pitch"], start["init_euler321_yaw"])
    # the safe-mode set: gyro and sun sensor. The magnetometer is left out of the filter: against the on-board
    # axial dipole (13° RMS from IGRF-14 along this orbit) its updates pull the estimate up to 18° off the sun
    # in eclipse (docs/leo.md); without it the estimate coasts on the gyro through the shadow
    sensors = {"mekf": {"use_star_tracker": 0, "init_from_star_tracker": 0, "use_mag": 0,
                        **{f"q_init_{c}": q0[i] for i, c in enumerate("wxyz")}}, "star_tracker": {}}
    axes = {**{f"sun_axis_{c}": SUN_AXIS[i] for i, c in enumerate("xyz")},
            **{f"secondary_axis_{c}": SUN_SECONDARY[i] for i, c in enumerate("xyz")}}
    sc = _pointing("leo/sun-pointing", {"reference": 2, **axes},
                   sensors, float(round(2 * ORBIT_PERIOD)),
                   "6U, 500 km sun-synchronous orbit: body +x on the sun through two orbits and their eclipses, "
                   "Mekf on gyro and sun sensor (no star tracker)")
    sc.components = [c for c in sc.components if c.name not in ("star_tracker", "magnetometer")]
    # the flight computer points at its own (on-board) sun, the one its estimate is consistent with: the command
    # reads the Ephemeris, after it in the Gauss–Seidel order
    sc.connections.update({f"command.sun_eci_{a}": f"ephemeris.sun_ref_{a}" for a in "xyz"})
    command = sc.component("command")
    sc.components.remove(command)
    sc.components.insert([c.name for c in sc.components].index("controller"), command)
    sc.unconnected = [*sc.unconnected, "estimator.q_meas_*", "estimator.st_valid", "estimator.b_meas_*"]
    sc.seed_params = [p for p in sc.seed_params if not p.startswith(("star_tracker.", "magnetometer."))]
    sc.log = {k: v for k, v in sc.log.items() if not v.startswith(("star_tracker.", "magnetometer."))}
    sc.log.update(sun_valid="sun_sensor.valid", **log_of("ephemeris", ["sun_ref_x", "sun_ref_y", "sun_ref_z"]))
    return sc


def quat_from_euler321(roll: float, pitch: float, yaw: float) -> list[float]:
    """q = q_z(yaw) ⊗ q_y(pitch) ⊗ q_x(roll), scalar first (the plant's 321 convention)."""
    cr, sr, cp, sp, cy, sy = (f(a / 2) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    return [cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr]


def nadir(textbook: bool = False) -> Scenario:
    name = "leo/nadir-textbook" if textbook else "leo/nadir"
    command = {"reference": 0} if textbook else {"reference": 1}
    desc = ("the loop of leo/nadir in the plant's textbook environment (circular orbit, dipole), inertial hold: "
            "the cost baseline" if textbook else
            "6U, 500 km sun-synchronous orbit: nadir pointing (LVLH) for one day, PD with rate feed-forward on "
            "the Mekf, wheels with magnetorquer dumping, disturbance budget")
    # fine pointing on the gyro and the star tracker (2 Hz, looking at the zenith: body -z); the sun sensor and the
    # magnetometer with the on-board models (2° and 13° RMS from the truth) serve leo/sun-pointing
    start = lvlh_start()
    q0 = quat_from_euler321(start["init_euler321_roll"], start["init_euler321_pitch"], start["init_euler321_yaw"])
    sensors = {"star_tracker": {"sample_period": 0.5, "mount_x": math.pi},
               "mekf": {"st_mount_x": math.pi, **{f"q_init_{c}": q0[i] for i, c in enumerate("wxyz")}},
               "vectors": False}
    return _pointing(name, command, sensors, DAY, desc, textbook=textbook)


BUILDERS = {"leo/detumble": detumble, "leo/sun-pointing": sun_pointing, "leo/nadir": nadir,
            "leo/nadir-textbook": lambda: nadir(textbook=True)}
EXPORTED = ("leo/detumble", "leo/sun-pointing", "leo/nadir")


def build(name: str, stop_time: float | None = None, **_kw) -> Scenario:
    """The scenario ``name``; ``stop_time``: a shorter (or longer) run of the same loop."""
    return built(BUILDERS, name, stop_time)


def built(builders: dict, name: str, stop_time: float | None = None) -> Scenario:
    """The scenario ``name`` of a plug-in's ``builders`` (name → function), with ``stop_time`` when given (the
    ``build`` of the plug-ins that build on this spacecraft: leo, mission)."""
    if name not in builders:
        raise KeyError(f"unknown scenario {name!r}: expected one of {list(builders)}")
    sc = copy.deepcopy(builders[name]())
    if stop_time is not None:
        sc.stop_time = float(stop_time)
    return sc


def names() -> list[tuple[str, str]]:
    return [("leo/detumble", "6U, 500 km SSO, IGRF-14: B-dot detumbling from 5 deg/s per axis (three orbits)"),
            ("leo/sun-pointing", "6U, 500 km SSO: sun pointing through eclipses, Mekf without star tracker (two orbits)"),
            ("leo/nadir", "6U, 500 km SSO: nadir pointing for a day, disturbance budget, wheel momentum and dumping"),
            ("leo/nadir-textbook", "the leo/nadir loop in the plant's textbook environment (cost baseline)")]
