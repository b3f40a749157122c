"""Every capability flag in every modelDescription we write is exercised (issue 22): our FMUs
(fmus/*.fmu) and the closed-loop container FMUs (fmus/loops/*.fmu). A flag declared true is used the way
a master would use it; a flag declared false that promises an absence is checked to be absent. And a
generic master (fmpy's simulate_fmu with its default settings) runs every FMU at its DefaultExperiment
step and at 0.01 s without an error (a loop FMU whose fixed step does not divide 0.01 s declares a
constant step and refuses 0.01 s with an error, which is what it declares)."""

from __future__ import annotations

import ctypes
import shutil
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, \
    fmi2CallbackLoggerTYPE, fmi2StepFinishedTYPE

from scfmu import scenario as scenarios
from scfmu.verify import REF_INPUT_OFFSETS

ROOT = Path(__file__).resolve().parents[1]
OURS = sorted((ROOT / "fmus").glob("*.fmu"))
LOOPS = sorted((ROOT / "fmus" / "loops").glob("*.fmu"))
HANDLED = {"modelIdentifier", "needsExecutionTool", "canHandleVariableCommunicationStepSize", "canInterpolateInputs",
           "maxOutputDerivativeOrder", "canRunAsynchronuously", "canBeInstantiatedOnlyOncePerProcess",
           "canNotUseMemoryManagementFunctions", "canGetAndSetFMUstate", "canSerializeFMUstate",
           "providesDirectionalDerivative"}


def flags(path: Path) -> dict:
    with zipfile.ZipFile(path) as z:
        cs = ET.fromstring(z.read("modelDescription.xml")).find("CoSimulation")
    return dict(cs.attrib)


def true(f: dict, name: str) -> bool:
    return f.get(name, "false") == "true"


def test_there_are_fmus_to_check():
    assert len(OURS) == len(list((ROOT / "modelDescription").glob("*.xml"))), "run scripts/build_fmus.sh"
    assert len(LOOPS) >= 10


@pytest.mark.parametrize("path", OURS + LOOPS, ids=lambda p: p.stem)
def test_every_declared_flag_is_one_this_test_exercises(path):
    unknown = set(flags(path)) - HANDLED
    assert not unknown, f"{path.name}: flags without a test: {unknown}"


class Slave:
    """An initialized FMU2Slave on the FMU's default inputs, with the Real inputs and outputs."""

    def __init__(self, path: Path, unzipdir: str, callbacks=None):
        self.md = read_model_description(str(path))
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=path.stem)
        self.fmu.instantiate(callbacks=callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        real = [v for v in self.md.modelVariables if v.type == "Real"]
        wired = connected_inputs(path)
        ins = [v for v in real if v.causality == "input" and not v.name.split(".")[-1].startswith("q")
               and v.name not in wired]
        self.inputs = [v.valueReference for v in ins]
        # where a small signal alone is refused (a position inside the Earth), the reference experiment's offset
        offsets = REF_INPUT_OFFSETS.get(self.md.coSimulation.modelIdentifier, {})
        self.offsets = [offsets.get(v.name, 0.0) for v in ins]
        # an atmospheric density (Orbit's rho) is non-negative and thin in orbit (0.01 kg/m3 brings it down)
        self.density = [v.valueReference for v in ins if v.unit == "kg/m3"]
        self.outputs = [v.valueReference for v in real if v.causality == "output"]
        self.h = float(self.md.defaultExperiment.stepSize)
        self.t = 0.0

    def run(self, n: int, steps=None) -> np.ndarray:
        rows = []
        for k in range(n):
            if self.inputs:
                self.fmu.setReal(self.inputs, [1e-12 * (1 + np.sin(0.3 * (self.t + i))) if vr in self.density
                                               else 0.01 * np.sin(0.3 * (self.t + i)) + self.offsets[i]
                                               for i, vr in enumerate(self.inputs)])
            h = self.h if steps is None else steps[k % len(steps)]
            self.fmu.doStep(self.t, h)
            self.t += h
            rows.append(self.fmu.getReal(self.outputs))
        return np.array(rows)

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def connected_inputs(path: Path) -> set[str]:
    """The inputs a loop FMU's scenario feeds from another unit ("instance.port"): the container shows them as
    inputs too, but a value set on one only replaces the source's for a step (a position of a few centimetres
    would reach the plant); the test perturbs the inputs the scenario leaves open. Empty for a unit FMU."""
    if path.parent.name != "loops":
        return set()
    from scfmu.registry import REGISTRY
    from scfmu.scenario import ssp
    from scfmu.scenario.plan import build_plan
    name = next(n for n in REGISTRY.exported_scenarios() if ssp.file_stem(n) == path.stem)
    return {f"{d}.{di}" for d, di, _s, _so in build_plan(scenarios.get(name)).links}


@pytest.fixture(scope="module")
def unzipped(tmp_path_factory):
    d = tmp_path_factory.mktemp("flags")
    yield {p: extract(str(p), unzipdir=str(d / p.stem)) for p in OURS + LOOPS}
    shutil.rmtree(d, ignore_errors=True)  # 1.6 GB of unpacked units (every platform's binaries)


@pytest.mark.parametrize("path", OURS + LOOPS, ids=lambda p: p.stem)
def test_declared_flags_hold(path, unzipped):
    f = flags(path)
    s = Slave(path, unzipped[path])
    s.run(5)
    if true(f, "canHandleVariableCommunicationStepSize"):
        # steps that are not multiples of each other or of the default step
        s.run(8, steps=[0.01, 0.024, 0.007, 0.05, s.h, 0.013, 0.1, 0.0031])
    if true(f, "canGetAndSetFMUstate"):
        st = s.fmu.getFMUstate()
        t0 = s.t
        first = s.run(6)
        s.fmu.setFMUstate(st)
        s.t = t0
        again = s.run(6)
        np.testing.assert_array_equal(first, again)
        if true(f, "canSerializeFMUstate"):
            blob = s.fmu.serializeFMUstate(st)
            st2 = s.fmu.deSerializeFMUstate(blob)
            s.fmu.setFMUstate(st2)
            s.t = t0
            np.testing.assert_array_equal(s.run(6), first)
            s.fmu.freeFMUstate(st2)
        s.fmu.freeFMUstate(st)
    if true(f, "providesDirectionalDerivative") and s.inputs and s.outputs:
        # against central differences taken by the master (set input, read outputs at the same instant)
        vr = s.inputs[0]
        u0 = s.fmu.getReal([vr])[0]
        d = s.fmu.getDirectionalDerivative(s.outputs, [vr], [1.0])
        du = 1e-5 * (1.0 + abs(u0))  # small enough for the curvature of the unit-vector laws (Triad, Quest)
        s.fmu.setReal([vr], [u0 + du])
        yp = np.array(s.fmu.getReal(s.outputs))
        s.fmu.setReal([vr], [u0 - du])
        ym = np.array(s.fmu.getReal(s.outputs))
        s.fmu.setReal([vr], [u0])
        fd = (yp - ym) / (2 * du)
        # rtol 2e-3: the fuzzy laws are only piecewise smooth (the two difference steps differ)
        np.testing.assert_allclose(d, fd, rtol=2e-3, atol=1e-6 * (1.0 + np.abs(fd).max()))
    if f.get("maxOutputDerivativeOrder", "0") == "0" and "maxOutputDerivativeOrder" in f:
        with pytest.raises(Exception):
            s.fmu.getRealOutputDerivatives(s.outputs[:1], [1])
    if f.get("canInterpolateInputs") == "false" and s.inputs:
        with pytest.raises(Exception):
            s.fmu.setRealInputDerivatives(s.inputs[:1], [1], [0.0])
    if f.get("canBeInstantiatedOnlyOncePerProcess") == "false":
        other = Slave(path, unzipped[path])
        a, b = other.run(3), Slave(path, unzipped[path]).run(3)
        np.testing.assert_array_equal(a, b)
        other.free()
    s.free()


@pytest.mark.parametrize("path", OURS, ids=lambda p: p.stem)
def test_no_memory_management_functions_are_called(path, unzipped):
    """canNotUseMemoryManagementFunctions="true": instantiate, step, take, serialize and restore states
    with allocateMemory/freeMemory callbacks that count their calls: none."""
    assert true(flags(path), "canNotUseMemoryManagementFunctions")
    calls = []
    libc = ctypes.CDLL(None)
    libc.calloc.restype = ctypes.c_void_p
    libc.calloc.argtypes = [ctypes.c_size_t, ctypes.c_size_t]
    libc.free.argtypes = [ctypes.c_void_p]

    def alloc(n, size):
        calls.append("alloc")
        return libc.calloc(n, size)

    def free(p):
        calls.append("free")
        libc.free(p)

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda *a: None)
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(alloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    cb.stepFinished = fmi2StepFinishedTYPE()
    cb.componentEnvironment = None
    s = Slave(path, unzipped[path], callbacks=cb)
    s.run(3)
    st = s.fmu.getFMUstate()
    s.fmu.setFMUstate(s.fmu.deSerializeFMUstate(s.fmu.serializeFMUstate(st)))
    s.run(3)
    s.free()
    assert calls == []


def loop_step(path: Path) -> float:
    return float(read_model_description(str(path)).defaultExperiment.stepSize)


@pytest.mark.parametrize("path", OURS + LOOPS, ids=lambda p: p.stem)
def test_generic_master_runs_at_the_default_step(path):
    r = simulate_fmu(str(path), output_interval=loop_step(path))  # the communication step in fmpy
    assert np.allclose(np.diff(r["time"]), loop_step(path))
    assert len(r) > 1 and all(np.isfinite(r[n]).all() for n in r.dtype.names)


@pytest.mark.parametrize("path", OURS + LOOPS, ids=lambda p: p.stem)
def test_generic_master_runs_at_10_ms(path):
    h = loop_step(path)
    k = 0.01 / h
    if path in LOOPS and abs(k - round(k)) > 1e-9:
        # a loop whose fixed step does not divide 0.01 s declares a constant step and refuses others
        assert not true(flags(path), "canHandleVariableCommunicationStepSize")
        with pytest.raises(Exception):
            simulate_fmu(str(path), output_interval=0.01, stop_time=0.1)
        return
    # fmpy's co-simulation communication step is the output interval
    r = simulate_fmu(str(path), output_interval=0.01)
    assert np.allclose(np.diff(r["time"]), 0.01)
    assert len(r) > 1 and all(np.isfinite(r[n]).all() for n in r.dtype.names)
