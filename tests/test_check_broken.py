"""`scfmu check` against units broken on purpose (tests/foreign/broken/broken_unit.c, compiled here with gcc
against the FMI 2.0 headers fmpy ships): the healthy build passes every check, and each broken build is
caught by the check named for its fault, with the failure kind and a reproducer that ends in the guilty call:
a crash (SIGSEGV) in fmi2DoStep and a hang in fmi2DoStep by nominal_run, NaN returned with fmi2OK by
nominal_run, a state machine that accepts every call in every state by state_machine, and 1 MiB leaked per
instance by memory."""

from __future__ import annotations

import shutil
import subprocess
import sys
import uuid
import zipfile
from pathlib import Path

import pytest

from foreign_units import fmi_headers_dir
from scfmu.check import CLASSIC_CHECKS, check

BROKEN_DIR = Path(__file__).resolve().parent / "foreign" / "broken"
VARIANTS = {"ok": 0, "crash": 1, "hang": 2, "nan": 3, "lax": 4, "leak": 5, "ends": 6}


def build_broken(dest: Path, variant: str) -> Path:
    """dest/BrokenUnit_<variant>.fmu: the C unit with BROKEN=<variant's number>."""
    if shutil.which("gcc") is None:
        pytest.fail("gcc is needed to build the broken units (scripts/setup.sh installs it)")
    guid = "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"spacecraft_fmus/tests/broken/{variant}")
    so = dest / f"BrokenUnit_{variant}.so"
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-fvisibility=hidden", "-std=gnu11", "-Wall", "-Wextra",
                    "-Werror", f"-I{fmi_headers_dir()}", f'-DMODEL_GUID="{guid}"', f"-DBROKEN={VARIANTS[variant]}",
                    "-o", str(so), str(BROKEN_DIR / "broken_unit.c"), "-lm"], check=True)
    fmu = dest / f"BrokenUnit_{variant}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("modelDescription.xml", (BROKEN_DIR / "modelDescription.xml").read_text().replace("@GUID@", guid))
        z.write(so, "binaries/linux64/BrokenUnit.so")
    return fmu


@pytest.fixture(scope="module")
def broken(tmp_path_factory):
    d = tmp_path_factory.mktemp("broken")
    return {v: build_broken(d, v) for v in VARIANTS}


def failed(rep) -> dict:
    return {r["check"]: r for r in rep.failures()}


def test_the_healthy_build_passes_every_check(broken):
    rep = check(broken["ok"], quick=True, seed=3)
    # its instance handle is the pointer calloc gave: a freed handle whose address a new instance got is that
    # instance's handle (a robustness finding, which the standard does not require); everything else passes
    f = {r["check"]: r for r in rep.failures()}
    assert set(f) == {"stale_handles"}, rep.text()
    assert f["stale_handles"]["class"] == "robustness" and f["stale_handles"]["rule"].startswith("R5")
    assert "its address was given to a new instance" in f["stale_handles"]["detail"]
    assert rep.row("start_times", "cs")["metrics"]["accepted"] == 20
    assert rep.row("state_nan", "cs")["status"] == "n/a"
    assert rep.row("fmu_state", "cs")["status"] == "n/a"  # canGetAndSetFMUstate="false"
    assert rep.row("state_machine", "cs")["metrics"]["forbidden_calls"] >= 9


def test_a_crash_in_do_step_is_caught_by_nominal_run(broken):
    rep = check(broken["crash"], quick=True, checks=["nominal_run", "state_machine"])
    f = failed(rep)
    assert set(f) == {"nominal_run"}, rep.text()
    assert f["nominal_run"]["kind"] == "crash"
    assert "SIGSEGV" in f["nominal_run"]["detail"]
    # the reproducer ends in the call that never returned: the step from t = 0.05
    assert f["nominal_run"]["reproducer"][-1].startswith("fmi2DoStep(c1, 0.05"), f["nominal_run"]["reproducer"][-3:]
    assert f["nominal_run"]["reproducer"][-1].endswith("...")
    assert rep.row("state_machine", "cs")["status"] == "pass"  # the next check ran in a fresh child


def test_a_hang_in_do_step_is_caught_by_nominal_run_within_the_time_limit(broken):
    rep = check(broken["hang"], quick=True, call_timeout=3, checks=["nominal_run", "bad_arguments"])
    f = failed(rep)
    assert set(f) == {"nominal_run"}, rep.text()
    assert f["nominal_run"]["kind"] == "hang" and f["nominal_run"]["class"] == "robustness"
    assert "a call did not return within 3 s" in f["nominal_run"]["detail"]
    assert f["nominal_run"]["reproducer"][-1].startswith("fmi2DoStep(c1, 0.05")
    assert rep.seconds < 60


def test_a_full_check_of_a_unit_that_hangs_everywhere_takes_under_a_minute(broken):
    """Every step from t = 0.05 never returns: the first hang takes the call bound (5 s), every later one
    AFTER_HANG_CALL (2 s); the full gauntlet (not --quick) ends within 60 s with every stepping check a hang."""
    rep = check(broken["hang"])
    assert rep.seconds < 60, rep.seconds
    hangs = {r["check"] for r in rep.failures() if r["kind"] == "hang"}
    assert {"nominal_run", "random_sequences", "threads", "start_times"} <= hangs, rep.text()  # memory: 3 steps
    assert all(r["class"] == "robustness" for r in rep.failures()), rep.text()
    print(f"full check of a unit that hangs: {rep.seconds:.1f} s, {len(hangs)} checks hang")


def test_a_unit_that_ends_its_run_with_discard_passes(broken):
    """Like Stair (FMI 2.0 Co-Simulation): the step from t = 0.05 returns fmi2Discard and any later step
    fmi2Error; a master stops at the Discard, and so does the checker (5 steps of 0.01 s, then the end)."""
    rep = check(broken["ends"], quick=True, checks=["nominal_run", "threads", "state_machine"])
    assert rep.ok, rep.text()
    row = rep.row("nominal_run", "cs")
    assert row["metrics"]["steps"] == 5 and row["metrics"]["ended"], row
    assert "fmi2Discard" in row["detail"], row["detail"]


def test_nan_returned_with_ok_is_caught_by_nominal_run(broken):
    rep = check(broken["nan"], quick=True)
    f = failed(rep)
    assert "nominal_run" in f, rep.text()
    assert f["nominal_run"]["kind"] == "nonfinite"
    assert "output y = nan returned with status fmi2OK" in f["nominal_run"]["detail"]
    assert f["nominal_run"]["reproducer"][-1].startswith("fmi2GetReal(c1, {2}, 1, values) -> fmi2OK")


def test_a_lax_state_machine_is_caught_by_state_machine(broken):
    rep = check(broken["lax"], quick=True)
    f = failed(rep)
    assert "state_machine" in f, rep.text()
    assert f["state_machine"]["kind"] == "wrong_state"
    assert "step in Instantiated returned fmi2OK" in f["state_machine"]["detail"]
    # the reproducer: instantiate, then the forbidden step, accepted
    repro = f["state_machine"]["reproducer"]
    assert repro[0].startswith("fmi2Instantiate(") and repro[1].startswith("fmi2DoStep(c") and \
        repro[1].endswith("-> fmi2OK"), repro
    assert "nominal_run" not in f and "memory" not in f


def test_a_leak_per_instance_is_caught_by_memory(broken):
    rep = check(broken["leak"], quick=True, checks=list(CLASSIC_CHECKS))
    f = failed(rep)
    assert set(f) == {"memory"}, rep.text()
    assert f["memory"]["kind"] == "leak"
    per = float(f["memory"]["detail"].split("(")[1].split(" kB per instance")[0])
    assert 900 < per < 1200, f["memory"]["detail"]  # 1 MiB = 1024 kB per instance


def test_the_command_line_exit_codes_and_reports(broken, tmp_path):
    def run(*args):
        return subprocess.run([sys.executable, "-m", "scfmu", "check", *map(str, args)], capture_output=True,
                              text=True, timeout=600)
    p = run(broken["ok"], "--quick", "--report", tmp_path / "ok", *[a for c in CLASSIC_CHECKS for a in ("--check", c)])
    assert p.returncode == 0, p.stdout + p.stderr
    assert "the FMU passes" in p.stdout
    assert (tmp_path / "ok" / "check.html").is_file() and (tmp_path / "ok" / "check.json").is_file()
    p = run(broken["lax"], "--quick", "--report", tmp_path / "lax")
    assert p.returncode == 1
    assert "reproducer of state_machine (CS):" in p.stdout
    import json
    data = json.loads((tmp_path / "lax" / "check.json").read_text())
    assert data["ok"] is False and any(r["check"] == "state_machine" and r["status"] == "fail" for r in data["rows"])
    assert "fmi2DoStep" in (tmp_path / "lax" / "check.html").read_text()
    for args, needle in [(["/no/such.fmu"], "not found"), ([tmp_path], "is not a file"),
                         ([broken["ok"], "--seed", "x"], "invalid int value"),
                         ([broken["ok"], "--sequences", "-1"], "--sequences -1"),
                         ([broken["ok"], "--check", "memroy"], "--check 'memroy' is not a check; allowed: nominal_run"),
                         ([broken["ok"], "--call-timeout", "0"], "--call-timeout 0")]:
        p = run(*args)
        assert p.returncode == 2, (args, p.stdout, p.stderr)
        assert needle in p.stderr and "Traceback" not in p.stderr, p.stderr


def test_a_model_description_against_the_schema_is_a_failed_row_not_a_traceback(tmp_path):
    """An FMU whose modelDescription breaks the schema (causality="sideways"): `schema` fails with the line
    and the reason; the checks that need the description read are not applicable; exit status 1."""
    ok = build_broken(tmp_path, "ok")
    bad = tmp_path / "BadSchema.fmu"
    with zipfile.ZipFile(ok) as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'causality="input"', b'causality="sideways"')
            zout.writestr(item, data)
    rep = check(bad, quick=True)
    assert rep.row("schema")["status"] == "fail"
    assert "sideways" in rep.row("schema")["detail"] and "line " in rep.row("schema")["detail"]
    assert rep.failed_checks() == {"schema"}
    assert rep.row("nominal_run")["status"] == "n/a"
    assert not rep.ok
    p = subprocess.run([sys.executable, "-m", "scfmu", "check", str(bad), "--quick"], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 1 and "Traceback" not in p.stdout + p.stderr, p.stderr


def test_an_archive_that_cannot_be_extracted_fails_the_archive_check(tmp_path):
    """A byte of the binary changed inside the zip (its CRC no longer matches): the modelDescription still
    reads (schema passes), the extraction fails: `archive` fails, the dynamic checks are not applicable."""
    ok = build_broken(tmp_path, "ok")
    stored = tmp_path / "Stored.fmu"
    with zipfile.ZipFile(ok) as zin, zipfile.ZipFile(stored, "w", zipfile.ZIP_STORED) as zout:
        for item in zin.infolist():
            zout.writestr(item.filename, zin.read(item))
    data = bytearray(stored.read_bytes())
    i = data.index(b"\x7fELF") + 200
    data[i] ^= 0xFF
    stored.write_bytes(bytes(data))
    rep = check(stored, quick=True)
    assert rep.row("schema")["status"] == "pass"
    assert rep.failed_checks() == {"archive"}, rep.text()
    assert "CRC" in rep.row("archive")["detail"] or "Bad" in rep.row("archive")["detail"], rep.row("archive")
    assert rep.row("threads")["status"] == "n/a"


def test_benchmark_preflight_check_stops_a_failing_unit(broken):
    """`scfmu benchmark UNIT.fmu --check`: the unit that accepts calls in every state is stopped before any run."""
    p = subprocess.run([sys.executable, "-m", "scfmu", "benchmark", str(broken["lax"]), "--check", "--quick"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "fails scfmu check (bad_arguments, random_sequences, state_machine); not benchmarked" in p.stderr
    assert "Traceback" not in p.stderr
