"""Paper 004 [Moradi-FTC]: fault-tolerant attitude control by reference correction with an optimised
open-loop spline torque."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("paper004", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    reg.paper("004", "Fault-tolerant attitude control by reference correction",
              commands={"optimize": ("SLSQP spline-torque optimisation for the faulty plant",
                                     "scfmu.papers.paper004.optimize:main"),
                        "cases": ("cases 004-1, 004-2, 004-3ol, 004-3, 004-X: terminal errors, pass/fail, plots",
                                  "scfmu.papers.paper004.cases:main")},
              report="scfmu.papers.paper004.report:build", docs="docs/paper004.md")
