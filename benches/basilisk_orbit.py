#!/usr/bin/env python3
"""One orbit (5,400 s at 0.1 s) of a rigid spacecraft under PD attitude control: the project's FMUs on the
native path (AttitudeCommand + PdController + AttitudePlant inside fmpy's container FMU, no Python call per
step) against the same closed loop in Basilisk (spacecraft hub + extForceTorque + simpleNav + inertial3D
+ attTrackingError + mrpFeedback, task rate 0.1 s, RK4), same inertia diag(1000, 500, 700) kg·m², same
initial attitude error. Only the simulation loop is timed (after initialization); minimum over
--repeat interleaved repetitions.

Basilisk (PyPI ``bsk``) pins versions that conflict with this project's requirements (tqdm, matplotlib),
so it is NOT in requirements.txt: it lives in its own virtual environment, used only by this script:

    python3 -m venv .venv-bsk && .venv-bsk/bin/pip install bsk==2.12.1
    .venv/bin/python benches/basilisk_orbit.py [--repeat 5] [--bsk-python .venv-bsk/bin/python]

The control laws differ (quaternion PD with ω_n = 1 rad/s per axis vs Basilisk's MRP feedback
L = −Kσ − Pω with K = 1000, P = 2000 N·m·s), so the table compares speed, not trajectories; both loops
settle the same 69° slew well within the orbit (final errors printed).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
T_END, DT = 5400.0, 0.1
EULER = (math.radians(40.0), math.radians(-40.0), math.radians(-60.0))  # command L of paper 000


def native_run() -> dict:
    from scfmu import scenario as scenarios
    from scfmu.engines.native import NativeLoop
    sc = scenarios.get("default", stop_time=T_END, step=DT)
    sc.components = [c for c in sc.components if c.name != "metrics"]
    sc.components[2].params["max_internal_step"] = DT  # one RK4 step per 0.1 s, as Basilisk's task
    sc.log = {"roll": "plant.roll", "pitch": "plant.pitch", "yaw": "plant.yaw"}
    with NativeLoop(sc, log_every=0) as m:
        t = time.perf_counter()
        r = m.run()
        wall = time.perf_counter() - t
    err = max(abs(r[a][-1] - e) for a, e in zip(("roll", "pitch", "yaw"), EULER))
    return {"wall_s": wall, "final_error_rad": err}


def basilisk_run() -> dict:
    import numpy as np
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import attTrackingError, inertial3D, mrpFeedback
    from Basilisk.simulation import extForceTorque, simpleNav, spacecraft
    from Basilisk.utilities import RigidBodyKinematics as rbk
    from Basilisk.utilities import SimulationBaseClass, macros

    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dyn")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(DT)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "sc"
    inertia = [1000.0, 0, 0, 0, 500.0, 0, 0, 0, 700.0]
    sc.hub.mHub = 100.0
    sc.hub.IHubPntBc_B = np.array(inertia).reshape(3, 3).tolist()
    # the FMU loop starts at rest at the identity and commands the 321 angles EULER: here the same
    # relative rotation as an initial error with respect to a zero reference
    dcm_RN = rbk.euler3212C([EULER[2], EULER[1], EULER[0]])
    sigma_NR = rbk.C2MRP(dcm_RN.T)
    sc.hub.sigma_BNInit = [[x] for x in sigma_NR]
    sc.hub.omega_BN_BInit = [[0.0], [0.0], [0.0]]
    sim.AddModelToTask("task", sc)
    ext = extForceTorque.ExtForceTorque()
    ext.ModelTag = "ext"
    sc.addDynamicEffector(ext)
    sim.AddModelToTask("task", ext)
    nav = simpleNav.SimpleNav()
    nav.ModelTag = "nav"
    sim.AddModelToTask("task", nav)
    ref = inertial3D.inertial3D()
    ref.ModelTag = "ref"
    ref.sigma_R0N = [0.0, 0.0, 0.0]
    sim.AddModelToTask("task", ref)
    err = attTrackingError.attTrackingError()
    err.ModelTag = "err"
    sim.AddModelToTask("task", err)
    ctl = mrpFeedback.mrpFeedback()
    ctl.ModelTag = "mrpFeedback"
    ctl.K = 1000.0
    ctl.P = 2000.0
    ctl.Ki = -1.0
    sim.AddModelToTask("task", ctl)
    cfg = messaging.VehicleConfigMsgPayload()
    cfg.ISCPntB_B = inertia
    cfg_msg = messaging.VehicleConfigMsg().write(cfg)
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    err.attRefInMsg.subscribeTo(ref.attRefOutMsg)
    ctl.guidInMsg.subscribeTo(err.attGuidOutMsg)
    ctl.vehConfigInMsg.subscribeTo(cfg_msg)
    ext.cmdTorqueInMsg.subscribeTo(ctl.cmdTorqueOutMsg)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(T_END))
    t = time.perf_counter()
    sim.ExecuteSimulation()
    wall = time.perf_counter() - t
    sigma = np.array(err.attGuidOutMsg.read().sigma_BR)
    return {"wall_s": wall, "final_error_rad": float(4 * math.atan(np.linalg.norm(sigma)))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--bsk-python", default=str(ROOT / ".venv-bsk" / "bin" / "python"))
    ap.add_argument("--basilisk-worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.basilisk_worker:
        print(json.dumps(basilisk_run()))
        return 0
    import os
    best = {"native": None, "basilisk": None}
    for _ in range(args.repeat):
        n = native_run()
        out = subprocess.run([args.bsk_python, __file__, "--basilisk-worker"], capture_output=True, text=True,
                             check=True)
        b = json.loads(out.stdout.strip().splitlines()[-1])
        for k, v in (("native", n), ("basilisk", b)):
            if best[k] is None or v["wall_s"] < best[k]["wall_s"]:
                best[k] = v
    n, b = best["native"], best["basilisk"]
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average {os.getloadavg()[0]:.1f}; "
          f"one orbit = {T_END:g} s at {DT} s ({int(T_END / DT)} steps), min of {args.repeat}")
    print("| loop | wall time [ms] | µs/step | final attitude error [rad] |")
    print("|---|---:|---:|---:|")
    for name, v in (("FMUs, native path (container, no Python per step)", n), ("Basilisk 2.12.1", b)):
        print(f"| {name} | {v['wall_s'] * 1e3:.1f} | {v['wall_s'] / (T_END / DT) * 1e6:.2f} | {v['final_error_rad']:.2e} |")
    print(f"ratio native / Basilisk: {n['wall_s'] / b['wall_s']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
