"""The controller benchmark: a unit (any FMI 2.0 Co-Simulation FMU, or a model name) runs through a family's
standard scenarios beside the built-in controllers of that family, and one page compares them.

The scenarios (``BenchmarkCase``) and the built-in controllers (``BuiltinController``) come from the
plug-ins' registrations (:mod:`scfmu.registry`); this module names no paper. Every (scenario, controller)
pair is one campaign on the campaign engine: the controller takes the scenario's ``slot`` (the model is
swapped, the old model's parameters are dropped, the slot's parameters such as the nominal inertia stay),
a Monte Carlo case runs one campaign row per draw. A pair whose unit does not fit (pre-flight check) is
reported as "n/a" with the reason; a run that fails is a failed row, never a lost benchmark.

Per pair the page shows the mean over the runs of EULERINT, ISE, ISF, settling time, effort and final
error, the number of runs that succeeded, pass/fail, and per scenario the rank of the unit under test by
the scenario's primary metric among the controllers that pass. Pass means: every run succeeded and
settled (its main error entered and stayed in the 2 % band before the end of the run; project choice).
"""

from __future__ import annotations

import csv
import html
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import campaign
from ..registry import REGISTRY, resolve
from ..scenario import get
from ..scenario.check import IncompatibleUnit, require
from ..scenario.ssp import file_stem
from . import engineering

COLUMNS = [("eulerint_deg_s", "EULERINT [deg·s]"), ("ise", "ISE"), ("isf", "ISF"), ("settling_s", "settling [s]"),
           ("effort_abs", "effort ∫Σ abs(u) dt"), ("final_error", "final error")]
NAMES = dict(COLUMNS) | {"mae_deg": "MAE [deg]", "euler_end_max_deg": "largest final angle [deg]"}
UNIT = "unit under test"


@dataclass
class Entry:
    case: str
    controller: str
    model: str
    runs: int = 0
    ok: int = 0
    settled: int = 0
    means: dict = field(default_factory=dict)
    status: str = ""  # "" (ran), or "n/a: reason"
    series: dict | None = None  # {"time": ..., signal: ...} of the first run
    failures: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return not self.status and self.runs > 0 and self.ok == self.runs and self.settled == self.runs


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


def run(unit: str | None, family: str, out: str | Path, label: str | None = None, unit_params: dict | None = None,
        port_map: dict | None = None, quick: bool = False, workers: int = 2, controllers: list[str] | None = None,
        cases: list[str] | None = None, client=None, log=print) -> list[Entry]:
    """Runs the benchmark and writes ``index.html``, ``benchmark.md``, ``results.csv`` and ``figures/``
    into ``out``; returns the entries. ``unit``: a path to an FMU or a model name (None: built-ins only)."""
    REGISTRY.load()
    only = cases
    cases = [c for c in REGISTRY.benchmark_cases if c.family == family
             and (only is None or any(x == c.scenario or x in c.label for x in only))]
    if not cases:
        raise KeyError(f"no benchmark scenario for family {family!r}{' matching ' + str(only) if only else ''}; "
                       f"families: {', '.join(REGISTRY.families())}")
    ctrls = [(b.label, b.model, dict(b.params)) for b in REGISTRY.controllers if b.family == family
             and (controllers is None or b.model in controllers or b.label in controllers)]
    if unit is not None:
        ctrls.append((label or UNIT, str(unit), dict(unit_params or {})))
    out = Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    own = client is None
    cluster = None
    if own:
        client, cluster = campaign._client(None, workers)
    entries: list[Entry] = []
    pairs: dict = {}  # (case, controller) -> scenario, for the Monte Carlo and the margins
    t0 = time.time()
    studies = None
    try:
        for case in cases:
            sets, seeds = _case_overrides(case, quick)
            base = get(case.scenario)
            for name, model, params in ctrls:
                e = Entry(case.label, name, model)
                entries.append(e)
                sc = base.with_models({case.slot: model})
                try:
                    sc = sc.with_overrides({f"{case.slot}.{k}": v for k, v in params.items()})
                    if name == (label or UNIT) and port_map:
                        sc = sc.with_port_map({f"{case.slot}.{k}": v for k, v in port_map.items()})
                    require(sc, instantiate=False)
                except (IncompatibleUnit, KeyError) as err:
                    e.status = "n/a: " + str(err.args[0] if err.args else err).replace("\n", " ")[:400]
                    log(f"  {case.label} / {name}: {e.status}")
                    continue
                every = max(1, sc.n_steps // 1500)
                pairs[(case.label, name)] = sc
                sc, ts_keys = engineering.instrument(sc, case.signal)  # effort, saturation, pointing signals
                c = campaign.Campaign(sc, sets, seeds, timeseries=ts_keys, ts_every=every)
                folder = out / "runs" / file_stem(case.scenario + ("_" + "_".join(f"{k}{v}" for k, v in case.overrides.items())
                                                                   if case.overrides else "")) / _slug(name)
                table = campaign.run(c, folder, client=client, progress=False, overwrite=True)
                rows = sorted(table.to_pylist(), key=lambda r: r["run"])
                e.runs = len(rows)
                good = [r for r in rows if r["status"] == "ok"]
                e.ok = len(good)
                e.settled = sum(1 for r in good if math.isfinite(r.get("settling_s", math.nan)))
                e.failures = [f"run {r['run']}: {r['status']}: {r['message'][:160]}" for r in rows if r["status"] != "ok"]
                for k, _ in COLUMNS + [(case.primary, "")]:
                    v = np.array([r.get(k, math.nan) for r in good], dtype=float)
                    e.means[k] = float(np.mean(v)) if v.size and np.all(np.isfinite(v)) else math.nan
                engineering.entry_metrics(e, sc, folder, good)
                if c.timeseries and good:
                    try:
                        e.series = campaign.read_timeseries(folder, good[0]["run"])
                    except OSError:
                        e.series = None
                log(f"  {case.label} / {name}: {e.ok}/{e.runs} ok, {case.primary} = {e.means.get(case.primary, math.nan):.6g}")
        if family == "attitude":  # robustness Monte Carlo and stability margins (scfmu.benchmark.engineering)
            studies = engineering.studies(cases, pairs, entries, out, client, quick, log)
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    write_page(out, family, cases, entries, unit_label=(label or UNIT) if unit is not None else None,
               quick=quick, seconds=time.time() - t0)
    if family == "attitude":
        engineering.append_to_page(out, cases, entries, ranks(cases, entries), (label or UNIT) if unit is not None else None, studies)
    return entries


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)[:80]


def ranks(cases, entries: list[Entry]) -> dict:
    """{case label: {controller: rank}} by the case's primary metric (lower is better) among the passing."""
    out = {}
    for case in cases:
        es = [e for e in entries if e.case == case.label and e.passed and math.isfinite(e.means.get(case.primary, math.nan))]
        vals = [e.means[case.primary] for e in es]  # equal values share a rank (1, 2, 2, 4)
        out[case.label] = {e.controller: 1 + sum(1 for v in vals if v < e.means[case.primary]) for e in es}
    return out


def _fmt(v) -> str:
    if isinstance(v, float):
        return "–" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def _figure(out: Path, case, entries: list[Entry], unit_label) -> str | None:
    es = [e for e in entries if e.case == case.label and e.series]
    if not es:
        return None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 3.6))
    for e in es:
        y = np.asarray(e.series[case.signal], dtype=float)
        if case.signal in ("roll", "pitch", "yaw", "theta"):
            y = np.degrees(y)
        ax.plot(e.series["time"], y, lw=2.2 if e.controller == unit_label else 1.0,
                ls="-" if e.controller == unit_label else "--", label=e.controller)
    unit = " [deg]" if case.signal in ("roll", "pitch", "yaw", "theta") or case.signal.endswith("_deg") else ""
    ax.set_xlabel("time [s]")
    ax.set_ylabel(case.signal + unit)
    ax.set_title(case.label, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    name = f"figures/{_slug(case.label)}.png"
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    return name


def write_page(out: Path, family: str, cases, entries: list[Entry], unit_label, quick: bool, seconds: float) -> None:
    rk = ranks(cases, entries)
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scenario", "controller", "model", "runs", "ok", "settled", "pass", "rank", "primary metric",
                    "primary value", *[k for k, _ in COLUMNS], "status"])
        prim = {c.label: c.primary for c in cases}
        for e in entries:
            w.writerow([e.case, e.controller, e.model, e.runs, e.ok, e.settled, e.passed, rk.get(e.case, {}).get(e.controller, ""),
                        prim[e.case], e.means.get(prim[e.case], math.nan), *[e.means.get(k, math.nan) for k, _ in COLUMNS],
                        e.status])
    md = [f"# Controller benchmark: {family}", ""]
    h = [f"<h1>Controller benchmark: {html.escape(family)}</h1>"]
    intro = (f"{len(cases)} scenarios × {len({e.controller for e in entries})} controllers"
             f"{' (quick: Monte Carlo cases with 10 draws)' if quick else ''}; {seconds:.0f} s. Values are means over "
             f"the runs of a scenario that succeeded. Pass: every run succeeded and settled (2 % band) before its end. "
             f"Rank: by the scenario's primary metric (lower is better) among the controllers that pass.")
    md += [intro, ""]
    h.append(f"<p>{html.escape(intro)}</p>")
    if unit_label:
        summ = [f"{case.label}: " + (f"rank {rk[case.label][unit_label]} of {len(rk[case.label])}"
                                     if unit_label in rk.get(case.label, {}) else "not ranked (did not pass or n/a)")
                for case in cases]
        md += [f"**{unit_label}**: " + "; ".join(summ), ""]
        h.append(f"<p><b>{html.escape(unit_label)}</b>: " + "; ".join(html.escape(x) for x in summ) + "</p>")
    for case in cases:
        md += [f"## {case.label}", "", f"Scenario `{case.scenario}`"
               + (f" with {case.overrides}" if case.overrides else "")
               + (f", Monte Carlo of {case.seeds} runs" if case.seeds else "") + f"; primary metric `{case.primary}`.", ""]
        h.append(f"<h2>{html.escape(case.label)}</h2><p>Scenario <code>{html.escape(case.scenario)}</code>"
                 + (f" with {html.escape(str(case.overrides))}" if case.overrides else "")
                 + (f", Monte Carlo of {case.seeds} runs" if case.seeds else "")
                 + f"; primary metric <code>{html.escape(case.primary)}</code>.</p>")
        keys = [k for k in dict.fromkeys([case.primary, *(k for k, _ in COLUMNS)])
                if any(math.isfinite(e.means.get(k, math.nan)) for e in entries if e.case == case.label)]
        head = ["controller", "runs ok", "pass", "rank", *[NAMES.get(k, k) for k in keys]]
        md += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        h.append("<table border=1 cellspacing=0 cellpadding=3><tr>" + "".join(f"<th>{html.escape(x)}</th>" for x in head) + "</tr>")
        for e in [x for x in entries if x.case == case.label]:
            if e.status:
                cells = [e.controller, "–", "n/a", "–", e.status] + [""] * max(0, len(keys) - 1)
            else:
                cells = [e.controller, f"{e.ok}/{e.runs}", "pass" if e.passed else "fail",
                         str(rk[case.label].get(e.controller, "–")), *[_fmt(e.means.get(k, math.nan)) for k in keys]]
            name = f"**{cells[0]}**" if e.controller == unit_label else cells[0]
            md.append("| " + " | ".join(x.replace("|", "/").replace("\n", " ") for x in [name, *cells[1:]]) + " |")
            style = " style='font-weight:bold'" if e.controller == unit_label else ""
            h.append(f"<tr{style}>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in cells) + "</tr>")
        h.append("</table>")
        fails = [f"{e.controller}: {x}" for e in entries if e.case == case.label for x in e.failures[:3]]
        if fails:
            md += ["", "Failed runs: " + "; ".join(fails)]
            h.append("<p>Failed runs: " + "; ".join(html.escape(x) for x in fails) + "</p>")
        fig = _figure(out, case, entries, unit_label)
        if fig:
            md += ["", f"![{case.label}]({fig})"]
            h.append(f"<p><img src='{fig}' alt='{html.escape(case.label)}' style='max-width:100%'></p>")
        md.append("")
    (out / "benchmark.md").write_text("\n".join(md) + "\n", encoding="utf-8")
    (out / "index.html").write_text("<!doctype html><html><head><meta charset='utf-8'><title>Controller benchmark: "
                                    f"{html.escape(family)}</title></head><body>" + "\n".join(h) + "</body></html>\n",
                                    encoding="utf-8")
