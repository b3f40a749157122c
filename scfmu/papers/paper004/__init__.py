"""Paper 004 [Moradi-FTC]: fault-tolerant attitude control by reference correction with an optimised
open-loop spline torque."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("paper004", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    from ...metrics import EXTRA, LOGS, COMMON
    from . import envelope, model
    reg.metrics("paper004", model.metrics_row, [*COMMON, *EXTRA["attitude_nometrics"], *model.METRIC_COLUMNS],
                (*LOGS["attitude_nometrics"], "w_x", "w_y", "w_z"))
    reg.benchmark("attitude", "paper004/2", "actuator fault: 90 % loss of effectiveness, 20 s (paper 004)",
                  primary="euler_end_max_deg", signal="roll")
    reg.controller("attitude", "FeedbackLinearizingController", "feedback linearising",
                   {k: v for k, v in model.controller_params().items() if not k.startswith("inertia_")},
                   home=envelope.HOME, retune="scfmu.papers.paper004.envelope:retune", unused=envelope.UNUSED)
    reg.paper("004", "Fault-tolerant attitude control by reference correction",
              commands={"optimize": ("SLSQP spline-torque optimisation for the faulty plant",
                                     "scfmu.papers.paper004.optimize:main"),
                        "cases": ("cases 004-1, 004-2, 004-3ol, 004-3, 004-X: terminal errors, pass/fail, plots",
                                  "scfmu.papers.paper004.cases:main")},
              report="scfmu.papers.paper004.report:build", docs="docs/paper004.md")
