"""One FMI 2.0 co-simulation FMU per standard closed loop (``fmus/loops/<scenario>.fmu``).

Each file is the scenario's fmpy container FMU (:func:`scfmu.native.build_container`: the scenario's
FMUs nested under ``resources/``, wired in the scenario's Gauss–Seidel order, one fixed step of
``scenario.step`` per internal step) whose container variables ``"<instance>.<variable>"`` start at the
scenario's parameter values and fixed inputs, so importing the single file and simulating it with no
value set reproduces the scenario. Every parameter, input and output of every nested FMU stays visible
and settable by its qualified name.

``python -m scfmu.loops --out fmus/loops`` (called by ``scripts/build_fmus.sh``) writes the files of
:data:`scfmu.ssp.STANDARD` and validates each with ``fmpy.validate_fmu``.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

from .native import build_container, scenario_starts
from .scenario import Scenario
from .ssp import STANDARD, file_stem


def write_loop_fmu(scenario: Scenario, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    src = build_container(scenario, scenario_starts(scenario))
    tmp = path.with_suffix(".fmu.tmp")
    shutil.copyfile(src, tmp)
    tmp.replace(path)
    return path


def main(argv=None):
    from fmpy.validation import validate_fmu

    from . import scenarios
    ap = argparse.ArgumentParser(description="Write one container FMU per standard closed loop.")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "fmus" / "loops"))
    ap.add_argument("names", nargs="*", help="scenario names (default: the standard set)")
    a = ap.parse_args(argv)
    for name in a.names or STANDARD:
        p = write_loop_fmu(scenarios.get(name), Path(a.out) / f"{file_stem(name)}.fmu")
        problems = validate_fmu(str(p))
        if problems:
            raise SystemExit(f"{p}: fmpy validation failed: {problems[:5]}")
        print(f"wrote {p} ({p.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
