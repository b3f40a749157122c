"""Reproduction report: the renderer on synthetic sections (fast), the verdict rules on small synthetic
tables, and one end-to-end --quick build (scfmu report) whose claims table is checked."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

from scfmu.report import cli as report_cli
from scfmu.report import render, rules
from scfmu.report.types import (CONFIRMED, DEPENDS, NOT_CONFIRMED, Claim, Figure, PaperSection,
                                Sensitivity, Table)

# The papers CI builds with --quick: every paper plug-in with a report section.
CI_PAPERS = report_cli.papers_known()
# Every claim id of those papers (the list of the papers' conclusions).
CLAIM_IDS = {
    "000": [f"C000-{i}" for i in range(1, 8)],
    "001": [f"C001-{i}" for i in range(1, 5)],
    "002": [f"C002-{i}" for i in range(1, 6)],
    "003": [f"C003-{i}" for i in range(1, 3)],
    "004": [f"C004-{i}" for i in range(1, 5)],
}

PNG_1x1 = bytes.fromhex("89504e470d0a1a0a0000000d4948445200000001000000010806000000"
                        "1f15c4890000000d49444154789c6360000002000100ffff03000006000557bfab"
                        "d40000000049454e44ae426082")


class _Page(HTMLParser):
    """Collects the claims table rows, every <img src>, and checks tags are balanced."""

    VOID = {"meta", "img", "br", "hr", "link", "input"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.imgs, self.rows = [], [], []
        self.in_claims = False
        self.cell = None
        self.row = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.imgs.append(a["src"])
        if tag not in self.VOID:
            self.stack.append(tag)
        if tag == "table" and a.get("id") == "claims":
            self.in_claims = True
        if self.in_claims and tag == "tr":
            self.row = []
        if self.in_claims and tag == "td":
            self.cell = ""

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        assert self.stack and self.stack[-1] == tag, f"unbalanced </{tag}>, open: {self.stack[-3:]}"
        self.stack.pop()
        if self.in_claims and tag == "td":
            self.row.append(self.cell.strip())
            self.cell = None
        if self.in_claims and tag == "tr" and self.row:
            self.rows.append(self.row)
        if tag == "table" and self.in_claims:
            self.in_claims = False

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data


def parse(path: Path) -> _Page:
    p = _Page()
    p.feed(path.read_text(encoding="utf-8"))
    p.close()
    assert p.stack == [], f"unclosed tags {p.stack}"
    return p


def synthetic_sections(out: Path) -> list[PaperSection]:
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    (figs / "a.png").write_bytes(PNG_1x1)
    (figs / "b.png").write_bytes(PNG_1x1)
    t = Table("numbers <&> | pipes", ["x", "y <i>"], [[1, 0.123456789], ["<b>bold</b>", math.nan]], digits=3)
    s1 = PaperSection("901", "A paper with <script>alert(1)</script> in its title", "setup & more",
                      [Claim("C901-1", "x < y & y > z", CONFIRMED, "evidence with a | pipe", tables=[t],
                             figures=[Figure("figures/a.png", "caption one")], sensitive_to=["p1", "p2"],
                             sensitivity=[Sensitivity("p1", [0.1, 1.0], 1.0, "p1 ≥ 0.5",
                                                      figure=Figure("figures/b.png", "caption two"), table=t)]),
                       Claim("C901-2", "second", NOT_CONFIRMED, "none")],
                      notes="quick mode reduces things", runtime_s=1.5)
    s2 = PaperSection("902", "Second", "setup", [Claim("C902-1", "third", DEPENDS, "ev", sensitive_to=["q"])],
                      figures=[Figure("figures/missing.png", "not there")])
    return [s1, s2]


def test_render_synthetic(tmp_path):
    secs = synthetic_sections(tmp_path)
    meta = {"built": "2026-01-01", "commit": "abc", "quick": True, "workers": 2, "runs": {"901": 3, "902": 0},
            "runtime_s": 2.0}
    h, m = render.render(secs, tmp_path, meta)
    page = parse(h)
    text = h.read_text(encoding="utf-8")
    assert "<script>" not in text and "&lt;script&gt;" in text          # escaped
    assert "<b>bold</b>" not in text and "&lt;b&gt;bold&lt;/b&gt;" in text
    got = {r[0]: r[2] for r in page.rows}
    assert got == {"C901-1": CONFIRMED, "C901-2": NOT_CONFIRMED, "C902-1": DEPENDS}
    assert [r[3] for r in page.rows] == ["p1, p2", "–", "q"]
    assert sorted(page.imgs) == ["figures/a.png", "figures/b.png"]
    for src in page.imgs:
        assert not src.startswith("/") and (tmp_path / src).exists()
    assert "figure missing: figures/missing.png" in text
    for k in ("2026-01-01", "abc", "quick"):
        assert k in text
    md = m.read_text(encoding="utf-8")
    for cid, v in got.items():
        line = next(x for x in md.splitlines() if x.startswith(f"| {cid} |"))
        assert v in line
    assert "![caption one](figures/a.png)" in md and "![caption two](figures/b.png)" in md
    assert "figures/missing.png" in md and "![not there]" not in md
    assert "x \\| y" not in md and "evidence with a | pipe" in md       # body text unchanged, cells escaped
    assert "numbers <&> \\| pipes" in md
    assert "0.123" in md and "0.123" in text and "0.1234" not in md


def test_render_rejects_duplicate_ids(tmp_path):
    s = PaperSection("9", "t", "s", [Claim("C9-1", "a", CONFIRMED, "e"), Claim("C9-1", "b", CONFIRMED, "e")])
    with pytest.raises(ValueError):
        render.render([s], tmp_path, {})


def test_claim_rejects_unknown_verdict():
    with pytest.raises(ValueError):
        Claim("C9-1", "a", "maybe", "e")


# ----- verdict rules on small synthetic tables ---------------------------------------------------------
def test_rules_basic():
    assert rules.better(1.0, 2.0) and not rules.better(2.0, 1.0) and not rules.better(1.0, 1.0)
    assert not rules.better(0.999, 1.0, rel=0.005) and rules.better(0.99, 1.0, rel=0.005)
    assert rules.better(1.0, math.inf) and not rules.better(math.nan, 1.0)
    assert rules.count_better([1, 2, 3], [2, 2, 2]) == 1
    assert rules.at_least(3, 4, 0.75) and not rules.at_least(2, 4, 0.75) and rules.at_least(2, 3, 0.6)
    assert rules.spread([3.0, 1.0, 2.0]) == 2.0 and rules.spread([1.0, math.nan]) == math.inf
    assert rules.monotone_fraction([1, 2, 2, 3]) == 1.0
    assert rules.monotone_fraction([1, 3, 2, 4]) == pytest.approx(2 / 3)
    assert rules.strictly_monotone([3, 2, 1], increasing=False) and not rules.strictly_monotone([1, 1, 2])
    assert rules.combine(True, {"a": True}) == CONFIRMED
    assert rules.combine(False, {"a": False}) == NOT_CONFIRMED
    assert rules.combine(True, {"a": False}) == DEPENDS and rules.combine(False, {"a": True}) == DEPENDS
    assert rules.holds_where([1, 2, 3, 4, 5], [False, True, True, False, True], "x") == "2 ≤ x ≤ 3; x = 5"
    assert rules.holds_where([1, 2], [True, True]).startswith("everywhere")
    assert rules.holds_where([1, 2], [False, False]) == "nowhere tried"
    assert rules.holds_at(["a", "b", "c"], [True, False, True]) == "at a, c (2 of 3)"


def _fmus_built() -> bool:
    need = ["RelativeOrbitPlant", "PredictivePidController", "SingleAxisPlant", "FopidController", "PidController",
            "AttitudePlant", "ReferenceCorrector", "FeedbackLinearizingController"]
    return all((ROOT / "fmus" / f"{n}.fmu").exists() for n in need)


@pytest.mark.skipif(not _fmus_built(), reason="FMUs not built (scripts/build_fmus.sh)")
def test_report_quick_end_to_end(tmp_path):
    out = tmp_path / "report"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    r = subprocess.run([sys.executable, "-m", "scfmu", "report", "--quick", "--workers", "2",
                        "--papers", ",".join(CI_PAPERS), "--out", str(out)], capture_output=True, text=True, env=env,
                       timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "index.html" in r.stdout
    page = parse(out / "index.html")
    got = {row[0]: row[2] for row in page.rows}
    want = [c for p in CI_PAPERS for c in CLAIM_IDS[p]]
    assert list(got) == want
    assert all(v in (CONFIRMED, NOT_CONFIRMED, DEPENDS) for v in got.values())
    assert page.imgs and all((out / s).exists() for s in page.imgs)
    md = (out / "report.md").read_text(encoding="utf-8")
    for cid in want:
        assert f"| {cid} |" in md
    for cid in want:                                              # the terminal table lists every claim
        assert cid in r.stdout


def test_report_missing_paper_is_an_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "scfmu", "report", "--papers", "999", "--out",
                        str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert r.returncode != 0 and "paper 999" in (r.stdout + r.stderr)
