"""Paper 003 [T2FSMC-LEO]: interval type-2 fuzzy sliding-mode attitude control of a LEO satellite with
reaction wheels, against a GA-tuned sliding-mode controller; and the ``wheel_fault`` loop on its plant."""

from __future__ import annotations


def register(reg) -> None:
    from ...metrics import LOGS, columns
    from . import model, wheel_fault_scenario
    reg.scenarios("paper003", model.build, model.names, exported=("paper003/SMC/N", "paper003/T2FSMC/N"))
    reg.scenarios("wheel_fault", lambda name, **kw: wheel_fault_scenario.wheel_fault(**kw),
                  lambda: [("wheel_fault", "reaction-wheel saturation and an actuator fault (paper 003 plant)")],
                  exported=("wheel_fault",))
    reg.metrics("paper003", model.metrics, [*columns("attitude"), *model.EXTRA_COLUMNS], LOGS["attitude"])
    tuned = model.tuned_params()
    reg.benchmark("attitude", "wheel_fault", "wheel saturation + x-wheel fault (paper 003 plant)",
                  primary="final_error", signal="roll")
    for case, text in (("N", "no disturbance"), ("C", "constant disturbance"), ("S", "sinusoidal disturbance"),
                       ("W", "white-noise disturbance")):
        reg.benchmark("attitude", f"paper003/SMC/{case}", f"003-{case}: {text} (paper 003)", primary="ise")
    reg.benchmark("attitude", "paper003/SMC/U", "003-U: inertia uncertainty, Monte Carlo (paper 003)", primary="ise",
                  seeds=100, monte_carlo="scfmu.papers.paper003.model:mc_draws")
    home = ("paper003/*", "wheel_fault", "sensing/paper003/*")  # paper 003's plant (the sensing variant too)
    reg.controller("attitude", "SlidingModeController", "GA-tuned SMC", tuned["SMC"], home=home,
                   retune="scfmu.papers.paper003.envelope:retune_smc")
    reg.controller("attitude", "Type2FuzzySmcController", "type-2 fuzzy SMC", tuned["T2FSMC"], home=home,
                   retune="scfmu.papers.paper003.envelope:retune_t2fsmc")
    reg.paper("003", "Type-2 fuzzy sliding-mode attitude control of a LEO satellite",
              commands={"tune": ("GA tuning of the SMC gain, then the type-2 fuzzy coefficients",
                                 "scfmu.papers.paper003.commands:main_tune"),
                        "scenarios": ("scenarios 003-N, C, S, W and the 100-run Monte Carlo 003-U",
                                      "scfmu.papers.paper003.commands:main_scenarios"),
                        "wheel-fault": ("reaction-wheel saturation and an actuator fault on the paper 003 plant",
                                        "scfmu.papers.paper003.wheel_fault:main")},
              report="scfmu.papers.paper003.report:build", docs="docs/paper003.md")
