"""One FMI 2.0 co-simulation FMU per closed loop (its units FMI 2.0 or 3.0, Co-Simulation or Model Exchange)
(``fmus/loops/<scenario>.fmu``).

Each file is the scenario's fmpy container FMU (:func:`scfmu.engines.native.build_container`: the scenario's
FMUs nested under ``resources/``, wired in the scenario's Gauss–Seidel order, one fixed step of
``scenario.step`` per internal step) whose container variables ``"<instance>.<variable>"`` start at the
scenario's parameter values and fixed inputs, so importing the single file and simulating it with no
value set reproduces the scenario. Every parameter, input and output of every nested FMU stays visible
and settable by its qualified name.

``scfmu export loop`` (called by ``scripts/build_fmus.sh``) writes the files of the exported scenarios
and validates each with ``fmpy.validate_fmu``.

A loop FMU runs on a platform only when the container's binary (fmpy's, ``binaries/<platform>/``) and every
FMU inside it have a binary for that platform: :func:`strip_unshared_platforms` removes every other
platform folder, at the top and inside the nested FMUs (fmpy's container carries ``darwin64``, x86-64 only,
while our FMUs may carry none, or more platforms than the container can load).
"""

from __future__ import annotations

import shutil
import zipfile
from pathlib import Path, PurePosixPath

from ..engines.native import build_container, scenario_starts
from ..scenario.model import Scenario
from ..scenario.plan import build_plan


def write_loop_fmu(scenario: Scenario, path: str | Path) -> Path:
    """Writes the loop FMU of a scenario (its units may be FMI 2.0 or FMI 3.0 FMUs, Co-Simulation or Model
    Exchange: a Model Exchange unit is nested as its Co-Simulation face, :mod:`scfmu.engines.cs_face`; the
    loop FMU itself is FMI 2.0 Co-Simulation)."""
    plan = build_plan(scenario)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    src = build_container(plan, scenario_starts(plan.scenario))
    tmp = path.with_suffix(".fmu.tmp")
    shutil.copyfile(src, tmp)
    strip_unshared_platforms(tmp)
    tmp.replace(path)
    return path


def _platform_of(name: str, prefix: str) -> str | None:
    """``<platform>`` of an archive entry ``<prefix>binaries/<platform>/<file>``, else None."""
    parts = PurePosixPath(name[len(prefix):]).parts if name.startswith(prefix) else ()
    return parts[1] if len(parts) >= 3 and parts[0] == "binaries" else None


# FMI 2.0 platform folders and the FMI 3.0 platform tuple of the same binaries (the loop FMU is FMI 2.0; units
# nested in it may be FMI 3.0, whose folders are tuples)
_PLATFORM_KEY = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "darwin64": "x86_64-darwin"}


def _same_platform(a: str | None, b: str) -> bool:
    return a is not None and _PLATFORM_KEY.get(a, a) == _PLATFORM_KEY.get(b, b)


def strip_unshared_platforms(fmu: str | Path) -> list[str]:
    """Rewrites the container FMU ``fmu`` so that it keeps a platform's binaries only where the container
    binary and every nested FMU (``resources/<name>/modelDescription.xml``) carry that platform (an FMI 2.0
    folder such as ``linux64`` and the FMI 3.0 tuple ``x86_64-linux`` name the same platform); removes
    the other platform folders at the top and inside the nested FMUs. Returns the platforms kept (sorted).
    Entry order, contents and compression of what is kept are unchanged."""
    fmu = Path(fmu)
    with zipfile.ZipFile(fmu) as z:
        infos = z.infolist()
        names = [i.filename for i in infos]
        nested = [n[: -len("modelDescription.xml")] for n in names
                  if n.startswith("resources/") and n.endswith("/modelDescription.xml") and n.count("/") == 2]
        top = {p for n in names if (p := _platform_of(n, ""))}
        keep = {p for p in top if all(any(_same_platform(_platform_of(n, pre), p) for n in names) for pre in nested)}
        keys = {_PLATFORM_KEY.get(p, p) for p in keep}

        def kept(n: str) -> bool:
            pre = next((pre for pre in [""] + nested if _platform_of(n, pre)), None)
            return pre is None or _PLATFORM_KEY.get(_platform_of(n, pre), _platform_of(n, pre)) in keys

        if not keep:
            raise ValueError(f"{fmu.name}: no platform is carried by the container and every FMU inside it")
        if all(kept(n) for n in names):
            return sorted(keep)
        tmp = fmu.with_name(fmu.name + ".strip")
        with zipfile.ZipFile(tmp, "w") as out:
            for info in infos:
                if kept(info.filename):
                    out.writestr(info, z.read(info), compress_type=info.compress_type)
    tmp.replace(fmu)
    return sorted(keep)
