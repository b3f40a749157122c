"""The papers' reported numbers beside ours: the rows of ``numbers.csv`` and the "paper vs ours" tables of the
report (HTML, Markdown, terminal) and of the docs pages.

Every row carries how ours was obtained (``NumberRow.basis``: independent, calibrated, fixed by construction,
chosen among readings) and the bounds it was checked against. Only independent rows are evidence: the
counts per verdict ("At a glance", the docs' count line) are over independent rows; the others are shown,
labelled, and counted apart as "not evidence".
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from .fmt import _e, _is_num, _md, _paras, badge, fmt_cell
from .types import INDEPENDENT, NOT_CHECKABLE, NUMBER_VERDICTS, NumberRow, PaperSection

# numbers.csv: one row per reported number (the same table as the report's "paper vs ours" tables)
CSV_COLUMNS = ["paper", "item", "unit", "paper value", "our value", "relative difference", "verdict", "obtained",
               "bounds", "note", "sensitivity", "rule"]


def fmt_num(v, digits: int = 4) -> str:
    if v is None:
        return "–"
    return fmt_cell(float(v), digits) if _is_num(v) else str(v)


def fmt_rel(x: float) -> str:
    """Relative difference as a signed percentage ("+0.7 %"), "–" when undefined."""
    if x is None or not isinstance(x, float) or math.isnan(x):
        return "–"
    return f"{100 * x:+.1f} %"


def number_cells(n: NumberRow) -> list[str]:
    """[item, unit, paper value, our value, relative difference, verdict, obtained, note] as plain text."""
    paper = n.paper_text or fmt_num(n.paper_value)
    note = "; ".join(x for x in (n.note, n.rule) if x)
    return [n.item, n.unit, paper, fmt_num(n.ours), fmt_rel(n.rel_diff), n.verdict, obtained_text(n.basis, n.sensitivity),
            note]


def obtained_text(basis: str, sensitivity: str = "") -> str:
    """How ours was obtained, with a calibrated row's sensitivity across the calibration grid beside it."""
    return f"{basis} ({sensitivity})" if sensitivity else basis


def number_counts(numbers: list[NumberRow]) -> dict:
    """{verdict: count} over the independent rows (NUMBER_VERDICTS, zeros included) and "not evidence": the
    rows obtained otherwise (calibrated, fixed by construction, chosen among readings)."""
    d = {v: sum(1 for n in numbers if n.verdict == v and n.basis == INDEPENDENT) for v in NUMBER_VERDICTS}
    d["not evidence"] = sum(1 for n in numbers if n.basis != INDEPENDENT)
    return d


def counts_text(d: dict, independent: int, total: int) -> str:
    return (", ".join(f"{v} {d[v]}" for v in NUMBER_VERDICTS) + f"; not evidence (calibrated, by construction or "
            f"chosen) {d['not evidence']}; independent checks {independent} of {total}")


def numbers_csv_rows(sections: list[PaperSection]) -> list[list[str]]:
    """The rows of numbers.csv (CSV_COLUMNS), every section's numbers in order. Numbers are written with
    6 significant digits, the relative difference as a fraction (empty when undefined), the bounds
    separated by ";"."""
    out = []
    for s in sections:
        for n in s.numbers:
            rd = n.rel_diff
            out.append([s.paper, n.item, n.unit,
                        n.paper_text or ("" if n.paper_value is None else f"{float(n.paper_value):.6g}"),
                        "" if n.ours is None else (f"{float(n.ours):.6g}" if _is_num(n.ours) else str(n.ours)),
                        "" if math.isnan(rd) else f"{rd:.6g}", n.verdict, n.basis,
                        ";".join(f"{b:.6g}" for b in n.bounds), n.note, n.sensitivity, n.rule])
    return out


def write_numbers_csv(sections: list[PaperSection], path: Path) -> Path:
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(CSV_COLUMNS)
        w.writerows(numbers_csv_rows(sections))
    return path


def read_numbers_csv(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def numbers_md(numbers: list[NumberRow], digits: int = 4) -> list[str]:
    """The paper-vs-ours table in Markdown."""
    out = ["| item | unit | paper | ours | difference | verdict | obtained | note |",
           "|---|---|---:|---:|---:|---|---|---|"]
    for n in numbers:
        out.append("| " + " | ".join(_md(c) for c in number_cells(n)) + " |")
    d = number_counts(numbers)
    out += ["", "Counts: " + counts_text(d, sum(1 for n in numbers if n.independent), len(numbers)) + "."]
    return out


def numbers_html(sec: PaperSection) -> str:
    if not sec.numbers:
        return ""
    rows = []
    for n in sec.numbers:
        c = number_cells(n)
        rows.append(f"<tr><td>{_e(c[0])}</td><td>{_e(c[1])}</td><td class=\"num\">{_e(c[2])}</td>"
                    f"<td class=\"num\">{_e(c[3])}</td><td class=\"num\">{_e(c[4])}</td><td>{badge(n.verdict)}</td>"
                    f"<td>{badge(n.basis)}{_e(' ' + n.sensitivity) if n.sensitivity else ''}</td><td>{_e(c[7])}</td></tr>")
    counts = number_counts(sec.numbers)
    indep = [n for n in sec.numbers if n.independent]
    other = [f"{n.item} ({n.basis})" for n in sec.numbers if n.basis != INDEPENDENT]
    head = (f"<h3 id=\"numbers{_e(sec.paper)}\">The paper's numbers beside ours</h3><p>Independent rows: "
            + " · ".join(f"{badge(v)} {counts[v]}" for v in NUMBER_VERDICTS)
            + f"</p><p>Independent checks (obtained independently, and checkable): {len(indep)} of "
              f"{len(sec.numbers)}" + (f"; not evidence: {_e('; '.join(other))}" if other else "") + ".</p>")
    cal_txt = _paras(sec.calibrations) if sec.calibrations else ""
    return (head + "<table class=\"numbers\"><thead><tr><th>item</th><th>unit</th><th>paper</th><th>ours</th>"
            "<th>difference</th><th>verdict</th><th>obtained</th><th>note</th></tr></thead><tbody>"
            + "".join(rows) + "</tbody></table>" + cal_txt)


def numbers_text(sections: list[PaperSection]) -> str:
    """The paper-vs-ours rows and the per-paper counts as plain text for the terminal."""
    lines = [f"{'paper':5s} {'item':44s} {'paper':>14s} {'ours':>11s} {'diff':>9s} verdict"]
    for s in sections:
        for n in s.numbers:
            c = number_cells(n)
            item = c[0] if len(c[0]) <= 44 else c[0][:43] + "…"
            lines.append(f"{s.paper:5s} {item:44s} {c[2][:14]:>14s} {c[3]:>11s} {c[4]:>9s} {n.verdict}"
                         + ("" if n.basis == INDEPENDENT else f" ({n.basis})"))
    lines.append("")
    for s in sections:
        lines.append(f"paper {s.paper}: " + counts_text(number_counts(s.numbers), sum(1 for n in s.numbers
                                                                                     if n.independent), len(s.numbers)))
    return "\n".join(lines)


def row_independent(r: dict) -> bool:
    """A numbers.csv row (dict) is an independent check."""
    return r["obtained"] == INDEPENDENT and r["verdict"] != NOT_CHECKABLE
