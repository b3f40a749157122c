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

Platforms. The wrapper library is built for every platform the project's FMUs carry (Linux x86-64 by
``cargo build --release``; Windows x86-64, Linux aarch64 and macOS x86-64/arm64 by the cross-build scripts
``scripts/build_win64.sh``, ``build_aarch64.sh``, ``build_macos.sh``); each platform's wheel ships that
platform's build under ``scfmu/engines/me_cs/bin/<platform tuple>/`` (:func:`wrapper_libraries`). A face carries the wrapper
in every platform folder for which BOTH the wrapper was built AND the unit carries its own binary of that
CPU (checked from the binaries' headers): ``linux64``/``win64``/``aarch64-linux``/``darwin64`` for an FMI
2.0 unit (``darwin64``: one universal file with the Mac CPUs the unit's own ``darwin64`` file holds), the
platform tuples for an FMI 3.0 unit. Every other platform is simply not offered: its folder is left out of
the face, unit binary included (a loop FMU then drops that platform too, :mod:`scfmu.export.loops`). The
wrapper looks for the unit's library in its platform's standard folder (``platform_folder`` in
``scfmu/engines/me_cs/src/lib.rs``). A cross build of the wrapper that fails costs the FMUs nothing: the
script says why, and faces then carry no such platform.

Faces are cached next to the containers (``$SCFMU_CONTAINER_DIR``), keyed by the FMU file's SHA-256, the
solver settings and the wrapper libraries' identity.
"""

from __future__ import annotations

import hashlib
import os
import platform
import struct
import sys
import zipfile
from importlib import resources
from pathlib import Path
from xml.etree import ElementTree as ET

from ..fmu import fmu_digest
from ..scenario.plan import PlanError, Unit

LIB = "scfmu_me_cs"


# The wrapper's builds, by FMI 3.0 platform tuple (one per OS and CPU): (file name as cargo writes it, file
# name inside a face, the cross build's folder in a source checkout). The host's own build is cargo's
# target/release; a wheel ships each under scfmu/engines/me_cs/bin/<tuple>/ (scripts/build_wheel.sh).
_BUILDS = {
    "x86_64-linux": (f"lib{LIB}.so", f"{LIB}.so", None),
    "aarch64-linux": (f"lib{LIB}.so", f"{LIB}.so", "target/aarch64/aarch64-unknown-linux-gnu/release"),
    "x86_64-windows": (f"{LIB}.dll", f"{LIB}.dll", "target/win64/x86_64-win7-windows-gnu/release"),
    "x86_64-darwin": (f"lib{LIB}.dylib", f"{LIB}.dylib", "target/macos/x86_64-apple-darwin/release"),
    "aarch64-darwin": (f"lib{LIB}.dylib", f"{LIB}.dylib", "target/macos/aarch64-apple-darwin/release"),
}
# FMI 2.0 folder -> the tuples whose builds it holds (darwin64: one universal file of both Mac CPUs; the
# project's FMUs carry the aarch64 Linux build under the FMI 3.0 name, where the wrapper looks for it too)
_FMI2_FOLDERS = {"linux64": ("x86_64-linux",), "aarch64-linux": ("aarch64-linux",),
                 "win64": ("x86_64-windows",), "darwin64": ("x86_64-darwin", "aarch64-darwin")}
# FMI 3.0 tuples the wrapper can serve (scfmu/engines/me_cs/src/lib.rs, platform_folder)
_FMI3_TUPLES = ("x86_64-linux", "aarch64-linux", "x86_64-windows", "x86_64-darwin", "aarch64-darwin")
_EXT = {"linux": "so", "windows": "dll", "darwin": "dylib"}
_MACHO_CPU = {0x01000007: "x86_64", 0x0100000C: "aarch64"}  # mach-o/machine.h CPU_TYPE_X86_64, CPU_TYPE_ARM64
_ELF_CPU = {62: "x86_64", 183: "aarch64"}  # e_machine EM_X86_64, EM_AARCH64
_PE_CPU = {0x8664: "x86_64", 0xAA64: "aarch64"}  # IMAGE_FILE_MACHINE_AMD64, _ARM64


def binary_tuples(data: bytes) -> set[str]:
    """The platform tuples (``x86_64-linux``, ``aarch64-darwin``, ...) of a shared library's bytes, read
    from its header: ELF, PE or (thin or universal) Mach-O; empty when unknown or truncated (a unit's
    binary is not trusted: a header that points past the end is no platform)."""
    try:
        return _header_tuples(data)
    except struct.error:
        return set()


def _header_tuples(data: bytes) -> set[str]:
    if data[:4] == b"\x7fELF" and len(data) > 20:
        cpu = _ELF_CPU.get(struct.unpack_from("<H" if data[5] == 1 else ">H", data, 18)[0])
        return {f"{cpu}-linux"} if cpu else set()
    if data[:2] == b"MZ" and len(data) > 0x40:
        pe = struct.unpack_from("<I", data, 0x3C)[0]
        if data[pe:pe + 4] == b"PE\0\0":
            cpu = _PE_CPU.get(struct.unpack_from("<H", data, pe + 4)[0])
            return {f"{cpu}-windows"} if cpu else set()
        return set()
    if data[:4] == b"\xcf\xfa\xed\xfe":
        cpu = _MACHO_CPU.get(struct.unpack_from("<I", data, 4)[0])
        return {f"{cpu}-darwin"} if cpu else set()
    if data[:4] == b"\xca\xfe\xba\xbe":
        n = struct.unpack_from(">I", data, 4)[0]
        return {f"{_MACHO_CPU[c]}-darwin" for i in range(min(n, 16))
                if (c := struct.unpack_from(">I", data, 8 + 20 * i)[0]) in _MACHO_CPU}
    return set()


def _ext(folder: str) -> str:
    """File extension of the libraries in platform folder ``folder`` (FMI 2.0 folder or FMI 3.0 tuple)."""
    return _EXT[_FMI2_FOLDERS.get(folder, (folder,))[0].split("-")[1]]


def universal_macho(slices: list[bytes]) -> bytes:
    """One universal ("fat") Mach-O file of thin 64-bit slices, each at a 2^14-byte aligned offset
    (mach-o/fat.h, big-endian; the layout fmu-package gives the FMUs' darwin64 files)."""
    align = 14
    header = struct.pack(">II", 0xCAFEBABE, len(slices))
    body, offset = b"", 1 << align
    for sl in slices:
        cpu, sub = struct.unpack_from("<II", sl, 4)
        header += struct.pack(">IIIII", cpu, sub, offset, len(sl), align)
        body += b"\0" * (offset - (1 << align) - len(body)) + sl
        offset = (1 << align) + -(-len(body) // (1 << align)) * (1 << align)
    return header.ljust(1 << align, b"\0") + body


def host_tuple() -> str:
    """This machine's platform tuple."""
    cpu = "aarch64" if platform.machine().lower() in ("aarch64", "arm64") else "x86_64"
    osname = {"win32": "windows", "darwin": "darwin"}.get(sys.platform, "linux")
    return f"{cpu}-{osname}"


def checkout_build(tup: str) -> str:
    """Where a source checkout's build of the wrapper for platform ``tup`` is, relative to the checkout:
    ``target/release/...`` for ``x86_64-linux`` (the build and test machine), the cross-build script's
    folder for the others. The one list of these paths (scripts/build_wheel.sh and the tests ask here)."""
    built, _, cross = _BUILDS[tup]
    return f"{cross or 'target/release'}/{built}"


def wrapper_libraries() -> dict[str, Path]:
    """``{platform tuple: wrapper library}`` of every platform whose build is found: the package's
    ``scfmu/engines/me_cs/bin/<tuple>/`` (a wheel), else, in a source checkout (an editable install),
    cargo's ``target/release`` for this machine's platform and the cross builds' folders for the others."""
    pkg = Path(str(resources.files("scfmu")))
    root = pkg.parent  # the source checkout holding this package (editable install), if it is one
    checkout = (root / "Cargo.toml").is_file()
    out = {}
    for tup, (built, _, cross) in _BUILDS.items():
        shipped = pkg / "engines" / "me_cs" / "bin" / tup / built
        local = root / ("target/release" if tup == host_tuple() else cross or "-") / built
        if shipped.is_file():
            out[tup] = shipped
        elif checkout and local.is_file():
            out[tup] = local
    return out


def wrapper_library() -> Path | None:
    """This machine's wrapper library (see :func:`wrapper_libraries`), else None."""
    return wrapper_libraries().get(host_tuple())


def wrapper_identity() -> tuple:
    """What the faces depend on of the wrapper libraries (platform, size, modification time of each): part of
    the faces' and the containers' cache keys."""
    return tuple((t, p.stat().st_size, p.stat().st_mtime_ns) for t, p in sorted(wrapper_libraries().items()))


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


def _face_binaries(u: Unit, names: set[str], read, libs: dict[str, Path]) -> dict[str, bytes]:
    """``{folder: wrapper bytes}`` of the face of ``u``: every platform folder where the unit carries its own
    library (``read(name)`` gives an archive member) for a CPU whose wrapper was built (``libs``)."""
    ident = u.md.modelExchange.modelIdentifier
    folders = _FMI2_FOLDERS if u.fmi == 2 else {t: (t,) for t in _FMI3_TUPLES}
    out = {}
    for folder, tuples in folders.items():
        member = f"binaries/{folder}/{ident}.{_ext(folder)}"
        if member not in names:
            continue
        have = binary_tuples(read(member)) & set(tuples)  # the unit's own CPUs in that folder
        slices = [libs[t].read_bytes() for t in tuples if t in have and t in libs]
        if not slices:
            continue
        out[folder] = universal_macho(slices) if folder == "darwin64" else slices[0]
    return out


def cs_face(u: Unit, cache: Path) -> Path:
    """The Co-Simulation face of Model Exchange instance ``u`` (built once, then cached in ``cache``): the
    wrapper in every platform folder where both it and the unit have a binary (module docstring)."""
    if wrapper_library() is None:  # this machine's: the face must at least run here
        raise PlanError(f"{u.name}: a Model Exchange unit runs in fmpy's container FMU through scfmu's "
                        f"Co-Simulation wrapper, which is not built: run `cargo build --release -p {LIB}`")
    libs = wrapper_libraries()
    if u.md.modelExchange is None:
        raise PlanError(f"{u.name}: {Path(u.path).name} has no Model Exchange interface")
    cfg = _config(u)
    key = hashlib.sha256(repr((fmu_digest(u.path), cfg, wrapper_identity())).encode()).hexdigest()[:16]
    path = cache / f"{Path(u.path).stem}.me_{key}.fmu"
    if path.exists():
        return path
    with zipfile.ZipFile(u.path) as z:
        names = set(z.namelist())
        faces = _face_binaries(u, names, z.read, libs)
    if not faces:
        raise PlanError(f"{u.name}: {Path(u.path).name} carries no binary of a platform for which scfmu's "
                        f"Co-Simulation wrapper is built ({', '.join(sorted(libs))})")
    for folder in faces:
        fname = f"binaries/{folder}/{LIB}.{_ext(folder)}"
        if fname in names:
            raise PlanError(f"{u.name}: {Path(u.path).name} already carries a library named {fname}")
    cache.mkdir(parents=True, exist_ok=True)
    tmp = cache / f".{path.name}.{os.getpid()}"
    with zipfile.ZipFile(u.path) as zi, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zo:
        for info in zi.infolist():
            data = zi.read(info)
            if info.filename == "modelDescription.xml":
                data = _description(data)
            elif info.filename == f"resources/{LIB}.txt" or (info.filename.startswith("binaries/")
                                                              and info.filename.split("/")[1] not in faces):
                continue  # a platform without a wrapper or without the unit's binary is not offered
            zo.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
        for folder, data in faces.items():
            zo.writestr(f"binaries/{folder}/{LIB}.{_ext(folder)}", data)
        zo.writestr(f"resources/{LIB}.txt", cfg)
    os.replace(tmp, path)
    return path
