"""The benchmark's page: ``results.csv``, ``benchmark.md`` and ``index.html`` with the warnings block, one
table and response figure per scenario and the sections other modules register (:func:`.common.add_section`).
"""

from __future__ import annotations

import csv
import html
import math
from pathlib import Path

import numpy as np

from .common import (COLUMNS, EST_KEY, METRIC_UNITS, RESOLUTION, RESPONSE_RESOLUTION, SECTIONS, WARNINGS, Entry,
                     _slug, estimator_ranks, identical_groups, metric_title, ranks)


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


def write_page(out: Path, family: str, cases, entries: list[Entry], unit_label, quick: bool, seconds: float,
               mission: tuple = ()) -> None:
    """Writes ``results.csv``, ``benchmark.md`` and ``index.html`` (the sections registered by
    :func:`add_section` included; ``mission``: (mission case, its entries) of ``--mission``)."""
    rk = ranks(cases, entries)
    ctx = {"family": family, "unit_label": unit_label, "quick": quick, "ranks": rk, "mission": mission}
    _write_csv(out, family, cases, entries, rk)
    who = f"{unit_label} beside the built-in controllers" if unit_label else "the built-in controllers"
    title = f"Controller benchmark ({family}): {who}"
    md = [f"# {title}", ""]
    h = [f"<h1>{html.escape(title)}</h1>"]
    intro = _intro(cases, entries, quick, seconds)
    if any(EST_KEY in e.means for e in entries):
        intro += (" With estimator: each pair that ran once more on its scenario's estimator-in-the-loop variant "
                  "(gyro, star tracker, sun sensor, magnetometer, on-board ephemeris and the Mekf between the plant and "
                  "the controller, 10 Hz flight computer; same configuration, override sets and seeds): the mean of "
                  "the primary metric when every run succeeded, and its rank among the pairs that pass.")
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
        _case_section(md, h, out, family, case, entries, rk, unit_label)
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


def _write_csv(out: Path, family: str, cases, entries: list[Entry], rk: dict) -> None:
    prim = {c.label: c.primary for c in cases}
    est = any(EST_KEY in e.means for e in entries)  # --estimator: two more columns at the end
    erk = estimator_ranks(cases, entries) if est else {}
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.writer(f)
        # units in the header: "ise [rad²·s]"; the primary value is in the unit of its metric's column
        units = METRIC_UNITS.get(family, {})
        w.writerow(["scenario", "controller", "model", "runs", "ok", "settled", "pass", "rank", "primary metric",
                    "primary value", *[f"{k} [{units.get(k, '–')}]" for k, _ in COLUMNS], "envelope", "configuration",
                    "unbound slot values", "flags", "error_start [deg]", "error_end [deg]", "status",
                    *(["primary value with estimator", "rank with estimator", "estimator status"] if est else [])])
        for e in entries:
            w.writerow([e.case, e.controller, e.model, e.runs, e.ok, e.settled, e.passed, rk.get(e.case, {}).get(e.controller, ""),
                        prim[e.case], e.means.get(prim[e.case], math.nan), *[e.means.get(k, math.nan) for k, _ in COLUMNS],
                        e.envelope, e.config, "; ".join(e.unbound), "; ".join(e.flags), e.error0, e.error_end, e.status,
                        *([e.means.get(EST_KEY, math.nan), erk.get(e.case, {}).get(e.controller, ""), e.est_status]
                          if est else [])])


def _intro(cases, entries: list[Entry], quick: bool, seconds: float) -> str:
    rel, ab = RESOLUTION["default"]
    return (f"{len(cases)} scenarios × {len({e.controller for e in entries})} controllers"
            f"{' (quick: Monte Carlo cases with 10 draws)' if quick else ''}; {seconds:.0f} s. Values are means over "
            f"the runs of a scenario that succeeded. Pass: every run succeeded and settled (2 % band) before its end. "
            f"Rank: by the scenario's primary metric (lower is better) among the controllers that pass; values "
            f"equal within the resolution |a − b| ≤ {rel:g}·max(|a|, |b|) + {ab:g} (in the metric's unit) share a "
            f"rank (1, 2, 2, 4). Responses are identical when the plotted signal and the main error differ by at most "
            f"{RESPONSE_RESOLUTION[0]:g} of their largest value (+ {RESPONSE_RESOLUTION[1]:g}) at every logged sample "
            f"of the first run and the primary metric is equal. "
            f"Built-in controllers run with their paper's tuning on their paper's scenarios and re-tuned by a "
            f"stated rule elsewhere (the 'configuration' lines), or are listed as not designed for the plant.")


def _case_section(md: list, h: list, out: Path, family: str, case, entries: list[Entry], rk: dict, unit_label) -> None:
    """One scenario's heading, table, notes, configuration, failures and figure."""
    heading = f"{case.label}: {unit_label}" if unit_label else case.label
    desc = (f"Scenario `{case.scenario}`" + (f" with {case.overrides}" if case.overrides else "")
            + (f", Monte Carlo of {case.seeds} runs" if case.seeds else "") + f"; primary metric `{case.primary}` "
            f"({metric_title(case.primary, family)}).")
    md += [f"## {heading}", "", desc, ""]
    h.append(f"<h2>{html.escape(heading)}</h2><p>{html.escape(desc).replace('`', '')}</p>")
    keys = [k for k in dict.fromkeys([case.primary, *(k for k, _ in COLUMNS)])
            if any(math.isfinite(e.means.get(k, math.nan)) for e in entries if e.case == case.label)]
    head = ["controller", "runs ok", "pass", "rank", *[metric_title(k, family) for k in keys]]
    est = any(EST_KEY in e.means for e in entries if e.case == case.label)  # --estimator
    erk = estimator_ranks([case], entries)[case.label] if est else {}
    if est:
        head.append(f"with estimator: {metric_title(case.primary, family)} (rank)")
    md += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    h.append("<table border=1 cellspacing=0 cellpadding=3><tr>" + "".join(f"<th>{html.escape(x)}</th>" for x in head) + "</tr>")
    for e in [x for x in entries if x.case == case.label]:
        if e.status:
            cells = [e.controller, "–", "n/a", "–", e.status] + [""] * (max(0, len(keys) - 1) + est)
        else:
            mark = " ⚠" if (e.unbound or e.flags) else ""
            cells = [e.controller + mark, f"{e.ok}/{e.runs}", "pass" if e.passed else "fail",
                     str(rk[case.label].get(e.controller, "–")), *[_fmt(e.means.get(k, math.nan)) for k in keys]]
            if est:
                v = e.means.get(EST_KEY, math.nan)
                cells.append(f"{_fmt(v)} ({erk[e.controller]})" if e.controller in erk else _fmt(v))
        name = f"**{cells[0]}**" if e.controller == unit_label else cells[0]
        md.append("| " + " | ".join(x.replace("|", "/").replace("\n", " ") for x in [name, *cells[1:]]) + " |")
        style = " style='font-weight:bold'" if e.controller == unit_label else ""
        h.append(f"<tr{style}>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in cells) + "</tr>")
    h.append("</table>")
    notes = [f"{' = '.join(g)}: identical responses" for g in identical_groups(case, entries)]
    for e in [x for x in entries if x.case == case.label]:
        notes += [f"⚠ {e.controller}: {u}" for u in e.unbound] + [f"⚠ {e.controller}: {f_}" for f_ in e.flags]
    notes += [f"{e.controller} with estimator: {e.est_status}" for e in entries if e.case == case.label and e.est_status]
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
