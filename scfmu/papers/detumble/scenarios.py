"""The detumble scenarios (plain data): plant, magnetometer and B-dot law.

* ``detumble``: a 12U-class satellite, inertia diag(0.08, 0.10, 0.12) kg·m², tip-off rate 5 deg/s about
  each body axis, on the plant's 700 km, 98° circular orbit with its non-tilted dipole field; magnetometer
  at 1 Hz (100 nT noise); B-dot law at 1 Hz with a 1 s derivative filter and the gain rule
  k = 2 n (1 + sin ξ_m) J_min; magnetorquers of 0.2 A·m² per axis (500 turns, 0.01 m², 0.04 A). Two orbits.
* ``detumble/slow``: the same with a twentieth of the rule's gain and three orbits: the decay is slow
  against the field's rotation, the regime in which the orbit-averaged model holds
  (``src/models/estimation/tests/test_bdot_detumble.py`` compares its decay rate with that model).

Any plant, magnetometer or law parameter can be overridden (``plant.init_w_x``, ``bdot.gain``, ...)."""

from __future__ import annotations

import math

from ...scenario.model import DEFAULT_UNCONNECTED, Component, Scenario, log_of

TIP_OFF = math.radians(5.0)  # rad/s per axis
INERTIA = {"inertia_xx": 0.08, "inertia_yy": 0.10, "inertia_zz": 0.12}
J_MIN = 0.08
MU, RADIUS, INCLINATION = 3.986004418e14, 7078137.0, math.radians(98.0)  # the plant's orbit defaults
ORBIT_RATE = math.sqrt(MU / RADIUS**3)
ORBIT_PERIOD = 2 * math.pi / ORBIT_RATE
RULE_GAIN = 2 * ORBIT_RATE * (1 + math.sin(INCLINATION)) * J_MIN  # N·m·s
DIPOLE_MAX = 0.2  # A·m²
SLOW = 20.0  # detumble/slow: gain = RULE_GAIN / SLOW
STEP = 1.0


def build(name: str, **_kw) -> Scenario:
    if name == "detumble":
        bdot, orbits = {"gain_rule": 1}, 2
    elif name == "detumble/slow":
        bdot, orbits = {"gain_rule": 0, "gain": RULE_GAIN / SLOW}, 3
    else:
        raise KeyError(f"unknown scenario {name!r}: expected one of {[n for n, _ in names()]}")
    plant = {**INERTIA, "init_w_x": TIP_OFF, "init_w_y": TIP_OFF, "init_w_z": TIP_OFF, "mtq_mode": 1,
             "mtq_max_current": 0.04, "max_internal_step": 0.1}
    law = {"sample_period": 1.0, "filter_time_constant": 1.0, "dipole_max": DIPOLE_MAX, "orbit_rate": ORBIT_RATE,
           "field_inclination": INCLINATION, "inertia_min": J_MIN, **bdot}
    stop = STEP * round(orbits * ORBIT_PERIOD / STEP)
    return Scenario(
        name=name,
        # Gauss–Seidel order: the sensor and the law before the plant, so that the plant's command at t is the
        # law's sample from the field measured at t (the plant's outputs at t do not depend on its inputs)
        components=[
            Component("magnetometer", "Magnetometer", {"sample_period": 1.0}),
            Component("bdot", "BDot", law),
            Component("plant", "AttitudePlant", plant),
        ],
        stop_time=stop, step=STEP,
        log={**log_of("plant", ["w_x", "w_y", "w_z", "dipole_x", "dipole_y", "dipole_z", "b_body_x", "b_body_y",
                                "b_body_z"]),
             **log_of("bdot", ["m_cmd_x", "m_cmd_y", "m_cmd_z"])},
        unconnected=[*DEFAULT_UNCONNECTED, "plant.torque_cmd_*"],
        seed_params=["magnetometer.seed"],
        description=("tip-off 5 deg/s per axis, B-dot law on the magnetometer driving 0.2 A·m² magnetorquers, "
                     + ("gain rule, two orbits" if name == "detumble" else f"1/{SLOW:g} of the rule's gain, three orbits")),
    )


def names() -> list[tuple[str, str]]:
    return [("detumble", "12U satellite, tip-off 5 deg/s per axis, B-dot detumbling with the gain rule (two orbits)"),
            ("detumble/slow", "the same with 1/20 of the rule's gain (three orbits): the orbit-averaged regime")]
