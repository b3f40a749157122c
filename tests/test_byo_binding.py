"""A swapped unit gets the place's values under its own parameter names, or every output says why (issue 32).

The unit is the tests' C PD controller (tests/foreign_units.py) in its variant ``j_names``: the same law and
ports as PdController, but its nominal inertia parameters are called J1, J2, J3 (defaults 1000, 500, 700
kg·m²). On paper 003's plant (4, 5, 3.5 kg·m²):

* without a profile the slot values do not reach it: the console, the run manifest, the campaign manifest
  and the benchmark page name them ("inertia_xx = 4 not passed: the unit kept its own J1 = 1000"), and
  ``--strict`` refuses to run (exit 2, one line);
* with a profile (or ``--map controller.J1=inertia_xx``) its ISE on 003-N equals the built-in PdController's
  at the same gains to 1e-6 relative (two independent implementations of the law: Rust and C).

Also: the profile expressions are evaluated safely (no ``eval``), ``--map`` renames whole vectors, and an
unwired unit gets the ``--map`` that would wire it.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import pytest

import foreign_units as fu
from scfmu import metrics
from scfmu.engines import simulate
from scfmu.scenario import get
from scfmu.scenario import profile as profiles

CASE = "paper003/SMC/N"


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    return fu.ForeignUnits(tmp_path_factory.mktemp("foreign"))


@pytest.fixture(scope="module")
def prof(tmp_path_factory):
    p = tmp_path_factory.mktemp("profile") / "cpd_j.toml"
    p.write_text('unused = ["inertia_xy", "inertia_xz", "inertia_yz"]  # a diagonal-inertia law\n'
                 '[params]\nJ1 = "inertia_xx"\nJ2 = "inertia_yy"\nJ3 = "inertia_zz"\n')
    return p


@pytest.fixture(scope="module")
def pd_ise():
    """ISE of the built-in PdController (Rust) on 003-N with the place's inertia and wn = zeta = 1."""
    sc = get(CASE).with_models({"controller": "PdController"})
    return metrics.compute(sc.metrics, simulate(sc, "native"))["ise"]


def scfmu(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "scfmu", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def result(folder, stem: str, key: str) -> float:
    """A metric of `scfmu run` at full precision, from its manifest (the console prints 6 digits)."""
    return float(json.loads((folder / f"{stem}.manifest.json").read_text())["metrics"][key])


# ----- expressions ------------------------------------------------------------------------------------------------
def test_profile_expressions_are_arithmetic_only():
    env = {"inertia_xx": 4.0, "inertia_yy": 5.0, "step": 0.01}
    assert profiles.evaluate("inertia_xx", env) == 4.0
    assert profiles.evaluate(2.5, env) == 2.5
    assert profiles.evaluate("4 * inertia_xx + sqrt(step) - inertia_yy / 2", env) == pytest.approx(16.0 + 0.1 - 2.5, rel=1e-15)
    assert profiles.evaluate("max(inertia_xx, inertia_yy) ** 2", env) == 25.0
    assert profiles.evaluate("-abs(-inertia_yy)", env) == -5.0
    assert profiles.evaluate("0.5 * plant.u_max_x", {"plant.u_max_x": 10.0}) == 5.0  # another unit's parameter
    with pytest.raises(profiles.ProfileError, match="names 'plant.__class__'"):  # a key, never an attribute
        profiles.evaluate("plant.__class__", {"plant.u_max_x": 10.0})
    for bad in ("__import__('os').system('true')", "inertia_xx.real.imag", "(1).real", "[1, 2]", "lambda: 1", "'a' * 3",
                "open('x')", "inertia_xx if 1 else 2", "True + 1"):
        with pytest.raises(profiles.ProfileError):
            profiles.evaluate(bad, env, "J1")
    with pytest.raises(profiles.ProfileError, match="names 'inertia_q'.*inertia_xx"):
        profiles.evaluate("2 * inertia_q", env, "J1")
    with pytest.raises(profiles.ProfileError, match="not a finite"):
        profiles.evaluate("1e308 * 10", env)
    with pytest.raises(profiles.ProfileError, match="division by zero"):
        profiles.evaluate("inertia_xx / (step - step)", env)
    with pytest.raises(profiles.ProfileError, match="J1"):
        profiles.evaluate("10 ** 10 ** 10", env, "J1")  # refused at once (floats), not a huge integer


def test_profile_file_errors_name_the_key(tmp_path):
    p = tmp_path / "p.toml"
    p.write_text('[params]\nJ1 = "inertia_xx +"\n')
    with pytest.raises(profiles.ProfileError, match=r"params.J1.*not an expression"):
        profiles.load(p)
    p.write_text('[parms]\nJ1 = "inertia_xx"\n')
    with pytest.raises(profiles.ProfileError, match="unknown key"):
        profiles.load(p)
    p.write_text('[params]\nJ1 = [1, 2]\n')
    with pytest.raises(profiles.ProfileError, match="J1"):
        profiles.load(p)
    r = scfmu("run", "default", "--fmu", "controller=PdController", "--profile", p, "--no-plot", "--out", tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "J1" in r.stderr.strip().splitlines()[-1], r.stderr


# ----- binding a J-named unit ------------------------------------------------------------------------------------------
def test_unbound_inertia_is_reported_by_run_and_campaign_and_strict_refuses(units, prof, tmp_path):
    fmu = units.c_pd("j_names")
    want = "slot value inertia_xx = 4 not passed: the unit kept its own J1 = 1000"
    r = scfmu("run", CASE, "--t-end", "2", "--fmu", f"controller={fmu}", "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    assert want in r.stderr and "J2 = 500" in r.stderr and "J3 = 700" in r.stderr
    man = json.loads((tmp_path / "run" / "paper003_SMC_N.manifest.json").read_text())
    assert any(want in x for x in man["unbound_slot_values"]), man["unbound_slot_values"]
    r = scfmu("campaign", CASE, "--t-end", "2", "--fmu", f"controller={fmu}", "--seeds", "0:2", "--workers", "1",
              "--out", tmp_path / "c", "--no-progress", "--no-plots")
    assert r.returncode == 0, r.stdout + r.stderr
    assert want in r.stderr
    man = json.loads((tmp_path / "c" / "manifest.json").read_text())
    assert any(want in x for x in man["unbound_slot_values"]), man
    r = scfmu("campaign", CASE, "--t-end", "2", "--fmu", f"controller={fmu}", "--profile", prof, "--strict",
              "--workers", "1", "--out", tmp_path / "cp", "--no-progress", "--no-plots")
    assert r.returncode == 0 and "warning:" not in r.stderr, r.stdout + r.stderr
    man = json.loads((tmp_path / "cp" / "manifest.json").read_text())
    assert man["unbound_slot_values"] == [] and man["scenario"]["components"][1]["bind"]["J1"] == "inertia_xx"
    r = scfmu("run", CASE, "--t-end", "2", "--fmu", f"controller={fmu}", "--strict", "--out", tmp_path / "s")
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    refusal = [x for x in r.stderr.splitlines() if "--strict" in x]
    assert len(refusal) == 1 and want in refusal[0] and "(and 5 more)" in refusal[0], r.stderr
    assert not (tmp_path / "s" / "paper003_SMC_N.csv").exists()


def test_profile_and_map_bind_the_unit_ise_equals_builtin_pd(units, prof, pd_ise, tmp_path):
    fmu = units.c_pd("j_names")
    r = scfmu("run", CASE, "--fmu", f"controller={fmu}", "--profile", prof, "--strict", "--no-plot", "--out", tmp_path)
    assert r.returncode == 0 and "warning:" not in r.stderr, r.stderr
    ise = result(tmp_path, "paper003_SMC_N", "ise")
    assert math.isclose(ise, pd_ise, rel_tol=1e-6), (ise, pd_ise)
    # --map of the parameters does the same (it was silently ignored before issue 32)
    r = scfmu("run", CASE, "--fmu", f"controller={fmu}", "--map", "controller.J1=inertia_xx", "--map",
              "controller.J2=inertia_yy", "--map", "controller.J3=inertia_zz", "--no-plot", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    assert "inertia_xx = 4 not passed" not in r.stderr and "inertia_xy = 0.05 not passed" in r.stderr
    assert math.isclose(result(tmp_path, "paper003_SMC_N", "ise"), pd_ise, rel_tol=1e-6)
    # without: the unit's own 1000/500/700 kg·m², gains ~200x too high: a different answer
    r = scfmu("run", CASE, "--fmu", f"controller={fmu}", "--no-plot", "--out", tmp_path)
    assert not math.isclose(result(tmp_path, "paper003_SMC_N", "ise"), pd_ise, rel_tol=1e-3)
    # an expression of slot values, and --set that wins over the profile
    sc = profiles.apply(get(CASE).with_models({"controller": str(fmu)}), "controller",
                        profiles.Profile(params={"J1": "inertia_xx", "J2": "2 * inertia_yy / 2", "J3": "inertia_zz"}))
    from scfmu.scenario.resolve import resolve
    c = resolve(sc.with_overrides({"controller.J1": 7.0})).component("controller")
    assert c.params == {"J1": 7.0, "J2": 5.0, "J3": 3.5}
    # a --map naming a slot value the place does not offer is refused, naming it
    r = scfmu("run", CASE, "--fmu", f"controller={fmu}", "--map", "controller.J1=inertia_q", "--no-plot", "--out", tmp_path)
    assert r.returncode == 2 and "inertia_q" in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_vector_map_and_the_suggested_map(units, tmp_path):
    fmu = units.c_pd("wrong_ports")
    r = scfmu("run", "default", "--t-end", "3", "--fmu", f"controller={fmu}", "--no-plot", "--out", tmp_path)
    assert r.returncode == 2, r.stderr
    assert "--map controller.omega=w" in r.stderr and "--map controller.tau=torque_cmd" in r.stderr, r.stderr
    r = scfmu("run", "default", "--t-end", "3", "--fmu", f"controller={fmu}", "--map", "controller.omega=w", "--map",
              "controller.tau=torque_cmd", "--no-plot", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    ref = metrics.compute("attitude", simulate(get("default", stop_time=3.0), "native"))["eulerint_deg_s"]
    assert math.isclose(result(tmp_path, "default", "eulerint_deg_s"), ref, rel_tol=1e-9)


def test_benchmark_names_unbound_slots_beside_the_unit_and_binds_with_a_profile(units, prof, pd_ise, tmp_path):
    fmu = units.c_pd("j_names")
    r = scfmu("benchmark", fmu, "--label", "CJ", "--controllers", "PdController", "--cases", CASE,
              "--out", tmp_path / "plain", timeout=900)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    want = "inertia_xx = 4 not passed: the unit kept its own J1 = 1000"
    md = (tmp_path / "plain" / "benchmark.md").read_text()
    warn = md.split("## Warnings")[1].split("\n## ")[0]
    assert ("CJ: slot value inertia_xx (4) not passed in 1 of 1 scenarios: the unit kept its own J1 = 1000; "
            'bind it: a profile line J1 = "inertia_xx"') in warn, warn
    assert "| **CJ ⚠** |" in md and f"⚠ CJ: controller: slot value {want}" in md  # beside the unit's results
    assert want in (tmp_path / "plain" / "index.html").read_text()
    rows = {x["controller"]: x for x in csv.DictReader(open(tmp_path / "plain" / "results.csv"))}
    assert want in rows["CJ"]["unbound slot values"] and rows["PD, quaternion error"]["unbound slot values"] == ""
    assert want in r.stderr
    # one profile, evaluated per scenario: 4/5/3.5 kg·m² on 003-N, 1000/500/700 kg·m² on the large slew
    r = scfmu("benchmark", fmu, "--label", "CJ", "--controllers", "PdController", "--cases", f"{CASE},default",
              "--profile", prof, "--strict", "--out", tmp_path / "bound", timeout=900)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    rows = {(x["scenario"][:5], x["controller"]): x for x in csv.DictReader(open(tmp_path / "bound" / "results.csv"))}
    mine, pd = rows[("003-N", "CJ")], rows[("003-N", "PD, quaternion error")]
    assert mine["unbound slot values"] == "" and "profile cpd_j.toml" in mine["configuration"]
    ise = float(mine["ise [rad²·s]"])
    assert math.isclose(ise, pd_ise, rel_tol=1e-6) and mine["rank"] == pd["rank"] == "1"
    mine, pd = rows[("large", "CJ")], rows[("large", "PD, quaternion error")]
    k = "eulerint_deg_s [deg·s]"
    assert math.isclose(float(mine[k]), float(pd[k]), rel_tol=1e-6) and abs(float(pd[k]) - 156.408) < 1e-3
    r = scfmu("benchmark", fmu, "--controllers", "PdController", "--cases", CASE, "--strict", "--out", tmp_path / "s")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "inertia_xx = 4 not passed" in r.stderr, r.stderr


def test_export_writes_the_bound_values_into_the_ssp(units, prof, tmp_path):
    """`scfmu export ssp` with a profile: the SSP's parameter set of the unit holds the place's inertia under
    the unit's names (read back from the archive's XML); without it, the export warns."""
    import xml.etree.ElementTree as ET
    import zipfile
    fmu = units.c_pd("j_names")
    r = scfmu("export", "ssp", CASE, "--fmu", f"controller={fmu}", "--profile", prof, "--out", tmp_path / "a")
    assert r.returncode == 0 and "warning:" not in r.stderr, r.stdout + r.stderr
    with zipfile.ZipFile(next((tmp_path / "a").glob("*.ssp"))) as z:
        root = ET.fromstring(z.read("resources/controller.ssv"))
    vals = {p.get("name"): float(p[0].get("value")) for p in root.iter("{http://ssp-standard.org/SSP1/SystemStructureParameterValues}Parameter")}
    assert vals == {"J1": 4.0, "J2": 5.0, "J3": 3.5}, vals
    r = scfmu("export", "ssp", CASE, "--fmu", f"controller={fmu}", "--out", tmp_path / "b")
    assert r.returncode == 0 and "inertia_xx = 4 not passed: the unit kept its own J1 = 1000" in r.stderr, r.stderr
