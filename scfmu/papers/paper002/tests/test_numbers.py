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


def test_gains_on_the_pso_box_are_no_evidence():
    """A tuned gain on an edge of the PSO search box (model.BOUNDS) is fixed by construction, detected from the
    value: the committed PID K_D = 20 "reproduces" the candidate 19.08 but is the box's upper edge; a gain
    inside the box keeps its verdict and stays independent."""
    from scfmu.papers.paper002 import model as p2
    from scfmu.report.types import BY_CONSTRUCTION, INDEPENDENT
    rep = {"gains": [{"controller": "PID", "gain": "kd", "label": "K_D", "candidates": ["17.08", "19.08"]},
                     {"controller": "PID", "gain": "ki", "label": "K_I", "candidates": ["0.04"]}]}
    hi = p2.BOUNDS["kd"][1]
    rows = r.gain_rows({"PID": {"kd": hi, "ki": 0.0}}, rep)
    assert rows[0].verdict == REPRODUCED and rows[0].basis == BY_CONSTRUCTION and not rows[0].independent
    assert rows[1].basis == BY_CONSTRUCTION                      # K_I = 0: the lower edge
    rows = r.gain_rows({"PID": {"kd": 19.0, "ki": 0.05}}, rep)
    assert [x.basis for x in rows] == [INDEPENDENT, INDEPENDENT]
    # the committed tuning: every K_D sits on the box's upper edge
    import json
    from importlib import resources
    g = json.loads((resources.files("scfmu.papers.paper002") / "data" / "gains.json").read_text())["controllers"]
    rows = r.gain_rows({c: d["gains"] for c, d in g.items()}, r.common.reported("scfmu.papers.paper002"))
    kd = [x for x in rows if x.item.endswith("K_D")]
    assert len(kd) == 4 and all(x.basis == BY_CONSTRUCTION for x in kd)
