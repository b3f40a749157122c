"""Archive limits (issue 33, item 3): every FMU this package unpacks (ours, a user's, one shipped to a
campaign worker, the units nested in a loop FMU, an SSP) is inspected before anything is written: total
uncompressed size, number of entries and per-entry compression ratio are limited (defaults, environment
variables, an API argument), symbolic links and paths that leave the extraction folder are refused, and a
failed extraction leaves no folder behind.

The hostile archives are built here: a zip bomb (a 64 MiB entry of zeros that deflates to about 64 kB: small
on disk), an entry marked as a symbolic link, zip-slip names, an entry whose data is corrupted mid-way, and
a directory named like an FMU. Each is also given to ``scfmu run`` (exit 2, one line, no traceback)."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from scfmu import campaign
from scfmu import fmu as fmu_mod
from scfmu.fmu import ArchiveError, ArchiveLimits, fmu_path, inspect_archive, safe_extract, scratch
from scfmu.scenario import get, ssp

MiB = 1 << 20


def scfmu(*args, env=None, timeout=300):
    e = dict(os.environ, **(env or {}))
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=e)


def one_line_exit_2(r) -> str:
    """The stderr of a refused command: exit 2, exactly one error line (beside notices of a swap), no
    traceback."""
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr, r.stderr
    lines = [x for x in r.stderr.splitlines() if x.strip() and not x.startswith(("notice:", "warning:"))]
    assert len(lines) == 1, r.stderr
    return lines[0]


def copy_fmu_with(dst: Path, extra: list[tuple[zipfile.ZipInfo | str, bytes]], src: str = "PdController") -> Path:
    """Our PdController FMU with extra entries appended (name or ZipInfo, data)."""
    with zipfile.ZipFile(fmu_path(src)) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for i in zin.infolist():
            zout.writestr(i, zin.read(i))
        for info, data in extra:
            zout.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED, compresslevel=9)
    return dst


@pytest.fixture(scope="module")
def bomb(tmp_path_factory) -> Path:
    """A valid PdController FMU carrying resources/zeros.bin: 64 MiB of zeros deflated to ~65 kB."""
    p = tmp_path_factory.mktemp("bomb") / "Bomb.fmu"
    copy_fmu_with(p, [("resources/zeros.bin", bytes(64 * MiB))])
    assert p.stat().st_size < 7 * MiB  # small on disk (the FMU itself is ~6 MB of binaries)
    return p


@pytest.fixture
def private_tmp(tmp_path, monkeypatch) -> Path:
    """tempfile's folder redirected to an empty folder, to see what an extraction leaves behind."""
    d = tmp_path / "tmp"
    d.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(d))
    return d


def left(tmp: Path) -> list[str]:
    """What extractions left in the process's scratch folder(s) inside ``tmp`` (scfmu.fmu.scratch)."""
    return sorted(p.name for f in tmp.glob(scratch.PREFIX + "*") for p in f.iterdir() if p.name != scratch.LOCK)


def test_our_fmus_pass_the_default_limits():
    fmus = sorted(fmu_path("PdController").parent.rglob("*.fmu"))
    assert len(fmus) > 20
    for p in fmus:
        inspect_archive(p)  # raises on a refusal


def test_zip_bomb_is_refused_before_anything_is_written(bomb, private_tmp):
    info = [i for i in zipfile.ZipFile(bomb).infolist() if i.filename == "resources/zeros.bin"][0]
    assert info.file_size / info.compress_size > 500  # it is a bomb
    with pytest.raises(ArchiveError, match=r"resources/zeros.bin.*ratio \d+.*at most 200"):
        safe_extract(bomb)
    assert list(private_tmp.iterdir()) == []
    # an explicit limit lets it through (the API argument), into a folder that is then removed by us
    d = safe_extract(bomb, limits=ArchiveLimits(max_ratio=5000))
    assert (Path(d) / "resources" / "zeros.bin").stat().st_size == 64 * MiB
    import shutil
    shutil.rmtree(d)


def test_zip_bomb_on_the_command_line(bomb):
    line = one_line_exit_2(scfmu("run", "default", "--fmu", f"controller={bomb}", "--no-plot"))
    assert "zeros.bin" in line and "SCFMU_FMU_MAX_RATIO" in line
    # the ratio limit comes from the environment: raised, the unit runs
    r = scfmu("run", "default", "--fmu", f"controller={bomb}", "--t-end", "1", "--no-plot", "--out",
              bomb.parent / "o", env={"SCFMU_FMU_MAX_RATIO": "5000"})
    assert r.returncode == 0, r.stderr


def test_total_size_and_file_count_limits_from_the_environment(monkeypatch, private_tmp):
    pd = fmu_path("PdController")
    total = sum(i.file_size for i in zipfile.ZipFile(pd).infolist())
    monkeypatch.setenv("SCFMU_FMU_MAX_BYTES", str(total - 1))
    with pytest.raises(ArchiveError, match=f"more than {total - 1} bytes.*SCFMU_FMU_MAX_BYTES"):
        safe_extract(pd)
    monkeypatch.setenv("SCFMU_FMU_MAX_BYTES", str(total))
    d = safe_extract(pd)  # exactly at the limit: accepted
    assert (Path(d) / "modelDescription.xml").is_file()
    monkeypatch.delenv("SCFMU_FMU_MAX_BYTES")
    n = len(zipfile.ZipFile(pd).infolist())
    monkeypatch.setenv("SCFMU_FMU_MAX_FILES", str(n - 1))
    with pytest.raises(ArchiveError, match=f"{n} entries; at most {n - 1}.*SCFMU_FMU_MAX_FILES"):
        safe_extract(pd)
    monkeypatch.setenv("SCFMU_FMU_MAX_BYTES", str(pd.stat().st_size - 1))  # the archive itself is too large
    with pytest.raises(ArchiveError, match=f"{pd.stat().st_size} bytes; the limit is"):
        inspect_archive(pd)
    monkeypatch.delenv("SCFMU_FMU_MAX_BYTES")
    monkeypatch.setenv("SCFMU_FMU_MAX_FILES", "many")
    with pytest.raises(ArchiveError, match="SCFMU_FMU_MAX_FILES = 'many': expected a positive integer"):
        safe_extract(pd)
    assert left(private_tmp) == [Path(d).name]


def symlink_info(name: str) -> zipfile.ZipInfo:
    i = zipfile.ZipInfo(name)
    i.external_attr = (stat.S_IFLNK | 0o777) << 16
    i.create_system = 3  # Unix
    return i


def test_symlink_entry_is_refused_and_nothing_is_left(tmp_path, private_tmp):
    p = copy_fmu_with(tmp_path / "Link.fmu", [(symlink_info("resources/passwd"), b"/etc/passwd")])
    with pytest.raises(ArchiveError, match="'resources/passwd' refused: a symbolic link"):
        safe_extract(p)
    assert list(private_tmp.iterdir()) == []
    line = one_line_exit_2(scfmu("run", "default", "--fmu", f"controller={p}", "--no-plot"))
    assert "symbolic link" in line


@pytest.mark.parametrize("name, why", [
    ("../evil.txt", "'..' component"),
    ("resources/../../evil.txt", "'..' component"),
    ("/tmp/evil.txt", "absolute path"),
    ("C:/evil.txt", "drive letter"),
    ("C:evil.txt", "drive letter"),
    ("resources\\..\\..\\evil.txt", "backslash"),
])
def test_zip_slip_names_are_refused_before_writing(tmp_path, private_tmp, name, why):
    p = copy_fmu_with(tmp_path / "Slip.fmu", [(name, b"owned")])
    dest = tmp_path / "out" / "inner"
    with pytest.raises(ArchiveError, match=why):
        safe_extract(p, dest)
    assert not dest.exists() and not (tmp_path / "out" / "evil.txt").exists() and not (tmp_path / "evil.txt").exists()
    assert list(private_tmp.iterdir()) == []


def test_zip_slip_on_the_command_line(tmp_path):
    p = copy_fmu_with(tmp_path / "Slip.fmu", [("../../evil.txt", b"owned")])
    line = one_line_exit_2(scfmu("run", "default", "--fmu", f"controller={p}", "--no-plot"))
    assert "'../../evil.txt' refused" in line


def test_a_failure_while_writing_removes_the_folder(tmp_path, private_tmp):
    """A stored entry whose bytes are corrupted after the checks passed: the CRC fails mid-way through the
    extraction; the half-written folder is removed."""
    p = tmp_path / "Corrupt.fmu"
    with zipfile.ZipFile(fmu_path("PdController")) as zin, zipfile.ZipFile(p, "w", zipfile.ZIP_STORED) as zout:
        for i in zin.infolist():
            zout.writestr(i.filename, zin.read(i))
        zout.writestr("resources/zz_last.bin", b"A" * 100_000)
    data = bytearray(p.read_bytes())
    k = data.find(b"A" * 1000)
    data[k + 500] = ord("B")
    p.write_bytes(bytes(data))
    inspect_archive(p)  # the directory is fine
    with pytest.raises(ArchiveError, match="zz_last.bin|CRC|extraction failed"):
        safe_extract(p)
    assert left(private_tmp) == []
    # fmpy's own extract (used before) leaves its temporary folder behind on the same file
    from fmpy import extract
    with pytest.raises(Exception):
        extract(str(p))
    assert len([f for f in private_tmp.iterdir() if not f.name.startswith(scratch.PREFIX)]) == 1


def test_a_directory_named_like_an_fmu(tmp_path):
    d = tmp_path / "x.fmu"
    (d / "binaries").mkdir(parents=True)
    with pytest.raises(ArchiveError, match="is a directory, not an FMU file"):
        safe_extract(d)
    with pytest.raises(FileNotFoundError, match="is a directory"):
        fmu_path(str(d))
    line = one_line_exit_2(scfmu("run", "default", "--fmu", f"controller={d}", "--no-plot"))
    assert "a directory, not an FMU file" in line
    one_line_exit_2(scfmu("benchmark", str(d), "--cases", "x"))


def test_limits_travel_with_a_campaigns_runs_to_the_worker(bomb, monkeypatch):
    """A worker applies the client's limits (they are part of each run's spec): the bomb is refused on the
    worker side as a failed run, not extracted."""
    monkeypatch.setenv("SCFMU_FMU_MAX_RATIO", "300")
    c = campaign.Campaign(get("default", stop_time=1.0).with_models({"controller": str(bomb)}), isolate=False)
    spec = c.runs()[0]
    assert spec["archive_limits"]["max_ratio"] == 300
    monkeypatch.delenv("SCFMU_FMU_MAX_RATIO")  # the worker's own environment says nothing
    try:
        row, _ = campaign.run_one(spec)
        # the run's limits held for the run only: this process is back to its environment's
        assert fmu_mod.archive_limits() == fmu_mod.ArchiveLimits.from_env() and fmu_mod.archive_limits().max_ratio != 300
    finally:
        fmu_mod.set_archive_limits(None)
    assert row["status"] != "ok" and "at most 300" in row["message"], row


def test_an_ssp_is_extracted_with_the_same_limits(tmp_path):
    p = tmp_path / "evil.ssp"
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("SystemStructure.ssd", "<x/>")
        z.writestr("../../evil.ssv", "owned")
    with pytest.raises(ArchiveError, match="'..' component"):
        ssp.read_ssp(p, tmp_path / "work")
    assert not (tmp_path / "evil.ssv").exists() and not (tmp_path / "work").exists()
