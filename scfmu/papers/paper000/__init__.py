"""Paper 000 [Navabi-2019]: EULERINT-based comparison of PD (quaternion, DCM, Euler errors), LQR, pole
placement, MRAC, fuzzy PD and adaptive fuzzy attitude controllers on a rigid satellite."""

from __future__ import annotations


def register(reg) -> None:
    from . import envelope, scenarios
    reg.scenarios("default", scenarios.build,
                  lambda: [("default", "paper 000 run 000-6: quaternion PD, large command (40, -40, -60) deg")],
                  exported=("default",))
    reg.scenarios("paper000", scenarios.build, scenarios.names, exported=scenarios.EXPORTED[1:])
    # controller benchmark (scfmu benchmark --family attitude): the paper's slews and its controllers
    reg.benchmark("attitude", "paper000/000-5", "small slew (4, -4, -6) deg, linear plant (paper 000)")
    reg.benchmark("attitude", "default", "large slew (40, -40, -60) deg (paper 000)")
    for model, label, params in (("PdController", "PD, quaternion error", {"error_law": 0}),
                                 ("LqrController", "LQR", {}), ("PolePlacementController", "pole placement", {}),
                                 ("MracController", "MRAC (quaternion)", {"coordinates": 0}),
                                 ("FuzzyPdController", "fuzzy PD", {}),
                                 ("AdaptiveFuzzyController", "adaptive fuzzy", {})):
        reg.controller("attitude", model, label, params, home=envelope.HOME,
                       retune="scfmu.papers.paper000.envelope:retune", unused=envelope.UNUSED)
    reg.paper("000", "EULERINT-based design of an adaptive-fuzzy attitude controller",
              commands={"study": ("runs 000-1 … 000-11 and the robustness runs R1/R2: table, CSV and PNG per run",
                                  "scfmu.papers.paper000.study:main")},
              report="scfmu.papers.paper000.report:build", docs="docs/paper000.md")
