"""Paper 003 report, the running and the figures: the scenario constants, the campaigns of a list of
controller settings (``_settings_campaign``) and their per-case summary (``_summarise``), the swept
project-choice readings (``_sweeps``) and the overview and sweep figures. ``report.py`` holds the claims,
their verdict rules and ``build``.
"""

from __future__ import annotations

import math

import numpy as np

from . import model as p3
from ...report import common
from ...campaign import Campaign

CASES = ("N", "C", "S", "W", "U")
DET = ("N", "C", "S", "W")
CTRL = ("SMC", "T2FSMC")
LABEL = {"SMC": "GA-SMC", "T2FSMC": "T2F-SMC"}
CASE_NAME = {"N": "003-N nominal", "C": "003-C constant", "S": "003-S sinusoidal", "W": "003-W white noise",
             "U": "003-U inertia ±20 %"}
MAGNITUDE_KEYS = {"C": "dist_const_", "S": "dist_sin_amp_", "W": "dist_noise_std_"}
DIST_DEFAULT = 5e-4


# ----- running ------------------------------------------------------------------------------------------
def _dist_overrides(case: str, scale: float) -> dict:
    d = dict(p3.DISTURBANCES[case])
    if case in MAGNITUDE_KEYS:
        for k in d:
            if k.startswith(MAGNITUDE_KEYS[case]):
                d[k] = d[k] * scale
    return p3.prefixed("plant", d)


def _settings_campaign(controller: str, settings: list[tuple], t_end: float, n_mc: int, cases=DET,
                       log_every: int = 1, timeseries=None, ts_every: int = 1):
    """One campaign for a list of settings (label, controller overrides, disturbance scale): each setting
    runs ``cases`` and the first n_mc 003-U seeds. Returns (Campaign, index [(setting, case, seed)])."""
    sc = p3.scenario(controller, "N", stop_time=t_end)
    ov, index = [], []
    for si, (_, cov, ds) in enumerate(settings):
        cpre = p3.prefixed("controller", cov)
        for case in cases:
            ov.append({**cpre, **_dist_overrides(case, ds)})
            index.append((si, case, None))
        for s, u in zip(range(1, n_mc + 1), p3.mc_overrides(range(1, n_mc + 1))):
            ov.append({**cpre, **u})
            index.append((si, "U", s))
    return Campaign(sc, ov, [None], engine="native", log_every=log_every, timeseries=timeseries,
                    ts_every=ts_every), index


def _summarise(rows: list[dict], index: list[tuple], n_settings: int) -> list[dict]:
    """Per setting: {case: {"ise", "isf", "sse", ... "n", "failed"}} (U: Monte Carlo means)."""
    out = [dict() for _ in range(n_settings)]
    groups: dict = {}
    for r, (si, case, _) in zip(rows, index):
        groups.setdefault((si, case), []).append(r)
    for (si, case), rs in groups.items():
        ok = [r for r in rs if r["status"] == "ok"]
        d = {"n": len(ok), "failed": len(rs) - len(ok)}
        if not ok:
            d.update(ise=math.nan, isf=math.nan, sse=math.nan)
        else:
            for k in ("ise", "isf", "cost", *[f"sse_{a}_deg" for a in p3.ANGLES]):
                d[k] = float(np.mean([r[k] for r in ok]))
            d["sse"] = float(np.mean([d[f"sse_{a}_deg"] for a in p3.ANGLES]))
            if case == "U" and len(ok) > 1:
                d["ise_std"] = float(np.std([r["ise"] for r in ok], ddof=1))
                d["isf_std"] = float(np.std([r["isf"] for r in ok], ddof=1))
        out[si][case] = d
    return out


def _fmt(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


# ----- figures ----------------------------------------------------------------------------------------
def _plot_overview(summary: dict, path) -> None:
    plt = common.plt()
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    x = np.arange(len(CASES))
    for j, (key, ylabel) in enumerate((("ise", "ISE (rad² s)"), ("isf", "ISF (N² m² s)"),
                                       ("sse", "steady-state error, mean of 3 angles (deg)"))):
        for i, c in enumerate(CTRL):
            ax[j].bar(x + (i - 0.5) * 0.38, [summary[(c, k)][key] for k in CASES], 0.38, label=LABEL[c])
        ax[j].set_xticks(x, [f"003-{k}" for k in CASES])
        ax[j].set_ylabel(ylabel)
        ax[j].set_xlabel("scenario (003-U: mean of the Monte Carlo runs)")
        ax[j].grid(True, axis="y", alpha=0.3)
        ax[j].legend(loc="lower left", framealpha=0.9)
        if key == "sse":
            ax[j].set_yscale("log")
    fig.suptitle("Paper 003: GA-SMC vs T2F-SMC per scenario (lower is better)")
    common.save(fig, path)


def _plot_sweep(name: str, unit: str, values: list, summaries: list[dict], path) -> None:
    """Ratio T2F-SMC / GA-SMC of ISE, ISF and steady-state error per case against the swept value."""
    plt = common.plt()
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    numeric = all(isinstance(v, (int, float)) for v in values)
    xs = values if numeric else list(range(len(values)))
    for j, key in enumerate(("ise", "isf", "sse")):
        for case, mk in zip(CASES, "osd^v"):
            ys = [s[("T2FSMC", case)][key] / s[("SMC", case)][key] if (("SMC", case) in s and
                  s[("SMC", case)][key] > 0) else math.nan for s in summaries]
            ax[j].plot(xs, ys, marker=mk, label=f"003-{case}")
        ax[j].axhline(1.0, color="k", lw=0.8)
        ax[j].set_yscale("log")
        from matplotlib.ticker import FuncFormatter
        plain = FuncFormatter(lambda y, _: f"{y:g}")
        ax[j].yaxis.set_major_formatter(plain)
        ax[j].yaxis.set_minor_formatter(plain)
        ax[j].set_xlabel(f"{name}{f' ({unit})' if unit else ''}")
        ax[j].set_ylabel(f"{key.upper() if key != 'sse' else 'steady-state error'} ratio T2F-SMC / GA-SMC (-)")
        if numeric and min(values) > 0 and max(values) / min(values) > 20:
            ax[j].set_xscale("log")
        if not numeric:
            ax[j].set_xticks(xs, [str(v) for v in values])
        elif all(isinstance(v, int) for v in values):
            ax[j].set_xticks(xs)
        ax[j].grid(True, alpha=0.3)
        ax[j].legend(fontsize=7)
    fig.suptitle(f"Sensitivity to {name}: below 1 = T2F-SMC lower")
    common.save(fig, path)


# ----- the sweeps --------------------------------------------------------------------------------------
def _sweeps(tuned: dict, quick: bool) -> list[dict]:
    """The swept project-choice readings: name, unit, values, default, and for each value the controller
    overrides of each controller and the disturbance scale."""
    t2 = tuned["T2FSMC"]
    kappa0 = float(t2.get("kappa", 0.5))
    es0, eds0 = float(t2.get("e_scale", 0.05)), float(t2.get("edot_scale", 0.01))
    phi0 = 0.005
    kappas = [0.1, kappa0, 0.9] if quick else sorted({0.1, 0.3, round(kappa0, 4), 0.7, 0.9})
    if round(kappa0, 4) in kappas:
        kappas = [kappa0 if v == round(kappa0, 4) else v for v in kappas]
    sigmas = [(0.3, 0.5), (0.1, 0.9)] if quick else [(0.3, 0.5), (0.45, 0.5), (0.2, 0.6), (0.1, 0.9)]
    scales = [0.5, 1.0, 2.0] if quick else [0.25, 0.5, 1.0, 2.0, 4.0]
    dists = [1e-4, 5e-4, 5e-3] if quick else [1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3]
    phis = [0.002, 0.005, 0.02] if quick else [0.001, 0.002, 0.005, 0.01, 0.02]
    return [
        {"name": "Type2FuzzySmcController.kappa", "unit": "-", "values": kappas, "default": kappa0,
         "ctrl": lambda v: ({}, {"kappa": v}), "dist": lambda v: 1.0},
        {"name": "Type2FuzzySmcController.(sigma_lo, sigma_up)", "unit": "-", "values": sigmas, "default": (0.3, 0.5),
         "ctrl": lambda v: ({}, {"sigma_lo": v[0], "sigma_up": v[1]}), "dist": lambda v: 1.0},
        {"name": "Type2FuzzySmcController.table_transpose", "unit": "", "values": [0, 1], "default": 0,
         "ctrl": lambda v: ({}, {"table_transpose": v}), "dist": lambda v: 1.0},
        {"name": "Type2FuzzySmcController e_scale and edot_scale × factor", "unit": "× tuned", "values": scales,
         "default": 1.0, "ctrl": lambda v: ({}, {"e_scale": es0 * v, "edot_scale": eds0 * v}),
         "dist": lambda v: 1.0},
        {"name": "disturbance magnitude of 003-C, -S, -W", "unit": "N m", "values": dists, "default": DIST_DEFAULT,
         "ctrl": lambda v: ({}, {}), "dist": lambda v: v / DIST_DEFAULT, "cases": ("C", "S", "W"), "mc": False},
        {"name": "boundary layer Φ (both controllers)", "unit": "rad/s", "values": phis, "default": phi0,
         "ctrl": lambda v: ({"boundary_layer": v}, {"boundary_layer": v}), "dist": lambda v: 1.0},
    ]
