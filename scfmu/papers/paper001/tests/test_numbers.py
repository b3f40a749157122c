"""Paper 001's "more than 50 times" beside ours, on synthetic ratios."""

from scfmu.papers.paper001 import report as r
from scfmu.report.types import NOT_REPRODUCED, REPRODUCED

REP = {"label": "effort ratio", "bound": 50.0, "text": "> 50", "unit": "×", "c_lo": 25.0, "c_hi": 150.0, "T2": 25.0}


def test_six_fold_is_not_fifty_fold():
    row = r.effort_ratio_row({r.PRIMARY_Z: 6.4, "all axes peak": 7.0}, REP)
    assert row.verdict == NOT_REPRODUCED and "definition unknown" in row.note and "no definition" in row.note


def test_another_definition_passing_is_named_not_chosen():
    row = r.effort_ratio_row({r.PRIMARY_Z: 6.4, "all axes ∫‖F‖² dt": 80.0}, REP)
    assert row.verdict == NOT_REPRODUCED and "only with all axes ∫‖F‖² dt" in row.note


def test_beyond_the_bound_is_reproduced():
    assert r.effort_ratio_row({r.PRIMARY_Z: 51.0}, REP).verdict == REPRODUCED
