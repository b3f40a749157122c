"""The one matcher of the ``unconnected`` lists (:func:`scfmu.scenario.matches_input`), used by the scenarios'
wiring check and by the reference master's optional inputs: bare and qualified glob patterns, and the
reference master's reading of ``x_*`` as covering the scalar port ``x`` (SingleAxisPlant's ``torque_dist``)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from scfmu.engines.reference import CoSimulation
from scfmu.scenario import DEFAULT_UNCONNECTED, Component, Scenario, matches_input


@pytest.mark.parametrize("port, stems, expected", [
    ("torque_dist_x", False, True),  # a vector element, the glob itself
    ("torque_dist_z", True, True),
    ("torque_dist", False, False),  # the scalar stem only with stems
    ("torque_dist", True, True),
    ("torque_dist_", False, True),  # "*" matches the empty tail
    ("torque_distx", True, False),  # not the stem, not "stem_..."
    ("torque_dis", True, False),
    ("dist", True, True),  # "dist_*" covers the scalar "dist" too
    ("h_wheel", True, True),  # "h_wheel*": a glob without "_*", matched as a glob only
    ("h_wheel_1", False, True),
    ("h_whee", True, False),
    ("m_cmd", True, True),
    ("m_cmd_y", False, True),
    ("leader_true_anomaly", False, True),  # a plain name
    ("leader_true_anomaly_x", True, False),
    ("q_ref_dot_w", False, True),
    ("torque_cmd_x", True, False),
    ("Torque_dist_x", True, False),  # case-sensitive
])
def test_default_optional_inputs(port, stems, expected):
    assert matches_input(port, DEFAULT_UNCONNECTED, stems=stems) is expected


def test_qualified_patterns_name_one_instance():
    pats = ["plant.torque_cmd_*", "hold.u_*"]
    assert matches_input("torque_cmd_x", pats, "plant")
    assert not matches_input("torque_cmd_x", pats, "other")
    assert not matches_input("torque_cmd_x", pats)  # no instance: a qualified pattern names none
    assert not matches_input("torque_cmd", pats, "plant", stems=False)
    assert matches_input("u_1", pats, "hold") and not matches_input("u_1", pats, "plant")
    assert not matches_input("x", [])


def test_scenario_and_reference_master_read_the_lists_through_the_matcher():
    """The scenario's wiring check takes its own list as written (paper002 names "torque_dist" itself); the
    reference master's required-input rule covers the scalar stem of the default list."""
    sc = Scenario(name="t", components=[], stop_time=1.0, step=0.1, unconnected=[*DEFAULT_UNCONNECTED, "plant.torque_cmd_*"])
    assert sc._is_unconnected("plant", "torque_dist_y") and sc._is_unconnected("plant", "torque_cmd_x")
    assert not sc._is_unconnected("ctrl", "torque_cmd_x")
    assert not sc._is_unconnected("plant", "torque_dist")
    unit = SimpleNamespace(model="PdController")
    assert not CoSimulation._required(unit, "torque_dist") and not CoSimulation._required(unit, "torque_dist_x")
    assert CoSimulation._required(unit, "torque_cmd") and CoSimulation._required(unit, "torque_distx")


def test_model_qualified_patterns_name_the_inputs_of_one_model():
    """AttitudePlant's environment position may stay open (read with environment_inputs = 1 only);
    Environment's r, the same port name, must be wired: "AttitudePlant:r_*" names the first only."""
    pats = ["AttitudePlant:r_*"]
    assert matches_input("r_x", pats, model="AttitudePlant")
    assert matches_input("r_x", pats, model="/some/where/AttitudePlant.fmu")
    assert not matches_input("r_x", pats, model="Environment")
    assert not matches_input("r_x", pats)  # no model: names none
    sc = Scenario(name="t", components=[Component("plant", "AttitudePlant"), Component("env", "Environment")],
                  stop_time=1.0, step=0.1)
    assert sc._is_unconnected("plant", "r_y") and not sc._is_unconnected("env", "r_y")
    assert not CoSimulation._required(SimpleNamespace(model="AttitudePlant"), "v_z")
    assert CoSimulation._required(SimpleNamespace(model="Environment"), "r_x")


def test_the_sensors_environment_inputs_may_stay_open():
    """Magnetometer's b_eci, SunSensor's sun_eci and eclipse, Ephemeris' r and jd_utc are read with
    environment_inputs = 1 only: open by default; Environment's r stays required."""
    sc = Scenario(name="t", components=[Component("mag", "Magnetometer"), Component("sun", "SunSensor"),
                                        Component("eph", "Ephemeris"), Component("env", "Environment")],
                  stop_time=1.0, step=0.1)
    for inst, port in (("mag", "b_eci_x"), ("sun", "sun_eci_z"), ("sun", "eclipse"), ("eph", "r_y"),
                       ("eph", "jd_utc")):
        assert sc._is_unconnected(inst, port), (inst, port)
        assert not CoSimulation._required(SimpleNamespace(model=sc.component(inst).model), port)
    assert not sc._is_unconnected("env", "r_x")
    assert CoSimulation._required(SimpleNamespace(model="Environment"), "r_x")
