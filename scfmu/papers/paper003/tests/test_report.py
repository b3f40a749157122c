"""Verdict logic of the paper 003 report section (scfmu.report.paper003) on synthetic summary tables
whose answers are known by construction (no simulation)."""

from scfmu.papers.paper003 import report as R
from scfmu.report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED


def table(ise_t2f_lower=R.CASES, sse_t2f_lower=R.CASES, isf_lower=None):
    """GA-SMC has ISE 2, ISF 2, sse 2 everywhere; T2F-SMC 1 (lower) or 3 (higher) per case."""
    isf_lower = isf_lower or {c: "T2FSMC" for c in R.CASES}
    s = {}
    for c in R.CASES:
        s[("SMC", c)] = {"ise": 2.0, "isf": 2.0, "sse": 2.0}
        s[("T2FSMC", c)] = {"ise": 1.0 if c in ise_t2f_lower else 3.0,
                            "isf": 1.0 if isf_lower[c] == "T2FSMC" else 3.0,
                            "sse": 1.0 if c in sse_t2f_lower else 3.0}
    return s


def test_claim1_needs_both_lower_ise_and_lower_sse_in_every_case():
    assert R.claim1(table())[0]
    ok, per = R.claim1(table(ise_t2f_lower=("N", "C", "S", "W")))
    assert not ok and per["U"] == (False, True) and per["N"] == (True, True)
    assert not R.claim1(table(sse_t2f_lower=("C", "S", "W", "U")))[0]
    # a tie is not "smaller"
    s = table()
    s[("T2FSMC", "W")]["ise"] = 2.0
    assert not R.claim1(s)[0]


def test_claim2_body_and_abstract_readings_are_exclusive():
    body = R.claim2(table(isf_lower=dict(R.ISF_BODY)))
    assert body[:2] == (True, False)
    assert body[2] == {"N": "SMC", "C": "SMC", "S": "SMC", "W": "T2FSMC", "U": "T2FSMC"}
    assert R.claim2(table())[:2] == (False, True)                      # T2F-SMC lower everywhere
    neither = dict(R.ISF_BODY, U="SMC")
    assert R.claim2(table(isf_lower=neither))[:2] == (False, False)


def test_verdict_and_region_text():
    assert R.verdict(True, [True, True]) == CONFIRMED
    assert R.verdict(False, [False, False]) == NOT_CONFIRMED
    assert R.verdict(True, [True, False]) == DEPENDS
    assert R.verdict(False, [False, True]) == DEPENDS
    assert R.holds_where([0.1, 0.5, 0.9], [True, True, True], 0.5) == "everywhere tried"
    assert R.holds_where([0.1, 0.5, 0.9], [False] * 3, 0.5) == "nowhere tried"
    assert R.holds_where([0.1, 0.5, 0.9], [False, True, True], 0.5) == "holds at 0.5 (default), 0.9; fails at 0.1"


def test_summarise_averages_the_monte_carlo_and_skips_failed_runs():
    def row(ise, status="ok"):
        return {"status": status, "ise": ise, "isf": 2 * ise, "cost": 0.0,
                "sse_roll_deg": ise, "sse_pitch_deg": 0.0, "sse_yaw_deg": 0.0}
    rows = [row(1.0), row(2.0), row(4.0), row(100.0, "fmu_error")]
    index = [(0, "N", None), (0, "U", 1), (0, "U", 2), (0, "U", 3)]
    s = R._summarise(rows, index, 1)[0]
    assert s["N"]["ise"] == 1.0 and s["N"]["sse"] == 1.0 / 3
    assert s["U"]["ise"] == 3.0 and s["U"]["isf"] == 6.0 and s["U"]["n"] == 2 and s["U"]["failed"] == 1
    assert abs(s["U"]["ise_std"] - 2 ** 0.5) < 1e-15
