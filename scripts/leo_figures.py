#!/usr/bin/env python3
"""Figures and tables of docs/leo.md, the 6U CubeSat on its 500 km sun-synchronous orbit, made from the
packaged FMUs on the compiled engine (``.venv/bin/python scripts/leo_figures.py``):

1. ``leo_detumble.png``: the body rate under B-dot on the IGRF-14 field from a 5 deg/s tip-off;
2. ``leo_sun_pointing.png``: the eclipse factor, the sun sensor's validity, the pointing error of body +x to
   the sun and the Mekf's attitude sigma, through two orbits;
3. ``leo_nadir.png``: one day of nadir pointing: the disturbance torques (gravity gradient, drag, solar
   pressure, residual dipole), the wheel momentum under magnetorquer dumping and the pointing error.

Each run's logged signals go to ``DATA/leo_<name>.parquet`` (the SI unit of each column in its metadata; leo/nadir
logged every second), a summary to ``DATA/leo_summary.csv``. ``--quick``: two orbits of leo/nadir instead of a day (the CI size).
``--out`` (default docs/); the CSV files go to ``--data`` (default a temporary folder, printed).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from scfmu.engines import simulate
from scfmu.metrics import to_body
from scfmu.papers.leo import scenarios as leo
from scfmu.results import write_parquet


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def stack(r, stem: str, comps: str = "xyz") -> np.ndarray:
    return np.stack([np.asarray(r[f"{stem}_{a}"], dtype=float) for a in comps], axis=1)


def quat_err_deg(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    d = np.abs(np.sum(q1 * q2, axis=1)) / np.linalg.norm(q1, axis=1) / np.linalg.norm(q2, axis=1)
    return np.degrees(2 * np.arccos(np.clip(d, -1.0, 1.0)))


def run(name: str, data: Path, stop: float | None = None, log_every: int = 1, overrides: dict | None = None,
        tag: str = ""):
    """One run on the native engine (the container FMU: no Python per step), logged every ``log_every`` steps."""
    sc = leo.build(name).with_overrides(overrides or {})
    if stop is not None:
        sc.stop_time = stop
    t0 = time.perf_counter()
    r = simulate(sc, engine="native", log_every=log_every)
    wall = time.perf_counter() - t0
    write_parquet(data / f"leo_{name.split('/')[1]}{tag}.parquet", r)
    print(f"{name}{' ' + str(overrides) if overrides else ''}: {sc.stop_time:.0f} s simulated in {wall:.1f} s",
          flush=True)
    return r, wall


def detumble(out: Path, data: Path, plt) -> dict:
    r, wall = run("leo/detumble", data)
    t = np.asarray(r["time"]) / leo.ORBIT_PERIOD
    rate = np.degrees(np.linalg.norm(stack(r, "w"), axis=1))
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, rate)
    ax.set_yscale("log")
    ax.set(xlabel="time [orbits]", ylabel="|ω| [deg/s]",
           title="leo/detumble: B-dot on the IGRF-14 field, 6U, 500 km sun-synchronous orbit")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "leo_detumble.png", dpi=110)
    plt.close(fig)
    return {"scenario": "leo/detumble", "wall_s": wall, "rate_start_deg_s": rate[0], "rate_end_deg_s": rate[-1]}


def sun_pointing(out: Path, data: Path, plt) -> dict:
    r, wall = run("leo/sun-pointing", data)
    t = np.asarray(r["time"]) / leo.ORBIT_PERIOD
    s_b = to_body(stack(r, "q", "wxyz"), stack(r, "sun_eci"))
    err = np.degrees(np.arccos(np.clip(s_b[:, 0] / np.linalg.norm(s_b, axis=1), -1, 1)))
    # across the sun line (body y, z: what the sun sensor observes); about it the attitude is not observed
    sigma = np.degrees(np.sqrt(np.max(stack(r, "p_att", "yz"), axis=1)))
    s_est = to_body(stack(r, "q_est", "wxyz"), stack(r, "sun_ref"))  # the on-board sun, which the filter uses
    # the estimate's error across the sun line: the on-board sun seen through the estimate against the true sun in
    # body axes
    est_err = np.degrees(np.arccos(np.clip(np.sum(s_b * s_est, axis=1), -1, 1)))
    fig, axs = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    axs[0].plot(t, r["eclipse"], label="eclipse factor (visible fraction of the sun)")
    axs[0].plot(t, np.asarray(r["sun_valid"]) * 0.9, label="sun sensor valid (× 0.9)")
    axs[0].set(ylabel="[-]", title="leo/sun-pointing: body +x on the sun through eclipses")
    axs[0].legend(loc="lower right", fontsize=8)
    axs[1].plot(t, err)
    axs[1].set(ylabel="sun off +x [deg]", yscale="log")
    axs[2].plot(t, est_err, label="Mekf error across the sun line")
    axs[2].plot(t, 3 * sigma, label="3σ across the sun line (body y, z)")
    axs[2].set(xlabel="time [orbits]", ylabel="[deg]", yscale="log")
    axs[2].legend(fontsize=8)
    for ax in axs:
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "leo_sun_pointing.png", dpi=110)
    plt.close(fig)
    lit = np.asarray(r["eclipse"]) > 0.5
    late = np.asarray(r["time"]) > 0.25 * leo.ORBIT_PERIOD
    return {"scenario": "leo/sun-pointing", "wall_s": wall, "eclipse_fraction": 1 - lit.mean(),
            "pointing_err_lit_p95_deg": float(np.percentile(err[lit & late], 95)),
            "sigma_lit_median_deg": float(np.median(sigma[lit & late])),
            "sigma_eclipse_max_deg": float(sigma[~lit].max()) if (~lit).any() else math.nan}


def nadir(out: Path, data: Path, plt, stop: float | None) -> dict:
    r, wall = run("leo/nadir", data, stop, log_every=10)
    free, _ = run("leo/nadir", data, stop, log_every=10, overrides={"plant.mtq_enable": 0}, tag="_no_dumping")
    t = np.asarray(r["time"]) / 3600.0
    err = quat_err_deg(stack(r, "q", "wxyz"), stack(r, "q_ref", "wxyz"))
    fig, axs = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for stem, label in (("torque_gg", "gravity gradient"), ("torque_aero", "drag"), ("torque_srp", "solar pressure"),
                        ("torque_residual", "residual dipole")):
        axs[0].plot(t, np.linalg.norm(stack(r, stem), axis=1), label=label, lw=0.8)
    axs[0].set(ylabel="|torque| [N·m]", yscale="log", title="leo/nadir: disturbance budget, wheel momentum, pointing")
    axs[0].legend(fontsize=8, ncol=2)
    h = stack(r, "h_wheel")
    h_free = stack(free, "h_wheel")
    for i, a in enumerate("xyz"):
        axs[1].plot(t, h_free[:, i] * 1e3, label=f"h_wheel,{a} without dumping", lw=0.8)
    axs[1].plot(t, np.linalg.norm(h, axis=1) * 1e3, "k", label="|h_wheel| with magnetorquer dumping", lw=1.0)
    axs[1].axhline(1.5e-5 * 680 * 1e3, color="k", ls=":", lw=0.8, label="one wheel's capacity")
    axs[1].axhline(-1.5e-5 * 680 * 1e3, color="k", ls=":", lw=0.8)
    axs[1].set(ylabel="wheel momentum [mN·m·s]")
    axs[1].legend(fontsize=7, ncol=2)
    axs[2].plot(t, err, lw=0.8)
    axs[2].set(xlabel="time [h]", ylabel="nadir pointing error [deg]", yscale="log")
    for ax in axs:
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "leo_nadir.png", dpi=110)
    plt.close(fig)
    settled = np.asarray(r["time"]) > 600.0
    return {"scenario": "leo/nadir", "wall_s": wall, "simulated_s": float(r["time"][-1]),
            "pointing_err_p95_deg": float(np.percentile(err[settled], 95)),
            "h_wheel_max_mNms": float(np.abs(h).max() * 1e3),
            "h_wheel_max_no_dumping_mNms": float(np.abs(h_free).max() * 1e3),
            **{f"{stem}_rms_Nm": float(np.sqrt(np.mean(np.sum(stack(r, stem) ** 2, axis=1))))
               for stem in ("torque_gg", "torque_aero", "torque_srp", "torque_residual")}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("docs"))
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--quick", action="store_true", help="two orbits of leo/nadir instead of a day")
    a = ap.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
    data = a.data or Path(tempfile.mkdtemp(prefix="leo_figures_"))
    data.mkdir(parents=True, exist_ok=True)
    plt = _plt()
    rows = [detumble(a.out, data, plt), sun_pointing(a.out, data, plt),
            nadir(a.out, data, plt, 2 * round(leo.ORBIT_PERIOD) if a.quick else None)]
    keys = sorted({k for row in rows for k in row} - {"scenario"})
    with (data / "leo_summary.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["scenario", *keys])
        w.writeheader()
        w.writerows(rows)
    for row in rows:
        print(", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in row.items()))
    print(f"figures in {a.out}/, data in {data}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
