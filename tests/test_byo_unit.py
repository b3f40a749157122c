"""Bring your own unit: a component is a model name or a path to any FMI 2.0 Co-Simulation FMU, in every
engine, campaigns, SSP files, loop FMUs, scenario files and the benchmark; swapping a model drops its
parameters with a notice; a pre-flight check refuses what cannot fit, with every reason.

The unit "from elsewhere" here is one of our FMUs copied to a folder of its own under another file name
(the engines must take it by path, never by name); units built by other exporters (a C FMU written
against fmpy's FMI 2.0 headers, PythonFMU, deliberately broken ones) are in tests/test_foreign_units.py
and tests/test_byo_foreign.py."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu

from scfmu import campaign
from scfmu.engines import simulate
from scfmu.export.loops import write_loop_fmu
from scfmu.fmu import fmu_path
from scfmu.scenario import files, get, ssp
from scfmu.scenario.check import IncompatibleUnit, check, require

ENGINES = ("reference", "lean", "native")


def scfmu(*args, cwd=None, timeout=600):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd)


@pytest.fixture(scope="module")
def my_pd(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("user")
    p = d / "MyPd.fmu"
    shutil.copyfile(fmu_path("PdController"), p)
    return p


def short(name="default", t=3.0):
    return get(name, stop_time=t)


@pytest.mark.parametrize("engine", ENGINES)
def test_unit_by_path_equals_the_named_model_on_every_engine(my_pd, engine):
    ref = simulate(short(), engine)
    mine = simulate(short(), engine, fmus={"controller": str(my_pd)}, overrides={"controller.error_law": 0})
    for k in ref:
        assert np.array_equal(ref[k], mine[k]), k


def test_unit_by_path_in_libcosim(my_pd):
    from scfmu.engines.libcosim import run_libcosim
    a = run_libcosim(short())
    b = run_libcosim(short().with_models({"controller": str(my_pd)}).with_overrides({"controller.error_law": 0}))
    assert a["eulerint_deg_s"] == b["eulerint_deg_s"] and a["q_w"] == b["q_w"]


def test_swapping_drops_the_old_models_parameters_and_keeps_the_slot():
    sc = get("wheel_fault")
    assert sc.dropped_params({"controller": "LqrController"}) == {"controller": ["wn", "zeta"]}
    s2 = sc.with_models({"controller": "LqrController"})
    c = s2.component("controller")
    assert c.params == {} and s2.swapped == ["controller"]
    assert c.slot == {"inertia_xx": 4.0, "inertia_yy": 5.0, "inertia_zz": 3.5, "inertia_xy": 0.05, "inertia_xz": -0.03,
                      "inertia_yz": 0.02}
    # the plant keeps every parameter
    assert s2.component("plant").params == sc.component("plant").params


def test_cli_run_with_fmu_prints_one_notice_and_runs(my_pd, tmp_path):
    r = scfmu("run", "default", "--fmu", f"controller={my_pd}", "--set", "controller.error_law=0", "--t-end", "3",
              "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    notices = [line for line in r.stderr.splitlines() if line.startswith("notice:")]
    assert len(notices) == 1 and "error_law" in notices[0] and "MyPd.fmu" in notices[0], r.stderr
    ref = scfmu("run", "default", "--t-end", "3", "--out", tmp_path / "ref")
    ei = [re.search(r"eulerint_deg_s\s+(\S+)", x.stdout).group(1) for x in (r, ref)]
    assert ei[0] == ei[1]


def test_preflight_refuses_with_every_reason(my_pd):
    bad = get("default").with_models({"controller": "SingleAxisPlant"})
    with pytest.raises(IncompatibleUnit) as e:
        require(bad)
    assert "controller.u has no source" in str(e.value)
    rep = check(get("default").with_models({"controller": str(my_pd)}).with_overrides({"controller.no_such": 1.0}))
    assert any("no parameter 'no_such'" in x for x in rep.errors)
    # a port map naming a port the unit does not have
    rep = check(get("default").with_port_map({"controller.tau_x": "torque_cmd_x"}))
    assert any("'tau_x'" in x for x in rep.errors)
    r = scfmu("run", "default", "--fmu", "controller=SingleAxisPlant")
    assert r.returncode == 2 and "cannot run" in r.stderr and "has no source" in r.stderr


def test_preflight_refuses_non_fmus_and_missing_files(tmp_path):
    junk = tmp_path / "Junk.fmu"
    junk.write_bytes(b"not a zip")
    rep = check(get("default").with_models({"controller": str(junk)}))
    assert len(rep.errors) == 1 and "Junk.fmu" in rep.errors[0] and "modelDescription" in rep.errors[0]
    r = scfmu("run", "default", "--fmu", f"controller={tmp_path / 'Missing.fmu'}")
    assert r.returncode != 0 and "no such file" in r.stderr


def test_port_map_renames_a_units_ports():
    """The scenario's names are matched through the map: renaming torque_cmd_x to itself through an alias
    changes nothing; mapping a port to a name nobody has breaks the wiring with a message."""
    sc = short()
    broken = sc.with_port_map({"controller.torque_cmd_x": "tau_x"})
    with pytest.raises(IncompatibleUnit) as e:
        require(broken)
    assert "plant.torque_cmd_x has no source" in str(e.value)


def test_scenario_file_round_trip_runs_like_the_declaration(tmp_path):
    r = scfmu("scenarios", "--show", "default")
    assert r.returncode == 0 and "[[components]]" in r.stdout
    f = tmp_path / "my_loop.toml"
    f.write_text(r.stdout)
    assert files.load(f).to_dict() == dict(get("default").to_dict(), name="default")
    a = scfmu("run", f, "--t-end", "3", "--out", tmp_path / "a")
    b = scfmu("run", "default", "--t-end", "3", "--out", tmp_path / "b")
    assert a.returncode == 0, a.stderr
    metric_lines = r"^\s+\w+\s+\S+(?: \S+)?$"  # name, value, unit
    assert re.findall(metric_lines, a.stdout, re.M) == re.findall(metric_lines, b.stdout, re.M)
    assert len(re.findall(metric_lines, a.stdout, re.M)) > 10
    j = scfmu("scenarios", "--show", "paper001/a", "--json")
    assert json.loads(j.stdout)["components"][1]["model"] == "PredictivePidController"


def test_scenario_file_with_a_relative_fmu_path(tmp_path, my_pd):
    shutil.copyfile(my_pd, tmp_path / "Mine.fmu")
    text = files.dumps_toml(get("default", stop_time=2.0).with_models({"controller": "Mine.fmu"}))
    (tmp_path / "loop.toml").write_text(text)
    sc = files.load(tmp_path / "loop.toml")
    assert sc.component("controller").model == str((tmp_path / "Mine.fmu").resolve())
    r = scfmu("run", tmp_path / "loop.toml", "--out", tmp_path / "o", cwd=tmp_path)
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("text, msg", [
    ('stop_time = 1.0\nstep = 0.1\ncolour = "red"\ncomponents = []\n', "unknown field(s) ['colour']"),
    ('stop_time = 1.0\ncomponents = []\n', "missing field 'step'"),
    ('stop_time = "1"\nstep = 0.1\ncomponents = []\n', "field 'stop_time' must be a number"),
    ('stop_time = 1.0\nstep = 0.3\ncomponents = []\n', "not a positive multiple of step"),
    ('stop_time = 1.0\nstep = 0.1\n[[components]]\nname = "a"\n', "'model' must be a non-empty string"),
    ('stop_time = 1.0\nstep = 0.1\n[[components]]\nname = "a"\nmodel = "X"\nparms = {}\n', "unknown field(s) ['parms']"),
    ('stop_time = [1.0\n', "not valid TOML"),
])
def test_scenario_file_errors_name_the_field(tmp_path, text, msg):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(files.ScenarioFileError) as e:
        files.load(f)
    assert msg in str(e.value)
    r = scfmu("run", f)
    assert r.returncode != 0 and msg in r.stderr


def test_ssp_with_a_unit_by_path_reads_back_and_runs(tmp_path, my_pd):
    sc = short().with_models({"controller": str(my_pd)}).with_overrides({"controller.error_law": 0})
    p = ssp.write_ssp(sc, tmp_path / "mine.ssp")
    assert ssp.validate_ssp(p) == []
    with zipfile.ZipFile(p) as z:
        assert "resources/MyPd.fmu" in z.namelist()
        ssd = z.read("SystemStructure.ssd").decode()
    assert 'type="org.openmodelica"' in ssd and "FixedStepMaster" in ssd and 'stepSize="0.01"' in ssd
    back, paths = ssp.read_ssp(p, tmp_path / "unz")
    from scfmu.engines import run_reference
    a = run_reference(back, path_of=paths.__getitem__)
    b = simulate(short(), "reference")
    assert np.array_equal(a["eulerint_deg_s"], b["eulerint_deg_s"])


def test_loop_fmu_with_a_unit_by_path(tmp_path, my_pd):
    sc = short().with_models({"controller": str(my_pd)}).with_overrides({"controller.error_law": 0})
    p = write_loop_fmu(sc, tmp_path / "mine_loop.fmu")
    r = simulate_fmu(str(p), stop_time=3.0, output_interval=0.01, output=["metrics.eulerint_deg_s"])
    ref = simulate(short(), "reference")
    assert r["metrics.eulerint_deg_s"][-1] == ref["eulerint_deg_s"][-1]


def test_cli_export_takes_fmu(tmp_path, my_pd):
    r = scfmu("export", "ssp", "default", "--fmu", f"controller={my_pd}", "--set", "controller.error_law=0",
              "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    assert ssp.validate_ssp(tmp_path / "default.ssp") == []


def test_standard_ssp_files_carry_the_omsimulator_annotation():
    d = Path(fmu_path("PdController")).parent / "ssp"
    for p in sorted(d.glob("*.ssp")):
        with zipfile.ZipFile(p) as z:
            ssd = z.read("SystemStructure.ssd").decode()
        assert "org.openmodelica" in ssd and "oms:FixedStepMaster" in ssd, p.name


def test_foreign_fmu_is_shipped_to_a_worker_without_the_file(tmp_path, my_pd):
    """A worker that does not share the client's folder gets the FMU's bytes with the runs and writes them
    into its own cache; the row equals the row of a worker that has the file."""
    c = campaign.Campaign(short().with_models({"controller": str(my_pd)}).with_overrides({"controller.error_law": 0}))
    spec = c.runs()[0]
    assert spec["fmu_files"] == {str(my_pd): campaign.fmu_access.fmu_digest(my_pd)} and spec["isolate"]
    blobs = {spec["fmu_files"][str(my_pd)]: my_pd.read_bytes()}
    moved = json.loads(json.dumps(spec))
    gone = tmp_path / "elsewhere" / "MyPd.fmu"  # the path as the client knows it, absent on this "worker"
    moved["fmu_files"] = {str(gone): spec["fmu_files"][str(my_pd)]}
    for comp in moved["scenario"]["components"]:
        if comp["model"] == str(my_pd):
            comp["model"] = str(gone)
    campaign.runs.FMU_CACHE = tmp_path / "cache"
    a, _ = campaign.run_one(spec)
    b, _ = campaign.run_one(moved, blobs=blobs)
    assert a["status"] == b["status"] == "ok"
    assert a["eulerint_deg_s"] == b["eulerint_deg_s"]
    assert len(list((tmp_path / "cache").rglob("MyPd.fmu"))) == 1
    c2, _ = campaign.run_one(dict(moved, fmu_files={str(gone): "0" * 64}))  # neither the file nor the bytes
    assert c2["status"] == "error" and "was not shipped" in c2["message"]


def test_campaign_cli_with_fmu_on_an_existing_cluster(tmp_path, my_pd):
    from dask.distributed import LocalCluster
    import logging
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, host="127.0.0.1",
                      silence_logs=logging.CRITICAL) as cl:
        r = scfmu("campaign", "default", "--fmu", f"controller={my_pd}", "--t-end", "2", "--grid",
                  "controller.wn=0.5,1.0", "--set", "controller.error_law=0", "--scheduler", cl.scheduler_address,
                  "--out", tmp_path / "c", "--no-progress", "--no-plots")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "2 of 2 runs ok (ok: 2)" in r.stdout
    man = json.loads((tmp_path / "c" / "manifest.json").read_text())
    entry = man["fmus"][str(my_pd)]
    assert entry["model_name"] == "PdController" and entry["instance"] == "controller"
    assert entry["sha256"] == campaign.fmu_access.fmu_digest(my_pd) and entry["guid"]


def test_campaign_cli_exits_non_zero_when_runs_fail(tmp_path):
    r = scfmu("campaign", "default", "--t-end", "1", "--grid", "controller.wn=1.0,-1.0", "--workers", "1",
              "--out", tmp_path / "c", "--no-progress", "--no-plots")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "1 of 2 runs ok" in r.stdout and "fmu_error: 1" in r.stdout and "1 of 2 runs failed" in r.stderr


def test_benchmark_ranks_a_unit_beside_the_builtins(tmp_path, my_pd):
    r = scfmu("benchmark", my_pd, "--family", "attitude", "--set", "error_law=0", "--controllers",
              "PdController,FuzzyPdController", "--cases", "default,paper004/2", "--out", tmp_path, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    for f in ("index.html", "benchmark.md", "results.csv"):
        assert (tmp_path / f).stat().st_size > 200
    import csv
    rows = list(csv.DictReader(open(tmp_path / "results.csv")))
    by = {(x["scenario"].split(" (")[0], x["controller"]): x for x in rows}
    large = [k for k in by if k[0].startswith("large slew")][0][0]
    mine, pd = by[(large, "MyPd")], by[(large, "PD, quaternion error")]
    k = "eulerint_deg_s [deg·s]"
    assert mine[k] == pd[k] and abs(float(mine[k]) - 156.408) < 1e-3
    assert mine["pass"] == "True" and mine["rank"] == pd["rank"]  # the same law: the same rank
    md = (tmp_path / "benchmark.md").read_text()
    figures = sorted(p.name for p in (tmp_path / "figures").glob("*.png"))
    responses = [f for f in figures if not f.startswith(("bode_", "effort_"))]  # one response figure per scenario
    assert "**MyPd**" in md and "rank" in md and len(responses) == 2, figures
    # the large slew also gets its effort-vs-performance scatter and the Bode plots of its loops (margins)
    assert any(f.startswith("bode_large_slew") for f in figures) and any(f.startswith("effort_large") for f in figures)
