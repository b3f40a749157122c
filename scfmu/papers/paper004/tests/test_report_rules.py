"""Paper 004 report section: the verdict rules on small synthetic tables."""

import pytest



def test_paper004_rules():
    from scfmu.papers.paper004 import report as p
    assert p.requirement_ratio(0.005, 0.05) == pytest.approx(0.5)
    assert p.requirement_ratio(0.02, 0.05) == pytest.approx(2.0)
    assert p.tolerance_window(0.9, 50.0, 0.99) == (0.99, 50.0)


# ----- end to end ----------------------------------------------------------------------------------------
