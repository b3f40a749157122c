"""Paper 003 closed loops, declared once: sliding-mode (GA-SMC) and interval type-2 fuzzy sliding-mode
(T2F-SMC) attitude control of a LEO satellite with reaction wheels and magnetorquer momentum dumping.

Loop (``scfmu.scenarios.get("paper003/<SMC|T2FSMC>/<N|C|S|W|U>")``): AttitudeCommand (roll 20°,
pitch −15°, yaw 0°) → SlidingModeController or Type2FuzzySmcController (tuned values of
the package data file ``paper003/data/tuned.json``) → AttitudePlant (full inertia, quaternion kinematics, three reaction
wheels with magnetorquer dumping, gravity gradient on a 700 km / 98° orbit, RK4 0.01 s) →
AttitudeMetrics; wired by port name (the plant's wheel momentum ``h_wheel_*`` feeds the controller's
input of the same name); Δ = 0.01 s, 150 s.

Cases: N none; C constant 5e-4 N·m per axis; S sinusoid 5e-4 N·m, 0.1 rad/s, phases 0, π/2, π;
W white noise σ = 5e-4 N·m, hold 0.1 s, seed 1 (the scenario's seed parameter); U inertia_scale_{x,y,z}
uniform in [0.8, 1.2] from numpy's ``default_rng(seed)`` (the 003-U Monte Carlo uses seeds 1…100,
:func:`mc_overrides`), no disturbance.

Metrics (``Scenario.metrics = "paper003"``, :func:`metrics`): the attitude columns plus the steady-state
error per Euler angle (mean |wrapped error| over the last 10 % of the logged samples, deg), max and min
applied torque per axis, and the GA cost J = ISE + 1e4·ISF.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ...campaign import Campaign
from ...metrics import attitude
from ...scenario.model import Scenario, log_of
from ...scenario.templates import attitude_loop
from .data import data_file

TUNED_FILE = data_file("tuned.json")

D = math.radians
COMMAND = (D(20.0), D(-15.0), 0.0)
DT = 0.01
T_END = 150.0
ISF_WEIGHT = 1e4
AX = "xyz"
ANGLES = ("roll", "pitch", "yaw")

PLANT = {
    "inertia_xx": 4.0, "inertia_yy": 5.0, "inertia_zz": 3.5,
    "inertia_xy": 0.05, "inertia_xz": -0.03, "inertia_yz": 0.02,
    "kinematics": 0, "actuator_mode": 1, "mtq_enable": 1, "gg_enable": 1,
    "max_internal_step": 0.01,
}
# scenario key -> (label used in tables, FMU model, key in paper003_tuned.json)
CONTROLLERS = {"SMC": ("GA-SMC", "SlidingModeController"), "T2FSMC": ("T2F-SMC", "Type2FuzzySmcController")}
DISTURBANCES = {
    "N": {},
    "C": {f"dist_const_{a}": 5e-4 for a in AX},
    "S": {**{f"dist_sin_amp_{a}": 5e-4 for a in AX}, "dist_sin_freq": 0.1,
          "dist_sin_phase_x": 0.0, "dist_sin_phase_y": math.pi / 2, "dist_sin_phase_z": math.pi},
    "W": {**{f"dist_noise_std_{a}": 5e-4 for a in AX}, "dist_noise_hold": 0.1, "dist_noise_seed": 1},
    "U": {},
}
CASES = tuple(DISTURBANCES)
GA_BOUNDS = {"k_switch": (1e-4, 0.05), "e_scale": (0.005, 0.5), "edot_scale": (0.001, 0.1), "kappa": (0.0, 0.9)}

LOG_PLANT = ["roll", "pitch", "yaw"] + [f"{v}_{a}" for v in ("torque_applied", "h_wheel", "torque_ext") for a in AX]
LOG_CTRL = [f"{v}_{a}" for v in ("s", "k_gain") for a in AX]
LOG_METRICS = ["alpha_deg", "eulerint_deg_s", "effort_abs", "effort_sq", "ise", "isf"]
EXTRA_COLUMNS = ([f"sse_{a}_deg" for a in ANGLES] + [f"t{m}_{a}" for a in AX for m in ("max", "min")] + ["cost"])


def uncertainty_scales(seed: int) -> dict:
    """003-U: inertia_scale_{x,y,z} uniform in [0.8, 1.2] from numpy's default_rng(seed)."""
    s = np.random.default_rng(seed).uniform(0.8, 1.2, 3)
    return {f"inertia_scale_{a}": float(v) for a, v in zip(AX, s)}


def mc_overrides(seeds) -> list[dict]:
    """Campaign overrides of the 003-U Monte Carlo: one plant inertia scaling per run seed."""
    return [{f"plant.{k}": v for k, v in uncertainty_scales(int(s)).items()} for s in seeds]


def tuned_params(path: str | Path | None = None) -> dict[str, dict]:
    """{"SMC": {...}, "T2FSMC": {...}}: the committed GA results (the FMUs' defaults if the file is absent)."""
    p = Path(path) if path else TUNED_FILE
    if not p.exists():
        return {"SMC": {}, "T2FSMC": {}}
    t = json.loads(p.read_text())
    return {"SMC": dict(t["GA-SMC"]["SlidingModeController"]),
            "T2FSMC": dict(t["T2F-SMC"]["Type2FuzzySmcController"])}


def scenario(controller: str = "T2FSMC", case: str = "N", seed: int = 1, stop_time: float = T_END,
             step: float = DT, ctrl_params: dict | None = None, tuned: str | Path | None = None) -> Scenario:
    """The paper 003 loop with ``controller`` ("SMC" or "T2FSMC"; tuned values unless ``ctrl_params`` is
    given) in case N, C, S, W or U (U: the inertia scaling of ``seed``)."""
    if controller not in CONTROLLERS:
        raise KeyError(f"paper 003 controller {controller!r}: expected one of {list(CONTROLLERS)}")
    if case not in DISTURBANCES:
        raise KeyError(f"paper 003 case {case!r}: expected one of {list(DISTURBANCES)}")
    label, model = CONTROLLERS[controller]
    cp = tuned_params(tuned)[controller] if ctrl_params is None else dict(ctrl_params)
    pp = {**PLANT, **DISTURBANCES[case]}
    if case == "U":
        pp.update(uncertainty_scales(seed))
    sc = attitude_loop(f"paper003/{controller}/{case}", model, COMMAND, cp, pp, stop_time, step,
                       description=f"paper 003 case 003-{case}, {label}")
    sc.log = {**log_of("plant", LOG_PLANT), **log_of("controller", LOG_CTRL), **log_of("metrics", LOG_METRICS),
              **log_of("command", ["roll_ref", "pitch_ref", "yaw_ref"])}
    sc.metrics = "paper003"
    return sc


def metrics(r: dict) -> dict:
    """The attitude columns plus steady-state error per Euler angle, torque extremes and the GA cost."""
    m = attitude(r)
    n = len(r["time"])
    n_ss = max(1, int(round(0.1 * (n - 1))))
    for ang, ref in zip(ANGLES, COMMAND):
        err = np.angle(np.exp(1j * (ref - np.asarray(r[ang]))))  # wrapped to (-pi, pi]
        m[f"sse_{ang}_deg"] = float(np.degrees(np.mean(np.abs(err[-n_ss:]))))
    for a in AX:
        tq = np.asarray(r[f"torque_applied_{a}"])
        m[f"tmax_{a}"] = float(np.max(tq))
        m[f"tmin_{a}"] = float(np.min(tq))
    m["cost"] = m["ise"] + ISF_WEIGHT * m["isf"]
    return m


# ----- campaigns -------------------------------------------------------------------------------------
def scenario_campaign(controller: str, case: str, params: dict | None = None, t_end: float = T_END,
                      timeseries: list | None = None, ts_every: int = 1, tuned=None):
    """One run of case N, C, S or W (or U with seed 1) as a Campaign (every sample logged)."""
    sc = scenario(controller, case, stop_time=t_end, ctrl_params=params, tuned=tuned)
    return Campaign(sc, [{}], [None], engine="native", timeseries=timeseries, ts_every=ts_every)


def mc_campaign(controller: str, seeds, params: dict | None = None, t_end: float = T_END, tuned=None,
                extra: dict | None = None):
    """The 003-U Monte Carlo of one controller: run i has the inertia scaling of seeds[i]; ``extra``
    overrides are applied to every run (sensitivity sweeps)."""
    sc = scenario(controller, "N", stop_time=t_end, ctrl_params=params, tuned=tuned)
    if extra:
        sc = sc.with_overrides(extra)
    sc.name = f"paper003/{controller}/U"
    return Campaign(sc, mc_overrides(seeds), [None], engine="native")


def ga_campaign(controller: str, base_params: dict, genes: list[str], solutions, t_end: float = T_END,
                log_every: int = 0):
    """GA candidates on 003-N: one run per solution (gene values set on the controller). Only the final
    ISE and ISF enter the cost, so by default the loop runs in one container call (``log_every`` 0)."""
    sc = scenario(controller, "N", stop_time=t_end, ctrl_params=base_params)
    ov = [{f"controller.{g}": float(v) for g, v in zip(genes, s)} for s in solutions]
    return Campaign(sc, ov, [None], engine="native", log_every=log_every)


def rows(table) -> list[dict]:
    """A campaign results table as a list of row dicts (no pandas needed)."""
    cols = table.column_names
    data = [table.column(c).to_pylist() for c in cols]
    return [dict(zip(cols, vals)) for vals in zip(*data)]


TABLE_COLUMNS = ([f"sse_{a}_deg" for a in ANGLES] + ["ise", "isf", "cost"]
                 + [f"t{m}_{a}" for a in AX for m in ("max", "min")])


def mc_stats(rows_: list[dict]) -> dict:
    """Mean and standard deviation (ddof 1) of ISE, ISF and the steady-state errors over the ok runs."""
    ok = [r for r in rows_ if r["status"] == "ok"]
    out = {"runs": len(ok), "failed": len(rows_) - len(ok)}
    for k in ("ise", "isf", *[f"sse_{a}_deg" for a in ANGLES]):
        v = np.array([r[k] for r in ok], dtype=float)
        out[f"{k}_mean"] = float(v.mean()) if len(v) else math.nan
        out[f"{k}_std"] = float(v.std(ddof=1)) if len(v) > 1 else 0.0
    return out


# ----- figures ---------------------------------------------------------------------------------------
LABELS = {k: v[0] for k, v in CONTROLLERS.items()}


def _label(name: str) -> str:
    return LABELS.get(name, name)


def plot_scenario(runs: dict, title: str, path: str | Path) -> None:
    """Euler angles, applied torques, wheel momentum and external torque of one case, both controllers
    (``runs``: controller label -> logged signals of the scenario)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    styles = ["-", "--", ":", "-."]
    for (name, s), style in zip(runs.items(), styles):
        t = s["time"]
        for i, (ang, c) in enumerate(zip(ANGLES, "rgb")):
            a = AX[i]
            ax[0].plot(t, np.degrees(s[ang]), style, color=c, label=f"{ang} {_label(name)}")
            ax[1].plot(t, np.asarray(s[f"torque_applied_{a}"]) * 1e3, style, color=c, label=f"{a} {_label(name)}")
            ax[2].plot(t, np.asarray(s[f"h_wheel_{a}"]) * 1e3, style, color=c, label=f"{a} {_label(name)}")
    first = next(iter(runs.values()))
    for a, c in zip(AX, "rgb"):
        ax[3].plot(first["time"], np.asarray(first[f"torque_ext_{a}"]) * 1e3, color=c, lw=0.6, label=f"{a}")
    ax[0].set_ylabel("Euler 321 angle (deg)")
    ax[1].set_ylabel("applied torque (mN m)")
    ax[2].set_ylabel("wheel momentum (mN m s)")
    ax[3].set_ylabel("external torque (mN m)\n(disturbance + gravity gradient)")
    ax[3].set_xlabel("time (s)")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7, ncol=3)
    names = list(runs)
    ax[0].set_title(f"{title}: " + " vs ".join(f"{_label(n)} ({st})" for n, st in
                                               zip(names, ["solid", "dashed", "dotted", "dash-dot"])))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_monte_carlo(mc: dict, path: str | Path) -> None:
    """Box plots of ISE and ISF and a histogram of J over the 003-U runs (``mc``: label -> row dicts)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    names = list(mc)
    n = len(mc[names[0]])
    for i, key, unit in ((0, "ise", "rad² s"), (1, "isf", "N² m² s")):
        ax[i].boxplot([[r[key] for r in mc[k] if r["status"] == "ok"] for k in names])
        ax[i].set_xticks(range(1, len(names) + 1), [_label(k) for k in names])
        ax[i].set_ylabel(f"{key.upper()} ({unit})")
        ax[i].set_title(f"003-U: {key.upper()} over {n} runs")
        ax[i].grid(True, alpha=0.3)
    for k in names:
        ax[2].hist([r["cost"] for r in mc[k] if r["status"] == "ok"], bins=20, alpha=0.6, label=_label(k))
    ax[2].set_xlabel("J = ISE + 1e4 ISF (-)")
    ax[2].set_ylabel("runs")
    ax[2].legend()
    ax[2].grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def prefixed(instance: str, params: dict) -> dict:
    """{"name": v} -> {"instance.name": v} (campaign override form)."""
    return {f"{instance}.{k}": v for k, v in params.items()}


# ----- registry ---------------------------------------------------------------------------------------
def build(name: str, **kw) -> Scenario:
    """``paper003/<SMC|T2FSMC>/<N|C|S|W|U>`` (keyword ``seed`` picks the 003-U inertia scaling)."""
    parts = name.split("/")
    if len(parts) != 3:
        raise KeyError(f"unknown scenario {name!r}: expected paper003/<SMC|T2FSMC>/<N|C|S|W|U>")
    return scenario(parts[1], parts[2], **kw)


def names() -> list[tuple[str, str]]:
    return [(f"paper003/{c}/{k}", f"paper 003 case 003-{k}, {CONTROLLERS[c][0]}") for c in CONTROLLERS for k in CASES]


def mc_draws(n: int) -> list[dict]:
    """The 003-U Monte Carlo as n override sets (draws 1 … n of :func:`uncertainty_scales`)."""
    return mc_overrides(range(1, n + 1))
