"""The process's scratch folder: every temporary folder scfmu makes (the units it unpacks, a container's
work folder, an isolated child's folder) lives in one folder per process, ``scfmu_proc_<pid>_*`` in the
system's temporary folder.

A process that ends normally removes its folder (``atexit``, and multiprocessing's exit hooks, which are the
only ones a Dask worker or any other multiprocessing child runs). A process that does not end normally
(killed by its nanny after a timeout, by a signal, by the out-of-memory killer, or crashed by a user's unit)
leaves its folder behind; so the folder holds a lock (``.lock``, an ``flock`` on POSIX, an open handle on
Windows) for as long as its process lives, and the first scratch folder any later scfmu process makes
removes every ``scfmu_proc_*`` folder whose lock nobody holds. Unpacked units therefore never pile up in
``/tmp`` however a campaign's workers end: a long campaign with killed workers used to leave gigabytes.

A forked child shares its parent's lock (and folder): it is not removed while the child lives, and the child
never removes it (only the process that made a folder removes it at exit).
"""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import tempfile
import time
from pathlib import Path

PREFIX = "scfmu_proc_"
LOCK = ".lock"
# a folder without a lock file is being made (between its mkdtemp and the lock's rename) or was left by a
# process killed in that instant; it is removed only when older than this [s]
UNLOCKED_GRACE_S = 3600.0

_current: dict = {}  # (pid, base) -> (folder, open lock file descriptor)


def process_folder() -> Path:
    """This process's scratch folder (made on first use, in ``tempfile.gettempdir()``; making it first removes
    the folders of ended processes: :func:`sweep`)."""
    base = tempfile.gettempdir()
    key = (os.getpid(), base)
    hit = _current.get(key)
    if hit is not None and os.path.isdir(hit[0]):
        return Path(hit[0])
    sweep(base)
    folder = tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}_", dir=base)
    fd = _lock(folder)
    _current[key] = (folder, fd)
    atexit.register(_remove, os.getpid(), folder)
    try:  # the exit hooks a multiprocessing child runs (it ends with os._exit, skipping atexit)
        from multiprocessing import util
        util.Finalize(None, _remove, args=(os.getpid(), folder), exitpriority=0)
    except Exception:
        pass
    return Path(folder)


def mkdtemp(prefix: str) -> str:
    """A new folder inside this process's scratch folder (as :func:`tempfile.mkdtemp` makes one; the caller
    may remove it earlier, else it goes with the process's folder)."""
    return tempfile.mkdtemp(prefix=prefix, dir=process_folder())


def _lock(folder: str) -> int:
    """Takes the folder's lock; on POSIX the lock file is locked under a temporary name and then renamed, so
    that no sweeper ever sees ``.lock`` unlocked."""
    new = os.path.join(folder, LOCK + ".new")
    fd = os.open(new, os.O_CREAT | os.O_RDWR, 0o600)
    if os.name == "posix":
        import fcntl
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    os.replace(new, os.path.join(folder, LOCK))
    return fd


def _take(folder: str):
    """Takes the lock of an ended process's folder. Returns True when a live process holds it, None when the
    folder has no lock file, else a release function (call it after removing the folder)."""
    path = os.path.join(folder, LOCK)
    if os.name == "posix":
        import fcntl
        try:
            fd = os.open(path, os.O_RDWR)
        except FileNotFoundError:
            return None
        except OSError:
            return True
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            return True
        return lambda: os.close(fd)
    try:  # Windows: an open file cannot be deleted, and its owner keeps it open until it ends
        os.remove(path)
    except FileNotFoundError:
        return None
    except OSError:
        return True
    return lambda: None


def sweep(base: str | None = None) -> list[str]:
    """Removes every scratch folder in ``base`` (default: the temporary folder) of a process that has ended
    (its lock is free; or it has no lock and is older than an hour); only folders this user owns. Returns
    the removed folders."""
    base = base or tempfile.gettempdir()
    removed = []
    try:
        entries = list(os.scandir(base))
    except OSError:
        return removed
    mine = {f for f, _ in _current.values()}
    uid = os.getuid() if hasattr(os, "getuid") else None
    for e in entries:
        if not e.name.startswith(PREFIX) or e.path in mine:
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue
        if not stat.S_ISDIR(st.st_mode) or (uid is not None and st.st_uid != uid):
            continue
        taken = _take(e.path)
        if taken is True or (taken is None and time.time() - st.st_mtime < UNLOCKED_GRACE_S):
            continue
        try:
            shutil.rmtree(e.path, ignore_errors=True)
        finally:
            if taken is not None:
                taken()
        removed.append(e.path)
    return removed


def _remove(pid: int, folder: str) -> None:
    if os.getpid() != pid:  # a forked child never removes its parent's folder
        return
    for key, (f, fd) in list(_current.items()):
        if f == folder:  # the lock first: on Windows an open file cannot be removed
            del _current[key]
            try:
                os.close(fd)
            except OSError:
                pass
    shutil.rmtree(folder, ignore_errors=True)
