"""The generated parts of the docs pages (docs/paperNNN.md), written by ``scfmu report --docs docs`` from the
same data as the report:

* the "paper vs ours" block (between ``DOC_BEGIN`` and ``DOC_END``) from ``numbers.csv``;
* named blocks ``<!-- table:NAME:begin … -->`` … ``<!-- table:NAME:end -->`` from ``doc_tables.json``: every
  paper's claims table ("claims": claim, verdict, statement) and the tables a
  section lists in ``PaperSection.doc_tables`` (results at the defaults, …).

A test builds the report (--quick) and fails when a page's block differs from what the build wrote.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from .fmt import _md, fmt_cell, md_verdict
from .numbers import number_counts, obtained_text, read_numbers_csv, row_independent
from .types import INDEPENDENT, NUMBER_VERDICTS, PaperSection, Table

DOC_BEGIN = "<!-- numbers:begin (written by `scfmu report --docs docs`; do not edit by hand) -->"
DOC_END = "<!-- numbers:end -->"
TABLE_BEGIN = "<!-- table:{name}:begin (written by `scfmu report --docs docs`; do not edit by hand) -->"
TABLE_END = "<!-- table:{name}:end -->"
_TABLE_RE = re.compile(r"<!-- table:([A-Za-z0-9_.-]+):begin[^>]*-->")


def _g4(text: str) -> str:
    """A CSV number with 4 significant digits (text that is not a number unchanged)."""
    try:
        return f"{float(text):.4g}"
    except ValueError:
        return text


def docs_table(rows: list[dict], paper: str) -> str:
    """The Markdown table a docs/paperNNN.md page opens with, from numbers.csv rows of one paper."""
    out = [DOC_BEGIN, "", "| item | unit | paper | ours | difference | verdict | obtained |",
           "|---|---|---:|---:|---:|---|---|"]
    n = [r for r in rows if r["paper"] == paper]
    for r in n:
        rd = r["relative difference"]
        rd = f"{100 * float(rd):+.1f} %" if rd else "–"
        out.append("| " + " | ".join(_md(x) for x in (r["item"], r["unit"], r["paper value"] or "–",
                                                      _g4(r["our value"]) or "–", rd, r["verdict"],
                                                      obtained_text(r["obtained"], r.get("sensitivity") or "")))
                   + " |")
    counts = {v: sum(1 for r in n if r["verdict"] == v and r["obtained"] == INDEPENDENT) for v in NUMBER_VERDICTS}
    other = sum(1 for r in n if r["obtained"] != INDEPENDENT)
    out += ["", "Counts of the independent rows: " + ", ".join(f"{v} {k}" for v, k in counts.items())
            + f"; not evidence (calibrated, by construction or chosen) {other}; independent checks "
              f"{sum(1 for r in n if row_independent(r))} of {len(n)}.", "", DOC_END]
    return "\n".join(out)


def doc_block(text: str) -> str | None:
    """The generated numbers block of a docs page (None when the page has none)."""
    i, j = text.find(DOC_BEGIN), text.find(DOC_END)
    return None if i < 0 or j < i else text[i:j + len(DOC_END)]


def table_lines(t: Table) -> list[str]:
    out = ["| " + " | ".join(_md(c) for c in t.columns) + " |", "|" + "|".join("---" for _ in t.columns) + "|"]
    for row in t.rows:
        out.append("| " + " | ".join(_md(fmt_cell(v, t.digits)) for v in row) + " |")
    return out


def claims_table(sec: PaperSection) -> Table:
    """A paper's claims for its docs page: id, verdict and the claim in our words (what quick and full builds
    share; the readings each verdict names, swept on mode-dependent grids, are in the report)."""
    return Table("claims", ["claim", "verdict", "claim in our words"],
                 [[c.id, md_verdict(c), c.statement] for c in sec.claims])


def section_doc_tables(sec: PaperSection) -> dict[str, str]:
    """{block name: Markdown} of one section (its claims table and its ``doc_tables``)."""
    out = {"claims": "\n".join(table_lines(claims_table(sec)))}
    for name, t in (sec.doc_tables or {}).items():
        out[name] = (f"*{_md(t.caption)}*\n\n" if t.caption else "") + "\n".join(table_lines(t))
    return out


def write_doc_tables(sections: list[PaperSection], path: Path) -> Path:
    d = {s.paper: section_doc_tables(s) for s in sections}
    path.write_text(json.dumps(d, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    return path


def table_block(name: str, body: str) -> str:
    return f"{TABLE_BEGIN.format(name=name)}\n\n{body}\n\n{TABLE_END.format(name=name)}"


def table_blocks(text: str) -> dict[str, str]:
    """{name: the whole block} of every named table block of a page."""
    out = {}
    for m in _TABLE_RE.finditer(text):
        name = m.group(1)
        end = TABLE_END.format(name=name)
        j = text.find(end, m.end())
        if j < 0:
            raise ValueError(f"table block {name!r} has no end marker")
        out[name] = text[m.start():j + len(end)]
    return out


def stale_blocks(text: str, paper: str, numbers: list[dict], tables: dict) -> list[str]:
    """Names of the generated blocks of one page that differ from the build's data ("numbers" for the
    numbers block); a block the build did not write is stale too."""
    bad = []
    block = doc_block(text)
    if block is not None and block != docs_table(numbers, paper):
        bad.append("numbers")
    mine = tables.get(paper, {})
    for name, blk in table_blocks(text).items():
        if name not in mine or blk != table_block(name, mine[name]):
            bad.append(name)
    return bad


def update_docs(docs_dir: Path, csv_path: Path, tables_path: Path | None = None) -> list[Path]:
    """Rewrites the generated blocks of every docs/paperNNN.md of a paper in the build."""
    rows = read_numbers_csv(csv_path)
    tables_path = tables_path or Path(csv_path).with_name("doc_tables.json")
    tables = json.loads(tables_path.read_text(encoding="utf-8")) if tables_path.exists() else {}
    done = []
    for paper in sorted({r["paper"] for r in rows} | set(tables)):
        p = Path(docs_dir) / f"paper{paper}.md"
        if not p.exists():
            continue
        text = old = p.read_text(encoding="utf-8")
        blk = doc_block(text)
        if blk is not None and any(r["paper"] == paper for r in rows):
            text = text.replace(blk, docs_table(rows, paper))
        for name, blk in table_blocks(text).items():
            if name in tables.get(paper, {}):
                text = text.replace(blk, table_block(name, tables[paper][name]))
        if text != old:
            p.write_text(text, encoding="utf-8")
        done.append(p)
    return done


__all__ = ["DOC_BEGIN", "DOC_END", "docs_table", "doc_block", "update_docs", "write_doc_tables", "stale_blocks",
           "table_blocks", "table_block", "number_counts"]
