"""The prose check of the report's pages (scfmu/report/prose.py) without a build: every page against the last full
build's recorded values and rows, the parts checked against files of the repository, the pairs "X at s = Y",
and the tuning block of docs/paper002.md against the committed tuning. Each check is shown to fail on a page
broken on purpose."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from scfmu.report import docs, prose
from scfmu.report.types import PaperSection

ROOT = Path(__file__).resolve().parents[1]
RECORDED = json.loads((ROOT / "tests" / "data" / "report_full_values.json").read_text(encoding="utf-8"))


def _check(page: str, text: str | None = None) -> list[str]:
    """The check of one page (or of a changed text of it) against the recorded full build alone."""
    sc = prose.scope_of(page) or "all"
    text = (ROOT / page).read_text(encoding="utf-8") if text is None else text
    return prose.check_text(text, set(RECORDED[sc]), [set(r) for r in RECORDED["rows"][sc]], ROOT)


@pytest.mark.parametrize("page", prose.PAGES)
def test_every_number_of_the_pages_is_checked(page):
    """No part of a page is left unchecked (no ``prose: from`` part), and every number of its prose, of the parts
    checked against files and of its pairs passes against the last full build's record."""
    text = (ROOT / page).read_text(encoding="utf-8")
    assert prose.other_parts(text) == [], f"{page}: unchecked parts"
    assert _check(page) == []


def test_the_checked_parts_name_files_that_exist():
    parts = [(p, f) for p in prose.PAGES for files, _ in prose.checked_parts((ROOT / p).read_text(encoding="utf-8"))
             for f in files]
    assert parts and all((ROOT / f).is_file() for _, f in parts), parts
    assert any(f.startswith("modelDescription/") for _, f in parts) and any(f.endswith(".json") for _, f in parts)


def _broken(page: str, old: str, new: str) -> str:
    text = (ROOT / page).read_text(encoding="utf-8")
    assert old in text, f"{page} no longer says {old!r}: pick another sentence"
    return text.replace(old, new, 1)


def test_a_right_number_at_a_wrong_setting_fails():
    """3.5062° is the FOPID's MAE at T = 0.4 s; at T = 0.3 s it is wrong although 3.5062 and 0.3 are each numbers
    the report prints for paper 002 (the by-value check alone passes them)."""
    vals = set(RECORDED["002"])
    assert prose.matches("3.5062", vals) and prose.matches("0.3", vals)
    bad = _check("docs/paper002.md", _broken("docs/paper002.md", "3.5062° at T = 0.4 s", "3.5062° at T = 0.3 s"))
    assert bad == ["3.5062 at T = 0.3"]
    page = "ours 105.4 at s = 5.2 and 9.1 over 20 runs"
    assert prose.pairs(page) == [("105.4", "s", "5.2"), ("9.1", "runs", "20")]
    assert prose.unpaired(page, [{105.4, 2.62}, {9.1, 20.0}]) == ["105.4 at s = 5.2"]


def test_a_table_row_with_a_wrong_setting_fails():
    """A hand-written table row pairs its numbers: the MAE of the wheel time constant 0.4 s written on the 0.3 s row
    fails, although every number of it is one the report prints."""
    row = "| 002-4 | wheel_time_constant_s | 0.4 | 3.4796 | 3.4795 | 3.5073 | 3.5062 | PID |"
    bad = _check("docs/paper002.md", _broken("docs/paper002.md", row, row.replace("| 0.4 |", "| 0.3 |")))
    assert bad == ["row 0.3 3.4796 3.4795 3.5073 3.5062"]


def test_a_wrong_parameter_default_fails():
    """A default in a checked parameter table is the declared start of that variable, name by name: K_D's 9 and the
    swapped inertia defaults fail although 9, 3.5 and 5.0 are numbers of the declarations."""
    bad = _check("docs/paper002.md", _broken("docs/paper002.md", "| 2, 0.1, 8 |", "| 2, 0.1, 9 |"))
    assert bad == ["row 2 0.1 9", "kd = 9"]
    bad = _check("docs/paper003.md", _broken("docs/paper003.md", "| 4.0, 5.0, 3.5 |", "| 4.0, 3.5, 5.0 |"))
    assert bad == ["inertia_yy = 3.5", "inertia_zz = 5.0"]


def test_a_number_not_in_the_named_files_fails():
    """The GA-tuned switching gain is the committed tuning's (tuned.json); the gyro bias correlation time is the
    estimator set-up's (scfmu/scenario/templates.py)."""
    bad = _check("docs/paper003.md", _broken("docs/paper003.md", "k = 0.0029774 N m", "k = 0.0029775 N m"))
    assert bad == ["0.0029775"]
    bad = _check("docs/sensing.md", _broken("docs/sensing.md", "τ_c = 300 s", "τ_c = 350 s"))
    assert bad == ["350"]
    with pytest.raises(FileNotFoundError):
        _check("docs/paper004.md", _broken("docs/paper004.md", "paper004/tests/test_paper004.py -->",
                                           "paper004/tests/no_such_file.py -->"))


def test_the_tuning_block_is_the_committed_tuning():
    """docs/paper002.md's tuning table is the block the report writes from paper002/data/gains.json (the report's
    build writes the same; this needs no build)."""
    from scfmu.papers.paper002 import report_tables
    body = docs.section_doc_tables(PaperSection("002", "", "", [], doc_tables={"tuning": report_tables.tuning_table()}))
    page = (ROOT / "docs" / "paper002.md").read_text(encoding="utf-8")
    assert docs.table_blocks(page)["tuning"] == docs.table_block("tuning", body["tuning"])
    assert "| PD | 14.9667 | – | 20 |" in body["tuning"]
