"""Paper 001's "more than 50 times" beside ours, on synthetic ratios; the effort integrals on the controller's
own clock against closed forms."""

import math

import numpy as np

from scfmu.papers.paper001 import report as r
from scfmu.report.types import CHOSEN, INDEPENDENT, NOT_REPRODUCED, REPRODUCED

REP = {"label": "effort ratio", "bound": 50.0, "text": "> 50", "unit": "×", "c_lo": 25.0, "c_hi": 150.0, "T2": 25.0}
D = r.DEFAULT_SAMPLE


def row(ratios):
    return r.effort_ratio_rows({D: ratios}, REP)[0]


def test_six_fold_is_not_fifty_fold():
    x = row({r.PRIMARY_Z: 6.4, "all axes peak": 7.0})
    assert x.verdict == NOT_REPRODUCED and "definition unknown" in x.note and "no definition" in x.note
    assert x.basis == INDEPENDENT


def test_another_definition_passing_is_named_not_chosen():
    x = row({r.PRIMARY_Z: 6.4, "all axes ∫‖F‖² dt": 80.0})
    assert x.verdict == NOT_REPRODUCED and "only with all axes ∫‖F‖² dt" in x.note


def test_beyond_the_bound_is_reproduced():
    assert row({r.PRIMARY_Z: 51.0}).verdict == REPRODUCED


def test_sample_step_readings_are_rows_but_no_evidence():
    rows = r.effort_ratio_rows({D: {r.PRIMARY_Z: 1.007}, "sampled, Δ = 0.0125 s": {r.PRIMARY_Z: 60.0}}, REP)
    assert [x.basis for x in rows] == [INDEPENDENT, CHOSEN]
    assert rows[1].verdict == REPRODUCED and not rows[1].independent and "0.0125" in rows[1].item


def test_clock_integrals_are_exact_for_a_held_force():
    """F_z(t) = exp(−t/τ) held over steps of Δ: ∫|F| = Δ Σ e^{−kΔ/τ} (geometric series); on a grid 10× coarser
    than the transient the trapezoid of the old 10 ms log is far off, the controller clock is exact."""
    tau, dt, t_end = 0.0067, 0.001, 0.3
    n = int(round(t_end / dt))
    fz = np.exp(-np.arange(n + 1) * dt / tau)
    e = r.clock_efforts({m: 0.0 for m in r.EFFORTS}, fz, dt)
    q = math.exp(-dt / tau)
    assert abs(e["Z axis ∫|F_z| dt"] - dt * (1 - q ** n) / (1 - q)) < 1e-12
    assert abs(e["Z axis ∫F_z² dt"] - dt * (1 - q ** (2 * n)) / (1 - q * q)) < 1e-12
    assert e["Z axis peak |F_z|"] == 1.0
    coarse = fz[::10]
    trap = float(np.sum(0.5 * (coarse[1:] ** 2 + coarse[:-1] ** 2)) * 0.01)
    assert trap > 1.3 * e["Z axis ∫F_z² dt"]


def test_a_reading_supports_the_sentence_only_with_settling_unchanged():
    ratios = {r.PRIMARY_Z: 3.0, "all axes ∫‖F‖² dt (N²·s)": 81.5}
    assert r.sample_reading(ratios, 100.0, 101.0, 50.0) == ["all axes ∫‖F‖² dt (N²·s)"]
    assert r.sample_reading(ratios, 100.0, 110.0, 50.0) == []      # settling moved by 10 %
    assert r.sample_reading({r.PRIMARY_Z: 6.4}, 100.0, 100.0, 50.0) == []
