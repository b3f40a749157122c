"""FMI 3.0 Co-Simulation FMUs (fmus/fmi3/<Model>.fmu): every one validates in fmpy, matches the committed
modelDescription/fmi3/, simulates in fmpy's own FMI 3.0 master with results bit-identical to the FMI 2.0
FMU of the same model (Co-Simulation; Model Exchange is tests/test_model_exchange.py), AttitudePlant follows
the closed form under a constant torque, and a closed loop
stepped over FMI 3.0 equals the same loop over FMI 2.0 bit for bit."""

from __future__ import annotations

import math
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

ROOT = Path(__file__).resolve().parents[1]
FMI3_DIR = ROOT / "fmus" / "fmi3"
MODELS = sorted(p.stem for p in (ROOT / "modelDescription" / "fmi3").glob("*.xml"))
TIME_VR = 2147483647


def fmu3(model: str) -> str:
    p = FMI3_DIR / f"{model}.fmu"
    assert p.exists(), f"{p} missing: run scripts/build_fmus.sh"
    return str(p)


def fmu2(model: str) -> str:
    return str(ROOT / "fmus" / f"{model}.fmu")


# The FMI 3.0 functions (fmi3Functions.h of the standard, all interfaces: importers such as fmpy resolve
# every one when they load a binary), written out here rather than read from our own binary.
FMI3_FUNCTIONS = {
    "fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateModelExchange", "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution", "fmi3FreeInstance", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode",
    "fmi3EnterEventMode", "fmi3Terminate", "fmi3Reset",
    *(f"fmi3{gs}{t}" for gs in ("Get", "Set") for t in ("Float32", "Float64", "Int8", "UInt8", "Int16", "UInt16", "Int32",
                                                        "UInt32", "Int64", "UInt64", "Boolean", "String", "Binary", "Clock")),
    "fmi3GetNumberOfVariableDependencies", "fmi3GetVariableDependencies", "fmi3GetFMUState", "fmi3SetFMUState",
    "fmi3FreeFMUState", "fmi3SerializedFMUStateSize", "fmi3SerializeFMUState", "fmi3DeserializeFMUState",
    "fmi3GetDirectionalDerivative", "fmi3GetAdjointDerivative", "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal", "fmi3GetIntervalFraction", "fmi3GetShiftDecimal", "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal", "fmi3SetIntervalFraction", "fmi3SetShiftDecimal", "fmi3SetShiftFraction",
    "fmi3EvaluateDiscreteStates", "fmi3UpdateDiscreteStates",
    "fmi3EnterContinuousTimeMode", "fmi3CompletedIntegratorStep", "fmi3SetTime", "fmi3SetContinuousStates",
    "fmi3GetContinuousStateDerivatives", "fmi3GetEventIndicators", "fmi3GetContinuousStates",
    "fmi3GetNominalsOfContinuousStates", "fmi3GetNumberOfEventIndicators", "fmi3GetNumberOfContinuousStates",
    "fmi3EnterStepMode", "fmi3GetOutputDerivatives", "fmi3DoStep", "fmi3ActivateModelPartition",
}


def test_the_binary_exports_every_fmi3_function_and_fmpy_needs_no_other():
    import inspect
    import subprocess

    assert len(FMI3_FUNCTIONS) == 75
    with zipfile.ZipFile(fmu3("AttitudePlant")) as z, __import__("tempfile").TemporaryDirectory() as d:
        so = Path(d) / "AttitudePlant.so"
        so.write_bytes(z.read("binaries/x86_64-linux/AttitudePlant.so"))
        nm = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True, text=True, check=True).stdout
    exported = {line.split()[-1] for line in nm.splitlines() if line.split()[-1].startswith("fmi3")}
    assert exported == FMI3_FUNCTIONS
    assert {n for n, _ in inspect.getmembers(FMU3Slave) if n.startswith("fmi3")} <= exported


def test_every_model_has_an_fmi3_description_and_fmu():
    fmi2_models = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
    assert MODELS == fmi2_models and len(MODELS) == 35
    missing = [m for m in MODELS if not (FMI3_DIR / f"{m}.fmu").exists()]
    assert not missing, f"not built: {missing} (run scripts/build_fmus.sh)"


@pytest.mark.parametrize("model", MODELS)
def test_fmpy_validation_finds_no_problem(model):
    assert validate_fmu(fmu3(model)) == []


def test_the_schema_check_is_not_blind_to_clocks(tmp_path):
    """fmpy validates every description against the official FMI 3.0 XSD (test above); it refuses a
    clocked description that breaks the schema: a <Clock> without its required intervalVariability, a
    clocked output with an unknown variability."""
    from fmpy.model_description import ValidationError

    def read(xml: str):
        path = tmp_path / "modelDescription.xml"
        path.write_text(xml)
        return read_model_description(str(path))

    good = (ROOT / "modelDescription" / "fmi3" / "StarTracker.xml").read_text()
    assert read(good).scheduledExecution is not None  # the committed one passes
    broken = [good.replace(' intervalVariability="fixed"', "", 1),
              good.replace('variability="discrete" clocks=', 'variability="sometimes" clocks=', 1)]
    for xml in broken:
        assert xml != good
        with pytest.raises(ValidationError):
            read(xml)


@pytest.mark.parametrize("model", MODELS)
def test_archive_layout_and_description(model):
    with zipfile.ZipFile(fmu3(model)) as z:
        names = set(z.namelist())
        assert {"modelDescription.xml", f"binaries/x86_64-linux/{model}.so", "documentation/index.html"} <= names
        assert not any(n.startswith("binaries/linux64/") for n in names)
        assert z.read("modelDescription.xml") == (ROOT / "modelDescription" / "fmi3" / f"{model}.xml").read_bytes()
        # one binary serves both FMI versions
        with zipfile.ZipFile(fmu2(model)) as z2:
            assert z.read(f"binaries/x86_64-linux/{model}.so") == z2.read(f"binaries/linux64/{model}.so")
    md3, md2 = read_model_description(fmu3(model)), read_model_description(fmu2(model))
    assert md3.fmiVersion == "3.0" and md3.instantiationToken == md2.guid
    v3 = {v.name: v for v in md3.modelVariables}
    assert v3["time"].causality == "independent" and v3["time"].valueReference == TIME_VR
    # every FMI 2.0 variable, the Model Exchange states and derivatives included (same value references),
    # then the clocks of a sampled unit (FMI 3.0 only); a clocked output is discrete (2.4.7)
    clocks = [v for v in md3.modelVariables if v.type == "Clock"]
    assert len(md3.modelVariables) == len(md2.modelVariables) + 1 + len(clocks)
    for v in md2.modelVariables:
        w = v3[v.name]
        variability = "discrete" if w.clocks else v.variability
        assert (w.valueReference, w.causality, w.variability, w.start, w.unit) == (v.valueReference, v.causality, variability, v.start, v.unit)
        if v.derivative is not None:
            assert w.derivative.name == v.derivative.name
        assert w.type == {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}[v.type]


@pytest.mark.parametrize("model", MODELS)
def test_fmpy_simulation_equals_fmi2_bit_for_bit(model):
    """fmpy's own master runs the FMI 3.0 FMU with its defaults; every output column equals the FMI 2.0
    FMU's, bit for bit (same binary, same model code, different C API)."""
    md = read_model_description(fmu2(model))
    step = float(md.defaultExperiment.stepSize)
    r3 = simulate_fmu(fmu3(model), stop_time=100 * step, step_size=step, fmi_call_logger=None)
    r2 = simulate_fmu(fmu2(model), stop_time=100 * step, step_size=step, fmi_call_logger=None)
    assert len(r3) == len(r2) == 101
    assert r3.dtype.names == r2.dtype.names
    for n in r2.dtype.names:
        assert np.array_equal(r3[n], r2[n]), f"{model}.{n}"


def test_attitude_plant_constant_torque_closed_form():
    """Rest, diagonal inertia, constant torque T about x: w_x = T t / I_xx and the rotation angle about x
    is T t^2 / (2 I_xx); w_y = w_z = 0. The FMI 3.0 FMU agrees with this and with the FMI 2.0 FMU."""
    T, stop, h = 0.01, 10.0, 0.1
    start = {"torque_cmd_x": T}
    r3 = simulate_fmu(fmu3("AttitudePlant"), stop_time=stop, step_size=h, start_values=start, output=["w_x", "w_y", "w_z", "q_w", "q_x"])
    r2 = simulate_fmu(fmu2("AttitudePlant"), stop_time=stop, step_size=h, start_values=start, output=["w_x", "w_y", "w_z", "q_w", "q_x"])
    md = {v.name: v for v in read_model_description(fmu3("AttitudePlant")).modelVariables}
    ixx = float(md["inertia_xx"].start)
    t = r3["time"]
    assert t[-1] == pytest.approx(stop)
    np.testing.assert_allclose(r3["w_x"], T * t / ixx, rtol=1e-12, atol=1e-15)
    assert np.all(r3["w_y"] == 0.0) and np.all(r3["w_z"] == 0.0)
    angle = 2.0 * np.arctan2(r3["q_x"], r3["q_w"])
    np.testing.assert_allclose(angle, T * t**2 / (2.0 * ixx), rtol=1e-9, atol=1e-13)
    for n in ("w_x", "q_w", "q_x"):
        assert np.array_equal(r3[n], r2[n]), n


# ----- a closed loop over FMU3Slave and FMU2Slave -----------------------------------------------------

PLANT_OUT = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]
CTRL_IN = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]
CTRL_OUT = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]


def _open(model: str, version: int, tmp: Path, name: str):
    path = fmu3(model) if version == 3 else fmu2(model)
    md = read_model_description(path)
    d = extract(path, unzipdir=str(tmp / f"{model}{version}"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    if version == 3:
        s = FMU3Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        s.instantiate()
    else:
        s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        s.instantiate()
    return s, vr


def _loop(version: int, tmp: Path, steps: int = 300, h: float = 0.05) -> np.ndarray:
    plant, pv = _open("AttitudePlant", version, tmp, "plant")
    ctrl, cv = _open("PdController", version, tmp, "ctrl")
    get = (lambda s, v: s.getFloat64(v)) if version == 3 else (lambda s, v: s.getReal(v))
    setr = (lambda s, v, x: s.setFloat64(v, x)) if version == 3 else (lambda s, v, x: s.setReal(v, x))
    setr(plant, [pv["init_euler321_roll"], pv["init_w_y"]], [0.3, 0.02])
    setr(ctrl, [cv["q_ref_w"], cv["q_ref_x"]], [math.cos(0.1), math.sin(0.1)])
    for s in (plant, ctrl):
        if version == 3:
            s.enterInitializationMode(startTime=0.0, stopTime=steps * h)
        else:
            s.setupExperiment(startTime=0.0, stopTime=steps * h)
            s.enterInitializationMode()
        s.exitInitializationMode()
    rows = []
    t = 0.0
    for k in range(steps):
        y = get(plant, [pv[n] for n in PLANT_OUT])
        setr(ctrl, [cv[n] for n in CTRL_IN], y)
        u = get(ctrl, [cv[n] for n in CTRL_OUT])
        setr(plant, [pv[n] for n in CTRL_OUT], u)
        rows.append(y + u)
        plant.doStep(t, h)
        ctrl.doStep(t, h)
        last = t + h  # the FMU continues on the master's grid: its time is t + h of the last step
        t = (k + 1) * h
    if version == 3:
        assert plant.getFloat64([TIME_VR]) == [last]
    for s in (plant, ctrl):
        s.terminate()
        s.freeInstance()
    return np.array(rows)


def test_closed_loop_fmi3_equals_fmi2_bit_for_bit(tmp_path):
    a3 = _loop(3, tmp_path)
    a2 = _loop(2, tmp_path)
    assert a3.shape == (300, 10)
    assert np.abs(a3[-1, 4:7]).max() < np.abs(a3[0, 4:7]).max() + 1.0  # the loop ran and stayed bounded
    assert np.array_equal(a3, a2)
    shutil.rmtree(tmp_path, ignore_errors=True)
