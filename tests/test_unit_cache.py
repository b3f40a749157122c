"""The unit cache (issue 42, item 2: "unpack once, only what runs"; scfmu.fmu.units): an FMU is unpacked
once per content into a cache shared by processes, with the running platform's binaries only; concurrent
makers, killed makers, eviction under a size bound with entries in use, the ``off`` setting, a moved cache
and hostile archives. Every test uses a cache folder of its own under tmp_path; most run the cache in
child processes, the way separate ``scfmu`` commands and Dask workers use it."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
import zipfile
from pathlib import Path

import pytest

from scfmu import fmu as fmu_mod
from scfmu.fmu import ArchiveError, fmu_digest, fmu_path, scratch, units

ROOT = Path(__file__).resolve().parents[1]
HOST = sorted(units.host_folders())
FOREIGN = ["win64", "darwin64", "x86_64-windows", "aarch64-darwin", "aarch64-linux", "linux64", "x86_64-linux"]


def python(code: str, cache: Path, **env) -> subprocess.Popen:
    e = dict(os.environ, SCFMU_UNIT_CACHE=str(cache), PYTHONPATH=str(ROOT), **env)
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], env=e, cwd=str(ROOT),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish(p: subprocess.Popen, timeout: float = 300) -> str:
    out, err = p.communicate(timeout=timeout)
    assert p.returncode == 0, err[-3000:]
    return out


def inventory(cache: Path) -> dict:
    """{entry: (inode of its unit folder, bytes recorded)} and every other name in the cache folder."""
    out = {}
    for p in sorted(cache.iterdir()):
        if p.name.startswith("."):
            out[p.name] = None
        else:
            out[p.name] = (p.joinpath(units.UNIT).stat().st_ino, json.loads(p.joinpath(units.MARK).read_text())["bytes"])
    return out


def files(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in Path(folder).rglob("*") if p.is_file())


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    d = tmp_path / "units"
    monkeypatch.setenv("SCFMU_UNIT_CACHE", str(d))
    monkeypatch.delenv("SCFMU_UNIT_CACHE_MB", raising=False)
    return d


def multi_platform(dst: Path, src: str = "PdController") -> Path:
    """A copy of one of our FMUs that also carries fake binaries of every other platform, documentation,
    sources, layered-standard files under extra/, a resource, and a nested FMU (as a container carries its units) with binaries of its own."""
    lib = {"linux64": "so", "x86_64-linux": "so", "aarch64-linux": "so", "win64": "dll", "x86_64-windows": "dll",
           "darwin64": "dylib", "aarch64-darwin": "dylib"}
    with zipfile.ZipFile(fmu_path(src)) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        names = zin.namelist()
        for i in zin.infolist():
            zout.writestr(i, zin.read(i))
        for folder in FOREIGN:
            if f"binaries/{folder}/{src}.{lib[folder]}" not in names:
                zout.writestr(f"binaries/{folder}/{src}.{lib[folder]}", f"fake {folder}".encode())
            zout.writestr(f"resources/Inner/binaries/{folder}/Inner.{lib[folder]}", f"inner {folder}".encode())
        zout.writestr("resources/Inner/modelDescription.xml", "<fmiModelDescription/>")
        zout.writestr("resources/Inner/documentation/index.html", "<p/>")
        zout.writestr("resources/Inner/resources/table.txt", "1 2 3\n")
        zout.writestr("resources/table.txt", "4 5 6\n")
        zout.writestr("sources/model.c", "int x;\n")
        zout.writestr("documentation/extra.html", "<p/>")
        if "extra/org.fmi-standard.fmi-ls-ref/fmi-ls-manifest.xml" not in names:  # as a built FMU carries
            zout.writestr("extra/org.fmi-standard.fmi-ls-ref/fmi-ls-manifest.xml", "<fmiReferences/>")
        zout.writestr("resources/Inner/extra/org.example/notes.txt", "x\n")
    return dst


# ----- what an entry holds ------------------------------------------------------------------------------
def test_an_entry_holds_the_running_platforms_binaries_only(cache, tmp_path):
    fmu = multi_platform(tmp_path / "Multi.fmu")
    md, d = fmu_mod.unpacked(fmu)
    d = Path(d)
    assert d == cache / fmu_digest(fmu) / units.UNIT
    lib = {"linux64": "so", "x86_64-linux": "so", "aarch64-linux": "so", "win64": "dll", "x86_64-windows": "dll",
           "darwin64": "dylib", "aarch64-darwin": "dylib"}
    want = {"modelDescription.xml", "resources/table.txt", "resources/Inner/modelDescription.xml",
            "resources/Inner/resources/table.txt"}
    want |= {f"binaries/{f}/PdController.{lib[f]}" for f in HOST}
    want |= {f"resources/Inner/binaries/{f}/Inner.{lib[f]}" for f in HOST}
    assert set(files(d)) == want
    assert sorted(p.name for p in (d / "binaries").iterdir()) == HOST
    with zipfile.ZipFile(fmu) as z:  # the kept files are the archive's, byte for byte
        assert all((d / n).read_bytes() == z.read(n) for n in want)
    meta = json.loads((d.parent / units.MARK).read_text())
    assert meta["bytes"] == sum((d / f).stat().st_size for f in files(d))
    assert meta["platforms"] == HOST and meta["source"] == "Multi.fmu"


def test_the_filter_keeps_another_platform_when_asked():
    names = ["modelDescription.xml", "binaries/", "binaries/win64/", "binaries/win64/A.dll", "binaries/linux64/A.so",
             "binaries/x86_64-windows/A.dll", "documentation/index.html", "sources/a.c", "resources/r.txt",
             "resources/B/modelDescription.xml", "resources/B/binaries/darwin64/B.dylib",
             "resources/B/binaries/win64/B.dll", "resources/B/sources/b.c", "resources/notes/sources/keep.txt"]
    keep = units.platform_filter(names, folders={"win64", "x86_64-windows"})
    assert [n for n in names if keep(n)] == [
        "modelDescription.xml", "binaries/", "binaries/win64/", "binaries/win64/A.dll", "binaries/x86_64-windows/A.dll",
        "resources/r.txt", "resources/B/modelDescription.xml", "resources/B/binaries/win64/B.dll",
        "resources/notes/sources/keep.txt"]


def test_a_unit_runs_from_its_entry_and_the_entry_is_read_only(cache):
    """Fmu() without an unzip directory takes the cache's entry (shared, not removed on close); its files
    cannot be rewritten by mistake (their write bits are off)."""
    f = fmu_mod.Fmu("PdController", {"wn": 2.0, "zeta": 0.5, "inertia_xx": 10.0, "inertia_yy": 10.0,
                                     "inertia_zz": 10.0})
    try:
        assert Path(f.unzipdir).parent.parent == cache and not f._owns_dir
        f.set_values(["w_x", "w_y", "w_z"], [0.1, 0.0, 0.0])
        f.do_step(0.0, 0.01)
        # quaternion PD at q = q_ref, w_ref = 0: torque = -kd w with kd = 2 zeta wn J = 20 N.m.s
        assert f.get_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]) == pytest.approx([-2.0, 0.0, 0.0],
                                                                                            abs=1e-12)
    finally:
        f.close()
    unit = Path(f.unzipdir)
    assert (unit / "modelDescription.xml").is_file()  # kept after close
    if os.name == "posix":
        modes = {p.stat().st_mode & 0o222 for p in unit.rglob("*") if p.is_file()}
        assert modes == {0}


# ----- across processes -----------------------------------------------------------------------------------
RUN = """
    from scfmu.fmu import Fmu, units
    f = Fmu("PdController", {"wn": 1.0, "zeta": 1.0, "inertia_xx": 4.0, "inertia_yy": 4.0, "inertia_zz": 4.0})
    f.set_values(["w_x", "w_y", "w_z"], [0.0, 0.5, 0.0])
    f.do_step(0.0, 0.01)
    print(units.stats["extracted"], units.stats["reused"], f.unzipdir, f.get_reals(["torque_cmd_y"])[0])
    f.close()
"""


def test_a_second_process_unpacks_nothing(cache):
    first = finish(python(RUN, cache)).split()
    inv = inventory(cache)
    second = finish(python(RUN, cache)).split()
    assert first[:2] == ["1", "0"] and second[:2] == ["0", "1"]
    assert first[2] == second[2] and float(first[3]) == float(second[3]) == pytest.approx(-4.0, abs=1e-12)
    assert inventory(cache) == inv and len(inv) == 1  # the same folder, not written again


def test_a_second_scfmu_run_unpacks_nothing(cache, tmp_path):
    """``scfmu run default`` twice: the second run finds every unit (and the loop's container) in the cache:
    the same entries, the same folders (inodes)."""
    def run(out):
        r = subprocess.run([sys.executable, "-m", "scfmu", "run", "default", "--t-end", "1", "--no-plot",
                            "--out", str(tmp_path / out)], capture_output=True, text=True, timeout=300,
                           env=dict(os.environ, SCFMU_UNIT_CACHE=str(cache)))
        assert r.returncode == 0, r.stderr[-3000:]
        return (tmp_path / out / "default.csv").read_text()
    a = run("a")
    inv = inventory(cache)
    assert len(inv) >= 4 and not [k for k in inv if k.startswith(".")]
    b = run("b")
    assert inventory(cache) == inv
    assert a == b


def child(code: str, cache: Path, *models: str, **env) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), *models], cwd=str(ROOT), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=dict(os.environ, SCFMU_UNIT_CACHE=str(cache), PYTHONPATH=str(ROOT), **env))


RACE = """
    import os, sys, time
    from pathlib import Path
    from scfmu.fmu import Fmu, fmu_digest, fmu_path, units
    real = units.safe_extract
    def slow(*a, **k):  # every maker finishes its copy before any renames: they all race for the name
        d = real(*a, **k)
        while not Path(sys.argv[1]).exists():
            time.sleep(0.01)
        time.sleep(0.3)
        return d
    units.safe_extract = slow
    path = fmu_path("PdController")
    d = units.unpack(path, fmu_digest(path))
    f = Fmu("PdController", {"wn": 1.0, "zeta": 1.0, "inertia_xx": 4.0, "inertia_yy": 4.0, "inertia_zz": 4.0})
    f.set_values(["w_x", "w_y", "w_z"], [0.0, 0.0, 0.25])
    f.do_step(0.0, 0.01)
    print(units.stats["extracted"], d, f.unzipdir, f.get_reals(["torque_cmd_z"])[0])
    f.close()
"""


def test_concurrent_makers_leave_one_valid_entry(cache, tmp_path):
    go = tmp_path / "go"
    n = 4
    ps = [child(RACE, cache, str(go)) for _ in range(n)]
    deadline = time.time() + 120
    while len([p for p in cache.glob(units.TMP + "*") if (p / units.UNIT).exists()]) < n:
        assert time.time() < deadline and all(p.poll() is None for p in ps), "the makers did not all start"
        time.sleep(0.05)
    go.write_text("")
    outs = [finish(p).split() for p in ps]
    assert [o[0] for o in outs] == ["1"] * n  # every process made a copy ...
    assert len({o[1] for o in outs}) == 1 and all(o[1] == o[2] for o in outs)  # ... and all use one entry
    assert [float(o[3]) for o in outs] == [pytest.approx(-2.0, abs=1e-12)] * n
    inv = inventory(cache)
    assert list(inv) == [fmu_digest(fmu_path("PdController"))]  # the losers' copies are gone
    assert (cache / next(iter(inv)) / units.MARK).is_file()


KILLED = """
    import sys, time
    from scfmu.fmu import fmu_digest, fmu_path, units
    real = units.safe_extract
    def stuck(*a, **k):
        d = real(*a, **k)
        print("extracted", flush=True)
        time.sleep(600)  # killed here: the copy is written, its "complete" file is not
    units.safe_extract = stuck
    path = fmu_path("PdController")
    units.unpack(path, fmu_digest(path))
"""


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL")
def test_a_maker_killed_mid_extraction_leaves_nothing_that_is_used(cache):
    p = python(KILLED, cache)
    assert p.stdout.readline().strip() == "extracted"
    p.send_signal(signal.SIGKILL)
    p.communicate()
    left = list(cache.iterdir())
    assert [x.name.startswith(units.TMP) for x in left] == [True]  # a temporary folder, no entry
    assert (left[0] / units.UNIT / "modelDescription.xml").is_file() and not (left[0] / units.MARK).exists()
    out = finish(python(RUN, cache)).split()
    assert out[:2] == ["1", "0"]  # unpacked again, not taken from the dead maker's folder
    assert float(out[3]) == pytest.approx(-4.0, abs=1e-12)
    assert list(inventory(cache)) == [fmu_digest(fmu_path("PdController"))]  # the dead maker's folder swept


def test_an_entry_without_its_complete_file_is_made_again(cache):
    """A final folder whose ``complete`` file is missing (an evictor killed between removing it and the
    rename) is never used: removed and made again."""
    path = fmu_path("PdController")
    digest = fmu_digest(path)
    finish(python(RUN, cache))
    (cache / digest / units.MARK).unlink()
    (cache / digest / units.UNIT / "modelDescription.xml").chmod(0o644)
    (cache / digest / units.UNIT / "modelDescription.xml").write_text("half")
    out = finish(python(RUN, cache)).split()
    assert out[:2] == ["1", "0"] and float(out[3]) == pytest.approx(-4.0, abs=1e-12)
    assert (cache / digest / units.UNIT / "modelDescription.xml").read_bytes() == \
        zipfile.ZipFile(path).read("modelDescription.xml")


# ----- the bound -------------------------------------------------------------------------------------------
HOLD = """
    import sys, time
    from scfmu.fmu import unpacked, fmu_path
    for m in sys.argv[1:]:
        unpacked(fmu_path(m))
    print("held", flush=True)
    time.sleep(600)
"""
MAKE = """
    import sys
    from scfmu.fmu import unpacked, fmu_path
    for m in sys.argv[1:]:
        unpacked(fmu_path(m))
"""


def test_eviction_takes_the_least_recently_used_free_entry_and_skips_one_in_use(cache):
    pd, pid, lqr = (fmu_digest(fmu_path(m)) for m in ("PdController", "PidController", "LqrController"))
    finish(child(MAKE, cache, "PidController", "LqrController"))  # made by a process that has ended
    holder = child(HOLD, cache, "PdController")
    try:
        assert holder.stdout.readline().strip() == "held"
        now = time.time()
        for digest, age in ((pd, 300), (pid, 200), (lqr, 100)):  # the one in use is the least recently used
            os.utime(cache / digest / units.MARK, (now - age, now - age))
        assert [e["digest"] for e in units.entries(cache)] == [pd, pid, lqr]
        total = sum(e["bytes"] for e in units.entries(cache))
        assert units.prune(cache, budget=total - 1) == [pid]  # pd is in use: the next oldest goes
        assert sorted(inventory(cache)) == sorted([pd, lqr])
        assert units.prune(cache, budget=1) == [lqr]  # the bound cannot be met while pd is in use
        assert list(inventory(cache)) == [pd]
    finally:
        holder.kill()
        holder.communicate()
    assert units.prune(cache, budget=1) == [pd]  # its process has ended: free
    assert list(cache.iterdir()) == []


def test_a_new_entry_evicts_down_to_the_bound_of_the_setting(cache):
    """With SCFMU_UNIT_CACHE_MB below one unit, each new entry evicts every free older one; a process keeps
    its own entries while it lives (the bound is exceeded meanwhile)."""
    first = child(HOLD, cache, "PidController", "LqrController", SCFMU_UNIT_CACHE_MB="1")
    try:
        assert first.stdout.readline().strip() == "held"
        assert len(inventory(cache)) == 2  # both in use by their maker: none evicted
    finally:
        first.kill()
        first.communicate()
    finish(child(MAKE, cache, "PdController", SCFMU_UNIT_CACHE_MB="1"))
    assert list(inventory(cache)) == [fmu_digest(fmu_path("PdController"))]


# ----- settings ----------------------------------------------------------------------------------------------
def test_off_unpacks_whole_into_the_scratch_folder_and_writes_no_cache(tmp_path, monkeypatch):
    fmu = multi_platform(tmp_path / "Multi.fmu")
    monkeypatch.setenv("SCFMU_UNIT_CACHE", "off")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert units.cache_root() is None
    md, d = fmu_mod.unpacked(fmu)
    assert Path(d).parent == scratch.process_folder()
    with zipfile.ZipFile(fmu) as z:
        assert files(Path(d)) == sorted(n for n in z.namelist() if not n.endswith("/"))  # everything
    f = fmu_mod.Fmu("PdController", initialize=False)
    own = Path(f.unzipdir)
    assert f._owns_dir and own.parent == scratch.process_folder()
    f.close()
    assert not own.exists()
    assert not (tmp_path / "xdg").exists() and not (tmp_path / "home").exists()


def test_the_default_folder_follows_xdg_and_the_setting_moves_it(tmp_path, monkeypatch):
    monkeypatch.delenv("SCFMU_UNIT_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert units.cache_root() == tmp_path / "xdg" / "scfmu" / "units"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/ignored")  # the XDG rule: only an absolute path counts
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert units.cache_root() == tmp_path / "home" / ".cache" / "scfmu" / "units"
    monkeypatch.setenv("SCFMU_UNIT_CACHE", str(tmp_path / "elsewhere"))
    assert units.cache_root() == tmp_path / "elsewhere"


@pytest.mark.parametrize("var,value", [("SCFMU_UNIT_CACHE", "relative/dir"), ("SCFMU_UNIT_CACHE_MB", "-5"),
                                       ("SCFMU_UNIT_CACHE_MB", "lots"), ("SCFMU_UNIT_CACHE_MB", "inf")])
def test_a_bad_setting_is_refused(cache, monkeypatch, var, value):
    monkeypatch.setenv(var, value)
    with pytest.raises(ValueError, match=var):
        units.unpack(fmu_path("PdController"), fmu_digest(fmu_path("PdController")))
    assert not cache.exists()


def test_a_moved_cache_folder_still_serves(tmp_path):
    a, b = tmp_path / "a", tmp_path / "moved" / "b"
    first = finish(python(RUN, a)).split()
    b.parent.mkdir()
    a.rename(b)
    second = finish(python(RUN, b)).split()
    assert first[:2] == ["1", "0"] and second[:2] == ["0", "1"]
    assert Path(second[2]).parent.parent == b and float(second[3]) == pytest.approx(-4.0, abs=1e-12)


def test_a_hostile_archive_is_refused_and_nothing_is_written(cache, tmp_path):
    slip = tmp_path / "Slip.fmu"
    with zipfile.ZipFile(fmu_path("PdController")) as zin, zipfile.ZipFile(slip, "w") as z:
        for i in zin.infolist():
            z.writestr(i, zin.read(i))
        z.writestr("resources/../../../../escaped.txt", "x")
    bomb = tmp_path / "Bomb.fmu"
    with zipfile.ZipFile(fmu_path("PdController")) as zin, zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        for i in zin.infolist():
            z.writestr(i, zin.read(i))
        z.writestr("resources/zeros.bin", bytes(32 << 20), compress_type=zipfile.ZIP_DEFLATED, compresslevel=9)
    for hostile, why in ((slip, "'..' component"), (bomb, "zip bomb")):
        with pytest.raises(ArchiveError, match=why):
            units.unpack(hostile, fmu_digest(hostile))
    assert not (tmp_path / "escaped.txt").exists() and not (tmp_path.parent / "escaped.txt").exists()
    assert list(cache.iterdir()) == []  # no entry, no temporary folder
    with pytest.raises(ValueError, match="SHA-256"):
        units.unpack(fmu_path("PdController"), "../../x")


# ----- Dask workers --------------------------------------------------------------------------------------------
def test_campaign_workers_share_the_cache(cache, tmp_path):
    """Two Dask worker processes run a campaign: each unit is unpacked once for both (one entry per
    content); a second campaign unpacks nothing (the same entries, the same folders)."""
    code = """
        import sys
        from scfmu import campaign
        from scfmu import scenario as scenarios
        c = campaign.Campaign(scenarios.get("default", stop_time=0.5),
                              campaign.grid({"controller.wn": [0.5, 1.0, 2.0, 3.0]}), seeds=[None])
        rows = campaign.run(c, sys.argv[1], n_workers=2, chunk=1, progress=False).to_pylist()
        print(" ".join(r["status"] for r in rows))
    """
    def run(out):
        p = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), str(tmp_path / out)], cwd=str(ROOT),
                             text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             env=dict(os.environ, SCFMU_UNIT_CACHE=str(cache), PYTHONPATH=str(ROOT)))
        assert finish(p).split() == ["ok"] * 4
    run("a")
    inv = inventory(cache)
    assert len(inv) >= 4 and not [k for k in inv if k.startswith(".")]
    run("b")
    assert inventory(cache) == inv


def once_per_process_copy(dst: Path, src: str = "PdController") -> Path:
    """A copy of ``src`` whose description declares canBeInstantiatedOnlyOncePerProcess="true"."""
    with zipfile.ZipFile(fmu_path(src)) as z, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as out:
        for info in z.infolist():
            data = z.read(info)
            if info.filename == "modelDescription.xml":
                text = data.decode()
                flag = 'canBeInstantiatedOnlyOncePerProcess="false"'
                assert text.count(flag) >= 1
                text = text.replace(flag, flag.replace("false", "true"))
                data = text.encode()
            out.writestr(info, data)
    return dst


def test_a_once_per_process_unit_gets_a_library_file_per_instance(cache, tmp_path):
    """Two instances of one file share its cached entry (one library, loaded once); a unit that declares it can
    be instantiated only once per process gets a private extraction per instance, so each instance loads a
    library file of its own (a second dlopen of one file would share the library's globals)."""
    shared = [fmu_mod.Fmu("PdController", name=f"s{i}") for i in range(2)]
    once = once_per_process_copy(tmp_path / "Once.fmu")
    private = [fmu_mod.Fmu(str(once), name=f"p{i}") for i in range(2)]
    try:
        assert shared[0].unzipdir == shared[1].unzipdir and str(cache) in str(shared[0].unzipdir)
        assert private[0].unzipdir != private[1].unzipdir
        assert not any(str(cache) in str(f.unzipdir) for f in private)
        for f in private:
            f.do_step(0.0, 0.01)
    finally:
        for f in shared + private:
            f.close()
