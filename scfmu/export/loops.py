"""One FMI 2.0 co-simulation FMU per closed loop (its units FMI 2.0 or 3.0) (``fmus/loops/<scenario>.fmu``).

Each file is the scenario's fmpy container FMU (:func:`scfmu.engines.native.build_container`: the scenario's
FMUs nested under ``resources/``, wired in the scenario's Gauss–Seidel order, one fixed step of
``scenario.step`` per internal step) whose container variables ``"<instance>.<variable>"`` start at the
scenario's parameter values and fixed inputs, so importing the single file and simulating it with no
value set reproduces the scenario. Every parameter, input and output of every nested FMU stays visible
and settable by its qualified name.

``scfmu export loop`` (called by ``scripts/build_fmus.sh``) writes the files of the exported scenarios
and validates each with ``fmpy.validate_fmu``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from ..engines.native import build_container, scenario_starts
from ..scenario.model import Scenario
from ..scenario.plan import build_plan


def write_loop_fmu(scenario: Scenario, path: str | Path) -> Path:
    """Writes the loop FMU of a scenario (its units may be FMI 2.0 or FMI 3.0 Co-Simulation FMUs; the loop
    FMU itself is FMI 2.0 Co-Simulation)."""
    plan = build_plan(scenario)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    src = build_container(plan, scenario_starts(plan.scenario))
    tmp = path.with_suffix(".fmu.tmp")
    shutil.copyfile(src, tmp)
    tmp.replace(path)
    return path
