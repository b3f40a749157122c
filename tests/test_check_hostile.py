"""The hostile-master checks of `scfmu check` (start_times, stale_handles, state_nan; scfmu.check.hostile) on
FMUs we ship, FMI 2.0 and 3.0: a continuous controller (PdController) and a sampled sensor law (BDot).

What they report today (issue 45) is asserted with what the fixes of the Rust layer will change: a sampled
unit hangs on a start time of about -1e18 (its sample index wraps; the fix refuses such a start time at
initialisation, which also passes), and a freed instance whose address a new instance got steps the new one
(the fix refuses it, which passes). A NaN written into a serialized state breaks its checksum: refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from scfmu.check import HOSTILE_CHECKS, check

ROOT = Path(__file__).resolve().parents[1]
UNITS = [ROOT / "fmus" / "PdController.fmu", ROOT / "fmus" / "BDot.fmu", ROOT / "fmus" / "fmi3" / "PdController.fmu",
         ROOT / "fmus" / "fmi3" / "BDot.fmu"]


@pytest.mark.parametrize("fmu", UNITS, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_hostile_checks_on_shipped_fmus(fmu):
    if not fmu.is_file():
        pytest.fail(f"{fmu} missing: build the FMUs first (scripts/build_fmus.sh)")
    rep = check(fmu, quick=True, checks=list(HOSTILE_CHECKS), call_timeout=2)
    for itf in rep.interfaces:
        st = rep.row("start_times", itf)
        if "BDot" in fmu.name and st["status"] == "fail":  # today: the first DoStep at -1e18 never returns
            assert st["kind"] == "hang" and st["class"] == "robustness", st
            call = st["reproducer"][-1]
            assert call.split("(")[0].endswith("DoStep") and float(call.split(", ")[1]) <= -1e17, call
        else:
            assert st["status"] == "pass", st
            assert st["metrics"]["accepted"] + st["metrics"]["refused"] == 20
        sh = rep.row("stale_handles", itf)
        if sh["status"] == "fail":  # today: the address is reused and the stale handle steps the new instance
            assert sh["kind"] == "stale_handle" and sh["rule"].startswith("R5"), sh
            assert "its address was given to a new instance" in sh["detail"], sh["detail"]
        else:
            assert "refused" in sh["detail"], sh
        sn = rep.row("state_nan", itf)
        assert sn["status"] == "pass", sn
        m = sn["metrics"]
        assert m["words"] > 30 and m["refused"] == m["words"] and m["usable"] == 0, sn["detail"]
