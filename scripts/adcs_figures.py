#!/usr/bin/env python3
"""Figures of docs/adcs.md, the walkthrough detumble → determination → estimation → pointing, made from the
packaged FMUs (run from a checkout with the FMUs built: ``.venv/bin/python scripts/adcs_figures.py``).

1. ``adcs_detumble.png``: the body rate under the BDot law from a tip-off (the registered detumble scenario);
2. ``adcs_determination.png``: TRIAD and QUEST attitudes from the sun sensor and the magnetometer against the
   truth along the large slew of paper 000 (the logged sensor outputs fed to the packaged Triad and Quest);
3. ``adcs_estimation.png``: the Mekf's attitude error with its ±3σ band and its bias estimate against the
   gyro's true bias;
4. ``adcs_pointing.png``: the Euler-axis pointing error of the large slew fed by the truth, by the raw
   sensors and by the estimator.

Each part is skipped with a message when the units it needs are not built. ``--out`` (default docs/).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from scfmu import fmu as fmu_access
from scfmu import scenario as scenarios
from scfmu.engines import simulate

AX = "xyz"


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _have(*models: str) -> bool:
    have = set(fmu_access.models())
    missing = [m for m in models if m not in have]
    if missing:
        print(f"skipped: FMU(s) {', '.join(missing)} not built")
    return not missing


def quat_err_deg(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Angle [deg] of the rotation between two attitude quaternion series (n × 4, scalar first)."""
    d = np.abs(np.sum(q1 * q2, axis=1)) / np.linalg.norm(q1, axis=1) / np.linalg.norm(q2, axis=1)
    return np.degrees(2 * np.arccos(np.clip(d, -1.0, 1.0)))


def _stack(r: dict, stem: str, comps: str = "wxyz") -> np.ndarray:
    return np.stack([np.asarray(r[f"{stem}_{a}"], dtype=float) for a in comps], axis=1)


def detumble(out: Path) -> str | None:
    names = [n for n in scenarios.names() if "detumble" in n]
    if not names or not _have("BDot"):
        print("skipped: no registered detumble scenario" if not names else "")
        return None
    sc = scenarios.get(names[0])
    r = simulate(sc)
    t = np.asarray(r["time"])
    w = np.degrees(np.linalg.norm(_stack(r, "w", AX), axis=1))
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.semilogy(t / 60, w, label="|ω| with BDot")
    for a in AX:
        ax.semilogy(t / 60, np.abs(np.degrees(r[f"w_{a}"])), lw=0.6, alpha=0.6, label=f"|ω_{a}|")
    ax.set_xlabel("time [min]")
    ax.set_ylabel("body rate [deg/s]")
    ax.set_title(f"Detumbling with B-dot from a tip-off ({names[0]})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "adcs_detumble.png", dpi=100)
    plt.close(fig)
    print(f"detumble: |ω| {w[0]:.3g} deg/s at t = 0, {w[-1]:.3g} deg/s after {t[-1] / 60:.0f} min")
    return "adcs_detumble.png"


def _log_vectors(sc):
    extra = {**{f"sun_meas_{a}": f"sun_sensor.sun_meas_{a}" for a in AX},
             **{f"b_meas_{a}": f"magnetometer.b_meas_{a}" for a in AX},
             **{f"sun_ref_{a}": f"ephemeris.sun_ref_{a}" for a in AX},
             **{f"b_ref_{a}": f"ephemeris.b_ref_{a}" for a in AX},
             **{f"bias_true_{a}": f"gyro.bias_total_{a}" for a in AX}}
    sc.log = {**sc.log, **extra}
    return sc


def _static(model: str, r: dict, valid: np.ndarray, params: dict | None = None) -> np.ndarray:
    """The attitude a static determination unit gives at each logged sample where ``valid`` (NaN elsewhere)."""
    f = fmu_access.Fmu(model, params or {})
    try:
        vr = {k: [f.var(f"{k}_{a}").valueReference for a in AX] for k in ("sun_meas", "b_meas", "sun_ref", "b_ref")}
        out_vr = [f.var(f"q_est_{a}").valueReference for a in "wxyz"]
        n = len(r["time"])
        q = np.full((n, 4), math.nan)
        h = float(r["time"][1] - r["time"][0])
        for i in range(n):
            if valid[i]:
                for k, v in vr.items():
                    f.slave.setReal(v, [float(r[f"{k}_{a}"][i]) for a in AX])
                q[i] = f.slave.getReal(out_vr)
            f.slave.doStep(float(r["time"][i]), h)
        return q
    finally:
        f.close()


def determination(out: Path, r: dict) -> str | None:
    if not _have("Triad", "Quest"):
        return None
    t = np.asarray(r["time"])
    # at the sensors' sample instants (10 Hz; between them the held samples lag the slewing body)
    fresh = np.abs(t / 0.1 - np.round(t / 0.1)) < 1e-6
    valid = (np.asarray(r["sun_valid"]) > 0.5) & fresh
    qt = _stack(r, "q")
    # weights 1/σ² of each sensor's angular noise (sun 0.1 deg; field: 100 nT over the local field strength)
    b_norm = np.linalg.norm(_stack(r, "b_ref", AX), axis=1)
    w_sun, w_b = 1 / 1.745e-3 ** 2, 1 / (1e-7 / float(np.min(b_norm))) ** 2
    qs = {"TRIAD (sun anchor)": _static("Triad", r, valid),
          "QUEST": _static("Quest", r, valid, {"weight_sun": w_sun, "weight_b": w_b})}
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))
    for label, q in qs.items():
        e = quat_err_deg(qt, q)
        ax.plot(t, e, "o" if "TRIAD" in label else "x", ms=3, label=f"{label}: median {np.nanmedian(e):.3f} deg")
        print(f"determination: {label}: median error {np.nanmedian(e):.3f} deg over {np.sum(np.isfinite(e))} samples")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("attitude error [deg]")
    ax.set_yscale("log")
    ax.set_title("Static determination from sun sensor + magnetometer\n(10 Hz samples with the sun in the sensor's view)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "adcs_determination.png", dpi=100)
    plt.close(fig)
    return "adcs_determination.png"


def estimation(out: Path, r: dict) -> str:
    t = np.asarray(r["time"])
    qt, qe = _stack(r, "q"), _stack(r, "q_est")
    e = quat_err_deg(qt, qe)
    sig = np.degrees(np.sqrt(np.asarray(r["p_att_x"]) + np.asarray(r["p_att_y"]) + np.asarray(r["p_att_z"])))
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    ax[0].semilogy(t, np.maximum(e, 1e-6), lw=0.7, label="|attitude error| (estimate vs truth)")
    ax[0].semilogy(t, 3 * sig, "k--", lw=1, label="3σ of the filter (sqrt tr P_att)")
    ax[0].set_ylabel("attitude error [deg]")
    ax[0].set_title("Mekf on paper 000's large slew: attitude error and gyro bias")
    for a, c in zip(AX, "rgb"):
        ax[1].plot(t, np.degrees(r[f"bias_est_{a}"]) * 3600, color=c, lw=1, label=f"estimated bias {a}")
        ax[1].plot(t, np.degrees(r[f"bias_true_{a}"]) * 3600, "--", color=c, lw=0.8, label=f"true bias {a}")
    ax[1].set_ylabel("gyro bias [deg/h]")
    ax[1].set_xlabel("time [s]")
    for x in ax:
        x.grid(True, which="both", alpha=0.3)
        x.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "adcs_estimation.png", dpi=100)
    plt.close(fig)
    ph = t >= t[-1] / 3
    print(f"estimation: RMS attitude error {np.sqrt(np.mean(e[ph] ** 2)):.2e} deg after {t[-1] / 3:.0f} s, "
          f"filter σ {np.sqrt(np.mean(sig[ph] ** 2)):.2e} deg")
    return "adcs_estimation.png"


def pointing(out: Path, est: dict) -> str:
    truth, sens = simulate(scenarios.get("default")), simulate(scenarios.get("sensing/default"))
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))
    for r, label in ((truth, "perfect knowledge"), (sens, "raw gyro + star tracker"), (est, "Mekf estimate")):
        ax.semilogy(r["time"], np.maximum(r["alpha_deg"], 1e-6),
                    label=f"{label} (EULERINT {r['eulerint_deg_s'][-1]:.1f} deg·s, final {r['alpha_deg'][-1]:.1e} deg)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("Euler-axis error α [deg]")
    ax.set_title("Pointing: paper 000's large slew (quaternion PD) fed by truth, sensors, estimator")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "adcs_pointing.png", dpi=100)
    plt.close(fig)
    return "adcs_pointing.png"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="docs", help="output folder (default docs/)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    made = [detumble(out)]
    if _have("Mekf", "Ephemeris"):
        r = simulate(_log_vectors(scenarios.get("sensing+estimation/default")))
        made += [determination(out, r), estimation(out, r), pointing(out, r)]
    print("wrote " + ", ".join(str(out / m) for m in made if m))
    return 0


if __name__ == "__main__":
    sys.exit(main())
