"""Paper 001 report section: the verdict rules on small synthetic tables."""

import math

from scfmu.report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED


def test_paper001_rules():
    from scfmu.papers.paper001 import report as p
    # settling rises with the horizon, effort_abs falls (reading A), effort_sq rises (reading B)
    h = p.horizon_rule([5, 10, 25], [10, 20, 50], {"effort_abs": [30, 20, 10], "effort_sq": [1, 2, 3]})
    assert h["settling_rises"] and h["A:effort_abs"] and h["B:effort_sq"] and not h["A:effort_sq"]
    assert h["verdict"] == DEPENDS
    assert p.horizon_rule([5, 10], [10, 20], {"e": [2, 1]})["verdict"] == CONFIRMED
    assert p.horizon_rule([5, 10], [20, 10], {"e": [2, 1]})["verdict"] == NOT_CONFIRMED
    # settling flat from c = 25, effort 10x (abs) vs 3x (sq) from 25 to 150
    o = p.observer_rule([5, 25, 150], [60, 50, 51], {"abs": [1, 2, 20], "sq": [1, 2, 6]})
    assert o["settling_same"] and o["holds:abs"] and not o["holds:sq"] and o["verdict"] == DEPENDS
    assert p.observer_rule([25, 150], [50, 70], {"abs": [1, 20]})["verdict"] == NOT_CONFIRMED
    assert p.disturbance_rule(0.1, 40.0, 100.0, 101.0) and not p.disturbance_rule(1.0, 40.0, 100.0, 101.0)
    assert not p.disturbance_rule(0.1, 40.0, 100.0, 110.0)
    assert p.settled_at([5, 25, 50, 150], [80, 51, 50, 50]) == 25
    assert p.observer_rule([25, 150], [50, 50], {"sq": [1, 8]})["verdict"] == CONFIRMED         # 8x > 6x
    assert p.observer_rule([25, 150], [50, 50], {"sq": [1, 8]}, far=2.0)["verdict"] == NOT_CONFIRMED  # not > 12x
    assert p.tracking_rule(0.05, 66.0, 87.7) and not p.tracking_rule(0.1, 66.0, 87.7)
    assert not p.tracking_rule(0.0, math.nan, 87.7)
