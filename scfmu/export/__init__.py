"""Scenarios for other tools: SSP files (``.ssp``; SSP 1.0 by default, 2.0 on request, for FMI 3.0 units) and
loop FMUs (one container FMU per closed loop).

:func:`export` writes either kind for the given scenario names (default: every scenario a plug-in marks as
exported) and validates each file (SSP 1.0 schemas, the SSP 2.0 checks of :mod:`scfmu.scenario.ssp2`;
``fmpy.validate_fmu``); ``scfmu export ssp|loop``
is its command line, called by ``scripts/build_fmus.sh --scenario-files``. ``platform`` chooses the binaries
the files carry: ``"host"`` (default) this machine's only, ``"all"`` every one the FMUs carry
(:mod:`scfmu.export.platforms` says why and how).
"""

from __future__ import annotations

from pathlib import Path

from ..registry import REGISTRY
from ..scenario import get
from ..scenario.ssp import file_stem, identifier, validate_ssp, write_ssp
from ..scenario.ssp2 import check_version
from .loops import write_loop_fmu
from .platforms import PLATFORMS, keep_host_binaries

KINDS = ("ssp", "loop")


def export(kind: str, out: str | Path, names=None, log=print, platform: str = "host",
           ssp_version: str = "1.0") -> list[Path]:
    """Writes ``<out>/<name with / replaced by _>.ssp`` (kind "ssp", SSP ``ssp_version`` "1.0" or "2.0")
    or ``.fmu`` (kind "loop") for each scenario name (a registered name, or a scenario object) with the
    binaries of ``platform`` ("host" or "all") and validates it; returns the paths."""
    if kind not in KINDS:
        raise ValueError(f"export kind {kind!r}: expected one of {KINDS}")
    if platform not in PLATFORMS:
        raise ValueError(f"export platform {platform!r}: expected one of {PLATFORMS}")
    check_version(ssp_version)
    out = Path(out)
    written = []
    ssd_names = {}
    for item in (names or REGISTRY.exported_scenarios()):
        sc = get(item) if isinstance(item, str) else item
        stem = file_stem(item if isinstance(item, str) else sc.name)  # the name asked for (paper001/a, not .../dist0)
        if kind == "ssp":
            # the system names inside the files are identifiers and must stay unique across the set
            other = ssd_names.setdefault(identifier(file_stem(sc.name)), stem)
            if other != stem:
                raise ValueError(f"scenarios {other} and {stem} get the same SSP system name {identifier(file_stem(sc.name))}")
            p = write_ssp(sc, out / f"{stem}.ssp", version=ssp_version)
            if platform == "host":
                keep_host_binaries(p)
            problems = validate_ssp(p)
            what = f"not valid SSP {ssp_version}"
        else:
            from fmpy.validation import validate_fmu
            p = write_loop_fmu(sc, out / f"{stem}.fmu")
            if platform == "host":
                keep_host_binaries(p)
            problems = validate_fmu(str(p))
            what = "fmpy validation failed"
        if problems:
            raise RuntimeError(f"{p}: {what}: {problems[:5]}")
        log(f"wrote {p} ({p.stat().st_size // 1024} KiB, binaries: {'this machine' if platform == 'host' else 'all'})")
        written.append(p)
    return written
