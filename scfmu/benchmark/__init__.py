"""The controller benchmark: a unit (an FMI 2.0 or 3.0 FMU, Co-Simulation or Model Exchange, or a model name)
runs through a family's standard scenarios beside the built-in controllers of that family, and one page
compares them; the unit's configuration on the page says which FMI version and interface it ran with.

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

import fnmatch
import math
import time
from pathlib import Path

import numpy as np

from .. import campaign
from ..registry import REGISTRY, resolve
from ..scenario import get
from ..scenario import profile as profiles
from ..scenario.check import IncompatibleUnit, require
from ..scenario.plan import PlanError, build_plan
from ..scenario.resolve import unbound_slots
from . import engineering, engineering_page
from . import estimator as estimator_runs
from . import mission as mission_runs
from .common import (COLUMNS, METRIC_UNITS, RESOLUTION, RESPONSE_RESOLUTION, SECTIONS, TITLES, UNIT,  # noqa: F401
                     WARNINGS, Entry, _check_error_growth, _slug, add_column, add_section, add_warning, equal,
                     error_series, identical_groups, metric_title, ranks, resolution)
from .page import _figure, _fmt, _signal_label, warnings, write_page  # noqa: F401


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
        cases: list[str] | None = None, client=None, log=print, profile=None, strict: bool = False,
        estimator: bool = False, mission: bool = False, mission_runs_n: int | None = None) -> list[Entry]:
    """Runs the benchmark and writes ``index.html``, ``benchmark.md``, ``results.csv`` and ``figures/``
    into ``out``; returns the entries. ``unit``: a path to an FMU or a model name (None: built-ins only);
    ``profile``: a :class:`scfmu.scenario.profile.Profile` (or a path to one) for the unit; ``strict``: raise
    :class:`StrictRefusal` before any run when a slot value would not reach the unit; ``estimator``: also run
    every pair on its scenario's ``sensing+estimation/`` variant (:mod:`.estimator`) and show the primary
    metric with the estimator in the loop in a column (about twice the runs); ``mission``: also run every
    controller in the family's mission scenario (:mod:`.mission`; ``mission_runs_n`` runs, default the case's
    number, its quick number with ``quick``) and add the mission section with its p95 times."""
    cases, ctrls, profile, unit_label = _select(unit, family, label, controllers, cases, profile)
    if family == "attitude":  # its stability margins need python-control (the campaigns extra): say so first
        engineering.require_margins()
    if unit is not None and strict:
        _refuse_unbound(cases, str(unit), unit_label, unit_params, port_map, profile)
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
    mcase = mission_runs.case_of(family) if mission else None
    if mission and mcase is None:
        raise KeyError(f"family {family!r} has no mission scenario")
    missions: tuple = ()
    try:
        for case in cases:
            sets, seeds = _case_overrides(case, quick)
            base = get(case.scenario)
            for name, model, b in ctrls:
                e = Entry(case.label, name, model)
                entries.append(e)
                job = _prepare(e, case, base, (sets, seeds), name, model, b, (unit_params, port_map, profile), out,
                               pairs, log)
                if job is not None:
                    jobs.append(job)
        for how in dict.fromkeys(e.config for e in entries if e.envelope == "unit" and not e.status):
            log(f"  {unit_label}: {how}")
        # the pairs' campaigns run side by side (threads sharing the Dask client), so that single-run pairs keep
        # every worker busy; each pair's rows and series are its own, so the results do not depend on the order
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=max(2, 2 * (workers or 1))) as pool:
            for job in [pool.submit(_run_pair, client, log, *j) for j in jobs]:
                job.result()
            if estimator:
                est_jobs = [x for j in jobs for x in [estimator_runs.prepare(j[0], j[1], pairs[(j[1].label, j[0].controller)],
                                                                        j[3], out)] if x is not None]
                for job in [pool.submit(estimator_runs.run_pair, client, log, *j) for j in est_jobs]:
                    job.result()
            if mcase is not None:
                n = mission_runs_n or (mcase.quick_runs if quick else mcase.runs)
                ms, mjobs = mission_runs.prepare(mcase, ctrls, (unit_params, port_map, profile), configured, out, n, log)
                for job in [pool.submit(mission_runs.run_pair, client, log, mcase, *j) for j in mjobs]:
                    job.result()
                mission_runs.write_csv(out, mcase, ms)
                missions = (mcase, ms)
        if family == "attitude":  # robustness Monte Carlo and stability margins (scfmu.benchmark.engineering)
            studies = engineering.studies(cases, pairs, entries, out, client, quick, log)
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    write_page(out, family, cases, entries, unit_label=unit_label, quick=quick, seconds=time.time() - t0,
               mission=missions)
    if family == "attitude":
        engineering_page.append_to_page(out, cases, entries, ranks(cases, entries), unit_label, studies)
    return entries


def selected_cases(family: str, only: list[str] | None = None) -> list:
    """The benchmark cases of ``family`` (those whose scenario name is in ``only`` or whose label contains an
    item of it); a KeyError when none is."""
    REGISTRY.load()
    cases = [c for c in REGISTRY.benchmark_cases if c.family == family
             and (only is None or any(x == c.scenario or x in c.label for x in only))]
    if not cases:
        raise KeyError(f"no benchmark scenario for family {family!r}{' matching ' + str(only) if only else ''}; "
                       f"families: {', '.join(REGISTRY.families())}")
    return cases


def _select(unit, family: str, label, controllers, only, profile):
    """(cases, [(label, model, BuiltinController or None)], profile, unit label) of a benchmark call."""
    cases = selected_cases(family, only)
    if isinstance(profile, (str, Path)):
        profile = profiles.load(profile)
    builtins = [b for b in REGISTRY.controllers if b.family == family
                and (controllers is None or b.model in controllers or b.label in controllers)]
    ctrls: list = [(b.label, b.model, b) for b in builtins]
    unit_label = (label or UNIT) if unit is not None else None
    if unit is not None:
        ctrls.append((unit_label, str(unit), None))
    return cases, ctrls, profile, unit_label


def _refuse_unbound(cases, unit: str, unit_label, unit_params, port_map, profile) -> None:
    """``strict``: raises :class:`StrictRefusal` when a slot value of any case would not reach the unit."""
    bad = []
    for case in cases:
        try:
            sc = unit_scenario(get(case.scenario), case, unit, unit_params, port_map, profile)
        except KeyError:
            continue  # reported as n/a by the run
        bad += [f"{case.label}: {u.text()}" for u in unbound_slots(sc, [case.slot])]
    if bad:
        raise StrictRefusal(f"--strict: {len(bad)} slot value(s) would not reach {unit_label}: {bad[0]}"
                            + (f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""))


def configured(base, case, e: Entry, model: str, b, unit_params, port_map, profile):
    """The scenario ``base`` with controller ``model`` in the case's slot, configured as the entry says (the
    unit's parameters, profile and --map; a built-in's envelope); fills ``e.envelope`` and ``e.config``.
    None when a built-in is outside its envelope (``e.status`` says why)."""
    if b is None:
        e.envelope, e.config = "unit", "the unit under test" + "".join(
            [f" with {', '.join(f'{k} = {v}' for k, v in unit_params.items())}" if unit_params else "",
             f", profile {Path(profile.path).name}" if profile is not None and profile.path else "",
             f", --map {', '.join(f'{k}={v}' for k, v in port_map.items())}" if port_map else ""])
        return unit_scenario(base, case, model, unit_params, port_map, profile)
    e.envelope, params, e.config = configure(b, case, base)
    if e.envelope == "outside":
        e.status = e.config
        return None
    sc = base.with_models({case.slot: model})
    sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in params.items()})
    sc.component(case.slot).unused = sorted(set(b.unused))
    return sc


def _prepare(e: Entry, case, base, draws: tuple, name: str, model: str, b, binding: tuple, out: Path, pairs: dict, log):
    """The job (entry, case, scenario, campaign, folder) of one pair, or None when it does not run (its entry's
    status says why). ``draws``: (override sets, seeds) of the case; ``binding``: the unit's (parameters,
    --map, profile)."""
    sets, seeds = draws
    unit_params, port_map, profile = binding
    try:
        sc = configured(base, case, e, model, b, unit_params, port_map, profile)
        if sc is None:
            log(f"  {case.label} / {name}: {e.status}")
            return None
        require(sc, instantiate=False)
    except (IncompatibleUnit, KeyError, profiles.ProfileError) as err:
        e.status = "n/a: " + str(err.args[0] if err.args else err).replace("\n", " ")[:400]
        log(f"  {case.label} / {name}: {e.status}")
        return None
    if b is None:  # how the unit under test runs: its FMI version and interface, on the page and in the log
        e.config += _runs_as(sc, case.slot)
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
    return e, case, sc, c, folder


def _runs_as(sc, slot: str) -> str:
    """", run as FMI 3.0 Model Exchange" (or 2.0, Co-Simulation): the interface the engines give the unit in
    ``slot`` (Co-Simulation when it offers it, Model Exchange when it offers only that or is asked to); "" when
    the plan cannot be made (the run then reports why)."""
    try:
        u = next(u for u in build_plan(sc).units if u.name == slot)
    except (PlanError, OSError, KeyError, StopIteration):
        return ""
    itf = "Model Exchange, integrated by the engine" if u.interface == "me" else "Co-Simulation"
    return f", run as FMI {u.fmi}.0 {itf}"


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


add_warning(engineering.saturation_warnings)  # time in actuator saturation (scfmu.benchmark.engineering)
add_section(mission_runs.section)  # scfmu benchmark --mission
