"""Foreign units (tests/foreign_units.py, issue 21): FMUs made by other exporters than ours, built here, that
take PdController's place. The healthy C and PythonFMU controllers must give the PD law (numpy oracle) and
our PdController's torques; each deliberately broken C variant must fail exactly as declared, so that the
tests of the pre-flight check and of the campaign's failure handling can rely on them."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

import foreign_units as fu

ROOT = Path(__file__).resolve().parents[1]
IN_CI = os.environ.get("CI") == "true"
INPUTS = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z",
          "w_ref_x", "w_ref_y", "w_ref_z"]
TORQUE = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]


@pytest.fixture(scope="session")
def foreign(tmp_path_factory):
    return fu.ForeignUnits(tmp_path_factory.mktemp("foreign"))


def random_cases(n, seed):
    """n (inputs, parameters) with random attitudes, commands, rates and gains."""
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(n):
        q = rng.normal(size=4)
        q_ref = rng.normal(size=4)
        q, q_ref = q / np.linalg.norm(q), q_ref / np.linalg.norm(q_ref)
        w, w_ref = rng.normal(scale=0.05, size=3), rng.normal(scale=0.05, size=3)
        inputs = dict(zip(INPUTS, [*q, *w, *q_ref, *w_ref]))
        params = {"wn": rng.uniform(0.2, 3.0), "zeta": rng.uniform(0.0, 2.0),
                  "inertia_xx": rng.uniform(100, 2000), "inertia_yy": rng.uniform(100, 2000),
                  "inertia_zz": rng.uniform(100, 2000)}
        expected = fu.pd_law(q, w, q_ref, params["wn"], params["zeta"],
                             [params["inertia_xx"], params["inertia_yy"], params["inertia_zz"]])
        cases.append((inputs, params, expected))
    return cases


def open_loop(path, inputs, params, validate=True):
    """simulate_fmu with the inputs held constant (set as start values), 1 s at 0.1 s steps."""
    res = simulate_fmu(str(path), validate=validate, start_time=0.0, stop_time=1.0, step_size=0.1,
                       output_interval=0.1, start_values={**inputs, **params}, output=TORQUE)
    return np.column_stack([res[n] for n in TORQUE])


def assert_pd_law(path, seed, validate=True):
    for inputs, params, expected in random_cases(6, seed):
        got = open_loop(path, inputs, params, validate)
        assert got.shape == (11, 3)
        np.testing.assert_allclose(got, np.tile(expected, (11, 1)), rtol=1e-12,
                                   atol=1e-12 * np.abs(expected).max())


# ------------------------------------------------------------------------------------------------ the C unit

def test_c_pd_validates_and_gives_the_pd_law(foreign):
    path = foreign.c_pd("ok")
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert (md.fmiVersion, md.modelName, md.coSimulation.modelIdentifier) == ("2.0", "CPdController",
                                                                             "CPdController")
    assert md.modelExchange is None
    with zipfile.ZipFile(path) as z:
        assert "binaries/linux64/CPdController.so" in z.namelist()
    assert_pd_law(path, seed=21)


def test_c_pd_ports_and_units_are_pd_controllers(tmp_path):
    """Same port names, causalities and units as our PdController (value references differ on purpose)."""
    ours = {v.name: v for v in read_model_description(str(ROOT / "modelDescription" / "PdController.xml")).modelVariables}
    (tmp_path / "modelDescription.xml").write_text(fu.c_model_description("ok"))
    theirs = {v.name: v for v in read_model_description(str(tmp_path / "modelDescription.xml")).modelVariables}
    for name in [*INPUTS, *TORQUE, "wn", "zeta", "inertia_xx", "inertia_yy", "inertia_zz"]:
        assert (theirs[name].causality, theirs[name].type, theirs[name].unit) == \
               (ours[name].causality, ours[name].type, ours[name].unit), name
    assert all(theirs[n].valueReference != ours[n].valueReference for n in [*INPUTS, *TORQUE])


def test_c_pd_equals_our_pd_controller(foreign):
    """Round-off agreement with PdController (error_law = 0, gains from wn, zeta, inertia) at random inputs."""
    ours = ROOT / "fmus" / "PdController.fmu"
    if not ours.is_file():
        if IN_CI:
            pytest.fail("fmus/PdController.fmu missing in CI")
        pytest.skip("fmus/PdController.fmu not built (scripts/build_fmus.sh)")
    path = foreign.c_pd("ok")
    for inputs, params, expected in random_cases(4, seed=7):
        np.testing.assert_allclose(open_loop(path, inputs, params), open_loop(ours, inputs, params),
                                   rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_c_pd_rejects_a_wrong_guid_and_fixed_parameters_after_init(foreign):
    fmu, md = _slave(foreign.c_pd("ok"), guid="{00000000-0000-0000-0000-000000000000}")
    with pytest.raises(Exception, match="instantiate"):
        fmu.instantiate()
    fmu.freeLibrary()
    fmu, md = _slave(foreign.c_pd("ok"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.setReal([vr["wn"]], [2.0])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["q_ref_w"], vr["q_ref_x"]], [0.8, 0.6])
    assert fmu.getReal([vr["torque_cmd_x"]])[0] == pytest.approx(fu.pd_law([1, 0, 0, 0], [0, 0, 0], [0.8, 0.6, 0, 0], wn=2.0)[0])
    with pytest.raises(Exception):
        fmu.setReal([vr["wn"]], [3.0])
    fmu.terminate()
    fmu.freeInstance()


# ------------------------------------------------------------------------------------------------ PythonFMU

def test_python_pd_gives_the_pd_law(foreign):
    info = fu.python_info()
    print(f"\nhost Python: {info}")
    for units in (False, True):
        path = foreign.python_pd(units=units)
        ok, reason = foreign.python_loadable(units=units)
        if not ok:
            print(f"PythonFMU not loadable here: {reason}")
            if IN_CI and not fu.is_host_limit(reason):
                pytest.fail(f"the PythonFMU controller does not run, and not for lack of libpython: {reason}")
            pytest.skip(f"PythonFMU cannot run on this host: {reason}")
        md = read_model_description(str(path))
        assert md.coSimulation.modelIdentifier == "PyPdController"
        assert md.generationTool.startswith("PythonFMU")
        units_of = {v.name: v.unit for v in md.modelVariables}
        assert units_of["torque_cmd_x"] == ("N.m" if units else None)
        assert units_of["w_x"] == ("rad/s" if units else None)
        # PythonFMU 0.7.0 writes no InitialUnknowns for its outputs: fmpy's validation says so, nothing else
        problems = validate_fmu(str(path))
        assert all("InitialUnknowns" in p for p in problems), problems
        print(f"PythonFMU (units={units}) fmpy validation: {problems}")
        assert_pd_law(path, seed=3, validate=False)


def test_python_fmu_loadable_explains_a_missing_libpython(tmp_path):
    """The probe's reason for an interpreter without libpython names it, and counts as a host limit."""
    fake = tmp_path / "python"
    fake.write_text("#!/bin/sh\necho 'OSError: libpython3.11.so.1.0: cannot open shared object file: "
                    "No such file or directory' >&2\nexit 1\n")
    fake.chmod(0o755)
    ok, reason = fu.python_fmu_loadable(tmp_path / "x.fmu", python=str(fake))
    assert not ok and reason.startswith("libpython3.11.so.1.0 not found"), reason
    assert fu.is_host_limit(reason)
    fake.write_text("#!/bin/sh\necho 'KeyError: torque_cmd_x' >&2\nexit 1\n")
    ok, reason = fu.python_fmu_loadable(tmp_path / "x.fmu", python=str(fake))
    assert not ok and "KeyError" in reason and not fu.is_host_limit(reason), reason


# ------------------------------------------------------------------------------------------------ broken variants

def _slave(path, guid=None):
    md = read_model_description(str(path))
    d = extract(str(path))
    return FMU2Slave(guid=guid or md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                     instanceName="t"), md


# steps the FMU at 0.1 s to 1 s, printing each step's start time before the call (flushed)
_STEPPER = textwrap.dedent("""
    import sys
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(sys.argv[1])
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="t")
    fmu.instantiate(); fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode(); fmu.exitInitializationMode()
    for k in range(10):
        print(f"step {k / 10:.1f}", flush=True)
        fmu.doStep(k / 10, 0.1)
    print("done", flush=True)
""")


def test_crash_variant_segfaults_in_do_step_at_half_a_second(foreign):
    p = subprocess.run([sys.executable, "-c", _STEPPER, str(foreign.c_pd("crash"))], capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == -signal.SIGSEGV, (p.returncode, p.stdout, p.stderr[-2000:])
    assert p.stdout.split()[-2:] == ["step", "0.5"], p.stdout


def test_hang_variant_never_returns_from_do_step_at_half_a_second(foreign):
    proc = subprocess.Popen([sys.executable, "-c", _STEPPER, str(foreign.c_pd("hang"))],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        lines = []
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line.strip())
            if line.strip() == "step 0.5":
                break
        assert lines[-1:] == ["step 0.5"], (lines, proc.stderr.read() if proc.poll() is not None else "")
        with pytest.raises(subprocess.TimeoutExpired):
            proc.wait(timeout=3)  # stuck in fmi2DoStep(0.5, ...)
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == -signal.SIGKILL


def test_nan_variant_outputs_nan_from_half_a_second(foreign):
    fmu, md = _slave(foreign.c_pd("nan"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    out = [vr[n] for n in TORQUE]
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["q_ref_w"], vr["q_ref_z"]], [math.cos(0.2), math.sin(0.2)])
    seen = []
    for k in range(10):
        seen.append((k / 10, fmu.getReal(out)))
        fmu.doStep(k / 10, 0.1)  # never fails
    seen.append((1.0, fmu.getReal(out)))
    fmu.terminate()
    fmu.freeInstance()
    for t, v in seen:
        assert all(math.isnan(x) for x in v) if t >= 0.5 - 1e-9 else all(math.isfinite(x) for x in v), (t, v)
    assert seen[0][1][2] != 0.0


def test_error_variant_returns_fmi2error_with_a_message(foreign):
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2CallbackAllocateMemoryTYPE, \
        fmi2CallbackFreeMemoryTYPE
    from fmpy import calloc, free
    messages = []

    def logger(env, name, status, category, message):
        messages.append((status, category.decode(), message.decode()))

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    fmu, md = _slave(foreign.c_pd("error"))
    fmu.instantiate(callbacks=callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    for k in range(5):
        fmu.doStep(k / 10, 0.1)
    with pytest.raises(Exception, match="fmi2DoStep failed with status 3"):
        fmu.doStep(0.5, 0.1)
    assert messages == [(3, "logStatusError", "CPdController: deliberate failure at t = 0.5 (variant error)")]
    fmu.freeInstance()


def _vars(path):
    return {v.name: v for v in read_model_description(str(path)).modelVariables}


def test_wrong_ports_variant_renames_torque_and_rates(foreign):
    v = _vars(foreign.c_pd("wrong_ports"))
    assert {"tau_x", "tau_y", "tau_z", "omega_x", "omega_y", "omega_z"} <= set(v)
    assert not {"torque_cmd_x", "w_x", "w_y", "w_z"} & set(v)
    assert v["tau_x"].causality == "output" and v["tau_x"].unit == "N.m"
    assert v["omega_x"].causality == "input" and v["omega_x"].unit == "rad/s"
    assert {"w_ref_x", "q_w", "q_ref_w"} <= set(v)
    assert validate_fmu(str(foreign.c_pd("wrong_ports"))) == []


def test_bad_unit_and_no_unit_variants(foreign):
    bad, none = _vars(foreign.c_pd("bad_unit")), _vars(foreign.c_pd("no_unit"))
    for n in TORQUE:
        assert bad[n].unit == "N" and none[n].unit is None
    for n in ("w_x", "w_y", "w_z", "w_ref_x"):
        assert bad[n].unit == "rad/s" and none[n].unit is None
    assert none["wn"].unit == "rad/s" and none["inertia_xx"].unit == "kg.m2"  # parameters keep theirs
    for variant in ("bad_unit", "no_unit"):
        assert validate_fmu(str(foreign.c_pd(variant))) == [], variant


def test_no_binary_and_me_only_variants(foreign):
    from fmpy import supported_platforms
    path = foreign.c_pd("no_binary")
    with zipfile.ZipFile(path) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    assert supported_platforms(str(path)) == []
    assert read_model_description(str(path)).coSimulation is not None
    md = read_model_description(str(foreign.c_pd("me_only")))
    assert md.coSimulation is None and md.modelExchange is not None
    with zipfile.ZipFile(foreign.c_pd("me_only")) as z:
        assert "binaries/linux64/CPdController.so" in z.namelist()


def test_builds_are_fast_and_every_variant_is_distinct(tmp_path):
    t0 = time.perf_counter()
    paths = {v: fu.build_c_pd(tmp_path, v) for v in fu.C_VARIANTS}
    per_unit = (time.perf_counter() - t0) / len(paths)
    print(f"\nC variants built in {per_unit:.2f} s each")
    assert per_unit < 3.0
    guids = {read_model_description(str(p)).guid for p in paths.values()}
    assert len(guids) == len(paths)
    with pytest.raises(ValueError, match="unknown variant"):
        fu.build_c_pd(tmp_path, "segfault")
