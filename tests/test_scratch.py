"""Temporary folders: every private folder scfmu makes (a container's work folder, an isolated run, every unit
with SCFMU_UNIT_CACHE=off) lives in its process's scratch folder (scfmu.fmu.scratch),
which goes with the process however it ends. Each test runs Python processes with a temporary folder of
their own (TMPDIR) and lists what is left in it."""

import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from scfmu.fmu import fmu_path, scratch

ROOT = Path(__file__).resolve().parents[1]


def python(code: str, tmp: Path, env: dict | None = None, **kw) -> subprocess.Popen:
    env = dict(os.environ, TMPDIR=str(tmp), PYTHONPATH=str(ROOT), **(env or {}))
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], env=env, cwd=str(ROOT),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def ours(tmp: Path) -> list[str]:
    """What scfmu left in the temporary folder."""
    return sorted(p.name for p in tmp.iterdir() if p.name.startswith("scfmu"))


def test_a_campaign_on_worker_processes_leaves_no_unpacked_unit(tmp_path):
    """Dask's worker processes end the way every multiprocessing child does, with os._exit after the
    multiprocessing exit hooks (never atexit): the units they unpacked used to stay in /tmp, about 30 MB per
    worker and campaign."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    p = python(f"""
        from scfmu import campaign
        from scfmu import scenario as scenarios
        c = campaign.Campaign(scenarios.get("default", stop_time=0.5),
                              campaign.grid({{"controller.wn": [0.5, 1.0, 2.0, 3.0]}}), seeds=[None])
        rows = campaign.run(c, {str(tmp_path / 'out')!r}, n_workers=2, chunk=1, progress=False).to_pylist()
        assert [r["status"] for r in rows] == ["ok"] * 4, rows
        print("ran")
    """, tmp)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0 and "ran" in out, err[-3000:]
    assert ours(tmp) == []


def test_the_folder_of_a_killed_process_goes_with_the_next_process(tmp_path):
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    unit = str(fmu_path("PdController"))
    a = python(f"""
        import sys, time
        from scfmu.fmu import scratch, unpacked
        md, d = unpacked({unit!r})
        print(scratch.process_folder(), d, flush=True)
        time.sleep(300)
    """, tmp, env={"SCFMU_UNIT_CACHE": "off"})  # units unpacked into the scratch folder (not the unit cache)
    try:
        folder, unzipped = a.stdout.readline().split()
        assert Path(unzipped, "modelDescription.xml").is_file() and Path(unzipped).parent == Path(folder)
        # a live process's folder is never taken: its lock is held
        b = python("from scfmu.fmu import scratch; print(scratch.sweep())", tmp)
        out, err = b.communicate(timeout=60)
        assert b.returncode == 0 and out.strip() == "[]", err
        assert Path(unzipped, "modelDescription.xml").is_file()
    finally:
        a.send_signal(signal.SIGKILL)
        a.communicate()
    assert ours(tmp) == [Path(folder).name]  # SIGKILL: no exit hook ran
    c = python("from scfmu.fmu import scratch; print(scratch.process_folder())", tmp)
    out, err = c.communicate(timeout=60)
    assert c.returncode == 0, err
    assert ours(tmp) == []  # the killed process's folder swept, the new one's removed at its exit


def _child_uses_the_folder(q):
    q.put(str(scratch.process_folder()))


def test_a_forked_child_neither_removes_nor_sweeps_its_parents_folder():
    mine = scratch.process_folder()
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_child_uses_the_folder, args=(q,))
    p.start()
    theirs = q.get(timeout=60)
    p.join(60)
    assert p.exitcode == 0
    assert theirs != str(mine)  # the child made a folder of its own, and ran its exit hooks on it
    assert mine.is_dir() and not Path(theirs).exists()


def test_a_folder_without_lock_is_kept_for_an_hour(tmp_path):
    young = tmp_path / f"{scratch.PREFIX}1_young"
    old = tmp_path / f"{scratch.PREFIX}2_old"
    other = tmp_path / "scfmu_fmu_not_ours_to_judge"
    for d in (young, old, other):
        (d / "x").mkdir(parents=True)
    t = time.time() - scratch.UNLOCKED_GRACE_S - 60
    os.utime(old, (t, t))
    assert scratch.sweep(str(tmp_path)) == [str(old)]
    assert young.is_dir() and other.is_dir() and not old.exists()


@pytest.mark.skipif(os.name != "posix", reason="flock")
def test_a_folder_whose_lock_is_free_is_swept_whatever_its_age(tmp_path):
    d = tmp_path / f"{scratch.PREFIX}3_ended"
    (d / "unit" / "binaries").mkdir(parents=True)
    (d / scratch.LOCK).write_text("")
    assert scratch.sweep(str(tmp_path)) == [str(d)] and not d.exists()


def test_libcosim_that_cannot_unpack_a_unit_is_an_error_not_a_crash(tmp_path):
    """libcosim unpacks each unit into the temporary folder; when it cannot (here: the folder does not exist;
    on a full disk alike), libcosimpy used to hand the NULL slave on to libcosim, a segmentation fault that
    took the whole test session with it."""
    pytest.importorskip("libcosimpy")
    p = python("""
        from scfmu import scenario as s
        from scfmu.engines.libcosim import run_libcosim
        try:
            run_libcosim(s.get("default", stop_time=0.5))
        except RuntimeError as e:
            print("error:", e)
    """, tmp_path / "does_not_exist")
    out, err = p.communicate(timeout=120)
    assert p.returncode == 0, (p.returncode, err[-2000:])
    assert "error: libcosim cannot load command" in out and "temp_directory_path" in out, out


@pytest.mark.parametrize("cache", ["units", "off"])
def test_copies_of_a_unit_share_one_folder_and_a_description_unpacks_nothing(tmp_path, monkeypatch, cache):
    """A test session or a notebook meets the same FMU at many paths (copies, rebuilt identical files):
    unpacked once per content, not per path (in the unit cache, and in the scratch folder with the cache
    off); and reading a model description (planning, resolving, recording a run) unpacks nothing at all."""
    import shutil
    import tempfile

    from scfmu import fmu as fmu_mod
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    monkeypatch.setenv("SCFMU_UNIT_CACHE", "off" if cache == "off" else str(tmp_path / cache))
    src = fmu_path("PdController")
    copies = []
    for i in range(3):
        copies.append(tmp_path / f"copy{i}" / "PdController.fmu")
        copies[-1].parent.mkdir()
        shutil.copy(src, copies[-1])
    mds = [fmu_mod.described(p) for p in copies]
    assert all(md.modelName == "PdController" for md in mds)
    assert [p for p in tmp_path.rglob("modelDescription.xml")] == []
    dirs = {fmu_mod.unpacked(p)[1] for p in copies}
    assert len(dirs) == 1 and Path(next(iter(dirs)), "modelDescription.xml").is_file()
    other = fmu_path("PdController").parent / "fmi3" / "PdController.fmu"  # another file: its own folder
    assert fmu_mod.unpacked(other)[1] not in dirs
