"""A foreign FMI 3.0 clocked unit for the clocked engines' tests: C3SampledPd, written by hand in C against the
FMI 3.0 headers fmpy ships (tests/foreign/c3/c3_clocked.c; not built by our exporter), with its
modelDescription written here. A single-axis PD law sampled every ``period`` seconds (``sample_clock``, clocks
``error``) whose command is delivered ``delay`` seconds later (``delivery_clock``, clocks ``u``); inputs
``theta``, ``theta_ref``, the ports of PidController, so it takes the controller's place in the single-axis loop.

``pd_oracle(theta, theta_ref, ...)``: the law in NumPy (the tests' independent reference)."""

from __future__ import annotations

import os
import tempfile
import uuid
import zipfile
from pathlib import Path

import numpy as np

from foreign_units import C3_DIR, compile_shared

MODEL = "C3SampledPd"
TOKEN = "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"spacecraft_fmus/tests/foreign/{MODEL}")


def model_description(scheduled: bool = True) -> str:
    se = f'  <ScheduledExecution modelIdentifier="{MODEL}"/>\n' if scheduled else ""
    var = [
        '<Float64 name="time" valueReference="999" causality="independent" variability="continuous"/>',
        '<Float64 name="theta" valueReference="0" causality="input" unit="rad" start="0"/>',
        '<Float64 name="theta_ref" valueReference="1" causality="input" unit="rad" start="0"/>',
        '<Float64 name="u" valueReference="2" causality="output" variability="discrete" clocks="101" unit="N.m"/>',
        '<Float64 name="error" valueReference="3" causality="output" variability="discrete" clocks="100" unit="rad"/>',
        '<Float64 name="period" valueReference="10" causality="parameter" variability="fixed" unit="s" start="0.01"/>',
        '<Float64 name="delay" valueReference="11" causality="parameter" variability="fixed" unit="s" start="0"/>',
        '<Float64 name="kp" valueReference="12" causality="parameter" variability="fixed" start="1"/>',
        '<Float64 name="kd" valueReference="13" causality="parameter" variability="fixed" start="0"/>',
        '<Clock name="sample_clock" valueReference="100" causality="input" variability="discrete" '
        'intervalVariability="fixed" priority="0"/>',
        '<Clock name="delivery_clock" valueReference="101" causality="input" variability="discrete" '
        'intervalVariability="fixed" priority="1"/>',
    ]
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="3.0" modelName="{MODEL}" instantiationToken="{TOKEN}" '
            'description="written by hand in C (a foreign clocked FMI 3.0 unit for the tests)" '
            'generationTool="hand-written (tests/foreign/c3)" variableNamingConvention="structured">\n'
            f'  <CoSimulation modelIdentifier="{MODEL}" canHandleVariableCommunicationStepSize="true" '
            'hasEventMode="true"/>\n' + se +
            '  <UnitDefinitions>\n    <Unit name="rad"><BaseUnit rad="1"/></Unit>\n'
            '    <Unit name="s"><BaseUnit s="1"/></Unit>\n'
            '    <Unit name="N.m"><BaseUnit kg="1" m="2" s="-2"/></Unit>\n  </UnitDefinitions>\n'
            '  <ModelVariables>\n' + "".join(f"    {x}\n" for x in var) + '  </ModelVariables>\n'
            '  <ModelStructure>\n    <Output valueReference="2"/>\n    <Output valueReference="3"/>\n'
            '  </ModelStructure>\n</fmiModelDescription>\n')


def build(dest, scheduled: bool = True) -> Path:
    """dest/C3SampledPd.fmu (binary under binaries/x86_64-linux); without ``scheduled`` the description has no
    <ScheduledExecution> (dest/C3SampledPd_cs.fmu)."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    fmu = dest / (f"{MODEL}.fmu" if scheduled else f"{MODEL}_cs.fmu")
    with tempfile.TemporaryDirectory(prefix="c3c_") as tmp:
        so = compile_shared(C3_DIR / "c3_clocked.c", Path(tmp) / f"{MODEL}.so", [f'-DMODEL_TOKEN="{TOKEN}"'], MODEL)
        part = fmu.with_suffix(".part")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", model_description(scheduled))
            z.writestr(f"binaries/x86_64-linux/{MODEL}.so", so.read_bytes())
        os.replace(part, fmu)
    return fmu


def pd_oracle(t, theta, theta_ref, period, delay, kp, kd) -> np.ndarray:
    """u on the logged grid ``t`` from the logged ``theta``: sample k at t_k = k·period takes e_k =
    theta_ref − theta(t_k); u = kp e_k + kd (e_k − e_{k−1})/period from t_k + delay until the next delivery
    (0 before the first). ``t``, ``theta`` at the grid; every sample instant must be a grid time."""
    t = np.asarray(t)
    u = np.zeros_like(t)
    n = int(np.floor(t[-1] / period + 1e-9)) + 1
    e_prev = None
    for k in range(n):
        tk = k * period
        j = int(np.argmin(np.abs(t - tk)))
        e = theta_ref - theta[j]
        cmd = kp * e + kd * (e - (e if e_prev is None else e_prev)) / period
        e_prev = e
        u[t >= tk + delay - 1e-9] = cmd
    return u
