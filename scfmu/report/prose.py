"""Numbers in the prose of the report's pages (docs/paper00*.md, docs/sensing.md, docs/report.md) checked
against the report's data: every number written by hand outside a generated block must be one the report
prints in that paper's part of the report (its section of the page, its ``numbers.csv`` rows, its
``doc_tables.json`` tables; docs/report.md: the whole report), of the quick build or of the last full build
(whose printed values are recorded in ``tests/data/report_full_values.json``), at the precision it is
written with.

Not numbers of the prose: generated blocks (``<!-- numbers:… -->``, ``<!-- table:NAME:… -->``,
``<!-- timings:… -->``), code (fenced and inline), link targets, and identifiers (claim and run ids,
issue, paper, table, equation, section and figure numbers, dates).

A part of a page that documents the models or a paper's settings says where its numbers come from with
``<!-- prose: checked against PATH[, PATH …] -->`` … ``<!-- prose:end -->``: its numbers must be the report's or
numbers of those files of the repository (``modelDescription/<Model>.xml``: every variable's start, min, max
and value reference, i.e. the FMUs' declarations; ``.py``: the numeric literals of the module; ``.json``,
``.csv``: every number of the data; the value of a variable declared in rad also in degrees). In such a part
a parameter table's row ``| `kp`, `ki`, `kd` | 2, 0.1, 8 |`` is checked name by name: each default must be
that variable's declared start. A part fenced with ``<!-- prose: from <command> -->`` … ``<!-- prose:end -->``
records another command's output and is not checked; no page has one now, and a test keeps it so.

Pairs. A number written with the setting it holds at (``105.4 at s = 2.62``, ``0.0125 for c = 25``) must
have both numbers in one row of the data (a line of the report, a ``numbers.csv`` row, a line of a
generated table, a line or a declared variable of a named file, or a row of the recorded full build), so a
right number with a wrong setting fails although each number alone is one the report prints. A row of a
hand-written table pairs its numbers the same way: they must share one row of the data.

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
_OTHER = re.compile(r"(?<!`)<!-- prose: from (.*?) -->.*?<!-- prose:end -->", re.S)
_CHECKED = re.compile(r"(?<!`)<!-- prose: checked against ([^`\n>]*?) -->(.*?)<!-- prose:end -->", re.S)
_PAIR = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?:[^\d;:|()\n]{0,24}?\s)?(?:at|for) "
                   r"([A-Za-zΔθλμκσΦτ][\w]{0,8}) = -?(\d+(?:\.\d+)?)(?![\w]|\.\d)")
_RUNS = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?:[^\d;:|()\n]{0,24}?\s)?(?:for|over|in) (\d+) (runs|samples|points)\b")
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
    """The page without its generated blocks, parts from other commands or checked against files, code, link
    targets and identifiers."""
    for rx in (_BLOCK, _OTHER, _CHECKED, _FENCE, _CODE, _LINK, _IDS):
        text = rx.sub(" ", text)
    return text


def other_parts(text: str) -> list[str]:
    """The commands whose output a page records outside the report (``<!-- prose: from … -->``)."""
    return _OTHER.findall(text)


def checked_parts(text: str) -> list[tuple[list[str], str]]:
    """(files, text) of every part checked against files of the repository (``<!-- prose: checked against … -->``)."""
    return [([f.strip() for f in files.split(",") if f.strip()], body) for files, body in _CHECKED.findall(text)]


def numbers(text: str) -> list[str]:
    """The numbers of a page's prose, as written."""
    return _NUM.findall(prose(text).replace("−", "-"))


def pairs(text: str) -> list[tuple[str, str, str]]:
    """(number, setting name, setting value) of every "X at s = Y" / "X for c = Y" of a page's prose."""
    t = prose(text).replace("−", "-")
    return _PAIR.findall(t) + [(x, w, n) for x, n, w in _RUNS.findall(t)]


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


def _build_texts(out_dir: Path, scope: str | None) -> list[str]:
    """The rows a build printed for one paper (``scope``) or all: the lines of its report.md section, its
    numbers.csv rows, the lines of its generated tables."""
    d = Path(out_dir)
    rows: list[str] = []
    if (d / "report.md").exists():
        md = (d / "report.md").read_text(encoding="utf-8")
        rows += (md if scope is None else _section(md, scope)).splitlines()
    if (d / "numbers.csv").exists():
        import csv
        with open(d / "numbers.csv", newline="", encoding="utf-8") as f:
            rows += [" ".join(r[1:]) for r in csv.reader(f) if r and (scope is None or r[0] == scope)]
    if (d / "doc_tables.json").exists():
        t = json.loads((d / "doc_tables.json").read_text(encoding="utf-8"))
        for blocks in (t.values() if scope is None else [t.get(scope, {})]):
            for body in blocks.values():
                rows += body.splitlines()
    return rows


def build_values(out_dir: Path, scope: str | None = None) -> set[float]:
    """The numbers a build printed (its page, numbers.csv, doc_tables.json), for one paper (``scope``) or all."""
    return set().union(*[values(r) for r in _build_texts(out_dir, scope)])


def build_rows(out_dir: Path, scope: str | None = None) -> list[set[float]]:
    """The build's rows (see ``_build_texts``) as sets of numbers, those holding at least two."""
    return [v for v in (values(r) for r in _build_texts(out_dir, scope)) if len(v) > 1]


def file_rows(root: Path, name: str) -> list[set[float]]:
    """The rows of a file a part is checked against: a declared variable of a modelDescription XML (its start,
    min, max and value reference), the numeric literals of a line of a Python module, a line of any other file."""
    path = Path(root) / name
    if not path.is_file():
        raise FileNotFoundError(f"prose: checked against {name}: no such file under {root}")
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".xml":
        return [_variable_values(v) for v in re.split(r"<(?:ScalarVariable|Float64|Int32|Boolean)\b", text)]
    if path.suffix == ".py":
        import ast
        lines: dict[int, set[float]] = {}
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Constant) and type(node.value) in (int, float):
                lines.setdefault(node.lineno, set()).add(abs(float(node.value)))
        return list(lines.values())
    return [values(line) for line in text.splitlines()]


def _variable_values(xml: str) -> set[float]:
    """A declared variable's start, min, max, nominal and value reference; in degrees too when its unit is rad."""
    import math
    v = values(" ".join(re.findall(r'\b(?:start|min|max|nominal)="([^"]*)"', xml)))
    if re.search(r'\bunit="rad(?:/s)?"', xml):
        v |= {math.degrees(x) for x in v}
    return v | values(" ".join(re.findall(r'\bvalueReference="([^"]*)"', xml)))


def scoped_values(dirs: list[Path]) -> dict:
    """{scope: sorted values} over the builds, for every paper page and the whole report ("all"), and under
    "rows" {scope: the rows of at least two numbers}: a record."""
    out: dict = {}
    rows: dict = {}
    for sc in [scope_of(p) for p in PAGES]:
        v: set[float] = set()
        r: set[tuple] = set()
        for d in dirs:
            v |= build_values(d, sc)
            r |= {tuple(sorted(x)) for x in build_rows(d, sc)}
        out[sc or "all"] = sorted(v)
        rows[sc or "all"] = sorted(r)
    out["rows"] = rows
    return out


def matches(token: str, vals) -> bool:
    """The number as written is one of ``vals`` at its written precision (half a unit of its last digit)."""
    t = token.replace("−", "-")
    x = abs(float(t))
    if "e" in t.lower():
        tol = abs(x) * 5e-3
    else:
        dec = len(t.split(".")[1]) if "." in t else 0
        tol = 0.5 * 10.0 ** -dec
    return any(abs(v - x) <= tol * (1 + 1e-9) for v in vals)


def unmatched(text: str, vals: set[float]) -> list[str]:
    return [t for t in numbers(text) if not matches(t, vals)]


def unpaired(text: str, rows: list[set[float]]) -> list[str]:
    """The "X at s = Y" of a page's prose whose two numbers share no row of the data."""
    return [f"{x} at {n} = {y}" if n not in ("runs", "samples", "points") else f"{x} over {y} {n}"
            for x, n, y in pairs(text)
            if not any(matches(x, r) and matches(y, r) for r in rows)]


def unrowed(text: str, rows: list[set[float]]) -> list[str]:
    """The rows of a hand-written table (two numbers or more) whose numbers share no row of the data: a table row
    pairs its numbers as "X at s = Y" does."""
    bad = []
    for line in prose(text).replace("−", "-").splitlines():
        toks = _NUM.findall(line) if line.lstrip().startswith("|") else []
        if len(toks) > 1 and not any(all(matches(t, r) for t in toks) for r in rows):
            bad.append("row " + " ".join(toks))
    return bad


def declared_starts(root: Path, files: list[str]) -> dict[str, set[float]]:
    """{variable name: its declared start (and in degrees when the unit is rad)} of the modelDescription files."""
    out: dict[str, set[float]] = {}
    for f in (f for f in files if f.endswith(".xml")):
        text = (Path(root) / f).read_text(encoding="utf-8")
        for v in re.split(r"<(?:ScalarVariable|Float64|Int32|Boolean)\b", text):
            m = re.search(r'\bname="([^"]+)"', v)
            if m and 'start="' in v:
                start = re.sub(r'\b(?:min|max|nominal|valueReference)="[^"]*"', "", v)
                out.setdefault(m.group(1), set()).update(_variable_values(start))
    return out


def _names(cell: str) -> list[str]:
    """The parameter names a table cell gives in code marks; ``inertia_xx/yy/zz`` is three names."""
    out = []
    for n in re.findall(r"`([A-Za-z_][\w/]*)`", cell):
        head, *tails = n.split("/")
        stem = head.rsplit("_", 1)[0] + "_" if tails and "_" in head else ""
        out += [head] + [stem + t for t in tails]
    return out


def wrong_defaults(body: str, starts: dict[str, set[float]]) -> list[str]:
    """Rows ``| `name`, … | default, … |`` of a parameter table whose defaults are not the declared starts, name by
    name (a row whose names are not all declared variables is not a parameter row)."""
    bad = []
    for line in body.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2 or not line.lstrip().startswith("|"):
            continue
        names = _names(cells[0])
        nums = _NUM.findall(cells[1].replace("−", "-"))
        if not names or not all(n in starts for n in names) or len(nums) not in (1, len(names)):
            continue
        for n, t in zip(names, nums * len(names) if len(nums) == 1 else nums):
            if not matches(t, starts[n]):
                bad.append(f"{n} = {t}")
    return bad


def check_text(text: str, vals: set[float], rows: list[set[float]], root: Path) -> list[str]:
    """The numbers of a page that are not in the data, and its pairs that share no row; the parts checked against
    files also against those files."""
    bad = unmatched(text, vals) + unpaired(text, rows) + unrowed(text, rows)
    for files, body in checked_parts(text):
        frows = [r for f in files for r in file_rows(root, f)]
        v2 = vals.union(*frows)
        bad += [t for t in _NUM.findall(prose(body).replace("−", "-")) if not matches(t, v2)]
        bad += unpaired(body, rows + frows) + unrowed(body, rows + frows)
        bad += wrong_defaults(body, declared_starts(root, files))
    return bad


def check(pages, dirs: list[Path], recorded: dict | None = None, root: Path = Path(".")) -> dict[str, list[str]]:
    """{page: numbers of its prose that are not in its part of the builds' data (or of the recorded data, or of
    the files a part names, relative to the repository's folder ``root``), and pairs and table rows that share no
    row}."""
    out = {}
    for p in pages:
        sc = scope_of(str(p))
        vals: set[float] = set()
        rows: list[set[float]] = []
        for d in dirs:
            vals |= build_values(d, sc)
            rows += build_rows(d, sc)
        vals |= set((recorded or {}).get(sc or "all", []))
        rows += [set(r) for r in (recorded or {}).get("rows", {}).get(sc or "all", [])]
        out[str(p)] = check_text(Path(p).read_text(encoding="utf-8"), vals, rows, Path(root))
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
