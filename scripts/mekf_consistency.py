#!/usr/bin/env python3
"""Monte Carlo consistency of the ``Mekf`` FMU with the ``Gyro`` and ``StarTracker`` FMUs (issue 37).

Set-up (the choices are stated here and in docs/estimation.md):

* Plants: the paper 000 loop (run 000-6, quaternion PD slew of (40, -40, -60) deg, inertia
  diag(1000, 500, 700) kg m^2) and the paper 003 loop (T2F-SMC, case N, roll 20 deg / pitch -15 deg slew of
  the small satellite with reaction wheels, gravity gradient and magnetorquer dumping). The controllers get
  the TRUE state (the loops as the papers run them); the sensors and filters ride along, so the attitude
  motion is the closed-loop slew, the same in every run.
* Gyro 100 Hz: angle random walk N^2 = 1.9e-9 rad^2/s (0.15 deg/sqrt(h)), rate random walk K^2 = 1e-14 rad^2/s^3,
  no Gauss-Markov bias instability (the filter's bias model is a random walk), a turn-on bias drawn per run
  from N(0, sigma_b0^2), sigma_b0 = 5e-5 rad/s (~10 deg/h; numpy default_rng(seed)). Star tracker 5 Hz,
  5 / 41 arcsec (cross / about boresight), no latency, no sun exclusion.
* Three filters read the same sensors in every run: ``mekf`` with the true noise (the gyro's N^2, K^2, the
  star tracker's sigmas, prior sigma_b0), ``mekf_hi`` / ``mekf_lo`` with every noise variance (PSDs and
  sigma^2) x10 / x0.1 (the mis-set filters that must fail).
* Run r uses seed r for the gyro, the star tracker and the bias draw (seeded, bit-reproducible).

Checks (each number obtained from the runs, compared with chi-square bands of scipy.stats.chi2):

* NEES per error component i (3 attitude, 3 bias): e_i^2 / P_ii is chi2(1) for a consistent filter; averaged
  over the N runs at each sample it is chi2(N)/N; its time average must lie inside the 95 % two-sided band
  of chi2(N)/N (a conservative band for a time average of correlated samples). Only the covariance diagonal
  is an output, hence per component.
* NIS: summed over every update of every run and divided by the summed innovation dimension D it is
  chi2(D)/D (innovations of a consistent filter are white); it must lie inside its 95 % band.
* Bias at the end: |b_hat_i - b_i| <= 3 sqrt(P_b,ii); the count of exceedances over runs x axes must not exceed
  the 99.9 % quantile of Binomial(3N, 0.0027).
* Attitude error: per axis, the standard deviation over runs and samples (t >= 5 s) within 20 % of the
  filter's own sigma sqrt(mean P_ii).

Usage: ``python scripts/mekf_consistency.py [--runs 100] [--out out/mekf]`` writes ``mekf_consistency.csv``
(ensemble NEES and NIS vs time per plant and filter) and ``mekf_consistency.png``. The runs count also
comes from the environment variable SCFMU_MEKF_RUNS.
"""

from __future__ import annotations

import argparse
import copy
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

from scfmu.engines import simulate
from scfmu.scenario.model import Component, log_of

AX = "xyz"
QN = ("w", "x", "y", "z")
ARW_PSD = 1.9e-9  # rad^2/s
RRW_PSD = 1e-14  # rad^2/s^3
SIGMA_B0 = 5e-5  # rad/s
ST_CROSS, ST_ABOUT = 2.5e-5, 2.0e-4  # rad
FILTERS = {"mekf": 1.0, "mekf_hi": 10.0, "mekf_lo": 0.1}
T_STEADY = 5.0  # s, start of the window of the attitude-error standard deviation


def base_loop(plant: str, stop_time: float):
    if plant == "paper000":
        from scfmu.papers.paper000.scenarios import paper000
        return paper000("000-6", stop_time=stop_time, step=0.01)
    if plant == "paper003":
        from scfmu.papers.paper003.model import scenario
        return scenario("T2FSMC", "N", stop_time=stop_time, step=0.01)
    raise KeyError(f"plant {plant!r}: expected paper000 or paper003")


def filter_params(scale: float) -> dict:
    """Mekf parameters with every noise variance scaled by ``scale`` (1 = the sensors' true values)."""
    s = math.sqrt(scale)
    return {"sample_period": 0.01, "init_from_star_tracker": 1, "sigma_bias_init": SIGMA_B0,
            **{f"arw_psd_{a}": ARW_PSD * scale for a in AX}, **{f"rrw_psd_{a}": RRW_PSD * scale for a in AX},
            "st_noise_cross": ST_CROSS * s, "st_noise_about": ST_ABOUT * s}


def scenario(plant: str, stop_time: float, filters: dict = FILTERS):
    """The paper loop with a Gyro, a StarTracker and one Mekf per entry of ``filters`` riding along."""
    sc = copy.deepcopy(base_loop(plant, stop_time))
    sc.components = [*sc.components,
                     Component("gyro", "Gyro", {"sample_period": 0.01, "bias_corr_time": 300.0,
                                                **{f"arw_psd_{a}": ARW_PSD for a in AX},
                                                **{f"rrw_psd_{a}": RRW_PSD for a in AX},
                                                **{f"bias_instability_{a}": 0.0 for a in AX}}),
                     Component("star_tracker", "StarTracker", {"sample_period": 0.2, "latency": 0.0, "sun_exclusion": 0.0,
                                                               "noise_cross": ST_CROSS, "noise_about": ST_ABOUT}),
                     *[Component(n, "Mekf", filter_params(s)) for n, s in filters.items()]]
    # each filter's w_meas_*, q_meas_*, st_valid connect by name to the gyro's and the star tracker's outputs
    sc.unconnected = [*sc.unconnected, *[f"{n}.{p}" for n in filters for p in ("sun_*", "b_meas_*", "b_ref_*")]]
    sc.seed_params = [*sc.seed_params, "gyro.seed", "star_tracker.seed"]
    log = {**log_of("plant", [f"q_{a}" for a in QN]), **{f"b_true_{a}": f"gyro.bias_total_{a}" for a in AX}}
    for n in filters:
        log.update({f"{n}.{v}": f"{n}.{v}" for v in [*(f"q_est_{a}" for a in QN), *(f"bias_est_{a}" for a in AX),
                                                   *(f"p_att_{a}" for a in AX), *(f"p_bias_{a}" for a in AX),
                                                   "nis", "nis_dim"]})
    sc.log = log
    sc.metrics = ""
    sc.name = f"mekf-consistency/{plant}"
    return sc


def quat_mul(p, q):
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw], axis=-1)


def rotation_vector(q):
    """Rotation vector of unit quaternions (..., 4), the shorter rotation (numpy, written here)."""
    q = np.where(q[..., :1] < 0, -q, q)
    v = q[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    ang = 2 * np.arctan2(s, q[..., :1])
    return np.where(s > 0, v * ang / np.where(s > 0, s, 1), 0.0)


def run_one(sc, seed: int, engine: str = "auto") -> dict:
    bias = np.random.default_rng(seed).normal(0.0, SIGMA_B0, 3)
    r = simulate(sc, engine, seed=seed, overrides={f"gyro.bias_const_{a}": float(b) for a, b in zip(AX, bias)})
    q_true = np.column_stack([r[f"q_{a}"] for a in QN])
    b_true = np.column_stack([r[f"b_true_{a}"] for a in AX])
    out = {"time": r["time"]}
    for n in FILTERS:
        if f"{n}.nis" not in r:
            continue
        q_est = np.column_stack([r[f"{n}.q_est_{a}"] for a in QN])
        conj = q_est * np.array([1, -1, -1, -1])
        out[n] = {"e_att": rotation_vector(quat_mul(conj, q_true)),  # q = q_hat (x) exp(e/2), body axes
                  "e_bias": np.column_stack([r[f"{n}.bias_est_{a}"] for a in AX]) - b_true,
                  "p_att": np.column_stack([r[f"{n}.p_att_{a}"] for a in AX]),
                  "p_bias": np.column_stack([r[f"{n}.p_bias_{a}"] for a in AX]),
                  "nis": np.asarray(r[f"{n}.nis"], float), "dim": np.asarray(r[f"{n}.nis_dim"], float)}
    return out


def monte_carlo(plant: str, runs: int, stop_time: float, engine: str = "auto", progress: bool = False) -> dict:
    """Stacks the runs: {filter: {key: array (runs, samples, ...)}, "time": t}."""
    sc = scenario(plant, stop_time)
    it = range(1, runs + 1)
    if progress:
        from tqdm import tqdm
        it = tqdm(it, desc=f"MEKF Monte Carlo {plant}", unit="run")
    rs = [run_one(sc, s, engine) for s in it]
    out = {"time": rs[0]["time"]}
    for n in FILTERS:
        out[n] = {k: np.stack([r[n][k] for r in rs]) for k in rs[0][n]}
    return out


def check(mc: dict, name: str) -> dict:
    """The consistency numbers of filter ``name`` and whether each check passes."""
    d, t = mc[name], mc["time"]
    n_runs = d["nis"].shape[0]
    e = np.concatenate([d["e_att"], d["e_bias"]], axis=2)
    p = np.concatenate([d["p_att"], d["p_bias"]], axis=2)
    nees_comp = (e**2 / p).mean(axis=0)  # (samples, 6): ensemble mean per component, chi2(N)/N each
    nees_avg = nees_comp.mean(axis=0)  # time average per component
    lo, hi = stats.chi2.ppf([0.025, 0.975], n_runs) / n_runs
    nis_sum, dof = float(d["nis"].sum()), float(d["dim"].sum())
    nis_avg = nis_sum / dof
    nlo, nhi = stats.chi2.ppf([0.025, 0.975], dof) / dof
    # bias at the end within 3 sigma
    eb, sb = d["e_bias"][:, -1, :], np.sqrt(d["p_bias"][:, -1, :])
    outside = int((np.abs(eb) > 3 * sb).sum())
    allowed = int(stats.binom.ppf(0.999, eb.size, 2 * stats.norm.sf(3)))
    # attitude error standard deviation vs the filter's sigma, t >= T_STEADY
    m = t >= T_STEADY
    std = d["e_att"][:, m, :].reshape(-1, 3).std(axis=0)
    sig = np.sqrt(d["p_att"][:, m, :].reshape(-1, 3).mean(axis=0))
    ratio = std / sig
    res = {"runs": n_runs, "nees_components": nees_avg, "nees_mean": float(nees_avg.mean()), "nees_band": (lo, hi),
           "nis": nis_avg, "nis_dof": dof, "nis_band": (nlo, nhi), "bias_outside_3sigma": outside,
           "bias_allowed": allowed, "bias_checks": eb.size, "std_ratio": ratio,
           "nees_comp_t": nees_comp}
    res["nees_ok"] = bool(np.all((nees_avg >= lo) & (nees_avg <= hi)))
    res["nis_ok"] = bool(nlo <= nis_avg <= nhi)
    res["bias_ok"] = outside <= allowed
    res["std_ok"] = bool(np.all(np.abs(ratio - 1) <= 0.2))
    res["ok"] = res["nees_ok"] and res["nis_ok"] and res["bias_ok"] and res["std_ok"]
    return res


def summary(plant: str, name: str, r: dict) -> str:
    c = ", ".join(f"{x:.3f}" for x in r["nees_components"])
    return (f"{plant} {name}: NEES per component (att x,y,z, bias x,y,z) [{c}] band [{r['nees_band'][0]:.3f}, "
            f"{r['nees_band'][1]:.3f}] -> {'ok' if r['nees_ok'] else 'FAIL'}; NIS/dof {r['nis']:.4f} over "
            f"{r['nis_dof']:.0f} dof, band [{r['nis_band'][0]:.4f}, {r['nis_band'][1]:.4f}] -> "
            f"{'ok' if r['nis_ok'] else 'FAIL'}; bias outside 3 sigma {r['bias_outside_3sigma']}/{r['bias_checks']} "
            f"(allowed {r['bias_allowed']}) -> {'ok' if r['bias_ok'] else 'FAIL'}; attitude std / sigma "
            f"[{', '.join(f'{x:.3f}' for x in r['std_ratio'])}] (1 +- 0.2) -> {'ok' if r['std_ok'] else 'FAIL'}")


def nis_vs_time(d: dict) -> tuple[np.ndarray, np.ndarray]:
    """Ensemble NIS per dof at each sample with updates (NaN elsewhere) and its dof."""
    dof = d["dim"].sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(dof > 0, d["nis"].sum(axis=0) / dof, np.nan), dof


def write_outputs(results: dict, out: Path) -> tuple[Path, Path]:
    """CSV of the ensemble NEES (attitude and bias, per dof) and NIS per dof vs time; PNG with the bands."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    cols, names = [], []
    plants = list(results)
    fig, axes = plt.subplots(2, len(plants), figsize=(6.5 * len(plants), 7), squeeze=False)
    for j, plant in enumerate(plants):
        mc, checks = results[plant]
        t = mc["time"]
        if not cols:
            cols.append(t)
            names.append("time_s")
        for n in FILTERS:
            r = checks[n]
            nees_att = r["nees_comp_t"][:, :3].mean(axis=1)
            nees_bias = r["nees_comp_t"][:, 3:].mean(axis=1)
            nis_t, _ = nis_vs_time(mc[n])
            cols += [nees_att, nees_bias, nis_t]
            names += [f"{plant}_{n}_nees_att_per_dof", f"{plant}_{n}_nees_bias_per_dof", f"{plant}_{n}_nis_per_dof"]
            lbl = {"mekf": "true noise", "mekf_hi": "noise variances x10", "mekf_lo": "noise variances x0.1"}[n]
            axes[0, j].semilogy(t, nees_att, lw=0.8, label=f"attitude, {lbl}")
            axes[0, j].semilogy(t, nees_bias, lw=0.8, ls="--", label=f"bias, {lbl}")
            m = np.isfinite(nis_t)
            axes[1, j].semilogy(t[m], nis_t[m], ".", ms=2, label=lbl)
        r = checks["mekf"]
        n_runs = r["runs"]
        lo, hi = r["nees_band"]
        axes[0, j].axhspan(lo, hi, color="g", alpha=0.2, label=f"95 % band of chi2({n_runs})/{n_runs}")
        _, dof = nis_vs_time(mc["mekf"])
        d0 = float(np.median(dof[dof > 0]))
        nlo, nhi = stats.chi2.ppf([0.025, 0.975], d0) / d0
        axes[1, j].axhspan(nlo, nhi, color="g", alpha=0.2, label=f"95 % band of chi2({d0:.0f})/{d0:.0f}")
        axes[0, j].set_title(f"{plant}: ensemble NEES per error component ({n_runs} runs)")
        axes[1, j].set_title(f"{plant}: ensemble NIS per innovation dof (star-tracker updates)")
        axes[0, j].set_ylabel("NEES / dof (-)")
        axes[1, j].set_ylabel("NIS / dof (-)")
        for a in axes[:, j]:
            a.set_xlabel("time (s)")
            a.grid(True, which="both", alpha=0.3)
            a.legend(fontsize=7)
    fig.suptitle("Mekf consistency: Monte Carlo with the Gyro and StarTracker FMUs")
    fig.tight_layout()
    png = out / "mekf_consistency.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    n = max(len(c) for c in cols)
    csv = out / "mekf_consistency.csv"
    data = np.column_stack([np.pad(np.asarray(c, float), (0, n - len(c)), constant_values=np.nan) for c in cols])
    np.savetxt(csv, data, delimiter=",", header=",".join(names), comments="", fmt="%.9g")
    return csv, png


STOP = {"paper000": 30.0, "paper003": 60.0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=int(os.environ.get("SCFMU_MEKF_RUNS", "100")))
    ap.add_argument("--out", type=Path, default=Path("out/mekf"))
    ap.add_argument("--engine", default="auto")
    a = ap.parse_args(argv)
    if a.runs < 2:
        print(f"--runs: {a.runs} is not allowed (at least 2 runs)", file=sys.stderr)
        return 2
    results = {}
    for plant in STOP:
        t0 = time.perf_counter()
        mc = monte_carlo(plant, a.runs, STOP[plant], a.engine, progress=True)
        checks = {n: check(mc, n) for n in FILTERS}
        results[plant] = (mc, checks)
        for n in FILTERS:
            print(summary(plant, n, checks[n]))
        print(f"{plant}: {a.runs} runs in {time.perf_counter() - t0:.1f} s")
    csv, png = write_outputs(results, a.out)
    print(f"wrote {csv} and {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
