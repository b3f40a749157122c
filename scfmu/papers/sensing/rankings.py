"""``scfmu paper sensing rankings``: do paper 000's and paper 003's controller rankings survive realistic
sensing?

Per group (paper 000's large slew (40, -40, -60) deg, one scenario per controller, ranked by EULERINT;
paper 003's cases 003-N, C, S, W, SMC against T2F-SMC, ranked by ISE) every controller runs once with the
plant's truth and ``--seeds`` times with sensors (``sensing/<scenario>``: gyro, star tracker, 10 Hz flight
computer with 0.05 s delay; run seeds 1…n go to the sensors' seeds, and in 003-W to the plant's noise
seed too) and as many times with the estimator in the loop (``sensing+estimation/<scenario>``: the same
sensors plus sun sensor, magnetometer, on-board ephemeris and the ``Mekf`` feeding the controller; the
seeds also go to the two new sensors). The controllers are ranked by the truth value and by the mean over
the seeds of each variant; a ranking "survives" when the order is the same as with the truth. Writes ``rankings.csv`` (one row per controller and group) and
``rankings.png`` under ``--out``; every run goes through the campaign engine (Dask, native engine).
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from ... import campaign
from ...scenario import get
from ...scenario.ssp import file_stem
from .scenarios import PAPER000_LARGE

GROUPS = [("paper 000 large slew", "eulerint_deg_s", "EULERINT [deg·s]", dict(PAPER000_LARGE))]
GROUPS += [(f"paper 003 003-{k}", "ise", "ISE [rad²·s]", {f"paper003/SMC/{k}": "GA-SMC", f"paper003/T2FSMC/{k}": "T2F-SMC"})
           for k in "NCSW"]


TIE = 1e-6  # relative difference below which two controllers tie (PD, LQR and pole placement have equal gains)


def _rank(values: dict) -> dict:
    """{label: rank} (1 = lowest; ties within TIE share the rank; NaN last)."""
    order = sorted(values, key=lambda k: (not math.isfinite(values[k]), values[k]))
    out = {}
    for i, k in enumerate(order):
        prev = order[i - 1] if i else None
        tie = prev is not None and math.isclose(values[k], values[prev], rel_tol=TIE)
        out[k] = out[prev] if tie else i + 1
    return out


VARIANTS = (("truth", ""), ("sensed", "sensing/"), ("est", "sensing+estimation/"))  # (row key, scenario prefix)


def _stats(prefix: str, v: np.ndarray) -> dict:
    ok = np.isfinite(v)
    return {f"{prefix}_mean": float(np.mean(v[ok])) if ok.any() else math.nan,
            f"{prefix}_std": float(np.std(v[ok], ddof=1)) if ok.sum() > 1 else 0.0,
            f"{prefix}_min": float(np.min(v[ok])) if ok.any() else math.nan,
            f"{prefix}_max": float(np.max(v[ok])) if ok.any() else math.nan,
            f"{prefix}_runs_ok": int(ok.sum())}


def _order(r: dict) -> str:
    return ", ".join(f"{r[k]}. {k}" for k in sorted(r, key=r.get))


def run(out: Path, seeds: int, workers: int, stop_003: float | None, log=print, estimator: bool = True,
        client=None) -> list[dict]:
    """One row per controller and group: the truth value, the sensed and (``estimator``) the estimator-in-the-
    loop statistics over the seeds (over the runs that succeeded; ``*_runs_ok`` counts them), the ranks and
    whether each ranking survives. ``client``: a Dask client to use (default: one started here)."""
    out.mkdir(parents=True, exist_ok=True)
    own = client is None
    cluster = None
    if own:
        client, cluster = campaign._client(None, workers)
    variants = VARIANTS if estimator else VARIANTS[:2]
    rows = []
    try:
        for group, metric, _, members in GROUPS:
            vals: dict = {key: {} for key, _ in variants}
            for name, label in members.items():
                kw = {"stop_time": stop_003} if (stop_003 and name.startswith("paper003")) else {}
                for key, prefix in variants:
                    sc = get(prefix + name, **kw)
                    sd = [None] if key == "truth" else list(range(1, seeds + 1))
                    folder = out / "runs" / file_stem(sc.name)
                    t = campaign.run(campaign.Campaign(sc, [{}], sd, engine="native"), folder, client=client,
                                     progress=False, overwrite=True).to_pylist()
                    vals[key][label] = np.array([r[metric] if r["status"] == "ok" else math.nan for r in t], dtype=float)
            rk = {key: _rank({k: float(np.mean(v)) for k, v in vals[key].items()}) for key, _ in variants}
            for label in members.values():
                row = {"group": group, "controller": label, "metric": metric, "truth": float(vals["truth"][label][0]),
                       "runs": seeds}
                for key, _ in variants[1:]:
                    row.update(_stats(key, vals[key][label]))
                row.update({f"rank_{key}": rk[key][label] for key, _ in variants})
                row["ranking_survives"] = rk["sensed"] == rk["truth"]
                if estimator:
                    row["ranking_survives_estimator"] = rk["est"] == rk["truth"]
                rows.append(row)
            log(f"{group}: truth {_order(rk['truth'])}; with sensors {_order(rk['sensed'])}: ranking "
                f"{'survives' if rk['sensed'] == rk['truth'] else 'CHANGES'}"
                + (f"; with the estimator {_order(rk['est'])}: ranking "
                   f"{'survives' if rk['est'] == rk['truth'] else 'CHANGES'}" if estimator else ""))
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    return rows


def write(rows: list[dict], out: Path) -> None:
    with open(out / "rankings.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(GROUPS), figsize=(4.2 * len(GROUPS), 4.2))
    for ax, (group, _, unit, members) in zip(axes, GROUPS):
        rs = [r for r in rows if r["group"] == group]
        x = np.arange(len(rs))
        est = "est_mean" in rs[0]
        w = 0.27 if est else 0.4
        ax.bar(x - w, [r["truth"] for r in rs], w, label="truth")
        ax.bar(x, [r["sensed_mean"] for r in rs], w, yerr=[r["sensed_std"] for r in rs], capsize=3,
               label=f"sensors (mean ± sd, {rs[0]['runs']} seeds)")
        if est:
            ax.bar(x + w, [r["est_mean"] for r in rs], w, yerr=[r["est_std"] for r in rs], capsize=3,
                   label=f"sensors + Mekf (mean ± sd, {rs[0]['runs']} seeds)")
        ax.set_xticks(x, [r["controller"] for r in rs], rotation=40, ha="right", fontsize=8)
        ax.set_ylabel(unit)
        verdict = f"sensors: {'survives' if rs[0]['ranking_survives'] else 'changes'}"
        if est:
            verdict += f"; Mekf: {'survives' if rs[0]['ranking_survives_estimator'] else 'changes'}"
        ax.set_title(f"{group}\n{verdict}", fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
        if rs[0]["metric"] == "ise":
            lo = np.nanmin([min(r["truth"], r["sensed_mean"], r.get("est_mean", math.inf)) for r in rs])
            ax.set_ylim(bottom=0.9 * lo)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "rankings.png", dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="scfmu paper sensing rankings", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/sensing", help="output folder (default out/sensing)")
    ap.add_argument("--seeds", type=int, default=10, help="sensor seeds per controller (default 10)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="3 seeds, paper 003 cases over 30 s instead of 150 s")
    ap.add_argument("--no-estimator", action="store_true", help="truth and sensors only (no sensing+estimation runs)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    t0 = time.time()
    rows = run(out, 3 if a.quick else a.seeds, a.workers, 30.0 if a.quick else None, estimator=not a.no_estimator)
    write(rows, out)
    print(f"wrote {out / 'rankings.csv'} and {out / 'rankings.png'} ({time.time() - t0:.0f} s)")
    return 0


def main_slew(argv=None) -> int:
    """``scfmu paper sensing slew``: paper 000's large slew (PD, run 000-6) with and without sensors:
    Euler-axis error, body rate (true and measured) and commanded torque, ``large_slew.png``."""
    ap = argparse.ArgumentParser(prog="scfmu paper sensing slew")
    ap.add_argument("--out", default="out/sensing")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    from ...engines import simulate
    truth, sens = simulate(get("default")), simulate(get("sensing/default"))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    t = truth["time"]
    ax[0].semilogy(t, np.maximum(truth["alpha_deg"], 1e-6), label=f"truth (EULERINT {truth['eulerint_deg_s'][-1]:.1f} deg·s)")
    ax[0].semilogy(t, np.maximum(sens["alpha_deg"], 1e-6), label=f"sensors + 10 Hz flight computer (EULERINT {sens['eulerint_deg_s'][-1]:.1f} deg·s)")
    ax[0].set_ylabel("Euler-axis error α (deg)")
    for i, (a_, c) in enumerate(zip("xyz", "rgb")):
        ax[1].plot(t, np.degrees(sens[f"w_meas_{a_}"]), color=c, lw=0.5, alpha=0.6, label=f"gyro {a_}")
        ax[1].plot(t, np.degrees(sens[f"w_{a_}"]), color=c, lw=1.2, label=f"true {a_} (with sensors)")
        ax[1].plot(t, np.degrees(truth[f"w_{a_}"]), "--", color=c, lw=0.8, label=f"true {a_} (truth loop)")
        ax[2].plot(t, sens[f"torque_cmd_{a_}"], color=c, lw=0.8, label=f"{a_} with sensors (held)")
        ax[2].plot(t, truth[f"torque_applied_{a_}"], "--", color=c, lw=0.8, label=f"{a_} truth")
    ax[1].set_ylabel("body rate (deg/s)")
    ax[2].set_ylabel("torque (N·m)")
    ax[2].set_xlabel("time (s)")
    for x in ax:
        x.grid(True, alpha=0.3)
        x.legend(fontsize=7, ncol=3)
    ax[0].set_title("Paper 000 large slew (40, −40, −60) deg, quaternion PD: truth vs gyro + star tracker + 10 Hz FC")
    fig.tight_layout()
    fig.savefig(out / "large_slew.png", dpi=100)
    plt.close(fig)
    print(f"EULERINT truth {truth['eulerint_deg_s'][-1]:.2f} deg·s, with sensors {sens['eulerint_deg_s'][-1]:.2f} deg·s; "
          f"final α {truth['alpha_deg'][-1]:.2e} / {sens['alpha_deg'][-1]:.2e} deg; wrote {out / 'large_slew.png'}")
    return 0
