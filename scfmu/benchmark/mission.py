"""The benchmark's mission column (``scfmu benchmark --mission``): each controller (the built-ins of the family
and the unit under test) takes the FINE_POINTING place of the family's mission scenario (registered by a
plug-in with ``reg.mission``, e.g. ``mission/tipoff``: separation, detumble, sun acquisition, determination,
then the controller under test on the estimator's output) in N dispersed runs, and the page gives per
controller the p95 time from separation to on target, its median, the p95 time to the mode manager's
hand-over, the runs that never got on target and the runs whose mode chattered.

* **The same runs for every controller**: the draws are the scenario's registered dispersions and one draw of
  each seed parameter per run, from one generator seeded 0, so controller A's run k and controller B's run k
  start from the same tip-off, inertia, attitude and sensor noise.
* **p95 over every run**: a run that never got on target (or failed) counts as not reached, so the p95 is "not
  reached" as soon as more than 5 % of the runs never get there; it is the order statistic of the runs
  (``inverted_cdf``: no interpolation between runs).
* **Design envelopes**: the built-in controller the mission scenario was tuned with runs with that tuning; the
  others run as elsewhere in the benchmark (their re-tuning rule for this spacecraft, or listed as not designed
  for it); the unit under test runs with its ``--set``, ``--map`` and profile.
* **Ranks**: by the p95 time, then (equal p95 times, "not reached" included) by the number of runs never on
  target; two p95 times within :data:`TIE_S` (the mode manager's sample period) are equal.
"""

from __future__ import annotations

import csv
import html
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import campaign
from ..campaign.cli import dispersed_sets
from ..registry import REGISTRY
from ..scenario import get
from ..scenario import profile as profiles
from ..scenario.check import IncompatibleUnit, require
from ..scenario.resolve import unbound_slots
from .common import _slug

TIE_S = 1.0  # p95 times closer than this [s] are equal (the ModeManager samples once a second)
CSV = "mission.csv"


@dataclass
class MissionEntry:
    """One controller's mission runs: ``values``/``handover`` hold each run's time [s] (inf: not reached)."""
    controller: str
    model: str
    envelope: str = ""
    config: str = ""
    status: str = ""  # "" (ran), "n/a: reason", "not designed for this plant: reason"
    runs: int = 0
    ok: int = 0
    values: list = field(default_factory=list)
    handover: list = field(default_factory=list)
    chatter_runs: int = 0
    failures: list = field(default_factory=list)
    unbound: list = field(default_factory=list)

    def p(self, q: float, which: str = "values") -> float:
        v = np.asarray(getattr(self, which), dtype=float)
        return float(np.percentile(v, q, method="inverted_cdf")) if v.size else math.nan

    @property
    def never(self) -> int:
        return int(np.sum(~np.isfinite(np.asarray(self.values, dtype=float))))


def case_of(family: str):
    """The family's mission case, or None when no plug-in registers one."""
    REGISTRY.load()
    return next((c for c in REGISTRY.mission_cases if c.family == family), None)


def draws(case, n: int) -> list[dict]:
    """The n override sets of the runs (module docstring): the same for every controller."""
    return dispersed_sets(get(case.scenario), n)


def prepare(case, ctrls, binding: tuple, configured, out: Path, n: int, log) -> tuple[list, list]:
    """(entries, jobs): one entry per controller of ``ctrls`` ([(label, model, built-in or None)]), a job
    (entry, campaign, folder) per controller that runs. ``configured``: the benchmark's configuration of a
    pair (:func:`scfmu.benchmark.configured`); ``binding``: the unit's (parameters, --map, profile)."""
    base = get(case.scenario)
    sets = draws(case, n)
    own = base.component(case.slot).model
    entries, jobs = [], []
    for name, model, b in ctrls:
        m = MissionEntry(name, model)
        entries.append(m)
        try:
            if b is not None and b.model == own:
                m.envelope, m.config, sc = "home", f"the tuning {case.scenario} was made with", base
            else:
                sc = configured(base, case, m, model, b, *binding)
            if sc is None:
                log(f"  mission / {name}: {m.status}")
                continue
            require(sc, instantiate=False)
        except (IncompatibleUnit, KeyError, profiles.ProfileError) as err:
            m.status = "n/a: " + str(err.args[0] if err.args else err).replace("\n", " ")[:400]
            log(f"  mission / {name}: {m.status}")
            continue
        m.unbound = [u.text() for u in unbound_slots(sc, [case.slot])]
        jobs.append((m, campaign.Campaign(sc, sets, [None], engine="auto"), out / "runs_mission" / _slug(name)))
    return entries, jobs


def run_pair(client, log, case, m: MissionEntry, c, folder: Path) -> None:
    rows = sorted(campaign.run(c, folder, client=client, progress=False, overwrite=True).to_pylist(),
                  key=lambda r: r["run"])
    m.runs = len(rows)
    good = {r["run"] for r in rows if r["status"] == "ok"}
    m.ok = len(good)

    def t(r, key):
        v = float(r.get(key, math.nan)) if r["run"] in good else math.nan
        return v if math.isfinite(v) else math.inf
    m.values = [t(r, case.metric) for r in rows]
    m.handover = [t(r, case.handover) for r in rows]
    m.chatter_runs = sum(1 for r in rows if r["run"] in good and (r.get("mode_chatter") or 0) > 0)
    m.failures = [f"run {r['run']}: {r['status']}: {r['message'][:160]}" for r in rows if r["run"] not in good]
    log(f"  mission / {m.controller}: {m.ok}/{m.runs} ok, p95 {case.metric} = {_s(m.p(95))}, never {m.never}")


def ranks(entries: list[MissionEntry]) -> dict:
    """{controller: rank} by the p95 time, then by the number of runs never on target (competition ranking;
    p95 times within TIE_S are equal; not reached after every time)."""
    ran = [m for m in entries if not m.status and m.runs]
    key = {m.controller: (m.p(95), m.never) for m in ran}

    def better(a, b):
        same = a[0] == b[0] or (math.isfinite(a[0]) and math.isfinite(b[0]) and abs(a[0] - b[0]) <= TIE_S)
        return a[1] < b[1] if same else a[0] < b[0]
    return {k: 1 + sum(1 for v in key.values() if better(v, key[k])) for k in key}


def _s(v: float) -> str:
    return "not reached" if v == math.inf else "–" if not math.isfinite(v) else f"{v:.0f}"


HEAD = ["controller", "configuration", "runs ok", "to hand-over p95 [s]", "to on target median [s]",
        "to on target p95 [s]", "never on target", "chatter runs", "rank"]


def _rows(entries: list[MissionEntry]) -> list[list[str]]:
    rk = ranks(entries)
    out = []
    for m in entries:
        if m.status or not m.runs:
            out.append([m.controller, m.status or m.config, "–", "–", "–", "–", "–", "–", "–"])
            continue
        out.append([m.controller, m.config + ("; " + "; ".join(m.unbound) if m.unbound else ""), f"{m.ok}/{m.runs}",
                    _s(m.p(95, "handover")), _s(m.p(50)), _s(m.p(95)), f"{m.never}/{m.runs}", str(m.chatter_runs),
                    str(rk.get(m.controller, "–"))])
    return out


def write_csv(out: Path, case, entries: list[MissionEntry]) -> None:
    with open(Path(out) / CSV, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "controller", "model", "envelope", "configuration", "status", "runs", "ok",
                    f"{case.handover} p95 [s]", f"{case.metric} median [s]", f"{case.metric} p95 [s]",
                    "never", "chatter runs", "rank", "unbound slot values", "failures"])
        rk = ranks(entries)
        for m in entries:
            ran = not m.status and m.runs
            w.writerow([case.scenario, m.controller, m.model, m.envelope, m.config, m.status, m.runs, m.ok,
                        *([m.p(95, "handover"), m.p(50), m.p(95), m.never, m.chatter_runs, rk.get(m.controller, "")]
                          if ran else ["", "", "", "", "", ""]), "; ".join(m.unbound), "; ".join(m.failures[:3])])


def section(out, case_, entries, ctx):
    """The page's mission section (page level; :func:`scfmu.benchmark.common.add_section`)."""
    found = ctx.get("mission")
    if case_ is not None or not found:
        return [], ""
    case, ms = found
    unit = ctx.get("unit_label")
    n = max((m.runs for m in ms), default=0)
    intro = (f"{case.label}. Each controller takes the place '{case.slot}' in the same {n} dispersed runs "
             f"(tip-off, inertia, attitude and sensor-noise draws of the scenario, one generator seeded 0). "
             f"Times from separation: to the mode manager's hand-over ({case.handover}) and to on target "
             f"({case.metric}); p95 and median over every run, a run that never got there or failed counted as not "
             f"reached (so the p95 is 'not reached' when more than 5 % never get there); ranked by the p95 to on "
             f"target (equal within {TIE_S:g} s), then by the runs never on target.")
    rows = _rows(ms)  # the unit under test's name in bold, as in the benchmark's other tables
    md = ["## Mission: time to fine pointing", "", intro, "", "| " + " | ".join(HEAD) + " |", "|" + "---|" * len(HEAD)]
    md += ["| " + " | ".join([f"**{r[0]}**" if r[0] == unit else r[0], *r[1:]]) + " |" for r in rows] + [""]
    fails = [f"{m.controller}: {x}" for m in ms for x in m.failures[:3]]
    md += [f"- failed run: {x}" for x in fails] + ([""] if fails else [])
    cell = [lambda x: f"<b>{html.escape(x)}</b>" if x == unit else html.escape(x)] + [html.escape] * (len(HEAD) - 1)
    h = (f"<h2>Mission: time to fine pointing</h2><p>{html.escape(intro)}</p><table border='1'><tr>"
         + "".join(f"<th>{html.escape(x)}</th>" for x in HEAD) + "</tr>"
         + "".join("<tr>" + "".join(f"<td>{f(x)}</td>" for f, x in zip(cell, r)) + "</tr>" for r in rows)
         + "</table>" + "".join(f"<p>failed run: {html.escape(x)}</p>" for x in fails))
    return md, h
