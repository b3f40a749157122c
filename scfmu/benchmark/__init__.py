"""The controller benchmark: a unit (any FMI 2.0 Co-Simulation FMU, or a model name) runs through a family's
standard scenarios beside the built-in controllers of that family, and one page compares them.

The scenarios (``BenchmarkCase``) and the built-in controllers (``BuiltinController``) come from the
plug-ins' registrations (:mod:`scfmu.registry`); this module names no paper. Every (scenario, controller)
pair is one campaign on the campaign engine: the controller takes the scenario's ``slot`` (the model is
swapped, the old model's parameters are dropped, the slot's values such as the nominal inertia stay), a
Monte Carlo case runs one campaign row per draw. A pair whose unit does not fit (pre-flight check) is
reported as "n/a" with the reason; a run that fails is a failed row, never a lost benchmark.

What makes the comparison one to trust:

* **Binding.** The slot values of the place reach the unit under its own parameter names (a unit profile,
  ``--map controller.J1=inertia_xx``); a value no parameter receives is named next to the unit's results
  and at the top of the page (:func:`scfmu.scenario.resolve.unbound_slots`); ``strict`` refuses to run.
* **Design envelopes.** Each built-in controller runs with its paper's tuning on its paper's scenarios, with
  its plug-in's stated re-tuning rule elsewhere, or is listed as "not designed for this plant" with the
  reason (:func:`configure`); a run whose error ends above its initial error is flagged.
* **Ties.** Metrics are compared with a stated resolution (:data:`RESOLUTION`): equal values share a rank
  (competition ranking 1, 2, 2, 4) and controllers with identical responses are grouped.

The page (``index.html``, ``benchmark.md``, ``results.csv``, ``figures/``) is built from parts that other
modules can extend by a call: :func:`add_column` (a metric column), :func:`add_section` (a section per
scenario or for the whole page) and :func:`add_warning` (lines of the warnings block).
"""

from __future__ import annotations

import csv
import fnmatch
import html
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import campaign
from ..registry import REGISTRY, resolve
from ..scenario import get
from ..scenario import profile as profiles
from ..scenario.check import IncompatibleUnit, require
from ..scenario.resolve import unbound_slots
from . import engineering

UNIT = "unit under test"

# Units of measure of the metrics per family (the metric sets' definitions in scfmu.metrics)
_ATT = {"eulerint_deg_s": "deg·s", "ise": "rad²·s", "isf": "N²·m²·s", "settling_s": "s", "effort_abs": "N·m·s",
        "final_error": "deg", "mae_deg": "deg", "euler_end_max_deg": "deg"}
METRIC_UNITS = {"attitude": _ATT,
                "single_axis": dict(_ATT, ise="rad²·s", isf="N²·m²·s"),
                "formation": {"ise": "m²·s", "isf": "N²·s", "settling_s": "s", "effort_abs": "N·s", "final_error": "m"}}
TITLES = {"eulerint_deg_s": "EULERINT", "ise": "ISE", "isf": "ISF", "settling_s": "settling time",
          "effort_abs": "effort ∫Σ abs(u) dt", "final_error": "final error", "mae_deg": "MAE",
          "euler_end_max_deg": "largest final angle"}
COLUMNS = [("eulerint_deg_s", "EULERINT"), ("ise", "ISE"), ("isf", "ISF"), ("settling_s", "settling time"),
           ("effort_abs", "effort ∫Σ abs(u) dt"), ("final_error", "final error")]

# Resolution of the comparisons: two values a, b of a metric are equal when
#   |a − b| ≤ rel · max(|a|, |b|) + abs      (abs in the metric's unit)
# (project choice: 1e-6 relative is far above the round-off differences of equivalent laws, ~1e-14, and far
# below any difference an engineer would act on; abs keeps values that are zero to round-off equal).
RESOLUTION = {"default": (1e-6, 1e-9)}
# responses are identical when max |Δ signal| over the logged samples ≤ rel · max |signal| + abs
RESPONSE_RESOLUTION = (1e-6, 1e-9)


def resolution(metric: str) -> tuple[float, float]:
    return RESOLUTION.get(metric, RESOLUTION["default"])


def equal(a: float, b: float, metric: str = "default") -> bool:
    rel, ab = resolution(metric)
    return abs(a - b) <= rel * max(abs(a), abs(b)) + ab


def metric_title(key: str, family: str) -> str:
    unit = METRIC_UNITS.get(family, {}).get(key) or ("deg" if key.endswith("_deg") else "s" if key.endswith("_s") else "")
    name = TITLES.get(key) or next((t for k, t in COLUMNS if k == key), key)
    return f"{name} [{unit}]" if unit else f"{name} [–]"


# ----- extension points ------------------------------------------------------------------------------------
SECTIONS: list = []  # fn(out, case or None, entries, ctx) -> (markdown lines, html text); case None: page-level
WARNINGS: list = []  # fn(cases, entries, ctx) -> [warning text]


def add_column(key: str, title: str, unit: str = "", family: str | None = None) -> None:
    """A metric column (a key of the campaign rows, e.g. one a metric set computes): shown with its unit,
    averaged over the runs, in the CSV."""
    if key not in [k for k, _ in COLUMNS]:
        COLUMNS.append((key, title))
    TITLES[key] = title
    for fam in ([family] if family else list(METRIC_UNITS)):
        if unit:
            METRIC_UNITS.setdefault(fam, {})[key] = unit


def add_section(fn) -> None:
    """``fn(out, case, entries, ctx) -> (markdown lines, html)``: called once per scenario (below its table)
    and once with ``case=None`` (after the scenarios); ``ctx`` has ``family``, ``unit_label``, ``quick``."""
    SECTIONS.append(fn)


def add_warning(fn) -> None:
    """``fn(cases, entries, ctx) -> [text]``: lines of the warnings block at the top of the page."""
    WARNINGS.append(fn)


@dataclass
class Entry:
    case: str
    controller: str
    model: str
    runs: int = 0
    ok: int = 0
    settled: int = 0
    means: dict = field(default_factory=dict)
    status: str = ""  # "" (ran), "n/a: reason", or "not designed for this plant: reason"
    series: dict | None = None  # {"time": ..., signal: ...} of the first run
    failures: list = field(default_factory=list)
    config: str = ""  # how the controller is configured on this scenario (paper's tuning, rule, your unit)
    envelope: str = ""  # "home" (its paper's tuning), "retuned", "outside", "unit"
    unbound: list = field(default_factory=list)  # slot values the unit does not receive (texts)
    unbound_items: list = field(default_factory=list)  # the same as scfmu.scenario.resolve.Unbound
    flags: list = field(default_factory=list)  # e.g. "error grew: …"
    rows: list = field(default_factory=list)  # the campaign rows of the runs that succeeded
    error0: float = math.nan  # main error at the start and at the end of the first run [deg] (if logged)
    error_end: float = math.nan

    @property
    def passed(self) -> bool:
        return not self.status and self.runs > 0 and self.ok == self.runs and self.settled == self.runs


# ----- design envelopes --------------------------------------------------------------------------------------
def _home(b, case) -> bool:
    if b.home:
        return any(fnmatch.fnmatchcase(case.scenario, p) for p in b.home)
    return b.plugin == case.plugin


def configure(b, case, scenario) -> tuple[str, dict, str]:
    """(envelope, parameters, sentence) of built-in controller ``b`` on benchmark case ``case``:
    ("home", its registered parameters, "its paper's tuning"), ("retuned", parameters from its rule, the
    rule), or ("outside", {}, the reason it is not designed for this plant)."""
    if _home(b, case):
        return "home", dict(b.params), "its paper's tuning on its paper's plant"
    if b.retune:
        slot = dict(scenario.component(case.slot).slot)
        try:
            extra, text = resolve(b.retune)(slot, scenario)
        except ValueError as e:
            return "outside", {}, f"not designed for this plant: {e}"
        return "retuned", {**b.params, **extra}, "re-tuned: " + text
    return "outside", {}, ("not designed for this plant: " + (b.outside or "its paper's tuning is for another "
                                                                 "plant and it declares no re-tuning rule"))


# ----- running ------------------------------------------------------------------------------------------------
def _case_overrides(case, quick: bool) -> tuple[list[dict], list]:
    """(override sets, seeds) of a case: one run, or a Monte Carlo (quick: 10 draws instead of the
    registered number; the set-up is the same)."""
    n = case.seeds if not quick else min(case.seeds, 10)
    base = dict(case.overrides)
    if n and case.monte_carlo:
        return [dict(base, **o) for o in resolve(case.monte_carlo)(n)], [None]
    if n:
        return [base], list(range(n))
    return [base], [None]


class StrictRefusal(ValueError):
    """``strict``: a slot value would not reach the unit under test (the message names it)."""


def unit_scenario(base, case, unit: str, unit_params: dict | None = None, port_map: dict | None = None,
                  profile=None):
    """The scenario ``base`` with the unit under test in the case's slot: its parameters, profile and --map."""
    sc = base.with_models({case.slot: unit})
    if profile is not None:
        sc = profiles.apply(sc, case.slot, profile)
    sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in (unit_params or {}).items()})
    if port_map:
        sc = sc.with_port_map({f"{case.slot}.{k}": v for k, v in port_map.items()})
    return sc


def run(unit: str | None, family: str, out: str | Path, label: str | None = None, unit_params: dict | None = None,
        port_map: dict | None = None, quick: bool = False, workers: int = 2, controllers: list[str] | None = None,
        cases: list[str] | None = None, client=None, log=print, profile=None, strict: bool = False) -> list[Entry]:
    """Runs the benchmark and writes ``index.html``, ``benchmark.md``, ``results.csv`` and ``figures/``
    into ``out``; returns the entries. ``unit``: a path to an FMU or a model name (None: built-ins only);
    ``profile``: a :class:`scfmu.scenario.profile.Profile` (or a path to one) for the unit; ``strict``: raise
    :class:`StrictRefusal` before any run when a slot value would not reach the unit."""
    REGISTRY.load()
    only = cases
    cases = [c for c in REGISTRY.benchmark_cases if c.family == family
             and (only is None or any(x == c.scenario or x in c.label for x in only))]
    if not cases:
        raise KeyError(f"no benchmark scenario for family {family!r}{' matching ' + str(only) if only else ''}; "
                       f"families: {', '.join(REGISTRY.families())}")
    if isinstance(profile, (str, Path)):
        profile = profiles.load(profile)
    builtins = [b for b in REGISTRY.controllers if b.family == family
                and (controllers is None or b.model in controllers or b.label in controllers)]
    ctrls: list = [(b.label, b.model, b) for b in builtins]
    unit_label = (label or UNIT) if unit is not None else None
    if unit is not None:
        ctrls.append((unit_label, str(unit), None))
        if strict:
            bad = []
            for case in cases:
                try:
                    sc = unit_scenario(get(case.scenario), case, str(unit), unit_params, port_map, profile)
                except KeyError:
                    continue  # reported as n/a by the run
                bad += [f"{case.label}: {u.text()}" for u in unbound_slots(sc, [case.slot])]
            if bad:
                raise StrictRefusal(f"--strict: {len(bad)} slot value(s) would not reach {unit_label}: {bad[0]}"
                                    + (f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""))
    out = Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    own = client is None
    cluster = None
    if own:
        client, cluster = campaign._client(None, workers)
    entries: list[Entry] = []
    jobs: list = []  # (entry, case, scenario, campaign, folder) of the pairs that run
    pairs: dict = {}  # (case, controller) -> scenario, for the Monte Carlo and the margins
    t0 = time.time()
    studies = None
    try:
        for case in cases:
            sets, seeds = _case_overrides(case, quick)
            base = get(case.scenario)
            for name, model, b in ctrls:
                e = Entry(case.label, name, model)
                entries.append(e)
                try:
                    if b is None:
                        e.envelope, e.config = "unit", "the unit under test" + "".join(
                            [f" with {', '.join(f'{k} = {v}' for k, v in unit_params.items())}" if unit_params else "",
                             f", profile {Path(profile.path).name}" if profile is not None and profile.path else "",
                             f", --map {', '.join(f'{k}={v}' for k, v in port_map.items())}" if port_map else ""])
                        sc = unit_scenario(base, case, model, unit_params, port_map, profile)
                    else:
                        e.envelope, params, e.config = configure(b, case, base)
                        if e.envelope == "outside":
                            e.status = e.config
                            log(f"  {case.label} / {name}: {e.status}")
                            continue
                        sc = base.with_models({case.slot: model})
                        sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in params.items()})
                        sc.component(case.slot).unused = sorted(set(b.unused))
                    require(sc, instantiate=False)
                except (IncompatibleUnit, KeyError, profiles.ProfileError) as err:
                    e.status = "n/a: " + str(err.args[0] if err.args else err).replace("\n", " ")[:400]
                    log(f"  {case.label} / {name}: {e.status}")
                    continue
                e.unbound_items = unbound_slots(sc, [case.slot])
                e.unbound = [u.text() for u in e.unbound_items]
                for u in e.unbound:
                    log(f"  warning: {case.label} / {name}: {u}")
                keys = [case.signal] + [k for k in ("alpha_deg", "roll", "pitch", "yaw", "roll_ref", "pitch_ref",
                                                    "yaw_ref", "theta", "theta_ref") if k in sc.log and k != case.signal]
                every = max(1, sc.n_steps // 1500)
                pairs[(case.label, name)] = sc
                sc, ts_keys = engineering.instrument(sc, case.signal)  # effort, saturation, pointing signals
                ts = list(dict.fromkeys([k for k in keys if k in sc.log] + (ts_keys or [])))
                c = campaign.Campaign(sc, sets, seeds, timeseries=ts or None, ts_every=every)
                folder = out / "runs" / _slug(case.label) / _slug(name)  # one folder per case (two cases may share a scenario)
                jobs.append((e, case, sc, c, folder))
        # the pairs' campaigns run side by side (threads sharing the Dask client), so that single-run pairs keep
        # every worker busy; each pair's rows and series are its own, so the results do not depend on the order
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=max(2, 2 * (workers or 1))) as pool:
            for job in [pool.submit(_run_pair, client, log, *j) for j in jobs]:
                job.result()
        if family == "attitude":  # robustness Monte Carlo and stability margins (scfmu.benchmark.engineering)
            studies = engineering.studies(cases, pairs, entries, out, client, quick, log)
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    write_page(out, family, cases, entries, unit_label=unit_label, quick=quick, seconds=time.time() - t0)
    if family == "attitude":
        engineering.append_to_page(out, cases, entries, ranks(cases, entries), unit_label, studies)
    return entries


def _run_pair(client, log, e: Entry, case, sc, c, folder: Path) -> None:
    """Runs one (scenario, controller) pair's campaign and fills its entry (means, series, flags)."""
    table = campaign.run(c, folder, client=client, progress=False, overwrite=True)
    rows = sorted(table.to_pylist(), key=lambda r: r["run"])
    e.runs = len(rows)
    good = [r for r in rows if r["status"] == "ok"]
    e.rows = good
    e.ok = len(good)
    e.settled = sum(1 for r in good if math.isfinite(r.get("settling_s", math.nan)))
    e.failures = [f"run {r['run']}: {r['status']}: {r['message'][:160]}" for r in rows if r["status"] != "ok"]
    for k in dict.fromkeys([k for k, _ in COLUMNS] + [case.primary]):
        v = np.array([r.get(k, math.nan) for r in good], dtype=float)
        e.means[k] = float(np.mean(v)) if v.size and np.all(np.isfinite(v)) else math.nan
    engineering.entry_metrics(e, sc, folder, good)
    if c.timeseries and good:
        try:
            e.series = campaign.read_timeseries(folder, good[0]["run"])
        except OSError:
            e.series = None
    _check_error_growth(e)
    log(f"  {case.label} / {e.controller}: {e.ok}/{e.runs} ok, {case.primary} = {e.means.get(case.primary, math.nan):.6g}"
        + (f"; {e.config}" if e.envelope == "retuned" else ""))


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)[:80]


def error_series(series: dict | None):
    """The main error [deg] over a logged run: α, else the largest 321-angle (or θ) error from its
    reference (0 where no reference is logged); None when neither is logged."""
    if not series:
        return None
    if "alpha_deg" in series:
        return np.abs(np.asarray(series["alpha_deg"], dtype=float))
    ang = [a for a in ("roll", "pitch", "yaw") if a in series] or (["theta"] if "theta" in series else [])
    if not ang:
        return None
    errs = []
    for a in ang:
        d = np.asarray(series[a], dtype=float) - np.asarray(series.get(f"{a}_ref", 0.0), dtype=float)
        errs.append(np.degrees(np.abs((d + np.pi) % (2 * np.pi) - np.pi)))
    return np.max(np.vstack(errs), axis=0)


def _check_error_growth(e: Entry) -> None:
    err = error_series(e.series)
    if err is None or err.size < 2:
        return
    e.error0, e.error_end = float(err[0]), float(err[-1])
    if e.error_end > e.error0 + 1e-9:
        e.flags.append(f"error grew: {e.error0:.3g} deg at the start, {e.error_end:.3g} deg at the end")


# ----- comparisons ------------------------------------------------------------------------------------------
def ranks(cases, entries: list[Entry]) -> dict:
    """{case label: {controller: rank}} by the case's primary metric (lower is better) among the passing;
    values equal within the metric's resolution share a rank (competition ranking: 1, 2, 2, 4)."""
    out = {}
    for case in cases:
        es = [e for e in entries if e.case == case.label and e.passed and math.isfinite(e.means.get(case.primary, math.nan))]
        vals = [e.means[case.primary] for e in es]
        out[case.label] = {e.controller: 1 + sum(1 for v in vals if v < e.means[case.primary]
                                                 and not equal(v, e.means[case.primary], case.primary))
                           for e in es}
    return out


def identical_groups(case, entries: list[Entry]) -> list[list[str]]:
    """Groups (2 or more) of controllers on ``case`` whose responses are identical: the case's plotted signal
    and the main error (α, or the largest angle error) of the first run differ by at most
    :data:`RESPONSE_RESOLUTION` at every logged sample, and the primary metric is equal within its resolution."""
    es = [e for e in entries if e.case == case.label and e.series and case.signal in e.series]
    rel, ab = RESPONSE_RESOLUTION

    def same(a, b) -> bool:
        if a is None or b is None:
            return a is None and b is None
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        return a.shape == b.shape and bool(np.all(np.isfinite(a)) and np.all(np.isfinite(b))) and \
            float(np.max(np.abs(a - b))) <= rel * float(max(np.max(np.abs(a)), np.max(np.abs(b)))) + ab

    groups: list[list[Entry]] = []
    for e in es:
        for g in groups:
            r = g[0]
            if same(r.series[case.signal], e.series[case.signal]) and same(error_series(r.series), error_series(e.series)) \
                    and equal(r.means.get(case.primary, math.nan), e.means.get(case.primary, math.nan), case.primary):
                g.append(e)
                break
        else:
            groups.append([e])
    return [[x.controller for x in g] for g in groups if len(g) > 1]


# ----- the page ------------------------------------------------------------------------------------------------
def _fmt(v) -> str:
    if isinstance(v, float):
        return "–" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def _signal_label(signal: str) -> str:
    if signal in ("roll", "pitch", "yaw", "theta"):
        return f"{signal} [deg]"
    if signal.endswith("_deg"):
        return f"{signal[:-4]} [deg]"
    if signal.startswith("pos"):
        return f"{signal} [m]"
    return f"{signal} [–]"


def _figure(out: Path, case, entries: list[Entry], unit_label) -> str | None:
    es = [e for e in entries if e.case == case.label and e.series and case.signal in e.series]
    if not es:
        return None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 3.8))
    groups = {g[0]: g for g in identical_groups(case, entries)}  # identical responses: one line, one label
    hidden = {x for g in groups.values() for x in g[1:]}
    for e in es:
        if e.controller in hidden and e.controller != unit_label:
            continue
        y = np.asarray(e.series[case.signal], dtype=float)
        if case.signal in ("roll", "pitch", "yaw", "theta"):
            y = np.degrees(y)
        ax.plot(e.series["time"], y, lw=2.2 if e.controller == unit_label else 1.0,
                ls="-" if e.controller == unit_label else "--",
                label=(" = ".join(groups[e.controller]) if e.controller in groups else e.controller)
                + (" (re-tuned)" if e.envelope == "retuned" else ""))
    ax.set_xlabel("time [s]")
    ax.set_ylabel(_signal_label(case.signal))
    who = f"{unit_label} vs the built-in controllers" if unit_label else "built-in controllers"
    ax.set_title(f"{case.label}\n{who}", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    name = f"figures/{_slug(case.label)}.png"
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    return name


def warnings(cases, entries: list[Entry], unit_label, ctx: dict) -> list[str]:
    """The lines of the warnings block: unbound slot values, built-ins out of their envelope (not designed
    for the plant, re-tuned), runs whose error grew, identical responses (ties), and the registered extras."""
    out = []
    # unbound slot values: one line per (controller, slot value) over the scenarios (the full sentence of
    # each scenario is next to the controller's results there)
    per: dict = {}
    for e in entries:
        for u in e.unbound_items:
            per.setdefault((e.controller, u.slot), []).append((e.case, u))
    n_cases = len(cases)
    for (ctrl, slot), items in per.items():
        u0 = items[0][1]
        vals = ", ".join(dict.fromkeys(f"{u.value:g}" if isinstance(u.value, float) else str(u.value) for _, u in items))
        kept = (f"the unit kept its own {', '.join(f'{n} = {st}' for n, st, _ in u0.kept)}; bind it: a profile line "
                f"{u0.kept[0][0]} = \"{slot}\" or --map {u0.instance}.{u0.kept[0][0]}={slot}" if u0.kept else
                f"the unit has no parameter {slot!r} and no binding reads it; bind it with a profile or --map, or "
                f"declare it unused in the profile")
        out.append(f"{ctrl}: slot value {slot} ({vals}) not passed in {len(items)} of {n_cases} scenarios: {kept}")
    for e in entries:
        if e.envelope == "outside":
            out.append(f"{e.case} / {e.controller}: {e.status} (not run)")
    retuned = sorted({e.controller for e in entries if e.envelope == "retuned"})
    if retuned:
        out.append("outside their papers' scenarios these built-in controllers run re-tuned by a stated rule "
                   f"(see 'configuration' under each table): {', '.join(retuned)}")
    for e in entries:
        for f in e.flags:
            out.append(f"{e.case} / {e.controller}: {f}")
    ties: dict = {}
    for case in cases:
        for g in identical_groups(case, entries):
            ties.setdefault(tuple(g), []).append(case.label)
    for g, labels in ties.items():
        out.append(f"{' = '.join(g)}: identical responses (tied) on {len(labels)} of {n_cases} scenarios: "
                   + "; ".join(labels))
    for fn in WARNINGS:
        out += list(fn(cases, entries, ctx) or [])
    return out


def write_page(out: Path, family: str, cases, entries: list[Entry], unit_label, quick: bool, seconds: float) -> None:
    rk = ranks(cases, entries)
    ctx = {"family": family, "unit_label": unit_label, "quick": quick, "ranks": rk}
    prim = {c.label: c.primary for c in cases}
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.writer(f)
        # units in the header: "ise [rad²·s]"; the primary value is in the unit of its metric's column
        units = METRIC_UNITS.get(family, {})
        w.writerow(["scenario", "controller", "model", "runs", "ok", "settled", "pass", "rank", "primary metric",
                    "primary value", *[f"{k} [{units.get(k, '–')}]" for k, _ in COLUMNS], "envelope", "configuration",
                    "unbound slot values", "flags", "error_start [deg]", "error_end [deg]", "status"])
        for e in entries:
            w.writerow([e.case, e.controller, e.model, e.runs, e.ok, e.settled, e.passed, rk.get(e.case, {}).get(e.controller, ""),
                        prim[e.case], e.means.get(prim[e.case], math.nan), *[e.means.get(k, math.nan) for k, _ in COLUMNS],
                        e.envelope, e.config, "; ".join(e.unbound), "; ".join(e.flags), e.error0, e.error_end, e.status])
    who = f"{unit_label} beside the built-in controllers" if unit_label else "the built-in controllers"
    title = f"Controller benchmark ({family}): {who}"
    md = [f"# {title}", ""]
    h = [f"<h1>{html.escape(title)}</h1>"]
    rel, ab = RESOLUTION["default"]
    intro = (f"{len(cases)} scenarios × {len({e.controller for e in entries})} controllers"
             f"{' (quick: Monte Carlo cases with 10 draws)' if quick else ''}; {seconds:.0f} s. Values are means over "
             f"the runs of a scenario that succeeded. Pass: every run succeeded and settled (2 % band) before its end. "
             f"Rank: by the scenario's primary metric (lower is better) among the controllers that pass; values "
             f"equal within the resolution |a − b| ≤ {rel:g}·max(|a|, |b|) + {ab:g} (in the metric's unit) share a "
             f"rank (1, 2, 2, 4). Responses are identical when the plotted signal and the main error differ by at most "
             f"{RESPONSE_RESOLUTION[0]:g} of their largest value (+ {RESPONSE_RESOLUTION[1]:g}) at every logged sample "
             f"of the first run and the primary metric is equal. "
             f"Built-in controllers run with their paper's tuning on their paper's scenarios and re-tuned by a "
             f"stated rule elsewhere (the 'configuration' lines), or are listed as not designed for the plant.")
    md += [intro, ""]
    h.append(f"<p>{html.escape(intro)}</p>")
    warn = warnings(cases, entries, unit_label, ctx)
    md += ["## Warnings", ""] + ([f"- {x}" for x in warn] if warn else ["None."]) + [""]
    h.append("<h2>Warnings</h2>" + ("<ul>" + "".join(f"<li>{html.escape(x)}</li>" for x in warn) + "</ul>"
                                    if warn else "<p>None.</p>"))
    if unit_label:
        summ = [f"{case.label}: " + (f"rank {rk[case.label][unit_label]} of {len(rk[case.label])}"
                                     if unit_label in rk.get(case.label, {}) else "not ranked (did not pass or n/a)")
                for case in cases]
        md += [f"**{unit_label}**: " + "; ".join(summ), ""]
        h.append(f"<p><b>{html.escape(unit_label)}</b>: " + "; ".join(html.escape(x) for x in summ) + "</p>")
    for case in cases:
        heading = f"{case.label}: {unit_label}" if unit_label else case.label
        desc = (f"Scenario `{case.scenario}`" + (f" with {case.overrides}" if case.overrides else "")
                + (f", Monte Carlo of {case.seeds} runs" if case.seeds else "") + f"; primary metric `{case.primary}` "
                f"({metric_title(case.primary, family)}).")
        md += [f"## {heading}", "", desc, ""]
        h.append(f"<h2>{html.escape(heading)}</h2><p>{html.escape(desc).replace('`', '')}</p>")
        keys = [k for k in dict.fromkeys([case.primary, *(k for k, _ in COLUMNS)])
                if any(math.isfinite(e.means.get(k, math.nan)) for e in entries if e.case == case.label)]
        head = ["controller", "runs ok", "pass", "rank", *[metric_title(k, family) for k in keys]]
        md += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        h.append("<table border=1 cellspacing=0 cellpadding=3><tr>" + "".join(f"<th>{html.escape(x)}</th>" for x in head) + "</tr>")
        for e in [x for x in entries if x.case == case.label]:
            if e.status:
                cells = [e.controller, "–", "n/a", "–", e.status] + [""] * max(0, len(keys) - 1)
            else:
                mark = " ⚠" if (e.unbound or e.flags) else ""
                cells = [e.controller + mark, f"{e.ok}/{e.runs}", "pass" if e.passed else "fail",
                         str(rk[case.label].get(e.controller, "–")), *[_fmt(e.means.get(k, math.nan)) for k in keys]]
            name = f"**{cells[0]}**" if e.controller == unit_label else cells[0]
            md.append("| " + " | ".join(x.replace("|", "/").replace("\n", " ") for x in [name, *cells[1:]]) + " |")
            style = " style='font-weight:bold'" if e.controller == unit_label else ""
            h.append(f"<tr{style}>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in cells) + "</tr>")
        h.append("</table>")
        notes = []
        for g in identical_groups(case, entries):
            notes.append(f"{' = '.join(g)}: identical responses")
        for e in [x for x in entries if x.case == case.label]:
            for u in e.unbound:
                notes.append(f"⚠ {e.controller}: {u}")
            for f_ in e.flags:
                notes.append(f"⚠ {e.controller}: {f_}")
        conf = [f"{e.controller}: {e.config}" for e in entries if e.case == case.label and e.config and not e.status]
        if notes:
            md += [""] + [f"- {x}" for x in notes]
            h.append("<ul>" + "".join(f"<li>{html.escape(x)}</li>" for x in notes) + "</ul>")
        if conf:
            md += ["", "Configuration: " + "; ".join(conf) + "."]
            h.append("<p><i>Configuration:</i> " + "; ".join(html.escape(x) for x in conf) + ".</p>")
        fails = [f"{e.controller}: {x}" for e in entries if e.case == case.label for x in e.failures[:3]]
        if fails:
            md += ["", "Failed runs: " + "; ".join(fails)]
            h.append("<p>Failed runs: " + "; ".join(html.escape(x) for x in fails) + "</p>")
        fig = _figure(out, case, entries, unit_label)
        if fig:
            md += ["", f"![{case.label}]({fig})"]
            h.append(f"<p><img src='{fig}' alt='{html.escape(case.label)}' style='max-width:100%'></p>")
        for fn in SECTIONS:
            m, x = fn(out, case, entries, ctx)
            md += list(m or [])
            h.append(x or "")
        md.append("")
    for fn in SECTIONS:
        m, x = fn(out, None, entries, ctx)
        md += list(m or [])
        h.append(x or "")
    (out / "benchmark.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    (out / "index.html").write_text(f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
                                    "</title></head><body>" + "\n".join(h) + "</body></html>\n", encoding="utf-8")


add_warning(engineering.saturation_warnings)  # time in actuator saturation (scfmu.benchmark.engineering)
