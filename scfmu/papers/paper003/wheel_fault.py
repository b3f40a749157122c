"""Reaction-wheel saturation + actuator fault scenario (issue 3 demo).

Paper 003 plant defaults (project choice): full inertia
[[4, 0.05, -0.03], [0.05, 5, 0.02], [-0.03, 0.02, 3.5]] kg m², three reaction wheels (k_t i_max = 0.05 N m,
J_w Ω_max = 0.504 N m s) with magnetorquer momentum dumping on the 700 km, 98° circular orbit, constant
disturbance 5e-4 N m per axis (scenario 003-C) and gravity gradient. The quaternion PdController is
retuned for this inertia (ω_n = 0.3 rad/s, ξ = 0.9, nominal diagonal 4, 5, 3.5 kg m²), so the slew
(roll 30°, pitch -20°, yaw 45°) asks for up to ~0.4 N m and the wheel torque saturates. At fault_time
the x wheel loses 70 % of its torque authority (effectiveness_x = 0.3, paper 004 fault model) and the z
wheel gets a bias of +0.01 N m on its command.

Writes out/wheel_fault/wheel_fault.csv and .png; prints the saturation and fault statistics.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path


import numpy as np

from . import wheel_fault_scenario as scenarios
from ...results import write_csv
from ...engines import simulate

COMMAND = scenarios.WHEEL_FAULT_COMMAND
CSV_KEYS = ["time", "roll", "pitch", "yaw"] + [f"{v}_{a}" for v in ["torque_applied", "h_wheel", "wheel_speed", "dipole", "w"]
                                               for a in "xyz"] + [f"torque_cmd_{a}" for a in "xyz"]


def run(t_end: float, dt: float, fault_time: float, effectiveness_x: float, bias_z: float, engine: str = "lean"):
    """The set-up is scenarios.wheel_fault(); `engine` picks the master (scfmu.simulate)."""
    return simulate(scenarios.wheel_fault(t_end, dt, fault_time, effectiveness_x, bias_z), engine)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/wheel_fault", help="output folder for CSV and PNG")
    ap.add_argument("--t-end", type=float, default=120.0)
    ap.add_argument("--dt", type=float, default=0.1)
    ap.add_argument("--fault-time", type=float, default=4.0)
    ap.add_argument("--effectiveness-x", type=float, default=0.3)
    ap.add_argument("--bias-z", type=float, default=0.01)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    r = run(args.t_end, args.dt, args.fault_time, args.effectiveness_x, args.bias_z)
    t = r["time"]
    tmax, hmax = 0.05, 1.2e-3 * 420
    print(f"Wheel saturation + fault: command (30, -20, 45) deg, fault at {args.fault_time} s "
          f"(a_x = {args.effectiveness_x}, bias_z = {args.bias_z} N m), dt = {args.dt} s, t_end = {args.t_end} s")
    for i, a in enumerate("xyz"):
        print(f"  axis {a}: max |torque_cmd| {np.max(np.abs(r[f'torque_cmd_{a}'])):.3f} N m, "
              f"max |torque_applied| {np.max(np.abs(r[f'torque_applied_{a}'])):.4f} N m, "
              f"max |h_wheel| {np.max(np.abs(r[f'h_wheel_{a}'])):.3f} N m s (limit {hmax:.3f}), "
              f"final angle error {math.degrees(r[['roll', 'pitch', 'yaw'][i]][-1] - COMMAND[i]):+.3f} deg")
    post = t >= args.fault_time
    print(f"  after the fault: max |torque_applied_x| = {np.max(np.abs(r['torque_applied_x'][post])):.4f} N m "
          f"(limit a_x k_t i_max = {args.effectiveness_x * tmax:.4f} plus |m x B| <= 1 A m2 * |B|)")
    write_csv(out / "wheel_fault.csv", r, CSV_KEYS)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    for axis, ref in zip(["roll", "pitch", "yaw"], COMMAND):
        line, = ax[0].plot(t, np.degrees(r[axis]), label=axis)
        ax[0].axhline(math.degrees(ref), color=line.get_color(), ls=":", lw=0.8)
    ax[0].set_ylabel("321 angle [deg]")
    ax[0].legend(loc="lower right")
    for a in "xyz":
        line, = ax[1].plot(t, r[f"torque_applied_{a}"], label=f"applied {a}")
        ax[1].plot(t, np.clip(r[f"torque_cmd_{a}"], -0.1, 0.1), color=line.get_color(), ls=":", lw=0.8, label=f"cmd {a} (clipped ±0.1)")
    ax[1].axhline(tmax, color="k", lw=0.5)
    ax[1].axhline(-tmax, color="k", lw=0.5)
    ax[1].axhline(args.effectiveness_x * tmax, color="C0", lw=0.5, ls="--")
    ax[1].axhline(-args.effectiveness_x * tmax, color="C0", lw=0.5, ls="--")
    ax[1].set_ylabel("torque [N·m]")
    ax[1].legend(ncol=3, fontsize=7)
    for a in "xyz":
        ax[2].plot(t, r[f"h_wheel_{a}"], label=f"h_w,{a}")
    ax[2].axhline(hmax, color="k", lw=0.5)
    ax[2].axhline(-hmax, color="k", lw=0.5)
    ax[2].set_ylabel("wheel momentum [N·m·s]")
    ax[2].legend()
    for a in "xyz":
        ax[3].plot(t, r[f"dipole_{a}"], label=f"m_{a}")
    ax[3].set_ylabel("dipole [A·m²]")
    ax[3].set_xlabel("time [s]")
    ax[3].legend()
    for x in ax:
        x.axvline(args.fault_time, color="r", lw=0.8, ls="--")
    fig.suptitle("AttitudePlant: wheel torque saturation and x-wheel fault (paper 003 plant, PD retuned)")
    fig.tight_layout()
    fig.savefig(out / "wheel_fault.png", dpi=110)
    print(f"wrote {out / 'wheel_fault.csv'} and {out / 'wheel_fault.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
