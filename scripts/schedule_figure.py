#!/usr/bin/env python3
"""The schedule of three clocked units under FMI 3.0 Scheduled Execution, drawn from a real run's activation log
(docs/fmi3.md, section Clocks).

The run: ``PidController`` (its clock ticks every ``step`` = 1 ms), ``Gyro`` (``sample_period`` = 10 ms) and
``StarTracker`` (``sample_period`` = 0.2 s, ``latency`` = 0.1 s: a sample clock at 0, 0.2, 0.4 s ... and a
delivery clock 0.1 s after each sample), their FMI 3.0 FMUs loaded by fmpy's ``FMU3ScheduledExecution`` (fmpy's
loader and ctypes binding, not scfmu's). Each unit's intervals and shifts are read from the FMU in
Initialization Mode (``fmi3GetIntervalDecimal``, ``fmi3GetShiftDecimal``); a small scheduler then walks the
ticks of all clocks in time order (at one instant: the units in the order above, within a unit the clock
priority), sets the unit's inputs, calls ``fmi3ActivateModelPartition(clock, tick)`` and logs
(time, unit, clock); the gyro's input is the rate of a slow rotation, the star tracker's the attitude, the
PID's the angle about one axis. The figure is drawn from that log only: time on x, one row per clock, a mark
per activation; a second panel zooms on the first 50 ms.

Usage: ``python scripts/schedule_figure.py [--t-end 1.0] [--out docs/schedule.png] [--log out/schedule.csv]``
(FMUs from ``SCFMU_FMU_DIR`` or the package's default folder).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

UNITS = (  # (instance, model, parameters)
    ("pid", "PidController", {"step": 0.001}),
    ("gyro", "Gyro", {"sample_period": 0.01}),
    ("star_tracker", "StarTracker", {"sample_period": 0.2, "latency": 0.1}),
)
AXIS = (0.48, -0.6, 0.64)
RATE = 0.02  # rad/s, the slow rotation the sensors see


def inputs(model: str, t: float) -> dict:
    """The unit's inputs at time t (s): a rotation at RATE about AXIS."""
    a = RATE * t
    if model == "PidController":
        return {"theta": a, "theta_ref": 0.0}
    if model == "Gyro":
        return {f"w_{c}": RATE * e for c, e in zip("xyz", AXIS)}
    return {"q_w": math.cos(a / 2), **{f"q_{c}": math.sin(a / 2) * e for c, e in zip("xyz", AXIS)}}


def open_unit(model: str, params: dict, tmp: Path, name: str):
    """fmpy's Scheduled Execution instance of the unit, initialized; returns (instance, description,
    [(clock variable, interval, shift)])."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3ScheduledExecution, fmi3Float64, fmi3IntervalQualifier, fmi3ValueReference

    from scfmu.fmu import fmu_dir
    path = fmu_dir() / "fmi3" / f"{model}.fmu"
    md = read_model_description(str(path))
    if md.scheduledExecution is None:
        raise SystemExit(f"{path}: no <ScheduledExecution> (build the clocked FMUs: scripts/build_fmus.sh)")
    s = FMU3ScheduledExecution(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp / name)),
                               modelIdentifier=md.scheduledExecution.modelIdentifier, instanceName=name)
    s.instantiate()
    by = {v.name: v for v in md.modelVariables}
    for k, v in params.items():
        s.setFloat64([by[k].valueReference], [v])
    s.enterInitializationMode(startTime=0.0)
    clocks = sorted((v for v in md.modelVariables if v.type == "Clock"), key=lambda v: v.valueReference)
    n = len(clocks)
    vrs = (fmi3ValueReference * n)(*[c.valueReference for c in clocks])
    iv, sh, q = (fmi3Float64 * n)(), (fmi3Float64 * n)(), (fmi3IntervalQualifier * n)()
    s.getIntervalDecimal(vrs, iv, q)
    s.getShiftDecimal(vrs, sh)
    s.exitInitializationMode()
    return s, md, list(zip(clocks, iv, sh))


def run(t_end: float) -> list[tuple[float, str, str]]:
    """The Scheduled Execution run; returns the activation log [(time in s, instance, clock name)]."""
    log = []
    with tempfile.TemporaryDirectory() as d:
        units = [(name, model, *open_unit(model, params, Path(d), name)) for name, model, params in UNITS]
        events = []  # (tick index of the clock, unit order, clock order, ...): exact integer schedule
        for i, (name, model, s, md, clocks) in enumerate(units):
            for j, (c, iv, sh) in enumerate(clocks):
                k = 0
                while sh + k * iv <= t_end * (1 + 1e-12):
                    events.append((sh + k * iv, i, j, k))
                    k += 1
        events.sort(key=lambda e: (round(e[0], 12), e[1], e[2]))
        for t, i, j, _ in events:
            name, model, s, md, clocks = units[i]
            by = {v.name: v for v in md.modelVariables}
            u = inputs(model, t)
            s.setFloat64([by[k].valueReference for k in u], list(u.values()))
            s.activateModelPartition(clocks[j][0].valueReference, t)
            log.append((t, name, clocks[j][0].name))
        for _, _, s, _, _ in units:
            s.terminate()
            s.freeInstance()
    return log


def draw(log, out: Path, t_end: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = list(dict.fromkeys((u, c) for _, u, c in log))
    label = {("pid", "sample_clock"): "PidController\nsample_clock", ("gyro", "sample_clock"): "Gyro\nsample_clock",
             ("star_tracker", "sample_clock"): "StarTracker\nsample_clock",
             ("star_tracker", "delivery_clock"): "StarTracker\ndelivery_clock"}
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    fig, axes = plt.subplots(2, 1, figsize=(10, 6.2), gridspec_kw={"height_ratios": [1, 1]})
    for ax, (t0, t1) in zip(axes, ((0.0, t_end), (0.0, 0.05))):
        for y, key in enumerate(rows):
            ts = [t for t, u, c in log if (u, c) == key and t0 - 1e-12 <= t <= t1 + 1e-12]
            ax.vlines(ts, y - 0.35, y + 0.35, colors=colours[y % len(colours)], linewidth=0.4 if t1 > 0.1 else 1.2)
        ax.set_yticks(range(len(rows)), [label.get(k, f"{k[0]}\n{k[1]}") for k in rows], fontsize=8)
        ax.set_ylim(len(rows) - 0.4, -0.6)
        ax.set_xlim(t0 - 0.005 * (t1 - t0), t1 + 0.005 * (t1 - t0))
        ax.grid(axis="x", alpha=0.3)
    samples = [t for t, u, c in log if (u, c) == ("star_tracker", "sample_clock")]
    deliveries = [t for t, u, c in log if (u, c) == ("star_tracker", "delivery_clock")]
    ys, yd = rows.index(("star_tracker", "sample_clock")), rows.index(("star_tracker", "delivery_clock"))
    for ts, td in zip(samples, deliveries):
        axes[0].annotate("", xy=(td, yd - 0.35), xytext=(ts, ys + 0.35),
                         arrowprops={"arrowstyle": "->", "color": "0.4", "lw": 0.8})
    if len(samples) > 1 and len(deliveries) > 1:
        axes[0].text((samples[1] + deliveries[1]) / 2, (ys + yd) / 2 - 0.18,
                     f"latency {deliveries[1] - samples[1]:.1f} s",
                     fontsize=7, ha="center", va="center", color="0.3",
                     bbox={"facecolor": "white", "edgecolor": "none", "pad": 1})
    counts = {k: sum(1 for _, u, c in log if (u, c) == k) for k in rows}
    axes[0].set_title("FMI 3.0 Scheduled Execution: fmi3ActivateModelPartition calls of a 1 ms PID, a 10 ms gyro "
                      "and a 0.2 s star tracker (latency 0.1 s)", fontsize=9)
    axes[1].set_title("first 50 ms (" + ", ".join(f"{label.get(k, k[0]).split(chr(10))[0]} {k[1]}: "
                                                   f"{counts[k]} calls in {t_end:g} s" for k in rows) + ")",
                      fontsize=7)
    for ax in axes:
        ax.set_xlabel("time t (s)", fontsize=8)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--t-end", type=float, default=1.0, help="end of the run in s (default 1.0)")
    p.add_argument("--out", type=Path, default=ROOT / "docs" / "schedule.png")
    p.add_argument("--log", type=Path, default=None, help="also write the activation log as CSV")
    a = p.parse_args(argv)
    log = run(a.t_end)
    if a.log:
        a.log.parent.mkdir(parents=True, exist_ok=True)
        with open(a.log, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["time_s", "unit", "clock"])
            w.writerows((repr(t), u, c) for t, u, c in log)
    draw(log, a.out, a.t_end)
    for key in dict.fromkeys((u, c) for _, u, c in log):
        ts = [t for t, u, c in log if (u, c) == key]
        print(f"{key[0]}.{key[1]}: {len(ts)} activations, first {ts[0]:g} s, last {ts[-1]:g} s")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
