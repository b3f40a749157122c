#!/usr/bin/env python3
"""One day (86,400 s at 0.1 s, 864,000 steps) of the `leo/nadir` scenario of issue 43 in Basilisk 2.12.1: a 6U
CubeSat on a 500 km sun-synchronous orbit, nadir pointing with three reaction wheels and magnetorquer momentum
management, under gravity (point mass + J2), facet drag in an exponential atmosphere, facet solar-radiation
pressure with eclipse, the geomagnetic field (WMM) and a residual dipole. All modules in one task at 0.1 s,
RK4. Only the simulation loop is timed (not the set-up); prints wall time, µs/step and sanity numbers, and,
with --json, one JSON line (what benches/leo_cost.py reads).

Basilisk (PyPI ``bsk``) pins versions that conflict with this project's requirements, so it lives in its own
virtual environment (see docs/benchmarks.md, "One orbit against Basilisk"):

    .venv-bsk/bin/python benches/basilisk_leo.py [--stop 86400] [--json]

Where Basilisk 2.12.1 has no module for a piece of the scenario, or needs data files the wheel does not ship
(it downloads its support data on demand), the closest offline equivalent is used:

- J2: the spherical-harmonics gravity model loaded in memory with the single coefficient C̄20 = −J2/√5
  (EGM-96 J2; the wheel ships no GGM03S file);
- field: magneticFieldWMM with the WMM2025 coefficient file shipped by the project venv's ``ahrs`` package
  (--wmm PATH; centered dipole if absent). No SPICE kernels: the Earth turns about the J2000 z axis from GMST
  at the epoch (planetEphemeris), without precession and nutation;
- sun: a constant sun message at the epoch's low-precision solar position (the sun moves ~1° in the day);
  eclipse: Basilisk's eclipse module (conical shadow) from that sun and an Earth at the origin;
- residual dipole: a second MtbEffector with three axis rods holding the constant dipole (Basilisk has no
  residual-dipole effector);
- pointing: hillPoint (body x radial out, z orbit normal), not nadir-z; the cost of the loop is the same.
"""

from __future__ import annotations

import argparse
import glob
import json
import math
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DT = 0.1
MU, RE, J2 = 3.986004418e14, 6_378_137.0, 1.08262668355315e-3
A, INC, RAAN = 6_878_137.0, math.radians(97.4), math.radians(337.5)
EPOCH = (2026, 3, 20, 12, 0, 0.0)  # UTC
JD_EPOCH = 2_461_120.0
INERTIA = [0.1543, 0, 0, 0, 0.1200, 0, 0, 0, 0.0510]
BOX = (0.100, 0.2263, 0.366)
COM = (0.005, 0.010, 0.020)  # centre of mass from the box centre (= the body point B)
DIPOLE_RES = (0.02, -0.01, 0.015)
RW_JS, RW_UMAX, RW_OMAX = 1.5e-5, 2e-3, 680.0
MTB_MAX = 0.2  # A·m² per rod (not given by the scenario; a typical 6U torque rod)
AU = 149_597_870_700.0
EARTH_RATE = 7.292115e-5  # rad/s


def sun_eci(jd: float) -> list[float]:
    """Low-precision solar position (Astronomical Almanac), J2000-ish axes, metres."""
    n = jd - 2_451_545.0
    g = math.radians((357.528 + 0.9856003 * n) % 360.0)
    lam = math.radians((280.460 + 0.9856474 * n) % 360.0 + 1.915 * math.sin(g) + 0.020 * math.sin(2 * g))
    eps = math.radians(23.439 - 4e-7 * n)
    r = (1.00014 - 0.01671 * math.cos(g) - 0.00014 * math.cos(2 * g)) * AU
    return [r * math.cos(lam), r * math.cos(eps) * math.sin(lam), r * math.sin(eps) * math.sin(lam)]


def gmst(jd: float) -> float:
    """Greenwich mean sidereal time (IAU 1982, UT1 = UTC), rad."""
    t = (jd - 2_451_545.0) / 36_525.0
    sec = 67_310.54841 + (876_600.0 * 3600.0 + 8_640_184.812866) * t + 0.093104 * t * t - 6.2e-6 * t**3
    return math.radians((sec / 240.0) % 360.0)


def facets():
    """The six box faces: (area, outward normal, centre relative to the box centre B)."""
    x, y, z = BOX
    out = []
    for axis, (area, half) in enumerate(((y * z, x / 2), (x * z, y / 2), (x * y, z / 2))):
        for sign in (1.0, -1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            out.append((area, n, [sign * half * c for c in n]))
    return out


def default_wmm() -> str | None:
    hits = sorted(glob.glob(str(ROOT / ".venv/lib/python3*/site-packages/ahrs/utils/WMM2025/WMM.COF")))
    return hits[0] if hits else None


def run(stop: float, wmm: str | None) -> dict:
    import numpy as np
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import (attTrackingError, hillPoint, mrpFeedback, mtbMomentumManagement,
                                        rwMotorTorque, tamComm)
    from Basilisk.simulation import (MtbEffector, eclipse, exponentialAtmosphere, facetDragDynamicEffector,
                                     facetSRPDynamicEffector, gravityEffector, magneticFieldCenteredDipole,
                                     magneticFieldWMM, magnetometer, planetEphemeris, reactionWheelStateEffector,
                                     simpleNav, spacecraft, svIntegrators)
    from Basilisk.utilities import RigidBodyKinematics as rbk
    from Basilisk.utilities import (SimulationBaseClass, macros, orbitalMotion, simIncludeGravBody, simIncludeRW,
                                    simSetPlanetEnvironment)

    t_setup = time.perf_counter()
    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("p").addTask(sim.CreateNewTask("task", macros.sec2nano(DT)))
    add = lambda m: sim.AddModelToTask("task", m)  # noqa: E731

    sc = spacecraft.Spacecraft()
    sc.ModelTag = "6U"
    sc.hub.mHub = 10.0
    sc.hub.r_BcB_B = [[c] for c in COM]
    sc.hub.IHubPntBc_B = np.array(INERTIA).reshape(3, 3).tolist()
    sc.setIntegrator(svIntegrators.svIntegratorRK4(sc))
    add(sc)

    # gravity: point mass + J2 (normalised C20) through the spherical-harmonics model
    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    sh = gravityEffector.SphericalHarmonicsGravityModel()
    sh.muBody, sh.radEquator, sh.maxDeg = MU, RE, 2
    sh.cBar = [[1.0], [0.0, 0.0], [-J2 / math.sqrt(5.0), 0.0, 0.0]]
    sh.sBar = [[0.0], [0.0, 0.0], [0.0, 0.0, 0.0]]
    earth.gravityModel = sh
    earth.mu, earth.radEquator = MU, RE
    grav.addBodiesTo(sc)

    # orbit and initial attitude: body = Hill frame, body rate = orbit rate
    oe = orbitalMotion.ClassicElements()
    oe.a, oe.e, oe.i, oe.Omega, oe.omega, oe.f = A, 0.0, INC, RAAN, 0.0, 0.0
    r0, v0 = orbitalMotion.elem2rv(MU, oe)
    sc.hub.r_CN_NInit, sc.hub.v_CN_NInit = r0, v0
    dcm_hn = np.array(orbitalMotion.hillFrame(r0, v0))
    sc.hub.sigma_BNInit = [[s] for s in rbk.C2MRP(dcm_hn)]
    sc.hub.omega_BN_BInit = [[0.0], [0.0], [math.sqrt(MU / A**3)]]

    # environment messages: sun at the epoch, Earth at the origin
    sun = messaging.SpicePlanetStateMsgPayload()
    sun.PositionVector, sun.PlanetName = sun_eci(JD_EPOCH), "sun"
    sun_msg = messaging.SpicePlanetStateMsg().write(sun)
    # the Earth turning at its rate from GMST at the epoch (planetEphemeris; its heliocentric orbit shrunk to
    # a = 1 m so that the Earth stays at the origin of the spacecraft's frame)
    eph = planetEphemeris.PlanetEphemeris()
    eph.ModelTag = "earthRotation"
    eph.setPlanetNames(planetEphemeris.StringVector(["earth"]))
    eoe = planetEphemeris.ClassicElements()
    eoe.a, eoe.e, eoe.i, eoe.Omega, eoe.omega, eoe.f = 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    eph.planetElements = planetEphemeris.classicElementVector([eoe])
    eph.rightAscension = planetEphemeris.DoubleVector([0.0])
    eph.declination = planetEphemeris.DoubleVector([math.pi / 2])
    eph.lst0 = planetEphemeris.DoubleVector([gmst(JD_EPOCH)])
    eph.rotRate = planetEphemeris.DoubleVector([EARTH_RATE])
    add(eph)
    earth_msg = eph.planetOutMsgs[0]
    ep = messaging.EpochMsgPayload()
    ep.year, ep.month, ep.day, ep.hours, ep.minutes, ep.seconds = EPOCH
    epoch_msg = messaging.EpochMsg().write(ep)

    atmo = exponentialAtmosphere.ExponentialAtmosphere()
    atmo.ModelTag = "atmo"
    # Vallado Table 8-4, 500-600 km band: rho = 6.967e-13 exp(-(h - 500 km)/63.822 km)
    atmo.planetRadius, atmo.scaleHeight = RE, 63_822.0
    atmo.baseDensity = 6.967e-13 * math.exp(500e3 / 63_822.0)
    atmo.envMaxReach = -1.0
    atmo.addSpacecraftToModel(sc.scStateOutMsg)
    add(atmo)
    ecl = eclipse.Eclipse()
    ecl.ModelTag = "eclipse"
    ecl.sunInMsg.subscribeTo(sun_msg)
    ecl.addPlanetToModel(earth_msg)
    ecl.addSpacecraftToModel(sc.scStateOutMsg)
    add(ecl)
    if wmm:
        mag = magneticFieldWMM.MagneticFieldWMM()
        mag.configureWMMFile(wmm)
        mag.epochInMsg.subscribeTo(epoch_msg)
    else:
        mag = magneticFieldCenteredDipole.MagneticFieldCenteredDipole()
        simSetPlanetEnvironment.centeredDipoleMagField(mag, "earth")
    mag.ModelTag = "field"
    mag.planetPosInMsg.subscribeTo(earth_msg)
    mag.addSpacecraftToModel(sc.scStateOutMsg)
    add(mag)

    # disturbance effectors: facet drag, facet SRP, residual dipole
    drag = facetDragDynamicEffector.FacetDragDynamicEffector()
    drag.ModelTag = "drag"
    srp = facetSRPDynamicEffector.FacetSRPDynamicEffector()
    srp.ModelTag = "srp"
    srp.setNumFacets(6)
    srp.setNumArticulatedFacets(0)
    for area, n, loc in facets():
        drag.addFacet(area, 2.2, n, loc)
        rot = [0.0, 0.0, 1.0] if abs(n[2]) < 0.5 else [1.0, 0.0, 0.0]
        srp.addFacet(area, np.eye(3).tolist(), n, rot, loc, 0.3, 0.1)
    drag.atmoDensInMsg.subscribeTo(atmo.envOutMsgs[0])
    srp.sunInMsg.subscribeTo(sun_msg)
    srp.sunEclipseInMsg.subscribeTo(ecl.eclipseOutMsgs[0])
    for eff in (drag, srp):
        sc.addDynamicEffector(eff)
        add(eff)
    rods = messaging.MTBArrayConfigMsgPayload()
    rods.numMTB = 3
    rods.GtMatrix_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    rods.maxMtbDipoles = [MTB_MAX] * 3
    rods_msg = messaging.MTBArrayConfigMsg().write(rods)
    res_rods = messaging.MTBArrayConfigMsgPayload()
    res_rods.numMTB, res_rods.GtMatrix_B, res_rods.maxMtbDipoles = 3, rods.GtMatrix_B, [1.0] * 3
    res_rods_msg = messaging.MTBArrayConfigMsg().write(res_rods)
    res_cmd = messaging.MTBCmdMsgPayload()
    res_cmd.mtbDipoleCmds = list(DIPOLE_RES)
    res_cmd_msg = messaging.MTBCmdMsg().write(res_cmd)
    residual = MtbEffector.MtbEffector()
    residual.ModelTag = "residualDipole"
    residual.mtbCmdInMsg.subscribeTo(res_cmd_msg)
    residual.mtbParamsInMsg.subscribeTo(res_rods_msg)
    residual.magInMsg.subscribeTo(mag.envOutMsgs[0])
    sc.addDynamicEffector(residual)
    add(residual)

    # actuators: three wheels on the body axes, three torque rods
    rwf = simIncludeRW.rwFactory()
    for axis in np.eye(3):
        rwf.create("custom", list(axis), Js=RW_JS, u_max=RW_UMAX, Omega_max=RW_OMAX / macros.RPM,
                   RWModel=messaging.BalancedWheels)
    rws = reactionWheelStateEffector.ReactionWheelStateEffector()
    rws.ModelTag = "wheels"
    rwf.addToSpacecraft(sc.ModelTag, rws, sc)
    add(rws)
    rw_cfg = rwf.getConfigMessage()
    mtb = MtbEffector.MtbEffector()
    mtb.ModelTag = "torqueRods"
    sc.addDynamicEffector(mtb)
    add(mtb)

    # flight software: nav, hillPoint, tracking error, MRP feedback, wheel mapping, TAM, momentum management
    nav = simpleNav.SimpleNav()
    nav.ModelTag = "nav"
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    add(nav)
    ref = hillPoint.hillPoint()
    ref.ModelTag = "hillPoint"
    ref.transNavInMsg.subscribeTo(nav.transOutMsg)
    add(ref)
    err = attTrackingError.attTrackingError()
    err.ModelTag = "attError"
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    err.attRefInMsg.subscribeTo(ref.attRefOutMsg)
    add(err)
    ctl = mrpFeedback.mrpFeedback()
    ctl.ModelTag = "mrpFeedback"
    ctl.K, ctl.P, ctl.Ki = 0.005, 0.02, -1.0
    ctl.guidInMsg.subscribeTo(err.attGuidOutMsg)
    ctl.vehConfigInMsg.subscribeTo(messaging.VehicleConfigMsg().write(
        messaging.VehicleConfigMsgPayload(ISCPntB_B=INERTIA)))
    ctl.rwParamsInMsg.subscribeTo(rw_cfg)
    ctl.rwSpeedsInMsg.subscribeTo(rws.rwSpeedOutMsg)
    add(ctl)
    rwm = rwMotorTorque.rwMotorTorque()
    rwm.ModelTag = "rwMotorTorque"
    rwm.controlAxes_B = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    rwm.rwParamsInMsg.subscribeTo(rw_cfg)
    rwm.vehControlInMsg.subscribeTo(ctl.cmdTorqueOutMsg)
    add(rwm)
    tam = magnetometer.Magnetometer()
    tam.ModelTag = "tam"
    tam.scaleFactor, tam.senNoiseStd = 1.0, [0.0, 0.0, 0.0]
    tam.stateInMsg.subscribeTo(sc.scStateOutMsg)
    tam.magInMsg.subscribeTo(mag.envOutMsgs[0])
    add(tam)
    tamc = tamComm.tamComm()
    tamc.ModelTag = "tamComm"
    tamc.dcm_BS = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    tamc.tamInMsg.subscribeTo(tam.tamDataOutMsg)
    add(tamc)
    mm = mtbMomentumManagement.mtbMomentumManagement()
    mm.ModelTag = "mtbMomentumManagement"
    mm.wheelSpeedBiases = [0.0, 0.0, 0.0]
    mm.cGain = 0.003
    mm.rwParamsInMsg.subscribeTo(rw_cfg)
    mm.mtbParamsInMsg.subscribeTo(rods_msg)
    mm.tamSensorBodyInMsg.subscribeTo(tamc.tamOutMsg)
    mm.rwSpeedsInMsg.subscribeTo(rws.rwSpeedOutMsg)
    mm.rwMotorTorqueInMsg.subscribeTo(rwm.rwMotorTorqueOutMsg)
    add(mm)
    rws.rwMotorCmdInMsg.subscribeTo(mm.rwMotorTorqueOutMsg)
    mtb.mtbCmdInMsg.subscribeTo(mm.mtbCmdOutMsg)
    mtb.mtbParamsInMsg.subscribeTo(rods_msg)
    mtb.magInMsg.subscribeTo(mag.envOutMsgs[0])

    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(stop))
    setup = time.perf_counter() - t_setup
    t0, c0 = time.perf_counter(), time.process_time()
    sim.ExecuteSimulation()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0

    sigma = np.array(err.attGuidOutMsg.read().sigma_BR)
    speeds = np.array(rws.rwSpeedOutMsg.read().wheelSpeeds[:3])
    b = np.array(mag.envOutMsgs[0].read().magField_N)
    steps = int(round(stop / DT))
    return {
        "engine": "Basilisk 2.12.1",
        "field": "WMM2025" if wmm else "centered dipole",
        "stop_s": stop,
        "steps": steps,
        "wall_s": wall,
        "cpu_s": cpu,
        "us_per_step": wall / steps * 1e6,
        "setup_s": setup,
        "final_pointing_error_deg": math.degrees(4.0 * math.atan(float(np.linalg.norm(sigma)))),
        "final_wheel_momentum_Nms": float(np.linalg.norm(RW_JS * speeds)),
        "final_field_nT": float(np.linalg.norm(b) * 1e9),
        "final_altitude_km": (float(np.linalg.norm(sc.scStateOutMsg.read().r_BN_N)) - RE) / 1e3,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop", type=float, default=86_400.0, help="simulated seconds (default one day)")
    ap.add_argument("--wmm", default=default_wmm(), help="WMM coefficient file (default: the project venv's ahrs)")
    ap.add_argument("--json", action="store_true", help="print one JSON line (for benches/leo_cost.py)")
    args = ap.parse_args()
    r = run(args.stop, args.wmm)
    if args.json:
        print(json.dumps(r))
        return 0
    for k, v in r.items():
        print(f"{k:28} {v}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
