"""Runs in Basilisk's own virtual environment (``.venv-bsk``, ``bsk`` 2.12.1; see tests/test_basilisk_surface.py):
reads cases as JSON on stdin, sets up a spacecraft hub with Basilisk's facet drag and facet solar-pressure
effectors in each case's state (position, velocity, attitude as a direction-cosine matrix [BN], density,
sun position, illumination factor), has each effector compute its force and torque about the body origin
(= the centre of mass here), and prints them as JSON. Also prints the constants Basilisk uses for the
solar pressure, so the caller can give our unit the same ones."""

from __future__ import annotations

import json
import sys

import numpy as np


def main() -> None:
    from Basilisk.architecture import messaging
    from Basilisk.simulation import facetDragDynamicEffector, facetSRPDynamicEffector, spacecraft
    from Basilisk.utilities import RigidBodyKinematics as rbk
    from Basilisk.utilities import SimulationBaseClass, macros

    cases = json.load(sys.stdin)
    out = []
    keep = []  # Basilisk messages must outlive the run
    for c in cases:
        sim = SimulationBaseClass.SimBaseClass()
        proc = sim.CreateNewProcess("p")
        proc.addTask(sim.CreateNewTask("t", macros.sec2nano(1.0)))
        sc = spacecraft.Spacecraft()
        sc.hub.mHub = 10.0
        sc.hub.IHubPntBc_B = np.diag([0.1, 0.08, 0.05]).tolist()
        sc.hub.r_CN_NInit = c["r"]
        sc.hub.v_CN_NInit = c["v"]
        sc.hub.sigma_BNInit = list(rbk.C2MRP(np.array(c["dcm_bn"])))
        sc.hub.omega_BN_BInit = [0.0, 0.0, 0.0]

        drag = facetDragDynamicEffector.FacetDragDynamicEffector()
        srp = facetSRPDynamicEffector.FacetSRPDynamicEffector()
        srp.setNumFacets(len(c["facets"]))
        for f in c["facets"]:
            drag.addFacet(f["area"], f["drag_coeff"], f["normal"], f["centre"])
            srp.addFacet(f["area"], np.eye(3).tolist(), f["normal"], [0.0, 0.0, 1.0], f["centre"], f["diffuse"], f["specular"])
        atmo = messaging.AtmoPropsMsgPayload()
        atmo.neutralDensity = c["rho"]
        atmo_msg = messaging.AtmoPropsMsg().write(atmo)
        drag.atmoDensInMsg.subscribeTo(atmo_msg)
        sun = messaging.SpicePlanetStateMsgPayload()
        sun.PositionVector = c["sun_position"]
        sun_msg = messaging.SpicePlanetStateMsg().write(sun)
        srp.sunInMsg.subscribeTo(sun_msg)
        ecl = messaging.EclipseMsgPayload()
        ecl.illuminationFactor = c["eclipse"]
        ecl_msg = messaging.EclipseMsg().write(ecl)
        srp.sunEclipseInMsg.subscribeTo(ecl_msg)
        keep += [atmo_msg, sun_msg, ecl_msg]
        if "v_air" in c:  # the air's inertial velocity (co-rotation), else Basilisk's default: air at rest
            wind = messaging.WindMsgPayload()
            wind.v_air_N = c["v_air"]
            wind.v_wind_N = [0.0, 0.0, 0.0]
            wind_msg = messaging.WindMsg().write(wind)
            drag.windVelInMsg.subscribeTo(wind_msg)
            keep.append(wind_msg)
        sc.addDynamicEffector(drag)
        sc.addDynamicEffector(srp)
        sim.AddModelToTask("t", sc)
        sim.AddModelToTask("t", drag)
        sim.AddModelToTask("t", srp)
        sim.InitializeSimulation()
        drag.ReadInputs()
        drag.computeForceTorque(0.0, 0.0)
        fd, td = list(drag.forceExternal_B), list(drag.torqueExternalPntB_B)
        srp.ReadMessages()
        srp.computeForceTorque(0.0, 0.0)
        fs, ts = list(srp.forceExternal_B), list(srp.torqueExternalPntB_B)
        out.append({"force_aero": [x[0] if isinstance(x, list) else x for x in fd],
                    "torque_aero": [x[0] if isinstance(x, list) else x for x in td],
                    "force_srp": [x[0] if isinstance(x, list) else x for x in fs],
                    "torque_srp": [x[0] if isinstance(x, list) else x for x in ts]})
    json.dump({"cases": out}, sys.stdout)


if __name__ == "__main__":
    main()
