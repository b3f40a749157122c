"""Reference results inside every FMU (fmi-ls-ref, scfmu/verify; issue 35 item 6).

The references are made at build time by our own run in fmpy (scripts/build_fmus.sh). They are checked here
against a second, independent importer: fmi-rs's simulator (a port of the Reference-FMUs' fmusim with its
own loader, calling sequence, input-table interpolation and CSV writer) behind an fmusim-compatible command
line (tests/tools/fmusim_rs.rs), used through ``scfmu verify --importer fmusim``. fmpy's replay is the
exporter's own importer (a reproducibility check); the fmi-rs replay is the independent one. A changed unit
(another controller's binary behind the same ports and references) fails verify, exit code 1.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from scfmu import verify as V

ROOT = Path(__file__).resolve().parents[1]
FMUS = sorted((ROOT / "fmus").glob("*.fmu")) + sorted((ROOT / "fmus" / "fmi3").glob("*.fmu"))
LOOPS = sorted((ROOT / "fmus" / "loops").glob("*.fmu"))
IDS = [str(p.relative_to(ROOT / "fmus")) for p in FMUS]
ROLE = re.compile(r"(document|requirement|specification|model|parameter|system|testcase|"
                  r"experiment(/(smoke-test|validation|uncertainty-analysis))?|result|method|rationale|report|request|"
                  r"delivery|configuration|signature|serialized-state(/.*)?|meta-data|other)\Z")


@pytest.fixture(scope="module")
def fmusim_rs():
    """The fmusim-compatible command line over fmi-rs (built once by cargo)."""
    exe = ROOT / "target" / "release" / "examples" / "fmusim_rs"
    cargo = shutil.which("cargo")
    if cargo:
        r = subprocess.run([cargo, "build", "--release", "--locked", "--example", "fmusim_rs"], cwd=ROOT,
                           capture_output=True, text=True, timeout=1800)
        assert r.returncode == 0, r.stderr[-2000:]
    if not exe.exists():
        pytest.fail(f"{exe} missing (cargo build --release --example fmusim_rs)")
    return str(exe)


def test_every_fmu_is_shipped():
    assert len(FMUS) >= 48 and len(LOOPS) >= 17, (IDS, LOOPS)


@pytest.mark.parametrize("fmu", FMUS + LOOPS, ids=IDS + [f"loops/{p.name}" for p in LOOPS])
def test_manifest_follows_fmi_ls_ref(fmu):
    """The manifest's root, attributes and roles as the layered standard's schema defines them; every
    Related file is in the archive; the result has a column per output and a row per communication point."""
    with zipfile.ZipFile(fmu) as z:
        names = set(z.namelist())
        root = ET.fromstring(z.read(V.MANIFEST))
        assert root.tag == "fmiReferences"
        assert root.get(f"{{{V.LS_NS}}}fmi-ls-name") == "org.fmi-standard.fmi-ls-ref"
        assert root.get(f"{{{V.LS_NS}}}fmi-ls-version") == V.LS_VERSION
        assert root.get(f"{{{V.LS_NS}}}fmi-ls-description") == V.LS_DESCRIPTION
        related = root.findall("Related")
        assert {r.get("role") for r in related} >= {"result", "experiment"}
        for r in related:
            assert ROLE.match(r.get("role")), r.get("role")
            target = os.path.normpath(f"{V.REF_DIR}/{r.get('source')}")
            assert target in names, target
        md_outputs = V.output_names(V._md(fmu))
        assert any(r.get("source").endswith("_in.csv") for r in related) == (fmu not in LOOPS and bool(V.input_names(V._md(fmu))))
    exp, head, data = V.read_references(fmu)
    assert head == ["time", *md_outputs]
    np.testing.assert_allclose(data[:, 0], exp.points(), rtol=0, atol=1e-9 * exp.stop)
    assert len(data) <= V.MAX_ROWS + 1
    assert any(np.ptp(data[:, j]) > 0 for j in range(1, data.shape[1])), "constant outputs would verify nothing"


@pytest.mark.parametrize("fmu", FMUS, ids=IDS)
def test_verifies_in_fmpy_and_in_fmi_rs(fmu, fmusim_rs, monkeypatch):
    monkeypatch.setenv("SCFMU_FMUSIM", fmusim_rs)
    for importer in ("fmpy", "fmusim"):
        devs = V.verify(fmu, importer)
        bad = [(d.name, d.max_dev, d.allowed) for d in devs if not d.ok]
        assert not bad, (importer, bad)


@pytest.mark.parametrize("fmu", LOOPS, ids=[p.name for p in LOOPS])
def test_loop_fmus_verify_in_fmpy_and_in_fmi_rs(fmu, fmusim_rs, monkeypatch):
    """A loop FMU's reference experiment is its scenario as it is (no inputs given)."""
    monkeypatch.setenv("SCFMU_FMUSIM", fmusim_rs)
    for importer in ("fmpy", "fmusim"):
        bad = [(d.name, d.max_dev, d.allowed) for d in V.verify(fmu, importer) if not d.ok]
        assert not bad, (importer, bad)


def test_a_changed_unit_fails_verify(tmp_path, fmusim_rs, monkeypatch, capsys):
    """PidController whose run under the reference experiment changed (its proportional gain kp set from
    2.0 to 2.5 by a parameter set the replay applies, the references left as made): beyond the tolerance in
    both importers, exit code 1 and the deviating outputs marked; the unchanged FMU passes with exit code 0.
    (Controllers of a family with the same ports are equal by construction under their defaults, so another
    unit's binary would not show a difference.)"""
    from scfmu.scenario.ssp import _ssv
    from scfmu.verify import main
    monkeypatch.setenv("SCFMU_FMUSIM", fmusim_rs)
    pid = ROOT / "fmus" / "PidController.fmu"
    with zipfile.ZipFile(pid) as z:
        files = {n: z.read(n) for n in z.namelist() if n.startswith(V.REF_DIR + "/") or n == V.DOC_FILE}
    files[V.MANIFEST] = V._manifest("PidController", True, True)
    files[f"{V.REF_DIR}/PidController_ref.ssv"] = _ssv([("kp", "Real", 2.5)], "PidController_ref")
    changed = tmp_path / "PidController.fmu"
    shutil.copyfile(pid, changed)
    V.inject(changed, files)
    for importer in ("fmpy", "fmusim"):
        assert main([str(changed), "--importer", importer]) == 1
        out = capsys.readouterr().out
        assert "FAILED" in out and "u " in out and "<-- beyond" in out, out
        assert main([str(pid), "--importer", importer]) == 0
        assert "OK" in capsys.readouterr().out


def test_bad_command_lines_are_one_line_errors(tmp_path, capsys):
    from scfmu.verify import main
    assert main([str(tmp_path / "none.fmu")]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main([str(ROOT / "fmus" / "Gyro.fmu"), "--importer", "dymola"]) == 2
    assert "expected one of fmpy, fmusim" in capsys.readouterr().err
    bare = tmp_path / "Bare.fmu"
    with zipfile.ZipFile(ROOT / "fmus" / "Gyro.fmu") as z, zipfile.ZipFile(bare, "w") as o:
        for n in z.namelist():
            if not n.startswith("extra/"):
                o.writestr(n, z.read(n))
    assert main([str(bare)]) == 1
    assert "no reference results" in capsys.readouterr().out


def test_reference_files_are_byte_stable(tmp_path):
    """Writing the references again gives the same archive bytes (fixed entry metadata, deterministic run)."""
    f = tmp_path / "PidController.fmu"
    shutil.copyfile(ROOT / "fmus" / "PidController.fmu", f)
    before = f.read_bytes()
    V.write_references([f], log=lambda *_: None)
    assert f.read_bytes() == before
