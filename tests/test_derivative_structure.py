"""`<Derivatives>` lists exact dependencies: for every Model Exchange unit with continuous states, the
structure of ∂ẋ/∂(x, u) found by perturbing each state and input of the running FMU (fmpy's FMU2Model,
several random points and parameter sets that switch every option on) equals the dependency lists in
the unit's modelDescription.xml: no dependency is missing (a tool's sorting and Jacobian sparsity
would be wrong) and none is listed that no parameter setting produces.

A perturbation either changes a derivative or leaves it bit-identical: a derivative that does not read
a variable is computed by the same floating-point operations, so any change at all is a dependency.
"""

from __future__ import annotations

from ctypes import c_double

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model

from scfmu.fmu import fmu_path

# Parameter sets per model, written out here so that together they switch on every term of the
# equations (each option of the model's documentation), plus a scale for random states and inputs.
FULL_INERTIA = {"inertia_xy": 20.0, "inertia_xz": -15.0, "inertia_yz": 10.0}
# actuator misalignment and scale factor couple every actuator axis into every body axis
MISALIGNED = {"actuator_misalignment_x": 0.02, "actuator_misalignment_y": -0.03, "actuator_misalignment_z": 0.01,
              "actuator_scale_x": 1.05}
ATTITUDE_FEATURES = [
    # ideal actuators, full inertia, gravity gradient
    {"actuator_mode": 0, "gg_enable": 1, **FULL_INERTIA},
    # reaction wheels with lag and magnetorquers, gravity gradient
    {"actuator_mode": 1, "mtq_enable": 1, "gg_enable": 1, "wheel_time_constant": 0.5, **FULL_INERTIA, **MISALIGNED},
    # reaction wheels without lag: the wheel torque follows the command directly
    {"actuator_mode": 1, "mtq_enable": 1, "gg_enable": 0, "wheel_time_constant": 0.0, **FULL_INERTIA, **MISALIGNED},
    # magnetorquers following the dipole command input m_cmd (B-dot), besides lagging wheels
    {"actuator_mode": 1, "mtq_mode": 1, "gg_enable": 1, "wheel_time_constant": 0.5, **FULL_INERTIA, **MISALIGNED},
    # the command and the dumping law sharing the coils (mtq_mode 2): the dumping share fed forward to the
    # wheels, (m - clamp(m_cmd)) x B, reads m_cmd where the sum is clamped (with lag: the lag states; without:
    # the wheel momenta); a gain that clamps every axis at some points (B is near the body z axis here)
    *({"actuator_mode": 1, "mtq_enable": 1, "mtq_mode": 2, "mtq_k_dump": 0.5, "gg_enable": 1, "wheel_time_constant": lag,
       **FULL_INERTIA, **MISALIGNED} for lag in (0.5, 0.0)),
    # the environment inputs: gravity gradient from r, field from b_eci (magnetorquers, residual dipole), drag
    # and solar pressure on three facets off the centre of mass
    *({"environment_inputs": 1, "actuator_mode": 1, "mtq_enable": 1, "gg_enable": 1, "wheel_time_constant": lag,
     "residual_dipole_x": 0.05, "residual_dipole_z": -0.02, **FULL_INERTIA, **MISALIGNED,
     **{f"facet{k}_{q}": v for k, n, c in ((1, (1.0, 0.3, 0.2), (0.5, 0.1, 0.0)), (2, (-0.2, 1.0, 0.4), (0.0, 0.6, 0.2)),
                                          (3, (0.3, -0.1, 1.0), (0.1, -0.2, 0.7)))
        for q, v in (("area", 2.0), ("specular", 0.3), ("diffuse", 0.2),
                     *((f"normal_{a}", x) for a, x in zip("xyz", n)), *((f"centre_{a}", x) for a, x in zip("xyz", c)))}}
      for lag in (0.5, 0.0)),  # with lag the field reaches the lag states, without it the wheel momenta
]
CASES = {
    "AttitudePlant": [dict(p, kinematics=k) for k in (0, 1, 2, 3, 4) for p in ATTITUDE_FEATURES],
    "SingleAxisPlant": [{}],
    "RelativeOrbitPlant": [{}, {"eccentricity": 0.1}],
    "AttitudeMetrics": [{}],
    "MracController": [{"coordinates": 0}, {"coordinates": 1}],
    "AdaptiveFuzzyController": [{"coordinates": 0}, {"coordinates": 1}],
    "PredictivePidController": [{"structure": 0}, {"structure": 1}],
    "ReferenceCorrector": [{"mode": 1, "node_x_1": 0.3, "node_y_2": -0.2, "node_z_3": 0.1}],
}
# Random states and inputs: x0 + scale N(0, 1); far enough from 0 that every term is above rounding
# (relative orbit: kilometres, so that the gravity terms in y and z show), small enough that no
# actuator saturates (attitude: commands of 0.01 N m against a wheel limit of 0.05 N m).
SCALE = {"AttitudePlant": 0.01, "RelativeOrbitPlant": 1000.0}


# States kept at a bound by projection (their derivative switches to 0 there): some points put them on it.
AT_BOUND = {m: {f"state_ihat_{c}": f"ihat_min_{c}" for c in "xyz"} for m in ("MracController", "AdaptiveFuzzyController")}


def _unit(rng):
    x = rng.standard_normal(3)
    return x / np.linalg.norm(x)


def md_of(model):
    return read_model_description(str(fmu_path(model)))


def probe(model: str, params: dict, seed: int, points: int = 8):
    """The set of (state k, variable name) with ∂ẋ_k/∂variable ≠ 0 at some random point."""
    path = str(fmu_path(model))
    md = read_model_description(path)
    by_name = {v.name: v for v in md.modelVariables}
    states = [u.variable.derivative for u in md.derivatives]
    inputs = [v for v in md.modelVariables if v.causality == "input" and v.type == "Real"]
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.modelExchange.modelIdentifier, instanceName="probe")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for name, value in params.items():
        v = by_name[name]
        (fmu.setInteger if v.type == "Integer" else fmu.setReal)([v.valueReference], [value])
    if params.get("environment_inputs") == 1:  # an orbit, a field and a sun before the first event iteration
        start = {"r_x": 7.0e6, "v_y": 7.5e3, "b_eci_z": 3e-5, "sun_eci_x": 1.0}
        fmu.setReal([by_name[k].valueReference for k in start], list(start.values()))
    fmu.exitInitializationMode()
    while fmu.newDiscreteStates()[0]:  # newDiscreteStatesNeeded
        pass
    fmu.enterContinuousTimeMode()
    nx = len(states)
    buf = (c_double * nx)()
    fmu.getContinuousStates(buf, nx)
    x0 = np.array(buf[:])
    rng = np.random.default_rng(seed)
    scale = SCALE.get(model, 0.1)
    found = set()
    vr_in = [v.valueReference for v in inputs]

    def deriv(x, u):
        fmu.setTime(1.0)
        if inputs:
            fmu.setReal(vr_in, list(u))
        fmu.setContinuousStates((c_double * nx)(*x), nx)
        dx = (c_double * nx)()
        fmu.getDerivatives(dx, nx)
        return np.array(dx[:])

    names_in = [v.name for v in inputs]

    def draw():
        x = x0 + scale * rng.standard_normal(nx)
        u = scale * rng.standard_normal(len(inputs))
        if "sun_distance" in names_in:  # the plant's environment: an orbit state, a field, a sun, air
            env = {"r": _unit(rng) * 7.0e6, "v": _unit(rng) * 7.5e3, "b_eci": _unit(rng) * 3e-5, "sun_eci": _unit(rng)}
            for stem, vec in env.items():
                u[[names_in.index(f"{stem}_{c}") for c in "xyz"]] = vec
            for name, value in (("eclipse", rng.uniform(0.2, 0.8)), ("rho", 1e-9), ("sun_distance", 1.496e11)):
                u[names_in.index(name)] = value
        for q in ("q", "q_ref"):  # unit quaternion inputs near the identity (controllers check the norm)
            ix = [names_in.index(f"{q}_{c}") for c in "wxyz" if f"{q}_{c}" in names_in]
            if len(ix) == 4:
                u[ix] = rng.standard_normal(4) * 0.3 + [1, 0, 0, 0]
                u[ix] /= np.linalg.norm(u[ix])
        return x, u

    for point in range(points):
        x, u = draw()
        base = deriv(x, u)
        bounded = list(AT_BOUND.get(model, {}).items())
        if bounded and point % 2:
            # the state sits on its bound where the law pushes it down (derivative held at 0): draw
            # points until one of them is there
            state, bound = bounded[(point // 2) % len(bounded)]
            k = [s.name for s in states].index(state)
            for _ in range(1000):
                x[k] = fmu.getReal([by_name[bound].valueReference])[0]
                base = deriv(x, u)
                if base[k] == 0.0:
                    break
                x, u = draw()
            assert base[k] == 0.0, f"no point found with {state} held at its bound"
        for j in range(nx):
            xp = x.copy()
            xp[j] += 1e-4 * (1 + abs(x[j]))
            for k in np.nonzero(deriv(xp, u) != base)[0]:
                found.add((states[k].name, states[j].name))
        for j in range(len(inputs)):
            up = u.copy()
            up[j] += 1e-4 * (1 + abs(u[j]))
            for k in np.nonzero(deriv(x, up) != base)[0]:
                found.add((states[k].name, inputs[j].name))
    fmu.terminate()
    fmu.freeInstance()
    return found


def declared(model: str):
    md = md_of(model)
    return {(u.variable.derivative.name, d.name) for u in md.derivatives for d in (u.dependencies or [])}


# Written out: the units that publish continuous states (an ME unit without states has no <Derivatives>).
ME_STATEFUL = set(CASES)


@pytest.mark.parametrize("model", sorted(ME_STATEFUL))
def test_derivative_dependencies_are_exact(model):
    md = md_of(model)
    assert md.modelExchange is not None and md.derivatives, f"{model} should publish continuous states"
    found = set()
    for i, params in enumerate(CASES[model]):
        found |= probe(model, params, seed=100 + i)
    listed = declared(model)
    missing = sorted(found - listed)
    spurious = sorted(listed - found)
    assert not missing, f"{model}: dependencies the FMU has but <Derivatives> does not list: {missing}"
    assert not spurious, f"{model}: dependencies <Derivatives> lists that no parameter set produces: {spurious}"
