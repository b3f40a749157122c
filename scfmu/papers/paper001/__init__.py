"""Paper 001 [NPPID-Formation]: formation flying with a nonlinear predictive PID and a disturbance observer."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("paper001", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    for dist in (0.0, 0.01, 1.0):
        reg.benchmark("formation", f"paper001/a/dist{dist:g}", f"step to (50, 40, 60) m, {dist:g} N disturbance "
                      "per axis (paper 001)", primary="ise", signal="pos_x")
    for case, (t2, c) in scenarios.PAPER001_CASES.items():
        reg.controller("formation", "PredictivePidController", f"NPPID case {case} (T2 = {t2:g} s, c = {c:g} 1/s)",
                       {"T1": 0.0, "T2": t2, "c": c})
    reg.paper("001", "Formation flying with a nonlinear predictive PID",
              commands={"formation": ("the four (T2, c) cases with and without disturbance, CSV and PNG",
                                      "scfmu.papers.paper001.formation:main")},
              report="scfmu.papers.paper001.report:build", docs="docs/paper001.md")
