"""A Co-Simulation face for a Model Exchange unit, so that fmpy's container FMU (the native engine and loop
FMUs), which nests Co-Simulation units only, can run it.

:func:`cs_face` copies the unit's FMU (FMI 2.0 or 3.0) and adds to the copy a ``<CoSimulation
modelIdentifier="scfmu_me_cs">`` element, the library ``binaries/<platform>/scfmu_me_cs`` (the Rust crate
``scfmu/engines/me_cs``) and ``resources/scfmu_me_cs.txt`` (the unit's Model Exchange model identifier, its
numbers of states and event indicators, and the instance's solver). At run time that library instantiates
the unit's own library as Model Exchange and integrates it over each communication step with the inputs
held: the classic Runge–Kutta 4 at a fixed step (the communication step, or ``max_step``) for ``method =
"RK4"``, Dormand–Prince 5(4) with adaptive steps under ``rtol``/``atol`` for any other method (as the
compiled engine does), with time events, state events located by bisection to 1e-12 relative in time,
``completedIntegratorStep`` and the event iteration. fmpy 0.3.32 ships no such wrapper (older fmpy releases
had one for FMI 2.0 only).

Faces are cached next to the containers (``$SCFMU_CONTAINER_DIR``), keyed by the FMU file's SHA-256, the
solver settings and the wrapper library's identity.
"""

from __future__ import annotations

import hashlib
import os
import platform
import sys
import zipfile
from importlib import resources
from pathlib import Path
from xml.etree import ElementTree as ET

from ..fmu import fmu_digest
from ..scenario.plan import PlanError, Unit

LIB = "scfmu_me_cs"


def _platform(fmi: int) -> tuple[str, str]:
    """(binary folder, library file name) of this platform for an FMI ``fmi`` unit."""
    if sys.platform == "win32":
        return ("win64" if fmi == 2 else "x86_64-windows"), f"{LIB}.dll"
    if sys.platform == "darwin":
        return ("darwin64" if fmi == 2 else "x86_64-darwin"), f"{LIB}.dylib"
    if platform.machine().lower() in ("aarch64", "arm64"):  # the project's folder for both versions
        return "aarch64-linux", f"{LIB}.so"
    return ("linux64" if fmi == 2 else "x86_64-linux"), f"{LIB}.so"


def wrapper_library() -> Path | None:
    """The built wrapper library: ``scfmu/engines/me_cs/bin/<folder>/`` (a wheel) or ``target/release/`` (a
    source checkout built with ``cargo build --release``), else None."""
    name = {"win32": f"{LIB}.dll", "darwin": f"lib{LIB}.dylib"}.get(sys.platform, f"lib{LIB}.so")
    pkg = Path(str(resources.files("scfmu")))
    shipped = pkg / "engines" / "me_cs" / "bin" / _platform(2)[0] / name
    if shipped.is_file():
        return shipped
    root = pkg.parent  # the source checkout holding this package (editable install), if it is one
    built = root / "target" / "release" / name
    return built if (root / "Cargo.toml").is_file() and built.is_file() else None


def _config(u: Unit) -> str:
    md = u.md
    ident = md.modelExchange.modelIdentifier
    s = u.solver or {}
    lines = [f"model_identifier={ident}", f"method={s.get('method', 'DOP853')}",
             f"rtol={float(s.get('rtol', 1e-10))!r}", f"atol={float(s.get('atol', 1e-12))!r}",
             f"max_step={float(s.get('max_step', 0.0))!r}"]
    if u.fmi == 2:  # an FMI 3.0 unit is asked for its numbers at instantiation
        lines += [f"states={len(md.derivatives)}", f"event_indicators={int(md.numberOfEventIndicators or 0)}"]
    return "\n".join(lines) + "\n"


def _description(xml: bytes) -> bytes:
    """The unit's modelDescription.xml with its ``<CoSimulation>`` element (if any) replaced by the wrapper's,
    placed right after ``<ModelExchange>`` (the order both schemas prescribe)."""
    root = ET.fromstring(xml)
    me = root.find("ModelExchange")
    for cs in root.findall("CoSimulation"):
        root.remove(cs)
    attrs = {"modelIdentifier": LIB, "canHandleVariableCommunicationStepSize": "true"}
    for k in ("needsExecutionTool", "canBeInstantiatedOnlyOncePerProcess"):
        if me.get(k) is not None:
            attrs[k] = me.get(k)
    cs = ET.Element("CoSimulation", attrs)
    cs.tail = me.tail
    root.insert(list(root).index(me) + 1, cs)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def cs_face(u: Unit, cache: Path) -> Path:
    """The Co-Simulation face of Model Exchange instance ``u`` (built once, then cached in ``cache``)."""
    lib = wrapper_library()
    if lib is None:
        raise PlanError(f"{u.name}: a Model Exchange unit runs in fmpy's container FMU through scfmu's "
                        f"Co-Simulation wrapper, which is not built: run `cargo build --release -p {LIB}`")
    if u.md.modelExchange is None:
        raise PlanError(f"{u.name}: {Path(u.path).name} has no Model Exchange interface")
    st = lib.stat()
    cfg = _config(u)
    key = hashlib.sha256(repr((fmu_digest(u.path), cfg, st.st_size, st.st_mtime_ns)).encode()).hexdigest()[:16]
    path = cache / f"{Path(u.path).stem}.me_{key}.fmu"
    if path.exists():
        return path
    folder, fname = _platform(u.fmi)
    with zipfile.ZipFile(u.path) as z:
        if f"binaries/{folder}/{fname}" in z.namelist():
            raise PlanError(f"{u.name}: {Path(u.path).name} already carries a library named {fname}")
    cache.mkdir(parents=True, exist_ok=True)
    tmp = cache / f".{path.name}.{os.getpid()}"
    with zipfile.ZipFile(u.path) as zi, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zo:
        for info in zi.infolist():
            data = zi.read(info)
            if info.filename == "modelDescription.xml":
                data = _description(data)
            elif info.filename == f"resources/{LIB}.txt" or (info.filename.startswith("binaries/")
                                                              and not info.filename.startswith(f"binaries/{folder}/")):
                continue  # the face runs where its wrapper library was built: this platform only
            zo.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
        zo.write(lib, f"binaries/{folder}/{fname}")
        zo.writestr(f"resources/{LIB}.txt", cfg)
    os.replace(tmp, path)
    return path
