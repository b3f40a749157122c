"""FMI 3.0 Model Exchange (fmus/fmi3/<Model>.fmu): the units that offer FMI 2.0 Model Exchange offer it in
FMI 3.0 too, with the same states, derivatives and dependency lists (read from the FMI 2.0 description,
an independent writer of the same declarations); every FMU validates in fmpy; fmpy's own FMI 3.0 ME
master (CVODE) integrates the plants to the closed form and to the FMI 2.0 ME result; a static law gives
its Co-Simulation outputs; the FMI 3.0 ME state machine and every bad call are refused with the status
the standard prescribes and a message naming the function."""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_size_t, c_uint8, POINTER
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Model, FMU3Slave, fmi3Boolean, fmi3Float64, fmi3Int32
from fmpy.validation import validate_fmu

from test_fmi_bad_input import ERROR, OK, TIME_VR, f64, status, vrs  # the raw-call helpers
from test_model_exchange import PLANT_CASES, dedup_last

ROOT = Path(__file__).resolve().parents[1]
MODELS = sorted(p.stem for p in (ROOT / "modelDescription" / "fmi3").glob("*.xml"))


def fmu3(model: str) -> str:
    p = ROOT / "fmus" / "fmi3" / f"{model}.fmu"
    assert p.exists(), f"{p} missing: run scripts/build_fmus.sh"
    return str(p)


def fmu2(model: str) -> str:
    return str(ROOT / "fmus" / f"{model}.fmu")


def me_models() -> list[str]:
    """The units with FMI 2.0 Model Exchange, read from their FMI 2.0 descriptions."""
    return [m for m in MODELS if read_model_description(fmu2(m)).modelExchange is not None]


ME_MODELS = me_models()


def test_the_model_exchange_units_are_the_fmi2_ones():
    # written out (tests/test_model_exchange.py has the same table): at least these have ME
    assert {"AttitudePlant", "SingleAxisPlant", "RelativeOrbitPlant", "PdController", "AttitudeCommand"} <= set(ME_MODELS)
    assert len(ME_MODELS) >= 12
    for m in MODELS:
        assert (read_model_description(fmu3(m)).modelExchange is not None) == (m in ME_MODELS), m


def interface_attributes(path: str) -> dict:
    import xml.etree.ElementTree as ET
    import zipfile

    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return {e.tag: dict(e.attrib) for e in root if e.tag in ("ModelExchange", "CoSimulation")}


def names(unknowns):
    return [u.variable.name for u in unknowns]


def deps(u):
    return None if u.dependencies is None else sorted(v.name for v in u.dependencies)


@pytest.mark.parametrize("model", ME_MODELS)
def test_fmi3_model_exchange_validates_and_matches_the_fmi2_description(model):
    assert validate_fmu(fmu3(model)) == []
    md3, md2 = read_model_description(fmu3(model)), read_model_description(fmu2(model))
    me3, me2 = md3.modelExchange, md2.modelExchange
    assert me3.modelIdentifier == me2.modelIdentifier == model
    assert me3.needsCompletedIntegratorStep is (not me2.completedIntegratorStepNotNeeded) is True
    # the capability flags, read from the XML itself (FMI 3.0 spells them differently from FMI 2.0)
    x3, x2 = interface_attributes(fmu3(model)), interface_attributes(fmu2(model))
    flags3 = ("canGetAndSetFMUState", "canSerializeFMUState", "providesDirectionalDerivatives")
    flags2 = ("canGetAndSetFMUstate", "canSerializeFMUstate", "providesDirectionalDerivative")
    assert [x3["ModelExchange"][f] for f in flags3] == [x2["ModelExchange"][f] for f in flags2] == ["true"] * 3
    assert [x3["ModelExchange"][f] for f in flags3] == [x3["CoSimulation"][f] for f in flags3]
    assert x3["ModelExchange"]["needsCompletedIntegratorStep"] == "true"
    # same states and derivatives (names, value references, order), the derivative naming its state
    assert md3.numberOfContinuousStates == md2.numberOfContinuousStates == len(md2.derivatives)
    assert names(md3.derivatives) == names(md2.derivatives)
    for u3, u2 in zip(md3.derivatives, md2.derivatives):
        d3, d2 = u3.variable, u2.variable
        assert (d3.valueReference, d3.causality, d3.variability) == (d2.valueReference, "local", "continuous")
        assert d3.derivative.name == d2.derivative.name and d3.derivative.valueReference == d2.derivative.valueReference
        assert d3.derivative.type == "Float64" and d3.derivative.initial == "calculated"
        assert deps(u3) == deps(u2), d3.name
    # the same dependency lists, translated from indices to value references
    assert names(md3.outputs) == names(md2.outputs)
    for u3, u2 in zip(md3.outputs, md2.outputs):
        assert deps(u3) == deps(u2), u3.variable.name
    assert names(md3.initialUnknowns) == names(md2.initialUnknowns)
    for u3, u2 in zip(md3.initialUnknowns, md2.initialUnknowns):
        assert deps(u3) == deps(u2), u3.variable.name


@pytest.mark.parametrize("model", sorted(set(MODELS) - set(ME_MODELS)))
def test_co_simulation_only_units_have_no_model_exchange_in_fmi3(model):
    md3 = read_model_description(fmu3(model))
    assert md3.modelExchange is None and md3.numberOfContinuousStates == 0 and not md3.derivatives


# ----- fmpy's FMI 3.0 Model Exchange master (CVODE) ---------------------------------------------------

# The closed forms of SingleAxisPlant and AttitudePlant run on both versions' FMUs in
# tests/test_model_exchange.py (parametrized over FMI 2.0 and FMI 3.0).


@pytest.mark.parametrize("model", sorted(PLANT_CASES))
def test_fmi3_model_exchange_equals_fmi2_model_exchange_under_the_same_solver(model):
    """The FMI 2.0 ME case of tests/test_model_exchange.py (the AttitudePlant one crosses a fault time
    event) run by fmpy's CVODE over FMI 2.0 and over FMI 3.0 with the same settings."""
    sv, outs, stop, dt = PLANT_CASES[model]
    kw = dict(fmi_type="ModelExchange", solver="CVode", stop_time=stop, output_interval=dt, relative_tolerance=1e-11,
              start_values=sv, output=outs)
    r3, r2 = dedup_last(simulate_fmu(fmu3(model), **kw)), dedup_last(simulate_fmu(fmu2(model), **kw))
    assert np.array_equal(r3["time"], r2["time"])
    for k in outs:
        scale = max(1.0, float(np.max(np.abs(r2[k]))))
        assert np.max(np.abs(r3[k] - r2[k])) <= 1e-12 * scale, k


def test_a_command_step_is_a_time_event_in_fmi3_as_in_fmi2():
    kw = dict(fmi_type="ModelExchange", stop_time=5.0, output_interval=1.0)
    r3, r2 = simulate_fmu(fmu3("AttitudeCommand"), **kw), simulate_fmu(fmu2("AttitudeCommand"), **kw)
    assert r3.dtype.names == r2.dtype.names
    for n in r2.dtype.names:
        assert np.array_equal(r3[n], r2[n]), n


# ----- the C functions through fmpy's ctypes bindings ---------------------------------------------------

class Me3:
    """One FMI 3.0 instance (Model Exchange unless `cs`) with a recording logger."""

    def __init__(self, tmp: Path, model: str = "AttitudePlant", cs: bool = False, name: str = "me"):
        path = fmu3(model)
        self.md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.n = self.md.numberOfContinuousStates
        self.messages: list[tuple[int, str, str]] = []
        # one extracted copy per model: instances of one library share its FMU-state table
        d = tmp / model
        if not d.exists():
            extract(path, unzipdir=str(d))
        d = str(d)
        cls = FMU3Slave if cs else FMU3Model
        self.s = cls(guid=self.md.guid, unzipDirectory=d, modelIdentifier=model, instanceName=name)

        def log(env, st, category, message):
            self.messages.append((st, category.decode(), message.decode()))

        self.error = None
        try:
            self.s.instantiate(logMessage=log)
        except Exception as e:  # fmpy raises when the instance pointer is NULL
            self.error = e
        self.c = self.s.component

    def last(self) -> str:
        return self.messages[-1][2] if self.messages else ""

    def init(self, **values):
        self.s.enterInitializationMode(startTime=0.0)
        if values:
            self.s.setFloat64([self.vr[k] for k in values], list(values.values()))
        self.s.exitInitializationMode()

    def to_continuous_time(self, **values):
        self.init(**values)
        self.s.updateDiscreteStates()
        self.s.enterContinuousTimeMode()

    def close(self):
        if self.c:
            self.s.fmi3FreeInstance(self.c)
        self.s.freeLibrary()


@pytest.fixture
def me(tmp_path):
    f = Me3(tmp_path)
    yield f
    f.close()


def test_a_static_law_in_fmi3_model_exchange_gives_its_co_simulation_outputs(tmp_path):
    ins = {"q_w": 0.9, "q_x": 0.1, "q_y": -0.3, "q_z": 0.2, "w_x": 0.01, "w_y": -0.02, "w_z": 0.03,
           "q_ref_w": 1.0, "q_ref_x": 0.0, "q_ref_y": 0.0, "q_ref_z": 0.0}
    norm = math.sqrt(sum(ins[k] ** 2 for k in ("q_w", "q_x", "q_y", "q_z")))
    for k in ("q_w", "q_x", "q_y", "q_z"):
        ins[k] /= norm
    out = ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]
    res = []
    for cs in (True, False):
        f = Me3(tmp_path, "PdController", cs=cs, name="cs" if cs else "me")
        try:
            assert f.c, f.messages
            f.init()
            if not cs:
                assert f.n == 0 and f.s.getNumberOfContinuousStates() == 0 and f.s.getNumberOfEventIndicators() == 0
                f.s.updateDiscreteStates()
                f.s.enterContinuousTimeMode()
                assert status(f.s.fmi3GetContinuousStateDerivatives, f.c, None, 0) == OK
                f.s.setTime(1.5)
            f.s.setFloat64([f.vr[k] for k in ins], list(ins.values()))
            res.append(f.s.getFloat64([f.vr[k] for k in out]))
        finally:
            f.close()
    assert res[0] == res[1]
    # the law by hand: T = wn^2 I e - 2 zeta wn I w with e = 2 q_E,w q_E,v, q_E = q* (x) q_ref = q* here
    e = [2 * ins["q_w"] * -ins[k] for k in ("q_x", "q_y", "q_z")]
    inertia = (1000.0, 500.0, 700.0)
    expect = [i * ei - 2 * i * w for i, ei, w in zip(inertia, e, (ins["w_x"], ins["w_y"], ins["w_z"]))]
    assert np.allclose(res[1], expect, rtol=1e-12, atol=1e-12)


def test_states_and_derivatives_by_value_reference_and_the_state_machine(me):
    tau, iz = 0.2, 700.0
    assert me.s.getNumberOfContinuousStates() == 18 and me.s.getNumberOfEventIndicators() == 0
    me.init(torque_cmd_z=tau)
    # Event Mode after initialization: time events are reported by fmi3UpdateDiscreteStates
    need, term, nominals, values, defined, _ = me.s.updateDiscreteStates()
    assert (need, term, nominals, defined) == (False, False, False, False)
    me.s.enterContinuousTimeMode()
    n = me.n
    x, dx, nom = (c_double * n)(), (c_double * n)(), (c_double * n)()
    me.s.getContinuousStates(x, n)
    me.s.getNominalsOfContinuousStates(nom, n)
    assert list(nom) == [1.0] * n
    order = [u.variable.derivative.name for u in me.md.derivatives]
    k = order.index("state_w_z")
    me.s.setTime(2.0)
    x[k] = tau / iz * 2.0
    me.s.setContinuousStates(x, n)
    me.s.getContinuousStateDerivatives(dx, n)
    assert dx[k] == pytest.approx(tau / iz, abs=1e-15)
    got = me.s.getFloat64([me.vr["state_w_z"], me.vr["der(state_w_z)"], me.vr["w_z"], TIME_VR])
    assert got == pytest.approx([tau / iz * 2.0, tau / iz, tau / iz * 2.0, 2.0], abs=1e-15)
    # a state set by value reference in Continuous-Time Mode (FMI 3.0 allows it) is the state
    me.s.setFloat64([me.vr["state_w_x"]], [0.125])
    assert me.s.getFloat64([me.vr["w_x"]]) == [0.125]
    enter, terminate = me.s.completedIntegratorStep()
    assert not terminate
    me.s.enterEventMode()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    assert status(me.s.fmi3Terminate, me.c) == OK
    me.s.getContinuousStates(x, n)  # still readable in Terminated
    assert x[k] == pytest.approx(tau / iz * 2.0)


def test_fmu_state_round_trip_in_continuous_time_mode(me):
    me.to_continuous_time(torque_cmd_z=0.2, init_w_x=0.01)
    n = me.n
    x, dx0, dx1 = (c_double * n)(), (c_double * n)(), (c_double * n)()
    me.s.setTime(1.0)
    me.s.getContinuousStates(x, n)
    me.s.getContinuousStateDerivatives(dx0, n)
    state = me.s.getFMUState()
    blob = me.s.serializeFMUState(state)
    me.s.completedIntegratorStep()
    me.s.enterEventMode()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    me.s.setTime(3.0)
    x2 = (c_double * n)(*[v + 0.01 for v in x])
    me.s.setContinuousStates(x2, n)
    restored = me.s.deserializeFMUState(blob)
    me.s.setFMUState(restored)
    assert me.s.getFloat64([TIME_VR]) == [1.0]
    me.s.getContinuousStateDerivatives(dx1, n)
    assert list(dx1) == list(dx0)
    me.s.setTime(1.5)  # after the restore the solver may go on from the restored time
    me.s.freeFMUState(state)
    me.s.freeFMUState(restored)


def err(f: Me3, fn, *args, contains: str = "") -> str:
    st = status(fn, f.c, *args)
    assert st == ERROR, (fn.__name__ if hasattr(fn, "__name__") else fn, st, f.last())
    msg = f.last()
    assert contains in msg, msg
    return msg


def test_wrong_call_order_is_refused_and_terminates(me):
    n = me.n
    x = (c_double * n)()
    msg = err(me, me.s.fmi3SetContinuousStates, x, n, contains="fmi3SetContinuousStates")
    assert "not allowed in state Instantiated" in msg
    # fmi3Error -> Terminated: initialization is refused until fmi3Reset
    assert status(me.s.fmi3EnterInitializationMode, me.c, fmi3Boolean(False), 0.0, 0.0, fmi3Boolean(False), 0.0) == ERROR
    assert "Terminated" in me.last()
    assert status(me.s.fmi3Reset, me.c) == OK
    me.s.enterInitializationMode(startTime=0.0)
    err(me, me.s.fmi3EnterContinuousTimeMode, contains="fmi3EnterContinuousTimeMode: not allowed in state Initialization Mode")
    me.s.fmi3Reset(me.c)
    me.init()
    # Event Mode: no time, no states, no integrator step, no second fmi3EnterEventMode
    for fn, args in [(me.s.fmi3SetTime, (1.0,)), (me.s.fmi3SetContinuousStates, (x, n)),
                     (me.s.fmi3CompletedIntegratorStep, (fmi3Boolean(True), byref(fmi3Boolean()), byref(fmi3Boolean()))),
                     (me.s.fmi3EnterEventMode, ())]:
        err(me, fn, *args, contains="not allowed in state Event Mode")
        assert status(me.s.fmi3Reset, me.c) == OK
        me.init()
    me.s.updateDiscreteStates()
    me.s.enterContinuousTimeMode()
    bs = [fmi3Boolean() for _ in range(5)]
    t = fmi3Float64()
    err(me, me.s.fmi3UpdateDiscreteStates, *[byref(b) for b in bs], byref(t),
        contains="fmi3UpdateDiscreteStates: not allowed in state Continuous-Time Mode")


def test_wrong_lengths_nan_states_and_infinite_time_are_refused(me):
    me.to_continuous_time()
    n = me.n
    x = (c_double * (n + 1))()
    for fn, arr in [(me.s.fmi3GetContinuousStates, "continuousStates[]"), (me.s.fmi3SetContinuousStates, "continuousStates[]"),
                    (me.s.fmi3GetContinuousStateDerivatives, "derivatives[]"), (me.s.fmi3GetNominalsOfContinuousStates, "nominals[]")]:
        msg = err(me, fn, x, n - 1, contains=f"{arr} has {n - 1} elements, but AttitudePlant has {n} continuous states")
        assert msg.startswith("me: fmi3"), msg
        me.s.fmi3Reset(me.c)
        me.to_continuous_time()
    err(me, me.s.fmi3GetEventIndicators, x, 1, contains="numberOfEventIndicators = 0")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    assert status(me.s.fmi3GetEventIndicators, me.c, None, 0) == OK
    err(me, me.s.fmi3GetContinuousStates, None, n, contains="continuousStates[] is NULL")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    me.s.getContinuousStates(x, n)
    x[5] = float("nan")
    err(me, me.s.fmi3SetContinuousStates, x, n, contains="continuousStates[5] (state_att_6) = NaN is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetTime, math.inf, contains="fmi3SetTime: time inf is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["state_w_x"]), 1, f64(math.nan), 1, contains="state_w_x is not finite")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3CompletedIntegratorStep, fmi3Boolean(True), None, byref(fmi3Boolean()), contains="enterEventMode is NULL")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3GetNumberOfContinuousStates, None, contains="nContinuousStates is NULL")


def test_what_cannot_be_set_in_continuous_time_mode(me):
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["inertia_xx"]), 1, f64(900.0), 1,
        contains="inertia_xx cannot be set in Continuous-Time Mode")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    i = (fmi3Int32 * 1)(1)
    err(me, me.s.fmi3SetInt32, vrs(me.vr["gg_enable"]), 1, i, 1, contains="fmi3SetInt32: Int32 variables are discrete")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(me.vr["der(state_w_x)"]), 1, f64(1.0), 1, contains="der(state_w_x) is a state derivative")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    err(me, me.s.fmi3SetFloat64, vrs(TIME_VR), 1, f64(1.0), 1, contains="it is set with fmi3SetTime")
    me.s.fmi3Reset(me.c)
    me.to_continuous_time()
    me.s.setFloat64([me.vr["torque_cmd_x"]], [0.5])  # a continuous input: fine


def test_a_co_simulation_only_unit_refuses_model_exchange(tmp_path):
    f = Me3(tmp_path, "PidController")
    try:
        assert not f.c and f.error is not None
        assert any("fmi3InstantiateModelExchange" in m[2] and "provides Co-Simulation only" in m[2] for m in f.messages), f.messages
    finally:
        f.s.freeLibrary()


def test_do_step_on_a_model_exchange_instance_and_me_calls_on_a_co_simulation_instance(tmp_path):
    me, cs = Me3(tmp_path, name="me"), Me3(tmp_path, cs=True, name="cs")
    try:
        me.to_continuous_time()
        ev, term, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        err(me, me.s.fmi3DoStep, 0.0, 0.1, fmi3Boolean(True), byref(ev), byref(term), byref(early), byref(last),
            contains="fmi3DoStep: Co-Simulation function, but this instance was created by fmi3InstantiateModelExchange")
        cs.init()
        x = (c_double * 18)()
        err(cs, cs.s.fmi3GetContinuousStates, x, 18,
            contains="fmi3GetContinuousStates: Model Exchange function, but this instance was created by fmi3InstantiateCoSimulation")
        # a Model Exchange FMU state cannot be set into a Co-Simulation instance
        me.s.fmi3Reset(me.c)
        me.to_continuous_time()
        state = me.s.getFMUState()
        cs.s.fmi3Reset(cs.c)
        cs.init()
        err(cs, cs.s.fmi3SetFMUState, state, contains="fmi3SetFMUState: FMU state was taken from a Model Exchange instance")
        me.s.freeFMUState(state)
        # and a Co-Simulation one not into a Model Exchange instance
        cs.s.fmi3Reset(cs.c)
        cs.init()
        state = cs.s.getFMUState()
        err(me, me.s.fmi3SetFMUState, state, contains="taken from a Co-Simulation instance")
        cs.s.freeFMUState(state)
    finally:
        me.close()
        cs.close()


def test_co_simulation_keeps_refusing_event_mode(tmp_path):
    cs = Me3(tmp_path, cs=True)
    try:
        cs.init()
        err(cs, cs.s.fmi3EnterEventMode, contains="hasEventMode = false")
        cs.s.fmi3Reset(cs.c)
        cs.init()
        bs = [fmi3Boolean() for _ in range(5)]
        t = fmi3Float64()
        err(cs, cs.s.fmi3UpdateDiscreteStates, *[byref(b) for b in bs], byref(t), contains="has no Event Mode")
    finally:
        cs.close()


def test_directional_derivatives_of_state_derivatives_follow_the_rigid_body(me):
    """providesDirectionalDerivatives = true in <ModelExchange>: the Jacobian entries a stiff solver asks
    for, against the rigid body by hand. At q = (cos(a/2), 0, 0, sin(a/2)), w = (0, 0, w_z) with J diagonal:
    d(w_z')/d(tau_z) = 1/I_z, d(q_w')/d(w_z) = -q_z/2, d(q_z')/d(w_z) = q_w/2, d(w_x')/d(w_y) = (I_y - I_z) w_z / I_x."""
    ix, iy, iz = 1000.0, 500.0, 700.0
    a, wz = 0.7, 0.03
    me.to_continuous_time()
    n = me.n
    x = (c_double * n)()
    me.s.getContinuousStates(x, n)
    order = [u.variable.derivative.name for u in me.md.derivatives]
    x[order.index("state_att_1")], x[order.index("state_att_4")] = math.cos(a / 2), math.sin(a / 2)
    x[order.index("state_w_z")] = wz
    me.s.setTime(1.0)
    me.s.setContinuousStates(x, n)
    v = me.vr
    d = me.s.getDirectionalDerivative([v["der(state_w_z)"]], [v["torque_cmd_z"]], [1.0])
    assert d[0] == pytest.approx(1 / iz, rel=1e-9)
    d = me.s.getDirectionalDerivative([v["der(state_att_1)"], v["der(state_att_4)"], v["der(state_w_x)"]], [v["state_w_z"]], [1.0])
    assert d[:2] == pytest.approx([-math.sin(a / 2) / 2, math.cos(a / 2) / 2], rel=1e-8)
    assert abs(d[2]) < 1e-12
    d = me.s.getDirectionalDerivative([v["der(state_w_x)"]], [v["state_w_y"]], [1.0])
    assert d[0] == pytest.approx((iy - iz) * wz / ix, rel=1e-7)
    # outputs with respect to states: w_z is the state itself
    assert me.s.getDirectionalDerivative([v["w_z"]], [v["state_w_z"]], [2.0]) == pytest.approx([2.0], rel=1e-9)
    err(me, me.s.fmi3GetDirectionalDerivative, vrs(v["state_w_z"]), 1, vrs(v["state_w_x"]), 1, f64(1.0), 1, f64(0.0), 1,
        contains="is neither a Real output nor a state derivative")
