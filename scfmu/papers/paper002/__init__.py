"""Paper 002 [Khatoonabadi-FO]: fractional-order PID against integer PID on a single axis with a wheel lag,
tuned by particle swarm optimisation."""

from __future__ import annotations


def register(reg) -> None:
    from ...metrics import COMMON, EXTRA, LOGS
    from . import model, scenarios
    reg.scenarios("paper002", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    reg.metrics("paper002", model.metrics_row, [*COMMON, *EXTRA["single_axis"], *model.METRIC_COLUMNS],
                LOGS["single_axis"])
    gains = model.load_gains()
    for ov, text in (({}, "30 deg step, nominal plant"), ({"plant.inertia_scale": 1.2}, "30 deg step, inertia +20 %"),
                     ({"plant.wheel_time_constant": 0.4}, "30 deg step, wheel lag 0.4 s")):
        reg.benchmark("single_axis", "paper002/PD", f"{text} (paper 002)", primary="mae_deg", signal="theta",
                      overrides=ov)
    for c in model.CONTROLLERS:
        m, params = model.controller_params(c, gains[c], model.Scenario())
        reg.controller("single_axis", m, f"{c} (PSO-tuned)", params)
    reg.paper("002", "Fractional-order PID attitude control tuned by PSO",
              commands={"tune": ("PSO tuning of PD, PID, FOPD, FOPID on the campaign engine (resumable)",
                                 "scfmu.papers.paper002.tune:main"),
                        "sweeps": ("runs 002-1 … 002-7 with the tuned gains: responses, MAE sweeps",
                                   "scfmu.papers.paper002.sweeps:main")},
              report="scfmu.papers.paper002.report:build", docs="docs/paper002.md")
