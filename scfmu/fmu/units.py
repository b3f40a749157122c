"""The unit cache: FMUs unpacked once per content and shared by every scfmu process of the user.

An FMU carries the binaries of every platform it was built for (ours: five), most of its bytes; a run
needs one. :func:`unpack` writes an FMU's ``modelDescription.xml``, ``resources/`` and whatever else it
holds, but of ``binaries/`` only the running platform's folders (fmpy's names for this machine, the FMI
2.0 folder such as ``linux64`` and the FMI 3.0 tuple such as ``x86_64-linux``; the Model Exchange wrapper
looks in the same two), and neither ``documentation/`` nor ``sources/``. The same holds for the FMUs nested
in a container or loop FMU (``resources/<name>/modelDescription.xml``). It writes them into the entry
``<root>/<SHA-256 of the file>/unit`` and later calls (this process or any other, a Dask worker included)
find them there: a warm run inflates nothing.

Where (:func:`cache_root`): ``$SCFMU_UNIT_CACHE`` (an absolute path), else
``$XDG_CACHE_HOME/scfmu/units``, else ``~/.cache/scfmu/units``. ``SCFMU_UNIT_CACHE=off`` disables the cache:
units are then unpacked whole into the process's scratch folder (scfmu.fmu.scratch), as before the cache.

Bound: after each new entry the least recently used entries are removed until the cache holds at most
``$SCFMU_UNIT_CACHE_MB`` megabytes (10^6 bytes; default 2048). An entry records its size and its last use
(the modification time of its ``complete`` file, touched at each use).

Concurrency and killed processes. An entry is made in a temporary folder ``<root>/.tmp-*`` whose lock a
living maker holds (the lock of scfmu.fmu.scratch: ``flock`` on POSIX, an open handle on Windows); the
``complete`` file (JSON: size, source name, platform folders) is written last, then the folder is renamed
to its final name in one step. When two processes make the same entry, the second rename fails and that
process removes its copy and uses the first. A folder without ``complete`` is never used; a temporary
folder whose maker has died is removed by the next maker (as the scratch folders are swept). Every process
that uses an entry holds a shared ``flock`` on the entry's ``.lock`` until it ends (the system releases it
when the process dies, however it dies); eviction takes an exclusive non-blocking lock, so it skips every
entry a living process uses, then removes ``complete`` first, renames the folder to ``<root>/.trash-*`` and
deletes it. A user that locked the entry in the meantime sees the lock file gone or ``complete`` missing
and unpacks again.

The archive checks of scfmu.fmu.archive run on the whole archive before anything is written, every
written path stays inside the temporary folder, and the unit's files are made read-only (POSIX): a cached
unit is shared, so nothing may write into it (a container's work folder, an isolated run and ``scfmu
check`` unpack into the private scratch folder instead).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
import tempfile
import time
from pathlib import Path

from . import scratch
from .archive import safe_extract

ENV = "SCFMU_UNIT_CACHE"
ENV_MB = "SCFMU_UNIT_CACHE_MB"
DEFAULT_MB = 2048
UNIT = "unit"  # the unzip directory inside an entry
MARK = "complete"  # written last: an entry without it is never used
TMP = ".tmp-"  # an entry being made (its maker holds scratch.LOCK)
TRASH = ".trash-"  # an evicted entry being deleted
DROPPED = ("documentation", "sources", "extra")  # top-level folders of an FMU that running it never reads
# (``extra/`` holds layered-standard files such as fmi-ls-ref reference results: tools read them from the
# archive; a unit sees only its resources folder)
_DIGEST = re.compile(r"^[0-9a-f]{64}$")

_HELD: dict = {}  # (root, digest) -> open descriptor of the entry's lock (shared lock until the process ends)
stats = {"extracted": 0, "reused": 0}  # entries this process made / found made (tests count them)


def cache_root() -> Path | None:
    """The cache folder (module docstring), or None when ``SCFMU_UNIT_CACHE=off``. A value that is neither
    ``off`` nor an absolute path is refused (ValueError), not guessed."""
    raw = os.environ.get(ENV)
    if raw is not None and raw.strip():
        raw = raw.strip()
        if raw.lower() == "off":
            return None
        p = Path(raw).expanduser()
        if not p.is_absolute():
            raise ValueError(f"{ENV} = {raw!r}: give an absolute folder, or 'off' to unpack each unit into the "
                             f"process's scratch folder")
        return p
    xdg = os.environ.get("XDG_CACHE_HOME", "").strip()
    base = Path(xdg) if xdg and os.path.isabs(xdg) else Path.home() / ".cache"  # XDG: a relative value is ignored
    return base / "scfmu" / "units"


def megabytes_setting(name: str, default_mb: float) -> int:
    """A size bound in bytes from the environment variable ``name`` (megabytes of 10^6 bytes, > 0; unset or
    empty: ``default_mb``); anything else is refused with a ValueError naming the variable."""
    raw = os.environ.get(name)
    if raw is None or not raw.strip():
        return int(default_mb * 10**6)
    try:
        mb = float(raw)
    except ValueError:
        mb = float("nan")
    if not mb > 0 or mb == float("inf"):
        raise ValueError(f"{name} = {raw!r}: a number of megabytes > 0 is allowed")
    return int(mb * 10**6)


def budget_bytes() -> int:
    """The cache's size bound from ``$SCFMU_UNIT_CACHE_MB`` (megabytes of 10^6 bytes, > 0; default 2048)."""
    return megabytes_setting(ENV_MB, DEFAULT_MB)


def host_folders() -> frozenset[str]:
    """The binaries folders a loader looks in on this machine: fmpy's FMI 2.0 folder and FMI 3.0 tuple
    (the names scfmu.check.static and the Model Exchange wrapper use too)."""
    import fmpy
    return frozenset((fmpy.platform, fmpy.platform_tuple))


def platform_filter(names: list[str], folders=None):
    """A predicate on the entry names of an FMU: False for ``documentation/``, ``sources/``, ``extra/`` and the
    ``binaries/<folder>/`` of other platforms than ``folders`` (default :func:`host_folders`), at the top
    and inside every nested FMU (``resources/<name>/`` with its own ``modelDescription.xml``)."""
    folders = host_folders() if folders is None else frozenset(folders)
    nested = [n[: -len("modelDescription.xml")] for n in names
              if n.startswith("resources/") and n.endswith("/modelDescription.xml") and n.count("/") == 2]
    prefixes = sorted(nested, key=len, reverse=True) + [""]

    def accept(name: str) -> bool:
        pre = next(p for p in prefixes if name.startswith(p))
        parts = name[len(pre):].split("/")  # a folder entry ends with "/": its last part is ""
        if parts[0] in DROPPED and len(parts) > 1:
            return False
        return not (parts[0] == "binaries" and len(parts) > 2 and parts[1] not in folders)

    return accept


def unpack(path: str | Path, digest: str) -> str:
    """The unzip directory of the FMU file ``path`` whose SHA-256 is ``digest``: its cache entry (made when
    missing; this process keeps it locked until it ends), or, with the cache off, a whole extraction into
    the process's scratch folder."""
    root = cache_root()
    if root is None:
        return safe_extract(path)
    if not _DIGEST.match(digest):
        raise ValueError(f"{digest!r} is not a SHA-256 digest")
    budget_bytes()  # a bad bound is refused before anything is written
    root = Path(os.path.abspath(root))
    d = root / digest
    key = (str(root), digest)
    if key in _HELD and (d / MARK).is_file():
        _touch(d)
        return str(d / UNIT)
    for _ in range(8):  # each round ends with the entry locked, or with it gone (evicted, lost) and retried
        unit = _open(d, key)
        if unit is not None:
            stats["reused"] += 1
            return unit
        unit = _make(root, d, path, key)
        if unit is not None:
            return unit
    raise RuntimeError(f"unit cache {root}: the entry of {Path(path).name} kept disappearing (8 attempts)")


def _touch(d: Path) -> None:
    try:
        os.utime(d / MARK)  # the last use: eviction order
    except OSError:
        pass  # a read-only cache still serves


def _share(fd: int) -> None:
    if os.name == "posix":
        import fcntl
        fcntl.flock(fd, fcntl.LOCK_SH)  # waits only while an evictor or the maker holds it exclusively


def _valid(d: Path, fd: int) -> bool:
    """True when the descriptor ``fd`` is the lock file now at ``d`` and the entry is complete."""
    try:
        return os.path.samestat(os.fstat(fd), os.stat(d / scratch.LOCK)) and (d / MARK).is_file()
    except OSError:
        return False


def _open(d: Path, key) -> str | None:
    """Locks (shared) an existing complete entry and returns its unit folder; None when there is none."""
    try:
        fd = os.open(d / scratch.LOCK, os.O_RDWR)
    except FileNotFoundError:
        if d.is_dir():
            _discard(d)  # a final folder without a lock file: not made by this module; not trusted
        return None
    _share(fd)
    if not _valid(d, fd):
        os.close(fd)
        if d.is_dir() and not (d / MARK).exists():
            _discard(d)  # an evictor ended between removing "complete" and the rename
        return None
    _HELD[key] = fd
    _touch(d)
    return str(d / UNIT)


def _tree_bytes(folder: Path) -> int:
    return sum(os.path.getsize(os.path.join(r, f)) for r, _, files in os.walk(folder) for f in files)


def _read_only(folder: Path) -> None:
    if os.name != "posix":
        return
    for r, _, files in os.walk(folder):
        for f in files:
            p = os.path.join(r, f)
            os.chmod(p, stat.S_IMODE(os.stat(p).st_mode) & ~0o222)


def _make(root: Path, d: Path, path, key) -> str | None:
    """Makes the entry ``d`` (module docstring); returns its unit folder, locked, or None when another process
    made it first or it was evicted before it could be locked (the caller then opens it or tries again)."""
    root.mkdir(parents=True, exist_ok=True)
    sweep(root)
    tmp = Path(tempfile.mkdtemp(prefix=f"{TMP}{d.name[:16]}_", dir=root))
    fd = scratch._lock(str(tmp))  # exclusive while it is made: no sweeper takes it
    won = False
    try:
        safe_extract(path, tmp / UNIT, keep=platform_filter)
        _read_only(tmp / UNIT)
        mark = {"digest": d.name, "bytes": _tree_bytes(tmp / UNIT), "source": Path(path).name,
                "platforms": sorted(host_folders())}
        (tmp / (MARK + ".new")).write_text(json.dumps(mark, indent=1) + "\n")
        os.replace(tmp / (MARK + ".new"), tmp / MARK)
        stats["extracted"] += 1
        if os.name != "posix":
            os.close(fd)  # Windows renames no folder holding an open file
            fd = None
        try:
            os.rename(tmp, d)
            won = True
        except OSError:  # another process made it first (the folder exists): use theirs
            pass
    finally:
        if not won:
            if fd is not None:
                os.close(fd)
            shutil.rmtree(tmp, ignore_errors=True)
    if not won:
        return None  # the caller opens the winner's entry
    if fd is None:
        try:
            fd = os.open(d / scratch.LOCK, os.O_RDWR)
        except OSError:
            return None
    _share(fd)  # exclusive -> shared (an evictor may slip in between: checked next)
    if not _valid(d, fd):
        os.close(fd)
        return None
    _HELD[key] = fd
    prune(root)
    return str(d / UNIT)


def _discard(d: Path) -> bool:
    """Removes entry ``d`` unless a living process holds its lock: ``complete`` first (the entry is no longer
    valid), then a rename to a trash folder, then the deletion. True when removed."""
    taken = scratch._take(str(d))
    if taken is True:
        return False
    trash = d.parent / f"{TRASH}{d.name[:16]}_{os.getpid()}_{time.monotonic_ns()}"
    try:
        try:
            os.remove(d / MARK)
        except FileNotFoundError:
            pass
        os.rename(d, trash)
    except OSError:
        return False
    finally:
        if callable(taken):
            taken()
    shutil.rmtree(trash, ignore_errors=True)
    return True


def entries(root: Path | None = None) -> list[dict]:
    """The complete entries of the cache: ``{"digest", "bytes", "last_use", "path"}``, oldest use first."""
    root = cache_root() if root is None else Path(root)
    out = []
    try:
        found = list(os.scandir(root))
    except OSError:
        return out
    for e in found:
        if not _DIGEST.match(e.name):
            continue
        try:
            st = os.stat(os.path.join(e.path, MARK))
            size = int(json.loads(Path(e.path, MARK).read_text())["bytes"])
        except (OSError, ValueError, KeyError, TypeError):
            continue  # being removed, or broken (discarded when next opened)
        out.append({"digest": e.name, "bytes": size, "last_use": st.st_mtime, "path": e.path})
    return sorted(out, key=lambda x: (x["last_use"], x["digest"]))


def prune(root: Path | None = None, budget: int | None = None) -> list[str]:
    """Removes the least recently used entries until the cache holds at most ``budget`` bytes (default
    :func:`budget_bytes`), skipping every entry a living process holds (this one's included). Returns the
    removed digests."""
    root = cache_root() if root is None else Path(root)
    if root is None:
        return []
    budget = budget_bytes() if budget is None else budget
    found = entries(root)
    total = sum(e["bytes"] for e in found)
    removed = []
    for e in found:
        if total <= budget:
            break
        if _discard(Path(e["path"])):
            total -= e["bytes"]
            removed.append(e["digest"])
    return removed


def sweep(root: Path | None = None) -> list[str]:
    """Removes the temporary folders of makers that have died (their lock is free, or they have none and
    are older than scratch.UNLOCKED_GRACE_S) and leftover trash folders. Returns the removed paths."""
    root = cache_root() if root is None else Path(root)
    removed = []
    try:
        found = list(os.scandir(root))
    except (OSError, TypeError):
        return removed
    for e in found:
        if e.name.startswith(TRASH):
            shutil.rmtree(e.path, ignore_errors=True)
            removed.append(e.path)
            continue
        if not e.name.startswith(TMP):
            continue
        try:
            age = time.time() - e.stat(follow_symlinks=False).st_mtime
        except OSError:
            continue
        taken = scratch._take(e.path)
        if taken is True or (taken is None and age < scratch.UNLOCKED_GRACE_S):
            continue
        try:
            shutil.rmtree(e.path, ignore_errors=True)
        finally:
            if callable(taken):
                taken()
        removed.append(e.path)
    return removed
