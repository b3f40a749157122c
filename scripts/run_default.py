#!/usr/bin/env python3
"""Default scenario: paper 000 large-angle command (roll 40°, pitch -40°, yaw -60° from rest) with the
quaternion PD law (run 000-6): AttitudeCommand + PdController + AttitudePlant + AttitudeMetrics wired
by port name in fmpy. Prints EULERINT, settling time and control effort; writes CSV and PNG.

The set-up is declared once in scfmu.scenarios.default(): inertia diag(1000, 500, 700) kg m², no torque limit,
RK4 0.01 s, communication step 0.01 s, t_end = 30 s.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from scfmu import scenarios  # noqa: E402
from scfmu.metrics import overshoot_percent, settling_time  # noqa: E402
from scfmu.results import write_csv  # noqa: E402
from scfmu.simulate import simulate  # noqa: E402

LARGE = scenarios.COMMANDS["L"]
CSV_KEYS = ["time", "q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw", "torque_applied_x",
            "torque_applied_y", "torque_applied_z", "alpha_deg", "eulerint_deg_s", "effort_abs", "effort_sq"]


def run(t_end: float = 30.0, dt: float = 0.01, command=LARGE, error_law: int = 0, engine: str = "lean"):
    """The set-up is scenarios.default() (paper 000 run 000-6); `engine` picks the master (scfmu.simulate)."""
    sc = scenarios.default(t_end, dt).with_overrides({
        "command.ref_euler321_roll": command[0], "command.ref_euler321_pitch": command[1],
        "command.ref_euler321_yaw": command[2], "controller.error_law": error_law})
    return simulate(sc, engine)


def summarize(r: dict, command=LARGE) -> dict:
    t = r["time"]
    out = {
        "eulerint_deg_s": r["eulerint_deg_s"][-1],
        "effort_abs_Nms": r["effort_abs"][-1],
        "effort_sq_N2m2s": r["effort_sq"][-1],
        "settling_alpha_s": settling_time(t, r["alpha_deg"], 0.0),
        "final_alpha_deg": r["alpha_deg"][-1],
    }
    for i, axis in enumerate(["roll", "pitch", "yaw"]):
        out[f"settling_{axis}_s"] = settling_time(t, r[axis], command[i])
        out[f"overshoot_{axis}_pct"] = overshoot_percent(r[axis], command[i])
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/default", help="output folder for CSV and PNG")
    ap.add_argument("--t-end", type=float, default=30.0)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--engine", default="lean", choices=["lean", "native", "reference"],
                    help="co-simulation master (all give bit-identical results)")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    r = run(args.t_end, args.dt, engine=args.engine)
    s = summarize(r)
    print(f"Paper 000 run 000-6: quaternion PD, large command (40, -40, -60) deg, dt = {args.dt} s, t_end = {args.t_end} s")
    for k, v in s.items():
        print(f"  {k:22s} {v:12.6g}")
    write_csv(out / "default_run.csv", r, CSV_KEYS)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    t = r["time"]
    for axis, ref in zip(["roll", "pitch", "yaw"], LARGE):
        line, = ax[0].plot(t, np.degrees(r[axis]), label=axis)
        ax[0].axhline(math.degrees(ref), color=line.get_color(), ls=":", lw=0.8)
    ax[0].set_ylabel("321 angle [deg]")
    ax[0].legend()
    ax[1].plot(t, r["alpha_deg"])
    ax[1].set_ylabel("Euler-axis error α [deg]")
    for c in "xyz":
        ax[2].plot(t, r[f"torque_applied_{c}"], label=f"τ_{c}")
    ax[2].set_ylabel("torque [N·m]")
    ax[2].set_xlabel("time [s]")
    ax[2].legend()
    fig.suptitle(f"Quaternion PD, large command: EULERINT = {s['eulerint_deg_s']:.2f} deg·s")
    fig.tight_layout()
    fig.savefig(out / "default_run.png", dpi=110)
    print(f"wrote {out / 'default_run.csv'} and {out / 'default_run.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
