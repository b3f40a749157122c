"""Paper 002's Table 4 gains beside ours: nearest candidate of a damaged entry, on synthetic gains."""

from scfmu.papers.paper002 import report as r
from scfmu.report.types import NOT_CHECKABLE, NOT_REPRODUCED, REPRODUCED

REP = {"gains": [{"controller": "PD", "gain": "kd", "label": "K_D", "candidates": ["1.44", "3.44", "5.44"]},
                 {"controller": "PD", "gain": "kp", "label": "K_P", "candidates": ["0.60"]},
                 {"controller": "FOPID", "gain": "lambda", "label": "λ", "candidates": ["0.77", "0.99"]}]}


def test_gain_rows():
    rows = r.gain_rows({"PD": {"kd": 3.5, "kp": 15.0}}, REP)
    assert [x.verdict for x in rows] == [REPRODUCED, NOT_REPRODUCED, NOT_CHECKABLE]
    assert rows[0].paper_value == 3.44 and rows[1].paper_value == 0.60
