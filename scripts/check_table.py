#!/usr/bin/env python3
"""The unit × check table of ``scfmu check`` over a folder of FMUs (docs/check.md's table of the Modelica
Reference-FMUs was made with it):

    .venv/bin/python scripts/check_table.py DIR [DIR ...] [--quick] [--json FILE]

Every ``*.fmu`` under each DIR (a folder per FMI version is fine: the unit's row says its version) is
checked, one unit after the other; the Markdown table goes to stdout: a cell is ``pass``, ``n/a``, or the
class of the finding, ``STD`` (violates the FMI standard) or ``ROB`` (fails a robustness rule of this
project), with the interface when only one of them failed. ``--json`` also writes every report. A folder
that does not exist or holds no FMU is a usage mistake (one line, exit 2)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

TAG = {"standard": "STD", "robustness": "ROB"}


def cell(rows: list[dict]) -> str:
    """One table cell from the rows of one check (one per interface, or one static row)."""
    if not rows:
        return "-"
    fails = [r for r in rows if r["status"] == "fail"]
    if not fails:
        return "pass" if any(r["status"] == "pass" for r in rows) else "n/a"
    parts = []
    for cls in ("standard", "robustness"):
        itfs = [(r.get("interface") or "").upper() for r in fails if r.get("class") == cls]
        if itfs:
            both = len(rows) > 1 and len(itfs) == len(rows)
            parts.append(TAG[cls] + ("" if both or not itfs[0] else " " + "+".join(itfs)))
    return ", ".join(parts)


def table(reports: list[dict]) -> str:
    from scfmu.check import DYNAMIC_CHECKS, STATIC_CHECKS
    checks = list(STATIC_CHECKS) + list(DYNAMIC_CHECKS)
    head = "| unit | FMI | " + " | ".join(f"`{c}`" for c in checks) + " | seconds |"
    out = [head, "|" + "---|" * (len(checks) + 3)]
    for rep in reports:
        by = {c: [r for r in rep["rows"] if r["check"] == c] for c in checks}
        out.append(f"| {rep['model'] or Path(rep['fmu']).stem} | {rep['fmi_version']} | "
                   + " | ".join(cell(by[c]) for c in checks) + f" | {rep['seconds']:.0f} |")
    return "\n".join(out)


def counts(reports: list[dict]) -> dict:
    """Failed rows by class, and units with at least one finding of each class."""
    n = {"standard": 0, "robustness": 0, "units_failing": 0, "units_with_standard": 0, "units": len(reports)}
    for rep in reports:
        f = [r for r in rep["rows"] if r["status"] == "fail"]
        n["standard"] += sum(r.get("class") == "standard" for r in f)
        n["robustness"] += sum(r.get("class") == "robustness" for r in f)
        n["units_failing"] += bool(f)
        n["units_with_standard"] += any(r.get("class") == "standard" for r in f)
    return n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="check_table.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("dirs", nargs="+", help="folders holding .fmu files")
    ap.add_argument("--quick", action="store_true", help="scfmu check --quick for each unit")
    ap.add_argument("--json", metavar="FILE", help="also write every report to FILE")
    a = ap.parse_args(argv)
    fmus = []
    for d in a.dirs:
        p = Path(d)
        found = sorted(p.rglob("*.fmu")) if p.is_dir() else []
        if not found:
            print(f"check_table.py: folder {d!r} {'holds no .fmu file' if p.is_dir() else 'does not exist'}; "
                  f"allowed: a folder with FMUs", file=sys.stderr)
            return 2
        fmus += found
    from scfmu.check import check
    reports = []
    for f in fmus:
        t = time.monotonic()
        rep = check(f, quick=a.quick).to_dict()
        reports.append(rep)
        print(f"check_table.py: {f}: {time.monotonic() - t:.0f} s", file=sys.stderr)
    print(table(reports))
    print()
    print(json.dumps(counts(reports)))
    if a.json:
        Path(a.json).write_text(json.dumps(reports, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
