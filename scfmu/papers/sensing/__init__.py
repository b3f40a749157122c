"""Sensing (issue 26): the papers' attitude loops with realistic measurements and a flight computer —
gyro, star tracker and a sampled controller with a computation delay (``scfmu.scenario.templates.
with_sensors``) — and whether paper 000's and paper 003's controller rankings survive them. Not a paper
of its own: a plug-in that takes the papers' scenarios by name from the registry (it imports no paper)."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("sensing", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    reg.scenarios(scenarios.EST_PREFIX, scenarios.build_estimation, scenarios.names_estimation)
    reg.benchmark("attitude", "sensing/default",
                  "large slew (40, -40, -60) deg with gyro, star tracker, 10 Hz flight computer (sensing)")
    reg.benchmark("attitude", "sensing/default", "large slew with sensors, Monte Carlo over sensor seeds (sensing)",
                  seeds=20)
    reg.benchmark("attitude", "sensing/paper003/SMC/N", "003-N with gyro, star tracker, 10 Hz flight computer (sensing)",
                  primary="ise")
    reg.paper("sensing", "Sensors in the loop: do the papers' controller rankings survive realistic sensing?",
              commands={"rankings": ("paper 000's large slew and paper 003's cases with and without sensors, "
                                     "a Monte Carlo over sensor seeds; rankings in CSV + PNG",
                                     "scfmu.papers.sensing.rankings:main"),
                        "slew": ("paper 000's large slew with and without sensors: large_slew.png",
                                 "scfmu.papers.sensing.rankings:main_slew")},
              report="scfmu.papers.sensing.report:build", docs="docs/sensing.md")
