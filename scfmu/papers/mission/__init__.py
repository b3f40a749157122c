"""A whole attitude control system in one loop (issue 44): the ``mission/*`` scenarios put the 6U CubeSat of
``leo/*`` under a ``ModeManager`` that takes it from separation (a tumbling tip-off) through DETUMBLE (B-dot),
SUN_ACQUISITION (the sun-safe law on the sun sensors and the gyro), DETERMINATION (the Triad's coarse attitude
initialises the Mekf, which converges on the star tracker) to FINE_POINTING (nadir, any attitude controller on
the Mekf's estimate), and back to SAFE on an actuator fault. Not a paper: a plug-in with the scenarios
``mission/tipoff`` and ``mission/wheel-fault``, the metric set ``mission`` (time to each mode, peak rate,
energy and momentum used, chatter, power in safe mode) and the figure/campaign page (docs/mission.md)."""

from __future__ import annotations


def register(reg) -> None:
    from . import metrics, scenarios
    reg.scenarios("mission", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
    reg.metrics("mission", metrics.compute, metrics.COLUMNS, metrics.LOGS)
    reg.dispersions("mission/tipoff", scenarios.DISPERSIONS)
    reg.mission("attitude", "mission/tipoff", "tip-off to fine pointing (mission/tipoff: detumble, sun acquisition, "
                "determination, then the controller under test points nadir on the Mekf's estimate)",
                runs=20, quick_runs=4, metric="t_on_target_s", handover="t_fine_pointing_s")
