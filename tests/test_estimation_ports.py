"""The estimation family's inputs carry the names of the outputs that feed them (issue 37): a scenario that
places the Mekf beside the Gyro, StarTracker, SunSensor, Magnetometer and Ephemeris wires it with no explicit
connection, and the magnetometer update it then makes is the right one.

* pre-flight: ``scfmu.scenario.check`` reports no error (no unwired input) with ``connections`` empty, and the
  resolved wiring feeds ``estimator.b_meas_*`` from the magnetometer, ``b_ref_*`` and ``sun_ref_*`` from the
  ephemeris, ``st_valid`` and ``sun_valid`` from the star tracker and the sun sensor; with the filter's
  former names (``mag_meas``/``mag_ref``, restored by a port map) the same check names the six unwired
  inputs — the check can fail;
* run (magnetometer-only filter, 60 s, 100 nT per axis at the orbit's start, where the field is the dipole's
  weakest, so the filter's angular noise sigma/|B| is exact): the filter's inputs equal the sensors' outputs
  bit for bit, it updates once per magnetometer sample (601 updates: 60 s at 10 Hz, both ends), and its
  normalized innovation squared averaged over the updates lies in the two-sided 95 % band of
  chi2(2 n)/(2 n) (scipy) — an innovation of a consistent filter with the right reference field. The same
  run with the reference field pinned to a wrong direction fails that band — the test can fail.
* the Triad, Quest and BDot inputs carry the sensors' names too.
"""

from __future__ import annotations

import copy
import zipfile
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from scfmu.engines import simulate
from scfmu.scenario.check import check
from scfmu.scenario.model import DEFAULT_UNCONNECTED, Component, Scenario, log_of

ROOT = Path(__file__).resolve().parents[1]
AX = "xyz"
B_MIN = 7.96e15 / 7078137.0 ** 3  # the dipole field at the (default) orbit's equator crossing, t = 0 [T]
MAG_NOISE = 1e-7  # [T] per axis


def scenario() -> Scenario:
    est = {"sample_period": 0.01, "use_star_tracker": 0, "use_sun": 0, "use_mag": 1, "init_from_star_tracker": 0,
           "sigma_att_init": 0.05, "mag_noise": MAG_NOISE / B_MIN}
    log = {**log_of("estimator", ["nis", "nis_dim", "p_att_x"]),
           **{f"est.{n}_{a}": f"estimator.{n}_{a}" for n in ("b_meas", "b_ref", "sun_ref") for a in AX},
           **{f"mag.b_meas_{a}": f"magnetometer.b_meas_{a}" for a in AX},
           **{f"eph.{n}_{a}": f"ephemeris.{n}_{a}" for n in ("b_ref", "sun_ref") for a in AX},
           "est.st_valid": "estimator.st_valid", "st.valid": "star_tracker.valid",
           "est.sun_valid": "estimator.sun_valid", "ss.valid": "sun_sensor.valid"}
    return Scenario(
        name="mekf-by-name",
        components=[
            Component("plant", "AttitudePlant", {"init_w_x": 0.01, "init_w_y": -0.02, "init_w_z": 0.015,
                                                 "max_internal_step": 0.01}),
            Component("gyro", "Gyro", {"sample_period": 0.01}),
            Component("star_tracker", "StarTracker", {"latency": 0.1}),
            Component("sun_sensor", "SunSensor", {}),
            Component("magnetometer", "Magnetometer", {"sample_period": 0.1, **{f"noise_{a}": MAG_NOISE for a in AX}}),
            Component("ephemeris", "Ephemeris", {}),
            Component("estimator", "Mekf", est),
        ],
        stop_time=60.0, step=0.01,
        unconnected=[*DEFAULT_UNCONNECTED, "plant.torque_cmd_*"],  # no controller: the plant coasts
        log=log, seed_params=["gyro.seed", "magnetometer.seed"])


def _ports(model: str) -> tuple[list[str], list[str]]:
    import xml.etree.ElementTree as ET
    with zipfile.ZipFile(ROOT / "fmus" / f"{model}.fmu") as z:
        md = ET.fromstring(z.read("modelDescription.xml"))
    vs = md.iter("ScalarVariable")
    pairs = [(v.get("name"), v.get("causality")) for v in vs]
    return [n for n, c in pairs if c == "input"], [n for n, c in pairs if c == "output"]


def test_the_mekf_is_wired_by_name_and_the_old_names_would_not_be():
    sc = scenario()
    assert sc.connections == {}
    rep = check(sc)
    assert rep.errors == [], rep.errors
    links = {f"{d}.{i}": f"{s}.{o}" for d, i, s, o in sc.wiring({c.name: _ports(c.model) for c in sc.components})}
    for a in AX:
        assert links[f"estimator.b_meas_{a}"] == f"magnetometer.b_meas_{a}"
        assert links[f"estimator.b_ref_{a}"] == f"ephemeris.b_ref_{a}"
        assert links[f"estimator.sun_ref_{a}"] == f"ephemeris.sun_ref_{a}"
        assert links[f"estimator.sun_meas_{a}"] == f"sun_sensor.sun_meas_{a}"
        assert links[f"estimator.w_meas_{a}"] == f"gyro.w_meas_{a}"
    assert links["estimator.st_valid"] == "star_tracker.st_valid"
    assert links["estimator.sun_valid"] == "sun_sensor.sun_valid"
    assert {f"estimator.q_meas_{a}" for a in "wxyz"} <= set(links)
    optional = {"init_request", *(f"q_coarse_{a}" for a in "wxyz")}  # the coarse re-initialisation: open by default
    est_inputs = [f"estimator.{n}" for n in _ports("Mekf")[0] if n not in optional]
    assert sorted(est_inputs) == sorted(k for k in links if k.startswith("estimator."))  # every other input has a source

    # the former names, restored by a port map: the pre-flight check names each unwired input
    old = copy.deepcopy(sc)
    old.component("estimator").ports = {"b_meas": "mag_meas", "b_ref": "mag_ref"}
    errs = check(old).errors
    for n in ("mag_meas", "mag_ref"):
        for a in AX:
            assert f"wiring: input estimator.{n}_{a} has no source" in errs, errs


def _mean_nis(r) -> tuple[float, int]:
    upd = np.asarray(r["nis_dim"]) > 0
    return float(np.mean(np.asarray(r["nis"])[upd]) / 2), int(upd.sum())


def test_the_magnetometer_update_wired_by_name_is_consistent():
    sc = scenario()
    r = simulate(sc, "native")
    for a in AX:  # the filter reads the sensors' outputs
        assert np.array_equal(r[f"est.b_meas_{a}"], r[f"mag.b_meas_{a}"])
        assert np.array_equal(r[f"est.b_ref_{a}"], r[f"eph.b_ref_{a}"])
        assert np.array_equal(r[f"est.sun_ref_{a}"], r[f"eph.sun_ref_{a}"])
    assert np.array_equal(r["est.st_valid"], r["st.valid"]) and np.array_equal(r["est.sun_valid"], r["ss.valid"])
    assert np.ptp(r["est.st_valid"]) == 1.0  # the flag goes from 0 (latency) to 1: a live link
    nis, n = _mean_nis(r)
    assert set(np.unique(r["nis_dim"])) == {0, 2} and n == 601, n  # one update per 10 Hz sample
    lo, hi = chi2.ppf([0.025, 0.975], 2 * n) / (2 * n)
    print(f"\nmagnetometer updates: {n}, mean NIS per dimension {nis:.4f}, 95 % band [{lo:.4f}, {hi:.4f}]")
    assert lo <= nis <= hi, (nis, lo, hi)
    assert r["p_att_x"][-1] < 0.05 ** 2 / 4  # the updates shrink the attitude covariance

    # the test can fail: a reference field pinned to a wrong direction (body x of R) instead of the ephemeris'
    bad = copy.deepcopy(sc)
    bad.inputs = {"estimator.b_ref_x": 1.0, "estimator.b_ref_y": 0.0, "estimator.b_ref_z": 0.0}
    nis_bad, _ = _mean_nis(simulate(bad, "native"))
    print(f"reference field pinned to +x: mean NIS per dimension {nis_bad:.2f}")
    assert nis_bad > hi, nis_bad


def test_static_determination_and_bdot_inputs_carry_the_sensors_names():
    sensors = set()
    for m in ("Magnetometer", "SunSensor", "Ephemeris"):
        sensors |= set(_ports(m)[1])
    for m in ("Triad", "Quest"):
        ins = set(_ports(m)[0])
        assert {f"{n}_{a}" for n in ("sun_meas", "b_meas", "sun_ref", "b_ref") for a in AX} <= ins <= sensors | {
            f"v{i}_{k}_{a}" for i in (3, 4) for k in ("meas", "ref") for a in AX}, ins - sensors
    assert set(_ports("BDot")[0]) == {f"b_meas_{a}" for a in AX}
