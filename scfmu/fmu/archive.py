"""The archive limits of every FMU (or SSP) this package unpacks.

Every FMU this package unpacks (ours, a user's, one shipped to a Dask worker, the units nested in a loop
FMU) goes through :func:`safe_extract`, which inspects the whole archive before it writes anything and
refuses (:class:`ArchiveError`):

* more than ``max_files`` entries (default 10,000; ``SCFMU_FMU_MAX_FILES``);
* more than ``max_bytes`` uncompressed in total (default 1 GiB; ``SCFMU_FMU_MAX_BYTES``);
* an entry larger than 1 MiB that is more than ``max_ratio`` times its compressed size (default 200;
  ``SCFMU_FMU_MAX_RATIO``; our own FMUs compress at most about 16:1, a zip bomb about 1000:1);
* symbolic links and other special files, encrypted entries, and paths that would leave the extraction
  folder: absolute paths, drive letters (``C:``), backslashes, ``..`` components, NUL bytes.

While writing it counts the bytes again (an entry that inflates past its declared size stops there), and on
any failure it removes the folder it created. :func:`inspect_archive` runs the same checks without
extracting (the pre-flight check uses it before reading a unit's model description).
"""

from __future__ import annotations

import os
import shutil
import stat
import zipfile
from dataclasses import dataclass
from pathlib import Path


# ----- archive limits ----------------------------------------------------------------------------------
class ArchiveError(ValueError):
    """An FMU (or SSP) archive refused by :func:`inspect_archive`/:func:`safe_extract`; the message names
    the file, the entry and the limit."""


@dataclass(frozen=True)
class ArchiveLimits:
    """Limits of one extraction (see the module docstring). ``ratio_floor``: entries up to this size
    [bytes] are not held to ``max_ratio`` (small files of repeated text compress well and cost nothing)."""
    max_bytes: int = 1 << 30
    max_files: int = 10_000
    max_ratio: float = 200.0
    ratio_floor: int = 1 << 20

    ENV = {"max_bytes": "SCFMU_FMU_MAX_BYTES", "max_files": "SCFMU_FMU_MAX_FILES", "max_ratio": "SCFMU_FMU_MAX_RATIO"}

    @classmethod
    def from_env(cls) -> "ArchiveLimits":
        """The defaults, each replaced by its environment variable when set (a positive number)."""
        kw = {}
        for field_, var in cls.ENV.items():
            text = os.environ.get(var)
            if text is None or not text.strip():
                continue
            try:
                v = float(text) if field_ == "max_ratio" else int(text)
            except ValueError:
                v = None
            if v is None or not v > 0 or v != v or v == float("inf"):
                raise ArchiveError(f"{var} = {text!r}: expected a positive "
                                   f"{'number' if field_ == 'max_ratio' else 'integer'}")
            kw[field_] = v
        return cls(**kw)

    def to_dict(self) -> dict:
        return {"max_bytes": self.max_bytes, "max_files": self.max_files, "max_ratio": self.max_ratio,
                "ratio_floor": self.ratio_floor}


_LIMITS_OVERRIDE: ArchiveLimits | None = None


def set_archive_limits(limits: ArchiveLimits | dict | None) -> ArchiveLimits | None:
    """Uses ``limits`` for every extraction of this process (a campaign's workers get the client's);
    None restores the environment's/defaults. Returns the limits set before, to put back."""
    global _LIMITS_OVERRIDE
    before = _LIMITS_OVERRIDE
    _LIMITS_OVERRIDE = ArchiveLimits(**limits) if isinstance(limits, dict) else limits
    return before


def archive_limits() -> ArchiveLimits:
    """The limits in force: :func:`set_archive_limits`, else the environment variables, else the defaults."""
    return _LIMITS_OVERRIDE if _LIMITS_OVERRIDE is not None else ArchiveLimits.from_env()


def _entry_problem(name: str) -> str | None:
    """Why an entry name is not a safe relative path (None when it is)."""
    if "\0" in name:
        return "a NUL byte in the name"
    if "\\" in name:
        return "a backslash in the path (entries use forward slashes)"
    if name.startswith("/"):
        return "an absolute path"
    if len(name) >= 2 and name[1] == ":" and name[0].isalpha():
        return "a drive letter"
    if ":" in name.split("/")[0]:
        return "a device or drive prefix"
    if any(part == ".." for part in name.split("/")):
        return "a '..' component (outside the extraction folder)"
    return None


def inspect_archive(path: str | Path, limits: ArchiveLimits | None = None) -> list[zipfile.ZipInfo]:
    """The entries of a zip archive after every check of :func:`safe_extract` (nothing is written);
    raises :class:`ArchiveError` naming the file, the entry and the limit."""
    limits = limits or archive_limits()
    path = Path(path)
    if path.is_dir():
        raise ArchiveError(f"{path} is a directory, not an FMU file (give the .fmu archive)")
    try:
        size = path.stat().st_size
    except OSError as e:
        raise ArchiveError(f"{path}: {e.strerror or e}") from None
    if size > limits.max_bytes:  # before its directory (which could list millions of entries) is read
        raise ArchiveError(f"{path}: {size} bytes; the limit is {limits.max_bytes} bytes (SCFMU_FMU_MAX_BYTES)")
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
    except zipfile.BadZipFile as e:
        raise ArchiveError(f"{path}: not a zip archive ({e})") from None
    except OSError as e:
        raise ArchiveError(f"{path}: {e.strerror or e}") from None
    if len(infos) > limits.max_files:
        raise ArchiveError(f"{path}: {len(infos)} entries; at most {limits.max_files} are extracted "
                           f"(SCFMU_FMU_MAX_FILES)")
    total = 0
    for i in infos:
        why = _entry_problem(i.filename)
        if why:
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: {why}")
        mode = i.external_attr >> 16
        if stat.S_ISLNK(mode):
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: a symbolic link")
        if stat.S_IFMT(mode) not in (0, stat.S_IFREG, stat.S_IFDIR):
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: a special file (mode {oct(mode)})")
        if i.flag_bits & 0x1:
            raise ArchiveError(f"{path}: entry {i.filename!r} refused: encrypted")
        total += i.file_size
        if total > limits.max_bytes:
            raise ArchiveError(f"{path}: more than {limits.max_bytes} bytes uncompressed (at entry {i.filename!r}); "
                               f"the limit is {limits.max_bytes} bytes (SCFMU_FMU_MAX_BYTES)")
        if i.file_size > limits.ratio_floor and i.file_size > limits.max_ratio * max(i.compress_size, 1):
            raise ArchiveError(f"{path}: entry {i.filename!r} inflates {i.compress_size} bytes to {i.file_size} "
                               f"(ratio {i.file_size / max(i.compress_size, 1):.0f}); at most {limits.max_ratio:g} "
                               f"is allowed (SCFMU_FMU_MAX_RATIO): a zip bomb?")
    return infos


def safe_extract(path: str | Path, dest: str | Path | None = None, limits: ArchiveLimits | None = None,
                 keep=None) -> str:
    """Extracts a zip archive (an FMU or SSP) into ``dest`` (a new temporary folder by default; created when
    absent) after :func:`inspect_archive`; returns the folder. ``keep(names)``, when given, receives every
    entry name of the (inspected) archive and returns a predicate on a name: only the entries it accepts are
    written (the unit cache writes one platform's binaries; scfmu.fmu.units). On any failure the folder is
    removed (when this call created it) and :class:`ArchiveError` is raised."""
    limits = limits or archive_limits()
    infos = inspect_archive(path, limits)  # the whole archive, whatever is then written
    if keep is not None:
        accept = keep([i.filename for i in infos])
        infos = [i for i in infos if accept(i.filename)]
    if dest is None:
        from .scratch import mkdtemp  # inside the process's scratch folder: removed however the process ends
        root = Path(mkdtemp(prefix="scfmu_fmu_"))
        created = root
    else:
        root = Path(dest)
        created = None if root.exists() else root
        root.mkdir(parents=True, exist_ok=True)
    base = root.resolve()
    written = 0
    try:
        with zipfile.ZipFile(path) as z:
            for i in infos:
                target = (base / i.filename).resolve()
                if target != base and base not in target.parents:  # a second line of defence
                    raise ArchiveError(f"{path}: entry {i.filename!r} refused: outside the extraction folder")
                if i.is_dir():
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                n = 0
                with z.open(i) as src, open(target, "wb") as out:
                    while True:
                        block = src.read(1 << 20)
                        if not block:
                            break
                        n += len(block)
                        written += len(block)
                        if n > i.file_size or written > limits.max_bytes:
                            raise ArchiveError(f"{path}: entry {i.filename!r} inflates past its declared size "
                                               f"({i.file_size} bytes)")
                        out.write(block)
    except BaseException as e:
        if created is not None:
            shutil.rmtree(created, ignore_errors=True)
        if isinstance(e, ArchiveError):
            raise
        if isinstance(e, (zipfile.BadZipFile, OSError, EOFError, RuntimeError, ValueError)):
            raise ArchiveError(f"{path}: extraction failed: {e}") from None
        raise
    return str(root)
