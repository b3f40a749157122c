"""valgrind memcheck over every FMU we ship (issue 33, item 6): a short generic walk (tests/hostile/fmu_walk.c:
two instances, initialisation with the inputs at their start values, steps with every real output read and
finite, an FMU state serialized and restored into the other instance, terminate, free, twice per library
load) under memcheck with definite and indirect leaks counted as errors. Time-bounded: in CI every FMU file
once (its Model Exchange interface where it has one, which runs more entry points and the derivatives,
else Co-Simulation), 20 steps; with SCFMU_LONG=1 every interface of every FMU, 200 steps. The leak checks per
library load and the hostile call sequences under valgrind are in tests/test_hardening.py
(both FMI versions)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from foreign_units import fmi_headers_dir
from scfmu.check import _extract, _release
from scfmu.check.static import binaries_check, unit_spec

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = sorted((ROOT / "fmus").glob("*.fmu")) + sorted((ROOT / "fmus" / "fmi3").glob("*.fmu"))
LONG = os.environ.get("SCFMU_LONG") == "1"
IN_CI = os.environ.get("CI") == "true"


@pytest.fixture(scope="module")
def walker(tmp_path_factory):
    if shutil.which("valgrind") is None:
        if IN_CI:
            pytest.fail("valgrind missing in CI (scripts/setup.sh installs it)")
        pytest.skip("valgrind not installed")
    prog = tmp_path_factory.mktemp("walk") / "fmu_walk"
    subprocess.run(["gcc", "-O1", "-g", "-Wall", "-Werror", f"-I{fmi_headers_dir()}", "-o", str(prog),
                    str(ROOT / "tests" / "hostile" / "fmu_walk.c"), "-ldl", "-lm"], check=True)
    return prog


def walk(prog: Path, fmu: Path, interface: str, steps: int) -> tuple[int, str, str]:
    md, d, created = _extract(fmu)
    try:
        _, libs = binaries_check(md, d)
        spec = unit_spec(md, d, interface, libs[interface])
        reals = ("Real", "Float64")
        ins = ",".join(f"{v['vr']}={float(v['start'] or 0.0)!r}" for v in spec["inputs"] if v["type"] in reals)
        outs = ",".join(str(v["vr"]) for v in spec["outputs"] if v["type"] in reals)
        cmd = ["valgrind", "--leak-check=full", "--show-leak-kinds=definite,indirect",
               "--errors-for-leak-kinds=definite,indirect", "--error-exitcode=99",
               str(prog), str(spec["version"]), interface, spec["library"], spec["token"], spec["resources"],
               str(steps), repr(spec["step"]), str(spec["nx"]), "1" if spec["can_serialize_state"] else "0", ins, outs]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        return p.returncode, p.stdout, p.stderr
    finally:
        _release(d, created)


def _cases():
    out = []
    for fmu in SHIPPED:
        import zipfile
        with zipfile.ZipFile(fmu) as z:
            has_me = "<ModelExchange" in z.read("modelDescription.xml").decode()
        itfs = (["cs", "me"] if has_me else ["cs"]) if LONG else (["me"] if has_me else ["cs"])
        out += [(fmu, i) for i in itfs]
    return out


def test_every_shipped_fmu_under_valgrind(walker):
    cases = _cases()
    assert len({f for f, _ in cases}) >= 48
    steps = 200 if LONG else 20
    with ThreadPoolExecutor(max_workers=2) as ex:
        results = list(ex.map(lambda c: (c, walk(walker, c[0], c[1], steps)), cases))
    bad = []
    for (fmu, itf), (rc, out, err) in results:
        summary = re.search(r"ERROR SUMMARY: (\d+) errors", err)
        lost = re.search(r"definitely lost: ([\d,]+) bytes", err)
        if rc != 0 or not out.startswith("ok") or not summary or summary.group(1) != "0" or \
                (lost and lost.group(1) != "0"):
            bad.append(f"{fmu.parent.name}/{fmu.name} {itf}: exit {rc} {out.strip()} "
                       + " | ".join(l for l in err.splitlines() if "lost:" in l or "ERROR" in l or "Invalid" in l
                                    or "->" in l or "log:" in l)[:600])
    print(f"valgrind memcheck: {len(cases)} walks ({steps} steps, 2 instances, FMU state round trip, 2 cycles)")
    assert not bad, "\n".join(bad)


def test_the_walk_under_valgrind_catches_a_leak(walker, tmp_path):
    """The broken unit that leaks 1 MiB per instance (tests/foreign/broken) fails the same walk."""
    from test_check_broken import build_broken
    fmu = build_broken(tmp_path, "leak")
    rc, out, err = walk(walker, fmu, "cs", 4)
    assert rc == 99, (rc, out, err[-2000:])
    assert re.search(r"definitely lost: 4,194,304 bytes in 4 blocks", err), err[-2000:]  # 2 cycles x 2 instances
