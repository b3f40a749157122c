"""The Co-Simulation face of a Model Exchange unit (the library of scfmu/engines/me_cs) called directly through
ctypes, FMI 2.0 and 3.0: the statuses the standard prescribes for calls it refuses (a null instance, a step
that is not a step, the functions it does not offer, a Model Exchange or event-mode instantiation), an
instance that stays usable after a refused step, and the FMI 3.0 output arguments of doStep. The engines'
tests (tests/test_engines_plan.py) check the trajectories the face integrates.

Each test loads its own copy of the library (the face serves one unit per loaded copy) next to the unpacked
AttitudePlant FMU with the face's settings file, as scfmu/engines/cs_face.py writes it."""

from __future__ import annotations

import ctypes as C
import shutil
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from scfmu.engines.cs_face import wrapper_library
from scfmu.fmu import Fmu

ROOT = Path(__file__).resolve().parents[1]
OK, ERROR = 0, 3
NAN, INF = float("nan"), float("inf")
VP, B, D = C.c_void_p, C.c_bool, C.c_double
LOG2 = C.CFUNCTYPE(None, VP, C.c_char_p, C.c_int, C.c_char_p, C.c_char_p)
LOG3 = C.CFUNCTYPE(None, VP, C.c_int, C.c_char_p, C.c_char_p)


class Callbacks2(C.Structure):
    _fields_ = [("logger", LOG2), ("allocate", VP), ("free", VP), ("step_finished", VP), ("env", VP)]


class Face:
    """A loaded copy of the face over an unpacked AttitudePlant (FMI ``fmi``), its messages in ``log``."""

    def __init__(self, fmi: int, tmp: Path):
        lib = wrapper_library()
        if lib is None:
            pytest.skip("the face library is not built (cargo build --release -p scfmu_me_cs)")
        fmu = ROOT / "fmus" / ("fmi3" if fmi == 3 else "") / "AttitudePlant.fmu"
        zipfile.ZipFile(fmu).extractall(tmp)
        self.md = read_model_description(str(fmu))
        cfg = "model_identifier=AttitudePlant\nmethod=DOP853\nrtol=1e-10\natol=1e-12\nmax_step=0.0\n"
        if fmi == 2:
            cfg += f"states={len(self.md.derivatives)}\nevent_indicators=0\n"
        (tmp / "resources").mkdir(exist_ok=True)
        (tmp / "resources" / "scfmu_me_cs.txt").write_text(cfg)
        shutil.copy(lib, tmp / f"face{fmi}.so")
        self.lib = C.CDLL(str(tmp / f"face{fmi}.so"))
        self.fmi, self.tmp, self.log = fmi, tmp, []
        self.log2 = LOG2(lambda _e, _n, _s, _c, m: self.log.append(m.decode()))
        self.log3 = LOG3(lambda _e, _s, _c, m: self.log.append(m.decode()))
        self.callbacks = Callbacks2(self.log2, None, None, None, None)
        self.lib.fmi2Instantiate.restype = self.lib.fmi3InstantiateCoSimulation.restype = VP
        self.lib.fmi3InstantiateModelExchange.restype = VP
        self.lib.fmi2Instantiate.argtypes = [C.c_char_p, C.c_int, C.c_char_p, C.c_char_p, VP, C.c_int, C.c_int]
        self.lib.fmi3InstantiateCoSimulation.argtypes = [C.c_char_p, C.c_char_p, C.c_char_p, B, B, B, B, VP,
                                                         C.c_size_t, VP, VP, VP]

    def instantiate(self, *, cs: bool = True, event_mode: bool = False, location: bytes | None = None):
        res = self.tmp / "resources"
        if self.fmi == 2:
            loc = location or res.as_uri().encode()
            return self.lib.fmi2Instantiate(b"p", 1 if cs else 0, self.md.guid.encode(), loc,
                                            C.byref(self.callbacks), 0, 1)
        loc = location or (str(res) + "/").encode()
        return self.lib.fmi3InstantiateCoSimulation(b"p", self.md.instantiationToken.encode(), loc, False, True,
                                                    event_mode, False, None, 0, None, C.cast(self.log3, VP), None)

    def call(self, name: str, *args) -> int:
        return getattr(self.lib, f"fmi{self.fmi}{name}")(*args)

    def initialize(self, c) -> None:
        if self.fmi == 2:
            assert self.call("SetupExperiment", VP(c), 0, D(0.0), D(0.0), 0, D(0.0)) == OK
            assert self.call("EnterInitializationMode", VP(c)) == OK
        else:
            assert self.call("EnterInitializationMode", VP(c), B(False), D(0.0), D(0.0), B(False), D(0.0)) == OK
        assert self.call("ExitInitializationMode", VP(c)) == OK

    def step(self, c, t: float, h: float) -> int:
        if self.fmi == 2:
            return self.lib.fmi2DoStep(VP(c), D(t), D(h), 1)
        return self.step3(c, t, h)[0]

    def step3(self, c, t: float, h: float) -> tuple:
        """fmi3DoStep with every output preset to a marker: (status, eventHandlingNeeded,
        terminateSimulation, earlyReturn, lastSuccessfulTime)."""
        ev, term, early, last = B(True), B(True), B(True), D(-1.0)
        st = self.lib.fmi3DoStep(VP(c), D(t), D(h), B(True), C.byref(ev), C.byref(term), C.byref(early),
                                 C.byref(last))
        return st, ev.value, term.value, early.value, last.value

    def _vr(self, name: str):
        return (C.c_uint * 1)(next(v.valueReference for v in self.md.modelVariables if v.name == name))

    def output(self, c, name: str) -> float:
        out = (D * 1)()
        if self.fmi == 2:
            assert self.call("GetReal", VP(c), self._vr(name), 1, out) == OK
        else:
            assert self.call("GetFloat64", VP(c), self._vr(name), 1, out, 1) == OK
        return out[0]

    def set_input(self, c, name: str, value: float) -> None:
        v = (D * 1)(value)
        if self.fmi == 2:
            assert self.call("SetReal", VP(c), self._vr(name), 1, v) == OK
        else:
            assert self.call("SetFloat64", VP(c), self._vr(name), 1, v, 1) == OK

    def free(self, c) -> None:
        getattr(self.lib, f"fmi{self.fmi}FreeInstance").argtypes = [VP]
        getattr(self.lib, f"fmi{self.fmi}FreeInstance")(c)


@pytest.fixture(params=[2, 3], ids=["fmi2", "fmi3"])
def face(request, tmp_path):
    return Face(request.param, tmp_path)


def test_the_face_instantiates_co_simulation_only(face):
    """Model Exchange from the face (FMI 2.0 fmuType 0, fmi3InstantiateModelExchange), FMI 3.0 event mode and a
    resource folder without the face's settings give no instance (NULL); the right call gives one."""
    if face.fmi == 2:
        assert face.instantiate(cs=False) is None
    else:
        assert face.instantiate(event_mode=True) is None
        assert face.lib.fmi3InstantiateModelExchange(b"p", b"", b"/tmp/", False, False, None, None) is None
    nowhere = b"file:///nonexistent/resources" if face.fmi == 2 else b"/nonexistent/resources/"
    assert face.instantiate(location=nowhere) is None
    c = face.instantiate()
    assert c is not None
    face.free(c)
    face.free(None)  # a null instance is ignored


def test_calls_on_no_instance_and_functions_not_offered_are_errors(face):
    c = face.instantiate()
    assert face.step(None, 0.0, 0.1) == ERROR
    assert face.call("Terminate", None) == ERROR
    assert face.call("Reset", None) == ERROR
    assert face.call("ExitInitializationMode", None) == ERROR
    state = "GetFMUstate" if face.fmi == 2 else "GetFMUState"
    assert face.call(state, VP(c), None) == ERROR  # the solver's state is not part of an FMU state
    if face.fmi == 2:
        assert face.call("CancelStep", VP(c)) == ERROR
        assert face.call("GetStatus", VP(c), 0, None) == ERROR
    else:
        assert face.call("EnterEventMode", VP(c)) == ERROR
        assert face.call("EnterStepMode", None) == ERROR
        assert face.call("SetTime", VP(c), D(1.0)) == ERROR  # Model Exchange functions: not on this face
    face.free(c)


@pytest.mark.parametrize("t, h", [(0.0, 0.0), (0.0, -0.1), (0.0, NAN), (INF, 0.1), (NAN, 0.1)])
def test_a_step_that_is_not_a_step_is_refused_and_the_instance_goes_on(face, t, h):
    c = face.instantiate()
    face.initialize(c)
    if face.fmi == 3:
        assert face.call("EnterStepMode", VP(c)) == OK
        # the flags are cleared, lastSuccessfulTime is left alone: nothing was integrated
        assert face.step3(c, t, h) == (ERROR, False, False, False, -1.0)
    else:
        assert face.step(c, t, h) == ERROR
    face.set_input(c, "torque_cmd_y", 2e-3)
    for k in range(5):
        assert face.step(c, 0.1 * k, 0.1) == OK
    # the Co-Simulation plant (its own fixed-step integrator) under the same held torque: within 1e-8 of the
    # body rate (measured ~1e-14)
    cs = Fmu("AttitudePlant", path=ROOT / "fmus" / ("fmi3" if face.fmi == 3 else "") / "AttitudePlant.fmu")
    cs.set("torque_cmd_y", 2e-3)
    for k in range(5):
        cs.do_step(0.1 * k, 0.1)
    w_cs, w_face = cs.get("w_y"), face.output(c, "w_y")
    cs.close()
    assert abs(w_cs) > 1e-7 and abs(w_face - w_cs) < 1e-8 * abs(w_cs), (w_face, w_cs)
    face.free(c)


def test_fmi3_do_step_reports_the_time_reached_and_no_event(tmp_path):
    f = Face(3, tmp_path)
    c = f.instantiate()
    f.initialize(c)
    assert f.step3(c, 0.0, 0.25) == (OK, False, False, False, 0.25)
    assert f.step3(c, 0.25, 0.5) == (OK, False, False, False, 0.75)
    f.free(c)


def test_reset_gives_the_first_run_again(face):
    """After Reset and a second initialization the same steps give bit-identical outputs (the solver starts
    afresh with the unit)."""
    c = face.instantiate()
    runs = []
    for _ in range(2):
        face.initialize(c)
        face.set_input(c, "torque_cmd_y", 2e-3)
        for k in range(5):
            assert face.step(c, 0.2 * k, 0.2) == OK
        runs.append([face.output(c, n) for n in ("q_w", "q_y", "w_y")])
        assert face.call("Reset", VP(c)) == OK
    assert runs[0] == runs[1]
    face.free(c)
