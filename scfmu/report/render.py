"""Renders the paper sections of the reproduction report as one static HTML page and a Markdown copy.

``render(sections, out_dir, meta)`` writes ``out_dir/index.html`` (inline CSS, no script, no server;
figures are relative links to ``figures/...`` beside it) and ``out_dir/report.md`` with the same
content: a summary table of every claim (id, statement, verdict, parameters the verdict is sensitive
to), then per paper its setup, claims (statement, verdict badge, evidence, tables, figures, sensitivity),
section tables/figures and notes. ``meta`` carries the build facts printed in the header (date, git
commit, quick or full, workers, run counts and runtime per paper).

Every text that comes from a section is escaped (``html.escape``) before it enters the page; in the
Markdown copy, table cells have their ``|`` escaped and line breaks folded.
"""

from __future__ import annotations

import json
from pathlib import Path

from . import docs as _docs
from .docs import DOC_BEGIN, DOC_END, doc_block, docs_table, update_docs  # noqa: F401 (the docs blocks)
from .fmt import BADGE, MD_MARK, _e, _is_num, _md, _paras, badge, fmt_cell, md_verdict  # noqa: F401
from .numbers import (CSV_COLUMNS, counts_text, fmt_num, fmt_rel, number_cells, number_counts,  # noqa: F401
                      numbers_csv_rows, numbers_html, numbers_md, numbers_text, read_numbers_csv, write_numbers_csv)
from .types import (BY_CONSTRUCTION_HOLDS, CONFIRMED, DEPENDS, NOT_CONFIRMED, NUMBER_VERDICTS, TESTED_VERDICTS, VERDICTS,
                    Claim, PaperSection, Sensitivity, Table)

CSS = """
body{font-family:-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#1f2328;line-height:1.45}
h1{border-bottom:2px solid #d0d7de;padding-bottom:.3em}
h2{border-bottom:1px solid #d0d7de;padding-bottom:.2em;margin-top:2.2em}
h3{margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0 1.2em 0;font-size:.92em}
th,td{border:1px solid #d0d7de;padding:.3em .6em;text-align:left;vertical-align:top}
th{background:#f6f8fa}
#glance td,#glance th{padding:.2em .45em;font-size:.9em}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
caption{caption-side:top;text-align:left;font-weight:600;padding:.2em 0}
.badge{display:inline-block;border-radius:1em;padding:.05em .7em;font-size:.85em;font-weight:600;white-space:nowrap}
.meta{color:#57606a;font-size:.92em}
.claim{border-left:4px solid #d0d7de;padding:.2em 0 .2em 1em;margin:1.4em 0}
figure{margin:1em 0}
figure img{max-width:100%;border:1px solid #d0d7de}
figcaption{color:#57606a;font-size:.9em;margin-top:.3em}
.missing{color:#cf222e}
.sens{background:#f6f8fa;padding:.4em .8em;border-radius:6px;margin:.6em 0}
pre{white-space:pre-wrap}
"""


CLAIM_COUNTS_TEXT = ("Claims: confirmed, depends on a reading and not confirmed count only claims that could have "
                     "failed; a claim whose outcome the implementation fixes (quantities computed by different routes "
                     "agree to rounding level) is shown as 'holds by construction' and counted apart.")


# ----- HTML pieces ------------------------------------------------------------------------------------
def table_html(t: Table) -> str:
    head = "".join(f"<th>{_e(c)}</th>" for c in t.columns)
    body = []
    for row in t.rows:
        cells = []
        for v in row:
            cls = ' class="num"' if _is_num(v) else ""
            cells.append(f"<td{cls}>{_e(fmt_cell(v, t.digits))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return (f"<table><caption>{_e(t.caption)}</caption><thead><tr>{head}</tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>")


def figure_html(f, out_dir: Path) -> str:
    exists = (out_dir / f.path).exists()
    src = _e(Path(f.path).as_posix())
    img = f'<img src="{src}" alt="{_e(f.caption)}">' if exists else \
        f'<p class="missing">figure missing: {src}</p>'
    return f"<figure>{img}<figcaption>{_e(f.caption)}</figcaption></figure>"


def sensitivity_html(s: Sensitivity, out_dir: Path) -> str:
    vals = ", ".join(fmt_cell(v) for v in s.values)
    out = [f'<div class="sens"><p><b>Sensitivity to {_e(s.parameter)}</b>: values tried {_e(vals)}; '
           f'today\'s default {_e(fmt_cell(s.default))}; the claim holds where: <b>{_e(s.holds_where)}</b>.</p>']
    if s.table is not None:
        out.append(table_html(s.table))
    if s.figure is not None:
        out.append(figure_html(s.figure, out_dir))
    out.append("</div>")
    return "".join(out)


def claim_html(c: Claim, out_dir: Path) -> str:
    out = [f'<div class="claim" id="{_e(c.id)}"><h3>{_e(c.id)} {verdict_html(c)}</h3>',
           f"<p><i>Claim:</i> {_e(c.statement)}</p>", f"<p><i>Evidence:</i></p>{_paras(c.evidence)}"]
    for t in c.tables:
        out.append(table_html(t))
    for f in c.figures:
        out.append(figure_html(f, out_dir))
    if c.sensitive_to:
        out.append("<p><i>Readings examined:</i> " + _e(", ".join(c.sensitive_to)) + "</p>")
    for s in c.sensitivity:
        out.append(sensitivity_html(s, out_dir))
    out.append("</div>")
    return "".join(out)


def _paper_meta(sec: PaperSection, meta: dict) -> str:
    runs = (meta.get("runs") or {}).get(sec.paper)
    bits = [f"runtime {sec.runtime_s:.1f} s"]
    if runs is not None:
        bits.insert(0, f"{runs} simulation runs")
    return ", ".join(bits)


def verdict_html(c: Claim) -> str:
    """The verdict badge, with the chosen readings when they are the claim's only support."""
    rest = c.verdict_text[len(c.verdict):]
    return badge(c.verdict) + (f" <small>{_e(rest.strip())}</small>" if rest else "")


def summary_rows(sections: list[PaperSection]) -> list[tuple[str, str, str, str, str, Claim]]:
    """(paper, claim id, statement, verdict, sensitive to, claim) for every claim, in section order."""
    return [(s.paper, c.id, c.statement, c.verdict, ", ".join(c.sensitive_to) or "–", c)
            for s in sections for c in s.claims]


def paper_summary(sec: PaperSection) -> dict:
    """Counts of the first page for one paper: the number verdicts, the independent checks and the claim
    verdicts."""
    d = number_counts(sec.numbers)
    d["numbers"] = len(sec.numbers)
    d["independent"] = sum(1 for n in sec.numbers if n.independent)
    d["calibration"] = sum(1 for n in sec.numbers if n.calibration)
    d["other"] = d["not evidence"]
    for v in VERDICTS:   # confirmed / depends / not confirmed count only claims that could have failed
        d[v] = sum(1 for c in sec.claims if c.verdict == v)
    return d


def summary_html(sections: list[PaperSection]) -> str:
    """The one-screen summary that opens the page: per paper the counts of its reported numbers per verdict
    and of its claims per verdict, with links to the paper's numbers table and section."""
    rows = []
    for s in sections:
        d = paper_summary(s)
        short = s.title if len(s.title) <= 48 else s.title[:47].rstrip() + "…"
        rows.append(f"<tr><td><a href=\"#paper{_e(s.paper)}\">{_e(s.paper)}</a></td>"
                    f"<td title=\"{_e(s.title)}\">{_e(short)}</td>"
                    + "".join(f"<td class=\"num\">{d[v]}</td>" for v in NUMBER_VERDICTS)
                    + f"<td class=\"num\">{d['other']}</td>"
                    + f"<td class=\"num\"><a href=\"#numbers{_e(s.paper)}\">{d['independent']} of {d['numbers']}</a></td>"
                    + "".join(f"<td class=\"num\">{d[v]}</td>" for v in TESTED_VERDICTS)
                    + f"<td class=\"num\">{d[BY_CONSTRUCTION_HOLDS]}</td></tr>")
    return ("<h2 id=\"at-a-glance\">At a glance</h2><table id=\"glance\"><thead><tr><th>paper</th><th>title</th>"
            + "".join(f"<th>{badge(v)}</th>" for v in NUMBER_VERDICTS)
            + "<th>not evidence</th><th>independent checks</th>"
            + "".join(f"<th>claims {badge(v)}</th>" for v in TESTED_VERDICTS)
            + f"<th>not counted: {badge(BY_CONSTRUCTION_HOLDS)}</th>"
            + "</tr></thead><tbody>" + "".join(rows) + "</tbody></table>"
            + "<p class=\"meta\">Reported numbers, counted over the independent rows only: reproduced = within 5 % of the paper's value (or its printed "
              "precision); same ordering only = off, but ranked among the paper's numbers as the paper ranks it; "
              "not checkable = the paper lacks what is needed. Not evidence = a row whose value was calibrated to "
              "the paper's number, is fixed by construction (a search bound or optimiser constraint puts it there) "
              "or was chosen among readings after comparing with the paper: shown, labelled, never counted. The "
              "full table is <a href=\"numbers.csv\">numbers.csv</a>. " + _e(CLAIM_COUNTS_TEXT) + "</p>")


def render_html(sections: list[PaperSection], out_dir: Path, meta: dict) -> str:
    mode = "quick (reduced grids, CI)" if meta.get("quick") else "full"
    head = ["<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">",
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">",
            f"<title>{_e(meta.get('title', 'Reproduction report'))}</title><style>{CSS}</style></head><body>",
            f"<h1>{_e(meta.get('title', 'Reproduction report'))}</h1>",
            f"<p class=\"meta\">Built {_e(meta.get('built', '?'))} · git commit {_e(meta.get('commit', '?'))} · "
            f"mode: {_e(mode)} · Dask workers: {_e(meta.get('workers', '?'))} · total runtime "
            f"{_e(fmt_cell(float(meta.get('runtime_s', 0.0)), 4))} s</p>"]
    head.append(summary_html(sections))
    if meta.get("intro"):
        head.append(_paras(meta["intro"]))
    counts = {v: sum(1 for r in summary_rows(sections) if r[3] == v)
              for v in (CONFIRMED, NOT_CONFIRMED, DEPENDS, BY_CONSTRUCTION_HOLDS)}
    head.append("<h2 id=\"summary\">Summary of the claims</h2>")
    head.append("<p>" + " · ".join(f"{badge(v)} {n}" for v, n in counts.items()) + "</p>")
    rows = "".join(
        f"<tr><td><a href=\"#{_e(cid)}\">{_e(cid)}</a></td><td>{_e(st)}</td><td>{verdict_html(c)}</td><td>{_e(sens)}</td></tr>"
        for _, cid, st, v, sens, c in summary_rows(sections))
    head.append("<table id=\"claims\"><thead><tr><th>claim</th><th>statement</th><th>verdict</th>"
                f"<th>readings examined</th></tr></thead><tbody>{rows}</tbody></table>")
    head.append("<table><caption>Runs and runtime per paper</caption><thead><tr><th>paper</th><th>title</th>"
                "<th>simulation runs</th><th>runtime (s)</th></tr></thead><tbody>" + "".join(
                    f"<tr><td><a href=\"#paper{_e(s.paper)}\">{_e(s.paper)}</a></td><td>{_e(s.title)}</td>"
                    f"<td class=\"num\">{_e(fmt_cell((meta.get('runs') or {}).get(s.paper)))}</td>"
                    f"<td class=\"num\">{_e(fmt_cell(float(s.runtime_s), 3))}</td></tr>" for s in sections)
                + "</tbody></table>")
    body = []
    for s in sections:
        body.append(f"<h2 id=\"paper{_e(s.paper)}\">Paper {_e(s.paper)}: {_e(s.title)}</h2>")
        body.append(f"<p class=\"meta\">{_e(_paper_meta(s, meta))}</p>")
        body.append(numbers_html(s))
        body.append("<h3>Setup</h3>" + _paras(s.setup))
        for c in s.claims:
            body.append(claim_html(c, out_dir))
        if s.tables or s.figures:
            body.append("<h3>Further results</h3>")
            body.extend(table_html(t) for t in s.tables)
            body.extend(figure_html(f, out_dir) for f in s.figures)
        if s.notes:
            body.append("<h3>Notes</h3>" + _paras(s.notes))
    return "".join(head + body) + "</body></html>\n"


# ----- Markdown -----------------------------------------------------------------------------------------
def table_md(t: Table) -> list[str]:
    out = [f"*{_md(t.caption)}*", "", "| " + " | ".join(_md(c) for c in t.columns) + " |",
           "|" + "|".join("---:" if any(_is_num(r[i]) for r in t.rows if i < len(r)) else "---"
                          for i in range(len(t.columns))) + "|"]
    for row in t.rows:
        out.append("| " + " | ".join(_md(fmt_cell(v, t.digits)) for v in row) + " |")
    out.append("")
    return out


def figure_md(f, out_dir: Path) -> list[str]:
    p = Path(f.path).as_posix()
    if not (out_dir / f.path).exists():
        return [f"*figure missing: {p}*", ""]
    return [f"![{_md(f.caption)}]({p})", "", f"*{f.caption}*", ""]


def render_md(sections: list[PaperSection], out_dir: Path, meta: dict) -> str:
    mode = "quick (reduced grids, CI)" if meta.get("quick") else "full"
    out = [f"# {meta.get('title', 'Reproduction report')}", "",
           f"Built {meta.get('built', '?')} · git commit {meta.get('commit', '?')} · mode: {mode} · Dask workers: "
           f"{meta.get('workers', '?')} · total runtime {fmt_cell(float(meta.get('runtime_s', 0.0)), 4)} s", ""]
    out += ["## At a glance", "", "Reported numbers counted over the independent rows only; *not evidence* = "
            "calibrated, fixed by construction or chosen among readings (shown, never counted).", "",
            "| paper | " + " | ".join(NUMBER_VERDICTS) + " | not evidence | independent checks | claims "
            "confirmed | depends | not confirmed | not counted: holds by construction |",
            "|---|" + "---:|" * (len(NUMBER_VERDICTS) + 6)]
    for s in sections:
        d = paper_summary(s)
        out.append(f"| [{s.paper}](#paper-{s.paper}) | " + " | ".join(str(d[v]) for v in NUMBER_VERDICTS)
                   + f" | {d['other']} | {d['independent']} of {d['numbers']} | {d[CONFIRMED]} | {d[DEPENDS]} | "
                   f"{d[NOT_CONFIRMED]} | {d[BY_CONSTRUCTION_HOLDS]} |")
    out += ["", CLAIM_COUNTS_TEXT, ""]
    if meta.get("intro"):
        out += [meta["intro"], ""]
    out += ["## Summary of the claims", "", "| claim | statement | verdict | readings examined |", "|---|---|---|---|"]
    for _, cid, st, v, sens, c in summary_rows(sections):
        out.append(f"| {_md(cid)} | {_md(st)} | {_md(md_verdict(c))} | {_md(sens)} |")
    out += ["", "| paper | title | simulation runs | runtime (s) |", "|---|---|---:|---:|"]
    for s in sections:
        out.append(f"| {s.paper} | {_md(s.title)} | {fmt_cell((meta.get('runs') or {}).get(s.paper))} | "
                   f"{fmt_cell(float(s.runtime_s), 3)} |")
    out.append("")
    for s in sections:
        out += [f"## Paper {s.paper}: {s.title}", "", f"*{_paper_meta(s, meta)}*", ""]
        if s.numbers:
            out += ["### The paper's numbers beside ours", ""] + numbers_md(s.numbers) + [""]
            if s.calibrations:
                out += [s.calibrations, ""]
        out += ["### Setup", "", s.setup, ""]
        for c in s.claims:
            out += [f"### {c.id}: {md_verdict(c)}", "", f"**Claim:** {c.statement}", "",
                    f"**Evidence:** {c.evidence}", ""]
            for t in c.tables:
                out += table_md(t)
            for f in c.figures:
                out += figure_md(f, out_dir)
            if c.sensitive_to:
                out += [f"**Readings examined:** {', '.join(c.sensitive_to)}", ""]
            for sv in c.sensitivity:
                vals = ", ".join(fmt_cell(v) for v in sv.values)
                out += [f"> **Sensitivity to {sv.parameter}**: values tried {vals}; today's default "
                        f"{fmt_cell(sv.default)}; the claim holds where: **{sv.holds_where}**.", ""]
                if sv.table is not None:
                    out += table_md(sv.table)
                if sv.figure is not None:
                    out += figure_md(sv.figure, out_dir)
        if s.tables or s.figures:
            out += ["### Further results", ""]
            for t in s.tables:
                out += table_md(t)
            for f in s.figures:
                out += figure_md(f, out_dir)
        if s.notes:
            out += ["### Notes", "", s.notes, ""]
    return "\n".join(out) + "\n"


def claims_text(sections: list[PaperSection], width: int = 70) -> str:
    """The summary table as plain text for the terminal."""
    rows = summary_rows(sections)
    lines = [f"{'claim':8s} {'verdict':22s} {'statement':{width}s} readings examined"]
    for _, cid, st, v, sens, c in rows:
        st1 = st if len(st) <= width else st[: width - 1] + "…"
        lines.append(f"{cid:8s} {v:22s} {st1:{width}s} {sens}" + (f" [{c.verdict_text}]" if c.chosen_support else ""))
    return "\n".join(lines)


def render(sections: list[PaperSection], out_dir: str | Path, meta: dict | None = None) -> tuple[Path, Path]:
    """Writes index.html and report.md into ``out_dir``; returns their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    meta = dict(meta or {})
    ids = [c.id for s in sections for c in s.claims]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ValueError(f"claim ids appear more than once: {dup}")
    h = out_dir / "index.html"
    m = out_dir / "report.md"
    h.write_text(render_html(sections, out_dir, meta), encoding="utf-8")
    m.write_text(render_md(sections, out_dir, meta), encoding="utf-8")
    write_numbers_csv(sections, out_dir / "numbers.csv")
    _docs.write_doc_tables(sections, out_dir / "doc_tables.json")
    write_verdicts(sections, out_dir / "verdicts.json", meta)
    return h, m


def verdicts_of(sections: list[PaperSection]) -> dict:
    """{"claims": {claim id: verdict}, "numbers": {"paper/item": verdict}}: what quick and full builds must
    agree on."""
    return {"claims": {c.id: c.verdict for s in sections for c in s.claims},
            "numbers": {f"{s.paper}/{n.item}": n.verdict for s in sections for n in s.numbers}}


def write_verdicts(sections: list[PaperSection], path: Path, meta: dict | None = None) -> Path:
    d = {"quick": bool((meta or {}).get("quick")), **verdicts_of(sections)}
    path.write_text(json.dumps(d, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    return path

