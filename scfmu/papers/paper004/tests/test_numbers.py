"""Paper 004's reported terminal values beside ours, and the calibration of the start, on synthetic values."""

from scfmu.papers.paper004 import report as r
from scfmu.report.types import NOT_REPRODUCED, REPRODUCED, SAME_ORDERING


def term(w, e):
    return {"w_end_max_deg_s": w, "euler_end_max_deg": e}


def test_calibration_picks_the_scale_closest_to_the_target():
    assert r.calibrate_scale({1.0: 0.07, 1.2: 0.6, 1.25: 0.74, 1.3: 0.9}, 0.7) == 1.25
    assert r.calibrate_scale({1.0: 0.6, 1.1: 0.8}, 0.7) == 1.0          # a tie goes to the smaller scale


def test_number_rows_precision_ordering_and_calibration_flag():
    rows = r.number_rows({"1": term(0.0122, 0.0416), "2": term(0.1595, 0.7455), "3": term(0.0099, 0.099)})
    by = {(x.item.split(":")[0], x.unit): x for x in rows}
    assert len(rows) == 6
    # "≈ 0.01" stands for [0.005, 0.015]: 0.0122 is within the printed precision
    assert by[("case 1 healthy, uncorrected", "deg/s")].verdict == REPRODUCED
    # "≈ 0.05" → [0.045, 0.055]; 0.0416 is outside but case 1 < case 3 < case 2 as in the paper
    assert by[("case 1 healthy, uncorrected", "deg")].verdict == SAME_ORDERING
    cal = [x for x in rows if x.calibration]
    assert len(cal) == 1 and cal[0].unit == "deg" and cal[0].item.startswith("case 2")
    # a case-2 angle ten times milder than the paper's: neither reproduced nor in the paper's order
    rows = r.number_rows({"1": term(0.0122, 0.0416), "2": term(0.016, 0.07), "3": term(0.0099, 0.099)})
    assert [x.verdict for x in rows if x.item.startswith("case 2") and x.unit == "deg"] == [NOT_REPRODUCED]
