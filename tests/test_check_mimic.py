"""`scfmu check` on units that behave, each in one respect, the way a Modelica Reference-FMU does
(tests/foreign/mimic/mimic3.c, FMI 3.0, built here with gcc; see tests/mimic_units.py): the false alarms the
checker used to raise on the Reference-FMUs stay gone, and the Reference-FMUs' real defects stay found, each
with its class (standard / robustness). The expectations come from the units' source: what each variant
does and at which time."""

from __future__ import annotations

import math

import pytest

from mimic_units import MIMICS, build_mimic
from scfmu.check import DYNAMIC_CHECKS, check


@pytest.fixture(scope="module")
def mimic(tmp_path_factory):
    d = tmp_path_factory.mktemp("mimic")
    return {name: build_mimic(d, name) for name in MIMICS}


def failed(rep) -> dict:
    return {(r["check"], r.get("interface")): r for r in rep.failures()}


def test_a_discrete_input_is_not_set_in_continuous_time_mode(mimic):
    # (a) like Feedthrough (ME): d may be set only in Instantiated, Initialization and Event Mode
    rep = check(mimic["discrete_input"], quick=True, seed=1)
    assert rep.ok, rep.text()
    assert rep.row("nominal_run", "me")["status"] == "pass"
    assert rep.row("threads", "me")["status"] == "pass"


def test_the_run_ends_when_the_unit_asks_for_it(mimic):
    # (b) like Stair: 5 ticks of 0.1 s, then terminateSimulation; the default step is 0.05 s -> 10 steps
    rep = check(mimic["terminate"], quick=True, seed=1)
    assert rep.ok, rep.text()
    for itf in ("cs", "me"):
        row = rep.row("nominal_run", itf)
        assert row["metrics"]["ended"] is True, row
        assert "terminateSimulation" in row["detail"], row["detail"]
    assert rep.row("nominal_run", "cs")["metrics"]["steps"] == 10


def test_a_scheduled_execution_only_unit_is_not_applicable(mimic):
    # (c) like Clocks: neither Co-Simulation nor Model Exchange, which is legal in FMI 3.0
    rep = check(mimic["scheduled"], quick=True)
    assert rep.ok, rep.text()
    assert rep.row("binaries")["status"] == "n/a"
    assert {r["status"] for r in rep.rows if r["check"] in DYNAMIC_CHECKS} == {"n/a"}
    assert len([r for r in rep.rows if r["check"] in DYNAMIC_CHECKS]) == len(DYNAMIC_CHECKS)


def test_an_array_state_counts_its_elements(mimic):
    # (d) like StateSpace: x has n = 3 elements; nx other than 3 is refused by the unit
    from scfmu import fmu as fmu_mod
    from scfmu.check.static import n_states
    assert n_states(fmu_mod.described(mimic["array_state"])) == 3
    rep = check(mimic["array_state"], quick=True)
    assert rep.ok, rep.text()


def test_no_step_size_and_a_stiff_unit_are_driven_without_a_hang_or_divergence(mimic):
    # (e) like Roberts: no stepSize, stop time 1e8 s, internal step 1e-6 s (CS), x' = -1000 (x - 1) (ME)
    rep = check(mimic["stiff_no_step"], quick=True, checks=["nominal_run", "threads", "fmu_state"])
    assert rep.ok, rep.text()
    assert "of 0.01 s" in rep.row("nominal_run", "cs")["detail"]
    assert rep.row("nominal_run", "me")["metrics"]["steps"] == 100


def test_a_nan_passed_through_with_ok_is_allowed(mimic):
    # (f) like Feedthrough (CS): y = u; a NaN input gives a NaN output with fmi3OK, as the standard allows
    rep = check(mimic["nan_through"], quick=True)
    assert rep.ok, rep.text()
    assert "accepted by u" in rep.row("bad_arguments", "cs")["detail"]


def test_the_detail_quotes_only_the_failing_calls_message(mimic):
    # (g) the unit logs "initialised" at fmi3ExitInitializationMode, then fails the step from 0.5 silently
    rep = check(mimic["quiet_error"], quick=True, checks=["nominal_run"])
    row = rep.row("nominal_run", "cs")
    assert row["status"] == "fail" and row["class"] == "robustness", row
    assert "the step from t = 0.5 returned fmi3Error" in row["detail"], row["detail"]
    assert "no log message during that call" in row["detail"] and "initialised" not in row["detail"]


def test_the_reference_fmus_real_defects_are_still_found(mimic):
    # a NaN step loops for ever (CS), SetTime(NaN) -> OK (ME), fmi3UpdateDiscreteStates in Continuous-Time Mode
    rep = check(mimic["ref_defects"], quick=True, checks=["bad_arguments", "state_machine"], call_timeout=2)
    f = failed(rep)
    assert set(f) == {("bad_arguments", "cs"), ("bad_arguments", "me"), ("state_machine", "me")}, rep.text()
    hang = f[("bad_arguments", "cs")]
    assert hang["kind"] == "hang" and hang["class"] == "robustness"
    assert hang["reproducer"][-1].startswith("fmi3DoStep(") and ", NAN, " in hang["reproducer"][-1]
    assert "within 2 s" in hang["detail"]
    nan_time = f[("bad_arguments", "me")]
    assert "fmi3SetTime to start time + nan returned fmi3OK" in nan_time["detail"]
    assert nan_time["class"] == "robustness" and nan_time["rule"].startswith("R4")
    sm = f[("state_machine", "me")]
    assert "event update in Continuous-Time Mode returned fmi3OK" in sm["detail"]
    assert sm["class"] == "standard" and "FMI 3.0" in sm["rule"]
    text = rep.text()
    assert "Violations of the FMI standard: 1" in text
    assert "Failures of this project's robustness rules (the standard does not require these): 2" in text
    d = rep.to_dict()
    assert d["findings"] == {"standard": ["state_machine (me)"],
                             "robustness": ["bad_arguments (cs)", "bad_arguments (me)"]}, d["findings"]
    from scfmu.check.report import to_html
    page = to_html(rep)
    std, rob = page.index("<h2>Violations of the FMI standard</h2>"), page.index("<h2>Failures of this project")
    assert std < page.index("event update in Continuous-Time Mode", std) < rob
    assert page.index("fmi3SetTime to start time + nan", rob) > rob


def test_extreme_start_times_return_or_are_refused(mimic):
    # a strict unit runs every start time; a unit with an internal fixed step of 1e-6 s cannot advance its
    # time at 1e12 s (t + 1e-6 == t beyond about 1e10 s) and never returns: a robustness finding
    rep = check(mimic["terminate"], quick=True, checks=["start_times"])
    assert rep.ok, rep.text()
    assert rep.row("start_times", "cs")["metrics"]["accepted"] == 20
    rep = check(mimic["stiff_no_step"], quick=True, checks=["start_times"], call_timeout=2)
    row = rep.row("start_times", "cs")
    assert row["status"] == "fail" and row["kind"] == "hang" and row["class"] == "robustness", row
    t0 = float(row["reproducer"][-1].split("(")[1].split(",")[1])
    assert math.isfinite(t0) and abs(t0) >= 1e10, row["reproducer"][-1]


def test_stale_instance_handles_are_refused_by_a_unit_with_tokens(mimic):
    # mimic3.c hands out tokens that are never reused: a freed handle is refused
    rep = check(mimic["terminate"], quick=True, checks=["stale_handles"])
    assert rep.ok, rep.text()
    assert "refused (fmi3Error)" in rep.row("stale_handles", "cs")["detail"]


def test_a_nan_written_into_a_plain_copy_state_and_a_reused_state_handle_are_found(mimic):
    # the state is a copy of {int mode; double time, u, ...}: u is the third 8-byte word (byte 16) and y = x
    # integrates it, so a NaN there reaches y after one step; word 0 (the mode) makes every call refused,
    # word 1 (the time) is not read. A freed state's address is the next state's (malloc), and it is set.
    rep = check(mimic["state_copy"], quick=True, checks=["state_nan", "stale_handles"])
    sn = rep.row("state_nan", "cs")
    assert sn["status"] == "fail" and sn["kind"] == "nonfinite" and sn["class"] == "robustness", sn
    assert sn["detail"].startswith("a state with NaN at byte 16 was accepted, then output y = nan"), sn["detail"]
    sh = rep.row("stale_handles", "cs")
    assert sh["status"] == "fail" and sh["rule"].startswith("R5"), sh
    assert sh["detail"] == "setting a freed FMU state returned fmi3OK (its address was reused by a new state)"


def test_the_table_script_makes_the_unit_by_check_table(mimic, tmp_path):
    """scripts/check_table.py (docs/check.md's Reference-FMU table): one row per unit, a cell per check."""
    import json
    import shutil
    import subprocess
    import sys
    from pathlib import Path
    d = tmp_path / "units"
    d.mkdir()
    for name in ("scheduled", "ref_defects"):
        shutil.copy(mimic[name], d)
    script = Path(__file__).resolve().parents[1] / "scripts" / "check_table.py"
    p = subprocess.run([sys.executable, str(script), str(d), "--quick"], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    table, counts = p.stdout.strip().split("\n\n")
    rows = {line.split(" | ")[0].strip("| "): line.split(" | ") for line in table.splitlines()[2:]}
    header = table.splitlines()[0].split(" | ")
    col = {h.strip("`| "): i for i, h in enumerate(header)}
    assert set(rows) == {"Mimic_scheduled", "Mimic_ref_defects"}
    assert rows["Mimic_scheduled"][col["binaries"]] == "n/a"
    assert rows["Mimic_ref_defects"][col["state_machine"]] == "STD ME"
    assert rows["Mimic_ref_defects"][col["bad_arguments"]] == "ROB"
    assert rows["Mimic_ref_defects"][col["nominal_run"]] == "pass"
    c = json.loads(counts)
    assert c["units"] == 2 and c["units_failing"] == 1 and c["units_with_standard"] == 1 and c["standard"] == 1
    p = subprocess.run([sys.executable, str(script), str(tmp_path / "nothere")], capture_output=True, text=True)
    assert p.returncode == 2 and "Traceback" not in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "'" + str(tmp_path / "nothere") + "' does not exist" in p.stderr
