"""Reproduction report: runs the experiments of the papers on the campaign engine (one Dask LocalCluster
for all of them), decides a verdict for every claim of every paper, and writes a static HTML page with
its figures and a Markdown copy.

  scfmu report                      # full report, all papers, out/report/index.html
  scfmu report --quick --workers 2  # reduced grids (CI), a few minutes
  scfmu report --papers 001,004     # some papers only

Each paper is a module scfmu.report.paperNNN with build(ctx) -> PaperSection (docs/report.md). The
campaigns of a paper are stored under OUT/runs/<name>; running the same command again resumes them
(runs already done are not repeated). Prints the claims table and the path of index.html.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path


from importlib import resources

from ..registry import REGISTRY, resolve
from ..scenario.values import UsageError
from .types import Context


def papers_known() -> tuple:
    """The papers whose plug-ins have a report section (all of them in a default build)."""
    return tuple(p.key for p in REGISTRY.all_papers() if p.report and p.key.isdigit())


def studies_known() -> tuple:
    """Plug-ins with a report section that are studies across papers, not papers (e.g. ``sensing``)."""
    return tuple(p.key for p in REGISTRY.all_papers() if p.report and not p.key.isdigit())


class ReportContext(Context):
    """Context that also counts the simulation runs of each paper (campaign rows, plus runs a section
    declares itself with ``add_runs``, e.g. optimiser evaluations)."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.paper = ""
        self.runs: dict[str, int] = {}

    def add_runs(self, n: int) -> None:
        self.runs[self.paper] = self.runs.get(self.paper, 0) + int(n)

    def campaign(self, c, name: str):
        table = super().campaign(c, name)
        self.add_runs(table.num_rows)
        return table


def git_commit() -> str:
    try:
        here = str(resources.files("scfmu"))  # a source checkout: its commit; an installed wheel: no git
        sha = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=here, capture_output=True, text=True,
                             check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                               capture_output=True, text=True).stdout.strip()
        return sha + ("+local changes" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        from .. import __version__
        return f"scfmu {__version__} (no git checkout)"


def parse_papers(text: str | None) -> list[str]:
    if not text:
        return list(papers_known()) + list(studies_known())
    out = []
    for p in text.split(","):
        p = p.strip()
        if not p:
            continue
        if p in studies_known():
            out.append(p)
            continue
        if not (p.isdigit() and len(p) <= 3):
            raise UsageError(f"--papers {text}: {p!r} is not a paper number ({', '.join(papers_known())}) nor a study "
                             f"({', '.join(studies_known())})")
        out.append(p.zfill(3))
    return out


def load_modules(papers: list[str]) -> dict:
    """The section builder of each paper's plug-in; an unknown paper or one without a section is an error
    (before any run)."""
    builders = {}
    for p in papers:
        try:
            plugin = REGISTRY.paper_plugin(p)
        except KeyError as e:
            raise UsageError(f"--papers: {e.args[0]}") from None
        if not plugin.report:
            raise UsageError(f"--papers: paper {p} ({plugin.plugin}) has no report section")
        builders[p] = resolve(plugin.report)
    return builders


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="scfmu report", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="reduced grids and run counts (CI)")
    ap.add_argument("--workers", type=int, default=2, help="Dask LocalCluster workers (default 2)")
    ap.add_argument("--papers", default=None, help="comma-separated paper numbers (default: every paper with a report section)")
    ap.add_argument("--out", type=Path, default=Path("out") / "report", help="output folder (index.html goes here)")
    ap.add_argument("--docs", type=Path, default=None,
                    help="also rewrite the generated blocks of each DOCS/paperNNN.md (the 'paper vs ours' table from "
                         "numbers.csv, the claims and results tables from doc_tables.json)")
    args = ap.parse_args(argv)
    if not 1 <= args.workers <= 1024:
        raise UsageError(f"--workers {args.workers}: allowed: a whole number in [1, 1024]")

    papers = parse_papers(args.papers)
    mods = load_modules(papers)
    from scfmu import campaign
    from scfmu.report import render

    from . import timings
    start = timings.measure_start()
    t_all = time.time()
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"report: papers {', '.join(papers)}, {'quick' if args.quick else 'full'} mode, {args.workers} Dask "
          f"workers -> {args.out}", flush=True)
    import warnings
    warnings.filterwarnings("ignore", message=".*Port .* is already in use.*")
    client, cluster = campaign._client(None, args.workers)
    ctx = ReportContext(out_dir=args.out, quick=args.quick, workers=args.workers, client=client)
    sections = []
    try:
        for p in papers:
            ctx.paper = p
            print(f"\n== paper {p} ==", flush=True)
            t0 = time.time()
            sec = mods[p](ctx)
            if not sec.runtime_s:
                sec.runtime_s = time.time() - t0
            sections.append(sec)
            print(f"paper {p}: {len(sec.claims)} claims, {ctx.runs.get(p, 0)} runs, {sec.runtime_s:.1f} s", flush=True)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    meta = {"title": "Reproduction report: the papers' claims checked with the FMUs",
            "built": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()), "commit": git_commit(),
            "quick": args.quick, "workers": args.workers, "runs": dict(ctx.runs),
            "runtime_s": time.time() - t_all,
            "intro": "Each paper section opens with the paper's reported numbers beside ours (verdicts: reproduced, "
                     "same ordering only, not reproduced, not checkable), each row saying how ours was obtained: "
                     "independent, calibrated (fitted to this number), fixed by construction (a search bound or an "
                     "optimiser constraint puts it there) or chosen among readings after comparing with the paper; "
                     "only independent rows are evidence. Each claim below is one of the papers' stated conclusions, in our words. "
                     "Its verdict is decided by an explicit rule in the code of the paper's section (stated with the "
                     "evidence): confirmed (holds with today's set-up and every other plausible reading checked), "
                     "not confirmed, or depends on a reading (named). A reading under which a claim holds only by "
                     "moving the paper's own numbers further away is listed and never counted as support. "
                     "Sensitivity blocks show the values tried and where the claim holds."}
    html_path, md_path = render.render(sections, args.out, meta)
    if args.docs is not None:
        for p in render.update_docs(args.docs, args.out / "numbers.csv", args.out / "doc_tables.json"):
            print(f"updated {p}")
    rec = timings.build_record(start, args.quick, args.workers, time.time() - t_all,
                               {s.paper: s.runtime_s for s in sections}, ctx.runs)
    (args.out / "timings.json").write_text(json.dumps(rec, indent=1) + "\n", encoding="utf-8")
    print("\n" + render.numbers_text(sections))
    print("\n" + render.claims_text(sections))
    print(f"\nreport: {html_path.resolve()}\nmarkdown: {md_path.resolve()}\n"
          f"total {time.time() - t_all:.1f} s, runs per paper: {dict(ctx.runs)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
