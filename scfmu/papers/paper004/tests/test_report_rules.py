"""Paper 004 report section: the verdict rules on small synthetic tables."""

import pytest



def test_paper004_rules():
    from scfmu.papers.paper004 import report as p
    assert p.requirement_ratio(0.005, 0.05) == pytest.approx(0.5)
    assert p.requirement_ratio(0.02, 0.05) == pytest.approx(2.0)
    assert p.tolerance_window(0.9, 50.0, 0.99) == (0.99, 50.0)


# ----- end to end ----------------------------------------------------------------------------------------


def _runs(offset: float):
    """A closed-loop run and an open-loop one differing by ``offset`` in q and ω, with a consistent q_ref_dot."""
    import numpy as np
    t = np.arange(0.0, 2.0, 0.01)
    r3 = {"time": t}
    for i, k in enumerate(["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]):
        r3[k] = 0.5 * np.cos(0.3 * t + i)
    for i, a in enumerate("xyz"):
        r3[f"q_ref_{a}"] = 0.1 * np.sin(t + i)
        r3[f"q_ref_dot_{a}"] = 0.1 * np.cos(t + i)
    ol = {k: (v + offset if k not in ("time",) and not k.startswith("q_ref") else v) for k, v in r3.items()}
    return r3, ol


def test_c4_holds_by_construction_is_detected_from_the_numbers():
    """The corrector integrates its own plant copy, so closed loop and open loop agree to rounding level: C004-4
    holds by construction. Broken on purpose (the runs differ by 1e-11, still inside the 1e-9 rule), it is an
    ordinary "confirmed"; by 1e-6, not confirmed: the class follows the measured agreement."""
    from scfmu.papers.paper004 import report as r
    from scfmu.report.types import BY_CONSTRUCTION_HOLDS, CONFIRMED, NOT_CONFIRMED
    assert r._claim4(*_runs(0.0)).verdict == BY_CONSTRUCTION_HOLDS
    assert r._claim4(*_runs(3e-16)).verdict == BY_CONSTRUCTION_HOLDS
    assert r._claim4(*_runs(1e-11)).verdict == CONFIRMED
    assert r._claim4(*_runs(1e-6)).verdict == NOT_CONFIRMED
