#!/usr/bin/env python3
"""Figures and tables of docs/mission.md, the whole ADCS under the ModeManager, from the packaged FMUs
(``.venv/bin/python scripts/mission_figures.py``):

1. ``mission_tipoff.png``: one run of mission/tipoff: the mode timeline, the true body rate and the pointing
   error to nadir;
2. ``mission_wheel_fault.png``: mission/wheel-fault: the mode timeline, the wheel speeds, the angle of body +x
   to the sun and the array's power against the safe-mode load;
3. ``mission_campaign.png``: the distribution of the time to fine pointing over a campaign of ``--runs`` tip-offs
   (the scenario's dispersions: tip-off rate, inertia, initial attitude, sun-sensor noise, every sensor seed) for
   each controller in the FINE_POINTING place (the built-in PD and LQR, and a user's unit given with
   ``--user FMU``), with the median, p95 and p99 and the fraction that never reaches fine pointing.

Each run's logged signals go to ``DATA/mission_<name>.parquet`` (SI unit of each column in its metadata), the
campaign rows to ``DATA/mission_campaign_<controller>.parquet`` and the summary to ``DATA/mission_summary.csv``.
A campaign found complete in ``DATA`` is read back, not run again. ``--quick``: 6 runs per controller, one orbit each (the CI size). ``--out`` (default docs/); ``--data`` (default a
temporary folder, printed).
"""

from __future__ import annotations

import argparse
import csv
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from scfmu import campaign
from scfmu.campaign.cli import dispersed_sets
from scfmu.engines import simulate
from scfmu.metrics import to_body
from scfmu.papers.mission import metrics, scenarios as mission
from scfmu.results import write_parquet

CONTROLLERS = {"PD": ("PdController", {}), "LQR": ("LqrController", {})}


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def run(name: str, data: Path):
    sc = mission.build(name)
    t0 = time.perf_counter()
    r = simulate(sc, engine="auto")
    wall = time.perf_counter() - t0
    write_parquet(data / f"mission_{name.split('/')[1].replace('-', '_')}.parquet", r)
    print(f"{name}: {sc.stop_time:.0f} s simulated in {wall:.1f} s; modes: "
          + ", ".join(f"{t:.0f} s {a} -> {b}" for t, a, b in metrics.timeline(r)), flush=True)
    return r, wall


def _mode_axis(ax, r):
    t = np.asarray(r["time"]) / 60.0
    ax.step(t, np.asarray(r["mode"]), where="post", color="k")
    ax.set_yticks(list(mission.MODES), [mission.MODES[k] for k in mission.MODES], fontsize=7)
    ax.set_ylabel("mode")
    ax.grid(alpha=0.3)


def stack(r, stem, comps="xyz"):
    return np.stack([np.asarray(r[f"{stem}_{a}"], dtype=float) for a in comps], axis=1)


def tipoff_figure(r, out: Path, plt) -> dict:
    t = np.asarray(r["time"]) / 60.0
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    _mode_axis(ax[0], r)
    ax[0].set_title("mission/tipoff: separation at 5.2 deg/s to nadir fine pointing under the ModeManager")
    ax[1].semilogy(t, np.degrees(np.linalg.norm(stack(r, "w"), axis=1)))
    ax[1].axhline(0.5, ls="--", c="gray", lw=0.8, label="rate_detumbled 0.5 deg/s")
    ax[1].set_ylabel("|ω| [deg/s]")
    ax[1].legend(fontsize=8)
    err = metrics.error_angle_deg(stack(r, "q", "wxyz"), stack(r, "q_ref", "wxyz"))
    ax[2].semilogy(t, np.maximum(err, 1e-4))
    ax[2].set_ylabel("error to nadir [deg]")
    ax[2].set_xlabel("time [min]")
    for a in ax[1:]:
        a.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "mission_tipoff.png", dpi=110)
    plt.close(fig)
    return metrics.compute(r)


def fault_figure(r, out: Path, plt) -> dict:
    t = np.asarray(r["time"]) / 60.0
    fig, ax = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    _mode_axis(ax[0], r)
    ax[0].set_title(f"mission/wheel-fault: x wheel fails at {mission.FAULT_TIME:g} s, reset at "
                    f"{mission.CLEAR_TIME:g} s, recovery commanded at {mission.RECOVER_TIME:g} s")
    ax[1].plot(t, stack(r, "wheel_speed"), label=["x", "y", "z"])
    ax[1].set_ylabel("wheel speed [rad/s]")
    ax[1].legend(fontsize=8)
    s_b = to_body(stack(r, "q", "wxyz"), stack(r, "sun_eci"))
    ax[2].plot(t, np.degrees(np.arccos(np.clip(s_b[:, 0] / np.linalg.norm(s_b, axis=1), -1, 1))))
    ax[2].set_ylabel("+x to sun [deg]")
    ax[3].plot(t, metrics.array_power(r), label="array (+x, cosine × visible fraction)")
    ax[3].axhline(mission.SAFE_LOAD, ls="--", c="r", lw=0.8, label=f"safe-mode load {mission.SAFE_LOAD:g} W")
    ax[3].set_ylabel("power [W]")
    ax[3].set_xlabel("time [min]")
    ax[3].legend(fontsize=8)
    for a in ax[1:]:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "mission_wheel_fault.png", dpi=110)
    plt.close(fig)
    return metrics.compute(r)


def campaign_rows(label: str, model: str, params: dict, runs: int, stop: float | None, data: Path, workers: int):
    sc = mission.build("mission/tipoff", stop_time=stop)
    if model != "PdController":
        sc = sc.with_models({"controller": model})
        sc.component("controller").params.update(params)
    sets = dispersed_sets(sc, runs)
    c = campaign.Campaign(sc, sets, [None], engine="auto")
    t0 = time.perf_counter()
    table = campaign.run(c, data / f"campaign_{label}", n_workers=workers, progress=True)
    rows = table.to_pylist()
    print(f"{label}: {runs} runs in {time.perf_counter() - t0:.0f} s", flush=True)
    return rows


def spread(rows, key: str = "t_fine_pointing_s") -> dict:
    ok = [r for r in rows if r["status"] == "ok"]
    v = np.array([r[key] for r in ok], dtype=float)
    fin = v[np.isfinite(v)]
    out = {"runs": len(rows), "ok": len(ok), "never": int(np.sum(~np.isfinite(v))),
           "chatter_runs": int(sum(r["mode_chatter"] > 0 for r in ok))}
    if fin.size:
        out.update(zip(("median_s", "p95_s", "p99_s"), (float(x) for x in np.percentile(fin, [50, 95, 99]))))
    return out


KEYS = {"t_fine_pointing_s": "separation to FINE_POINTING (the manager's hand-over)",
        "t_on_target_s": f"separation to on target (within {metrics.ON_TARGET_DEG:g} deg for "
                         f"{metrics.ON_TARGET_HOLD:g} s)"}


def campaign_figure(results: dict, out: Path, plt) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(9, 8))
    for ax, (key, text) in zip(axes, KEYS.items()):
        for label, rows in results.items():
            v = np.array([r[key] for r in rows if r["status"] == "ok"], dtype=float)
            s = spread(rows, key)
            fin = v[np.isfinite(v)] / 60.0
            tag = (f"median {s['median_s'] / 60:.1f}, p95 {s['p95_s'] / 60:.1f} min" if fin.size else "no run")
            text_label = f"{label}: {tag}; never: {s['never']}/{s['runs']}"
            if fin.size:
                ax.hist(fin, bins=20, alpha=0.5, label=text_label)
            else:
                ax.plot([], [], " ", label=text_label)
        ax.set_xlabel(f"time from {text} [min]")
        ax.set_ylabel("runs")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_title("mission/tipoff campaign: tip-off, inertia, attitude and sensor dispersions")
    fig.tight_layout()
    fig.savefig(out / "mission_campaign.png", dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="6 runs per controller, one orbit each")
    ap.add_argument("--runs", type=int, default=200, help="campaign runs per controller (default 200)")
    ap.add_argument("--user", default=None, help="a user's attitude controller FMU for the FINE_POINTING place")
    ap.add_argument("--user-param", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the user's unit (repeatable), e.g. wn=0.1")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="docs")
    ap.add_argument("--data", default=None)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    data = Path(args.data or tempfile.mkdtemp(prefix="mission_"))
    data.mkdir(parents=True, exist_ok=True)
    print(f"data: {data}", flush=True)
    plt = _plt()
    summary = []
    r, wall = run("mission/tipoff", data)
    summary.append({"what": "mission/tipoff", "wall_s": wall, **tipoff_figure(r, out, plt)})
    r, wall = run("mission/wheel-fault", data)
    summary.append({"what": "mission/wheel-fault", "wall_s": wall, **fault_figure(r, out, plt)})
    runs = 6 if args.quick else args.runs
    stop = float(round(mission.leo.ORBIT_PERIOD)) if args.quick else None  # a whole second: a multiple of the step
    controllers = dict(CONTROLLERS)
    if args.user:
        params = {k: float(v) for k, _, v in (p.partition("=") for p in args.user_param)}
        controllers["user"] = (str(Path(args.user).resolve()), params)
    results = {}
    for label, (model, params) in controllers.items():
        rows = campaign_rows(label, model, params, runs, stop, data, args.workers)
        results[label] = rows
        for key in KEYS:
            summary.append({"what": f"campaign {label} {key}", **spread(rows, key)})
    campaign_figure(results, out, plt)
    keys = sorted({k for s in summary for k in s}, key=lambda k: (k != "what", k))
    with open(data / "mission_summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(summary)
    for s in summary:
        print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in s.items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
