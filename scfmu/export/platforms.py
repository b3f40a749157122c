"""Which platforms' binaries an exported file carries (``scfmu export ssp|loop --platform host|all``).

``all`` keeps every binary the FMUs carry (in a checkout built with ``scripts/build_fmus.sh --all``: Linux x86-64
and aarch64, Windows x86-64, macOS), so the file runs on any of those machines; an SSP file of the default
scenario is then about 40 MB and a loop FMU 15–34 MB. ``host`` (the default) keeps only the binaries of the
machine that writes the file: a file to run here, in this machine's fmpy, libcosim or OMSimulator, is about
4 times smaller (docs/tools.md, sizes). From an installed wheel the two are the same (a wheel's FMUs carry its platform only).

A binary's platform is read from its header (ELF, PE or Mach-O: :func:`scfmu.engines.cs_face.binary_tuples`),
not from its folder's name: the aarch64 wheel's FMUs carry their aarch64 build in the FMI 2.0 folder
``linux64``. A platform folder is kept when one of its files is a build for this machine (a universal macOS
file counts for both CPUs). The rule applies at every depth: the archive's own ``binaries/``, the units
unpacked inside a loop FMU (``resources/<unit>/binaries/``) and the FMU files inside an SSP archive
(``resources/<unit>.fmu``), which are rewritten with the same rule.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path, PurePosixPath

from ..engines.cs_face import binary_tuples, host_tuple

PLATFORMS = ("host", "all")


def _folder_of(name: str) -> tuple[str, str] | None:
    """(prefix, platform folder) of an entry ``<prefix>binaries/<platform>/<file>``, else None."""
    parts = PurePosixPath(name).parts
    for i in range(len(parts) - 2):
        if parts[i] == "binaries" and (i == 0 or parts[i - 1] != "binaries"):
            return "/".join(parts[:i]), parts[i + 1]
    return None


def _strip(data: bytes, host: str, name: str) -> tuple[bytes, set[str]]:
    """(the archive ``data`` with only ``host``'s binaries, the folders removed as "prefix/binaries/platform"); a ValueError
    when a unit (the archive itself, or a unit unpacked or zipped inside it) carries binaries but none for ``host``."""
    removed: set[str] = set()
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        infos = z.infolist()
        keep_folder: dict[tuple[str, str], bool] = {}
        for info in infos:
            f = _folder_of(info.filename)
            if f is not None and not info.is_dir() and not keep_folder.get(f):
                keep_folder[f] = host in binary_tuples(z.read(info)[:1 << 16])
        for prefix in {p for p, _ in keep_folder}:
            if not any(keep for (p, _), keep in keep_folder.items() if p == prefix):
                where = f"{name}:{prefix}" if prefix else name
                raise ValueError(f"{where} carries no binary for this machine ({host}): write the file with "
                                 f"--platform all, or build the FMUs for {host}")
        out = io.BytesIO()
        with zipfile.ZipFile(out, "w") as w:
            for info in infos:
                f = _folder_of(info.filename)
                if f is not None and not keep_folder.get(f, True):
                    removed.add("/".join(filter(None, (f[0], "binaries", f[1]))))
                    continue
                body = z.read(info)
                if info.filename.endswith(".fmu") and not info.is_dir():  # an FMU inside (SSP resources)
                    body, inner = _strip(body, host, f"{name}:{info.filename}")
                    removed |= {f"{info.filename}:{r}" for r in inner}
                w.writestr(info, body, compress_type=info.compress_type)
    return out.getvalue(), removed


def keep_host_binaries(path: str | Path, host: str | None = None) -> list[str]:
    """Rewrites the SSP archive or FMU at ``path`` so that it carries only the binaries of ``host`` (default:
    this machine's platform tuple) at every depth; returns the removed platform folders (sorted). Raises
    ValueError when nothing would be left to run here (the archive carries no binary for this machine)."""
    path = Path(path)
    host = host or host_tuple()
    data, removed = _strip(path.read_bytes(), host, path.name)
    if removed:
        tmp = path.with_name(path.name + ".host")
        tmp.write_bytes(data)
        tmp.replace(path)
    return sorted(removed)
