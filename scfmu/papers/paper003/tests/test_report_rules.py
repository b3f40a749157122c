"""Paper 003 report rules: the ISF row beside ours, the readings examined."""


def test_isf_row_beside_ours_and_unit_readings_are_no_evidence():
    """Paper 003's ISF = 1.0611 (GA-SMC, nominal) beside ours; the torque-unit readings are labelled chosen."""
    from scfmu.papers.paper003 import report as r3
    from scfmu.report.types import CHOSEN, INDEPENDENT, NOT_CHECKABLE, NOT_REPRODUCED, REPRODUCED
    rows = r3.number_rows({("SMC", "N"): {"isf": 1.545e-4}})
    main = rows[0]
    assert main.paper_value == 1.0611 and main.basis == INDEPENDENT and main.verdict == NOT_REPRODUCED
    assert abs(main.rel_diff - (1.545e-4 - 1.0611) / 1.0611) < 1e-12
    assert all(x.basis == CHOSEN and not x.independent for x in rows[1:]) and len(rows) == 3
    assert abs(rows[1].ours - 1.545) < 1e-9                     # N·cm: × 1e4
    assert r3.number_rows({("SMC", "N"): {"isf": 1.06}})[0].verdict == REPRODUCED
    assert r3.number_rows({})[0].verdict == NOT_CHECKABLE
    assert r3.examined([("a", [True, False]), ("b", [True, True])]) == ["a (moves the verdict)", "b (verdict unchanged)"]
