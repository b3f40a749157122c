"""Numbers in the prose of the report's pages (docs/paper00*.md, docs/sensing.md, docs/report.md) checked
against the report's data: every number written by hand outside a generated block must be one the report
prints (its page, ``numbers.csv``, ``doc_tables.json``; of the quick build, or of the last full build, whose
printed values are recorded in ``tests/data/report_full_values.json``), at the precision it is written with.

Not numbers of the prose: generated blocks (``<!-- numbers:… -->``, ``<!-- table:NAME:… -->``,
``<!-- timings:… -->``), code (fenced and inline), link targets, and identifiers (claim and run ids,
issue, paper, table, equation, section and figure numbers, dates). A part of a page that records the
output of another command (not the report) says so with ``<!-- prose: from <command> -->`` … ``<!-- prose:end
-->``; it is not checked against the report, and the test lists those parts.

  python -m scfmu.report.prose OUT [OUT2 …] --pages docs/paper000.md …   # the unmatched numbers per page
  python -m scfmu.report.prose OUT --values > tests/data/report_full_values.json   # record a full build
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

PAGES = ("docs/paper000.md", "docs/paper001.md", "docs/paper002.md", "docs/paper003.md", "docs/paper004.md",
         "docs/sensing.md", "docs/report.md")
DATA_FILES = ("report.md", "numbers.csv", "doc_tables.json")

_BLOCK = re.compile(r"<!-- (numbers|table:[A-Za-z0-9_.-]+|timings):begin.*?<!-- \1:end -->", re.S)
_OTHER = re.compile(r"<!-- prose: from (.*?) -->.*?<!-- prose:end -->", re.S)
_FENCE = re.compile(r"```.*?```", re.S)
_CODE = re.compile(r"`[^`]*`")
_LINK = re.compile(r"\]\([^)]*\)|https?://\S+|\b[\w/.-]+\.(?:md|png|py|json|csv|rs|fmu|ssp|sh|toml)\b")
_IDS = re.compile(r"\b(?:C\d{3}-\d+|Csensing-\d|\d{3}-\d+[A-Za-z]*\w*|R[12](?:-[\d.]+)?(?:-\w+)*|"
                  r"[Ii]ssues? \d+(?:(?:, | and )\d+)*|[Pp]apers? \d{3}(?:(?:, | and |/| or )\d{3})*|"
                  r"Tables? \d+(?:(?:, | and )\d+)*|Eqs?\. \d+[a-z]?|Sec\. [\d.]+|Fig(?:ure)?s?\.? \d+|"
                  r"\d{4}-\d{2}-\d{2}|(?:19|20)\d{2}|FMI \d\.\d)\b")
_NUM = re.compile(r"(?<![\w.])\d+(?:\.\d+)?(?:e[−-]?\d+)?(?![\w])")
_DATA_NUM = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def prose(text: str) -> str:
    """The page without its generated blocks, parts from other commands, code, link targets and identifiers."""
    for rx in (_BLOCK, _OTHER, _FENCE, _CODE, _LINK, _IDS):
        text = rx.sub(" ", text)
    return text


def other_parts(text: str) -> list[str]:
    """The commands whose output a page records outside the report (``<!-- prose: from … -->``)."""
    return _OTHER.findall(text)


def numbers(text: str) -> list[str]:
    """The numbers of a page's prose, as written."""
    return _NUM.findall(prose(text).replace("−", "-"))


def values(text: str) -> set[float]:
    """Every number a data file holds (magnitudes)."""
    out = set()
    for m in _DATA_NUM.findall(text):
        try:
            out.add(abs(float(m)))
        except ValueError:
            pass
    return out


def build_values(out_dir: Path) -> set[float]:
    """The numbers a build printed (its page, numbers.csv, doc_tables.json)."""
    vals: set[float] = set()
    for n in DATA_FILES:
        p = Path(out_dir) / n
        if p.exists():
            vals |= values(p.read_text(encoding="utf-8"))
    return vals


def matches(token: str, vals: set[float]) -> bool:
    """The number as written is one of ``vals`` at its written precision (half a unit of its last digit)."""
    t = token.replace("−", "-")
    x = float(t)
    if "e" in t.lower():
        tol = abs(x) * 5e-3
    else:
        dec = len(t.split(".")[1]) if "." in t else 0
        tol = 0.5 * 10.0 ** -dec
    return any(abs(v - x) <= tol * (1 + 1e-9) for v in vals)


def unmatched(text: str, vals: set[float]) -> list[str]:
    return [t for t in numbers(text) if not matches(t, vals)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m scfmu.report.prose", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="+", type=Path, help="build folders (their report.md, numbers.csv, doc_tables.json)")
    ap.add_argument("--pages", nargs="*", type=Path, default=[Path(p) for p in PAGES])
    ap.add_argument("--values", action="store_true", help="print the builds' values as JSON (a record)")
    ap.add_argument("--recorded", type=Path, default=None, help="a recorded values file to add")
    a = ap.parse_args(argv)
    vals: set[float] = set()
    for d in a.out:
        vals |= build_values(d)
    if a.values:
        print(json.dumps(sorted(vals)))
        return 0
    if a.recorded:
        vals |= set(json.loads(a.recorded.read_text(encoding="utf-8")))
    bad = 0
    for p in a.pages:
        u = unmatched(p.read_text(encoding="utf-8"), vals)
        bad += len(u)
        print(f"{p}: {len(u)} unmatched" + (f": {' '.join(u)}" if u else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
