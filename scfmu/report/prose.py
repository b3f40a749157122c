"""Numbers in the prose of the report's pages (docs/paper00*.md, docs/sensing.md, docs/report.md) checked
against the report's data: every number written by hand outside a generated block must be one the report
prints in that paper's part of the report (its section of the page, its ``numbers.csv`` rows, its
``doc_tables.json`` tables; docs/report.md: the whole report), of the quick build or of the last full build
(whose printed values are recorded in ``tests/data/report_full_values.json``), at the precision it is
written with.

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
                  r"\d{4}-\d{2}-\d{2}|(?:19|20)\d{2}|FMI \d\.\d|321(?=[- ](?:angle|Euler|\(yaw)))\b")
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


def scope_of(page: str) -> str | None:
    """Which part of the report a page is checked against: docs/paperNNN.md → paper NNN's section, rows and
    tables; docs/sensing.md → the sensing section; any other page → the whole report."""
    name = Path(page).stem
    if name.startswith("paper") and name[5:].isdigit():
        return name[5:]
    return "sensing" if name == "sensing" else None


def _section(md: str, scope: str) -> str:
    """The part of a build's report.md about one paper (its "## Paper NNN" section)."""
    head = f"\n## Paper {scope}:"
    i = md.find(head)
    if i < 0:
        return ""
    j = md.find("\n## Paper ", i + len(head))
    return md[i:] if j < 0 else md[i:j]


def build_values(out_dir: Path, scope: str | None = None) -> set[float]:
    """The numbers a build printed (its page, numbers.csv, doc_tables.json), for one paper (``scope``) or all."""
    d = Path(out_dir)
    vals: set[float] = set()
    if (d / "report.md").exists():
        md = (d / "report.md").read_text(encoding="utf-8")
        vals |= values(md if scope is None else _section(md, scope))
    if (d / "numbers.csv").exists():
        import csv
        with open(d / "numbers.csv", newline="", encoding="utf-8") as f:
            for row in csv.reader(f):
                if scope is None or (row and row[0] == scope):
                    vals |= values(" ".join(row[1:] if row else []))
    if (d / "doc_tables.json").exists():
        t = json.loads((d / "doc_tables.json").read_text(encoding="utf-8"))
        vals |= values(json.dumps(t if scope is None else t.get(scope, {}), ensure_ascii=False))
    return vals


def scoped_values(dirs: list[Path]) -> dict[str, list[float]]:
    """{scope: sorted values} over the builds, for every paper page and the whole report ("all"): a record."""
    scopes = [scope_of(p) for p in PAGES]
    out = {}
    for sc in scopes:
        v: set[float] = set()
        for d in dirs:
            v |= build_values(d, sc)
        out[sc or "all"] = sorted(v)
    return out


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


def check(pages, dirs: list[Path], recorded: dict | None = None) -> dict[str, list[str]]:
    """{page: numbers of its prose that are not in its part of the builds' data (or of the recorded data)}."""
    out = {}
    for p in pages:
        sc = scope_of(str(p))
        vals: set[float] = set()
        for d in dirs:
            vals |= build_values(d, sc)
        vals |= set((recorded or {}).get(sc or "all", []))
        out[str(p)] = unmatched(Path(p).read_text(encoding="utf-8"), vals)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m scfmu.report.prose", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="+", type=Path, help="build folders (their report.md, numbers.csv, doc_tables.json)")
    ap.add_argument("--pages", nargs="*", type=Path, default=[Path(p) for p in PAGES])
    ap.add_argument("--values", action="store_true", help="print the builds' values per page scope as JSON (a record)")
    ap.add_argument("--recorded", type=Path, default=None, help="a recorded values file to add")
    a = ap.parse_args(argv)
    if a.values:
        print(json.dumps(scoped_values(a.out)))
        return 0
    rec = json.loads(a.recorded.read_text(encoding="utf-8")) if a.recorded else None
    res = check(a.pages, a.out, rec)
    for p, u in res.items():
        print(f"{p}: {len(u)} unmatched" + (f": {' '.join(u)}" if u else ""))
    return 1 if any(res.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
