"""Paper 000 [Navabi-2019]: EULERINT-based comparison of PD (quaternion, DCM, Euler errors), LQR, pole
placement, MRAC, fuzzy PD and adaptive fuzzy attitude controllers on a rigid satellite."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("default", scenarios.build,
                  lambda: [("default", "paper 000 run 000-6: quaternion PD, large command (40, -40, -60) deg")],
                  exported=("default",))
    reg.scenarios("paper000", scenarios.build, scenarios.names, exported=scenarios.EXPORTED[1:])
    reg.paper("000", "EULERINT-based design of an adaptive-fuzzy attitude controller",
              commands={"study": ("runs 000-1 … 000-11 and the robustness runs R1/R2: table, CSV and PNG per run",
                                  "scfmu.papers.paper000.study:main")},
              report="scfmu.papers.paper000.report:build", docs="docs/paper000.md")
