"""How long ``scfmu report`` takes, measured, in one place: every build writes ``OUT/timings.json`` (wall time,
report time and runs per section, workers, the machine's cores and its load average before the build);
``scfmu/report/timings.json`` holds the recorded quick and full builds, and the block between
``TIMINGS_BEGIN`` and ``TIMINGS_END`` in ``README.md`` and ``docs/report.md`` is written from it
(``python -m scfmu.report.timings --write README.md docs/report.md``; a test fails while a block differs).

  python -m scfmu.report.timings --record quick out/report_quick/timings.json   # after a measured build
  python -m scfmu.report.timings --write README.md docs/report.md
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from importlib import resources
from pathlib import Path

TIMINGS_BEGIN = "<!-- timings:begin (written by `python -m scfmu.report.timings --write`; do not edit by hand) -->"
TIMINGS_END = "<!-- timings:end -->"
QUICK_BUDGET_S = 300.0   # `scfmu report --quick` on an idle 2-core machine, 2 workers (issue 46)
RECORD = "timings.json"  # package data beside this module: {"quick": build, "full": build}


def measure_start() -> dict:
    """What a build records before it starts: date, cores, load average."""
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return {"date": time.strftime("%Y-%m-%d", time.gmtime()), "cores": os.cpu_count(), "load_before": round(load[0], 2)}


def build_record(start: dict, quick: bool, workers: int, wall_s: float, sections: dict, runs: dict) -> dict:
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return {**start, "mode": "quick" if quick else "full", "workers": workers, "wall_s": round(wall_s, 1),
            "load_after": round(load[0], 2), "sections_s": {k: round(v, 1) for k, v in sections.items()},
            "runs": dict(runs)}


def recorded() -> dict:
    return json.loads(resources.files("scfmu.report").joinpath(RECORD).read_text(encoding="utf-8"))


def _one(b: dict) -> str:
    secs = ", ".join(f"{k} {v:g} s" for k, v in b["sections_s"].items())
    return (f"`{'scfmu report --quick' if b['mode'] == 'quick' else 'scfmu report'}`: **{b['wall_s']:g} s** "
            f"({b['wall_s'] / 60:.1f} min) of report time, {sum(b['runs'].values())} runs on {b['workers']} Dask "
            f"workers ({secs}); measured {b['date']} on {b['cores']} cores with a load average of "
            f"{b['load_before']:g} before the build ({b['load_after']:g} after it, the build's own load included)")


def block(data: dict | None = None) -> str:
    """The Markdown block README.md and docs/report.md show."""
    d = recorded() if data is None else data
    lines = [TIMINGS_BEGIN, ""]
    for mode in ("quick", "full"):
        if mode in d:
            lines.append(f"- {_one(d[mode])}.")
    q = d.get("quick")
    if q:
        lines += ["", f"Budget of the quick build: {QUICK_BUDGET_S:g} s on an idle 2-core machine "
                      f"({'met' if q['wall_s'] <= QUICK_BUDGET_S else 'NOT met'} by the recorded build). Under load "
                      f"the times grow with the load average (the builds share the cores)."]
    return "\n".join(lines + ["", TIMINGS_END])


def stale(text: str, data: dict | None = None) -> bool:
    """The page's timings block differs from the recorded builds (a page without one is not stale)."""
    i, j = text.find(TIMINGS_BEGIN), text.find(TIMINGS_END)
    if i < 0:
        return False
    return text[i:j + len(TIMINGS_END)] != block(data)


def write(paths: list[Path], data: dict | None = None) -> None:
    new = block(data)
    for p in paths:
        t = p.read_text(encoding="utf-8")
        i, j = t.find(TIMINGS_BEGIN), t.find(TIMINGS_END)
        if i < 0 or j < i:
            raise SystemExit(f"{p}: no timings block ({TIMINGS_BEGIN} … {TIMINGS_END})")
        p.write_text(t[:i] + new + t[j + len(TIMINGS_END):], encoding="utf-8")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m scfmu.report.timings", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--record", nargs=2, metavar=("MODE", "TIMINGS_JSON"),
                    help="copy a build's timings.json into the recorded builds (MODE: quick or full)")
    ap.add_argument("--write", nargs="*", type=Path, default=[], help="rewrite the timings block of these pages")
    a = ap.parse_args(argv)
    if a.record:
        mode, src = a.record
        if mode not in ("quick", "full"):
            raise SystemExit("--record: MODE is quick or full")
        b = json.loads(Path(src).read_text(encoding="utf-8"))
        if b.get("mode") != mode:
            raise SystemExit(f"--record {mode}: {src} is a {b.get('mode')} build")
        target = Path(str(resources.files("scfmu.report").joinpath(RECORD)))
        d = json.loads(target.read_text(encoding="utf-8")) if target.exists() else {}
        d[mode] = b
        target.write_text(json.dumps(d, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    if a.write:
        write(a.write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
