"""Paper 001 [NPPID-Formation]: formation flying with a nonlinear predictive PID and a disturbance observer."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("paper001", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    reg.paper("001", "Formation flying with a nonlinear predictive PID",
              commands={"formation": ("the four (T2, c) cases with and without disturbance, CSV and PNG",
                                      "scfmu.papers.paper001.formation:main")},
              report="scfmu.papers.paper001.report:build", docs="docs/paper001.md")
