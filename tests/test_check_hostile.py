"""The hostile-master checks of `scfmu check` (start_times, stale_handles, state_nan; scfmu.check.hostile) on
FMUs we ship, FMI 2.0 and 3.0: a continuous controller (PdController) and a sampled sensor law (BDot).

Before the fixes of issue 45 a sampled unit hung on a start time of about -1e18 (its sample index wrapped)
and a freed instance whose address a new instance got stepped the new one; the checks reported both. Now a
start time beyond the exact sample-index range is refused at initialisation, handles are tokens that are
never reused, and a NaN written into a serialized state is refused: every row passes."""

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
        assert st["status"] == "pass", st
        assert st["metrics"]["accepted"] + st["metrics"]["refused"] == 20
        if "BDot" in fmu.name:  # the sampled unit refuses the start times beyond 2^53 sample periods
            assert st["metrics"]["refused"] >= 10, st["detail"]
        sh = rep.row("stale_handles", itf)
        assert sh["status"] == "pass" and "freed instance refused" in sh["detail"], sh
        sn = rep.row("state_nan", itf)
        assert sn["status"] == "pass", sn
        m = sn["metrics"]
        assert m["words"] > 30 and m["refused"] == m["words"] and m["usable"] == 0, sn["detail"]
