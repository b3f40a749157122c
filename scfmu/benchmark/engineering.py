"""What engineers compare on, beside every rank of the controller benchmark (attitude family): control
effort, time in actuator saturation, pointing errors (APE, MPE, RPE, PDE, jitter; definitions in
:mod:`scfmu.metrics`), an effort-vs-performance scatter per scenario, a robustness Monte Carlo
(:mod:`.robustness`) and the stability margins per axis (:mod:`.margins`).

Hooks used by :func:`scfmu.benchmark.run`: :func:`instrument` (extra logged signals and the time-series
keys), :func:`entry_metrics` (per controller and scenario, from the runs' time series), :func:`studies`
(Monte Carlo and margins, on the benchmark's Dask client); the page section is :mod:`.engineering_page`.

Pointing metrics are evaluated over the *pointing phase*, the last third of the run, with windows of a
quarter of it (both project choices, stated in seconds on the page), on the logged response (every
``ts_every``-th communication step, about 1500 points per run).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import campaign
from .. import metrics as M
from ..scenario.ssp import file_stem
from . import robustness

PLANT = "plant"
EXTRA_LOG = {**{f"eng_q_{c}": f"{PLANT}.q_{c}" for c in "wxyz"},
             **{f"eng_u_{a}": f"{PLANT}.torque_cmd_{a}" for a in "xyz"},
             **{f"eng_h_{a}": f"{PLANT}.h_wheel_{a}" for a in "xyz"}}
EVAL_FRACTION = 1 / 3
WINDOWS = 4
COLS = [("effort_abs", "effort ∫Σ|u| dt [N·m·s]"), ("sat_frac", "time in saturation [%]"),
        ("ape_deg", "APE [deg]"), ("mpe_deg", "MPE [deg]"), ("rpe_deg", "RPE [deg]"), ("pde_deg", "PDE [deg]"),
        ("jitter_deg", "jitter RMS [deg]")]
MC_COLS = ("primary", "effort_abs", "sat_frac", "ape_deg", "rpe_deg", "settling_s")
PRIMARY_NAMES = {"eulerint_deg_s": "EULERINT [deg·s]", "ise": "ISE [rad²·s]", "final_error": "final error [deg]",
                 "euler_end_max_deg": "largest final angle [deg]", "settling_s": "settling time [s]"}


def applies(sc) -> bool:
    try:
        c = sc.component(PLANT)
    except KeyError:
        return False
    return c.model == "AttitudePlant" and any(x.model == "AttitudeCommand" for x in sc.components)


def instrument(sc, signal: str):
    """(scenario with the extra logged signals, time-series keys) for a benchmark pair."""
    if not applies(sc):
        return sc, ([signal] if signal in sc.log else None)
    sc = sc.with_overrides({})
    cmd = next(x.name for x in sc.components if x.model == "AttitudeCommand")
    sc.log.update(EXTRA_LOG)
    sc.log.update({f"eng_qr_{c}": f"{cmd}.q_ref_{c}" for c in "wxyz"})
    keys = [k for k in dict.fromkeys([signal, *EXTRA_LOG, *(f"eng_qr_{c}" for c in "wxyz")]) if k in sc.log]
    return sc, keys


def limits(sc, t: np.ndarray) -> tuple[np.ndarray, float]:
    """(torque limit per sample and axis (n, 3) [N·m], wheel momentum limit [N·m·s] or inf)."""
    p = robustness.plant_values(sc, PLANT)
    eff = np.array([p.get(f"effectiveness_{a}", 1.0) for a in "xyz"])
    faulted = ((t >= p.get("fault_time", 0.0)) & (t < p.get("fault_clear_time", 1e30)))[:, None]
    if int(p.get("actuator_mode", 0)) == 1:
        base = np.full(3, p["wheel_torque_coeff"] * p["wheel_max_current"])
        hmax = p["wheel_inertia"] * p["wheel_max_speed"]
    else:
        base = np.array([p.get(f"u_max_{a}", 1e30) for a in "xyz"])
        hmax = math.inf
    return np.where(faulted, base * eff, base), hmax


def run_metrics(sc, r: dict) -> dict:
    """Saturation fraction and pointing errors of one run's time series ``r``."""
    t = np.asarray(r["time"], dtype=float)
    out = {}
    u = np.stack([r[f"eng_u_{a}"] for a in "xyz"], axis=1)
    lim, hmax = limits(sc, t)
    sat = np.any(np.abs(u) >= (1 - 1e-9) * lim, axis=1)
    if math.isfinite(hmax):
        h = np.stack([r[f"eng_h_{a}"] for a in "xyz"], axis=1)
        sat |= np.any(np.abs(h) >= hmax * (1 - 1e-9), axis=1)
    dt = np.diff(t)
    out["sat_frac"] = 100.0 * float(np.sum(dt[sat[:-1]]) / np.sum(dt)) if dt.size else math.nan
    q = np.stack([r[f"eng_q_{c}"] for c in "wxyz"], axis=1)
    qr = np.stack([r[f"eng_qr_{c}"] for c in "wxyz"], axis=1)
    e = M.error_rotation_deg(q, qr)
    t0, t1 = t[0] + (1 - EVAL_FRACTION) * (t[-1] - t[0]), t[-1]
    pe = M.pointing_errors(t, e, window=(t1 - t0) / WINDOWS, t_start=t0, t_end=t1)
    out.update({f"{k}_deg": v for k, v in pe.items()})
    return out


def eval_text(sc) -> str:
    T = sc.stop_time - sc.start_time
    return (f"pointing phase {sc.stop_time - EVAL_FRACTION * T:g}–{sc.stop_time:g} s, "
            f"RPE/PDE/jitter window {EVAL_FRACTION * T / WINDOWS:g} s")


SATURATION_WARNING = 25.0  # [%] of the run at an actuator limit that the page's warnings name (project choice)


def saturation_warnings(cases, entries, ctx) -> list[str]:
    """Warnings-block lines for the pairs whose actuators sit at their limit for more than
    :data:`SATURATION_WARNING` per cent of the run (mean over the runs)."""
    out = []
    for e in entries:
        v = e.means.get("sat_frac", math.nan)
        if math.isfinite(v) and v > SATURATION_WARNING:
            out.append(f"{e.case} / {e.controller}: actuators at their limit {v:.0f} % of the run "
                       f"(warned above {SATURATION_WARNING:g} %)")
    return out


def entry_metrics(e, sc, folder, good_rows) -> None:
    """Means over the runs that succeeded of the saturation fraction and pointing errors (into ``e.means``)."""
    if not applies(sc) or not good_rows:
        return
    vals = []
    for row in good_rows:
        try:
            vals.append(run_metrics(sc, campaign.read_timeseries(folder, row["run"])))
        except (OSError, KeyError):
            continue
    for k, _ in COLS:
        if k == "effort_abs":
            continue
        v = np.array([x.get(k, math.nan) for x in vals], dtype=float)
        e.means[k] = float(np.mean(v)) if v.size and np.all(np.isfinite(v)) else math.nan
    e.eval_text = eval_text(sc)


# ----- Monte Carlo and margins ----------------------------------------------------------------------------
def _signature(sc, with_units: bool) -> str:
    p = sc.component(PLANT).params
    keep = {k: v for k, v in sorted(p.items()) if not k.startswith(("dist_", "init_", "max_internal", "integrator",
                                                                        "kinematics"))}
    units = sorted(c.model for c in sc.components if c.name not in ("controller", "metrics")) if with_units else []
    return repr((keep, units))


def _faulted(sc) -> bool:
    p = sc.component(PLANT).params
    return any(k.startswith(("fault_", "effectiveness_")) for k in p)


def pick(cases, scenarios: dict, with_units: bool) -> list:
    """One nominal (not Monte Carlo, no actuator fault) case per distinct plant (and, for the margins, set
    of units in the loop). Among the cases of one plant: the first with the full (not the linear
    small-angle) kinematics, which uses the whole inertia matrix; for the Monte Carlo (``with_units``
    False) preferably one with disturbance torques, whose amplitude the dispersions scale."""
    chosen: dict = {}
    for case in cases:
        sc = scenarios.get(case.label)
        if sc is None or case.seeds or case.monte_carlo or not applies(sc) or _faulted(sc):
            continue
        p = sc.component(PLANT).params
        score = (int(p.get("kinematics", 0)) != 3,
                 (not with_units) and any(p.get(k) for k in robustness.DIST_PARAMS))
        sig = _signature(sc, with_units)
        if sig not in chosen or score > chosen[sig][0]:
            chosen[sig] = (score, case)
    return [c for _, c in chosen.values()]


MARGINS_EXTRA = "the stability margins need python-control: pip install 'scfmu[campaigns]'"


def require_margins() -> None:
    """python-control, which the margins need (the ``campaigns`` extra): a ModuleNotFoundError (``name``
    "control", the line naming the extra) before any run, never a "not linearised" row per controller."""
    try:
        import control  # noqa: F401
    except ImportError:
        raise ModuleNotFoundError(MARGINS_EXTRA, name="control") from None


def _margins_task(sc_dict: dict, fmu_dir: str | None):
    from .. import fmu as fmu_access
    from ..scenario.model import Scenario
    from .margins import loop_margins
    if fmu_dir:
        fmu_access.set_fmu_dir(fmu_dir)
    try:
        require_margins()  # a worker of a remote cluster without the extra: the row names it
    except ModuleNotFoundError as err:
        return f"{err} (on the Dask worker)"
    try:
        ms = loop_margins(Scenario.from_dict(sc_dict), horizon=20.0, n_freq=800, max_horizon=200.0)
        return [dict(axis=m.axis, gm_db=m.gm_db, gm_low_db=m.gm_low_db, pm_deg=m.pm_deg, wc=m.wc, wpc=m.wpc,
                     dm_s=m.dm_s, sample_time=m.sample_time, note=m.note, omega=m.omega, loop=m.loop) for m in ms]
    except Exception as err:  # a unit that cannot be linearised: reported, never a lost benchmark
        return f"{type(err).__name__}: {err}"[:300]


def studies(cases, pairs: dict, entries, out: Path, client, quick: bool, log=print) -> dict:
    """Runs the robustness Monte Carlo and the margins. ``pairs``: {(case label, controller): scenario}
    of the pairs that ran. Returns {"mc": {(case, controller): {metric: percentiles, "pass": fraction}},
    "margins": {(case, controller): [axis dicts] or "reason"}, "mc_cases": [...], "margin_cases": [...]}."""
    from .. import fmu as fmu_access
    import time
    t_start = time.perf_counter()
    res = {"mc": {}, "margins": {}, "mc_cases": [], "margin_cases": [], "mc_runs": 0}
    first = {}
    for (lab, _ctrl), sc in pairs.items():
        first.setdefault(lab, sc)
    n = robustness.QUICK_RUNS if quick else robustness.DEFAULT_RUNS
    res["mc_runs"] = n
    mc_cases = pick(cases, first, with_units=False)
    mg_cases = pick(cases, first, with_units=True)
    res["mc_cases"], res["margin_cases"] = [c.label for c in mc_cases], [c.label for c in mg_cases]
    # margins: one task per pair on the workers, submitted first so that they overlap the Monte Carlo
    fmu_dir = str(fmu_access.fmu_dir().resolve())
    futs = {}
    for case in mg_cases:
        for (lab, ctrl), sc in pairs.items():
            if lab == case.label and not any(fmu_access.is_path(c.model) for c in sc.components):
                futs[(lab, ctrl)] = client.submit(_margins_task, sc.to_dict(), fmu_dir, pure=False)
            elif lab == case.label:  # a foreign unit: in this process, where its file is
                futs[(lab, ctrl)] = None
    jobs = []
    for case in mc_cases:
        draws = robustness.dispersions(first[case.label], n, seed=0)
        jobs += [(case, lab, ctrl, sc, draws) for (lab, ctrl), sc in pairs.items() if lab == case.label]

    def one(job):
        case, lab, ctrl, sc, draws = job
        sc_i, keys = instrument(sc, case.signal)
        c = campaign.Campaign(sc_i, draws, [None], timeseries=keys, ts_every=max(1, sc_i.n_steps // 600))
        folder = out / "runs" / "robustness" / file_stem(case.scenario) / _slug(ctrl)
        table = campaign.run(c, folder, client=client, progress=False, overwrite=True)
        rows = sorted(table.to_pylist(), key=lambda r: r["run"])
        per = {k: [] for k in MC_COLS}
        passed = 0
        for r in rows:
            ok = r["status"] == "ok"
            passed += ok and math.isfinite(r.get("settling_s", math.nan))
            extra = {}
            if ok:
                try:
                    extra = run_metrics(sc_i, campaign.read_timeseries(folder, r["run"]))
                except (OSError, KeyError):
                    extra = {}
            for k in MC_COLS:
                src = case.primary if k == "primary" else k
                per[k].append(extra.get(src, r.get(src, math.nan)) if ok else math.nan)
        return (lab, ctrl), {**{k: robustness.percentiles(v) for k, v in per.items()},
                             "pass": passed / len(rows) if rows else math.nan, "runs": len(rows),
                             "primary_name": case.primary}

    # every Monte Carlo campaign at once (threads only wait on the Dask workers): the workers stay busy
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=max(1, min(8, len(jobs)))) as pool:
        for key, v in pool.map(one, jobs):  # results in the order of the jobs (deterministic page)
            res["mc"][key] = v
            log(f"  robustness {key[0]} / {key[1]}: {round(v['pass'] * v['runs'])}/{v['runs']} pass")
    res["seconds_mc"] = time.perf_counter() - t_start
    for key, fut in futs.items():
        if fut is None:
            res["margins"][key] = _margins_task(pairs[key].to_dict(), None)
        else:
            try:
                res["margins"][key] = fut.result()
            except Exception as err:
                res["margins"][key] = f"{type(err).__name__}: {err}"[:300]
        if isinstance(res["margins"][key], str):
            log(f"  margins {key[0]} / {key[1]}: {res['margins'][key]}")
    res["seconds"] = time.perf_counter() - t_start
    return res


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)[:80]
