"""Builds the Mimic3 units of tests/foreign/mimic/mimic3.c (FMI 3.0, written by hand for the tests of
`scfmu check`; each behaves in one respect the way a Modelica Reference-FMU does) and the BrokenUnit
variants that end their run like Stair (FMI 2.0). Used by tests/test_check_mimic.py."""

from __future__ import annotations

import os
import shutil
import tempfile
import uuid
import zipfile
from pathlib import Path

from foreign_units import compile_shared

MIMIC_DIR = Path(__file__).resolve().parent / "foreign" / "mimic"
# name: (MIMIC number, interfaces, default experiment attributes)
MIMICS = {"discrete_input": (1, ("me",), 'startTime="0" stopTime="2" stepSize="0.01"'),
          "terminate": (2, ("cs", "me"), 'startTime="0" stopTime="10" stepSize="0.05"'),
          "scheduled": (3, (), 'startTime="0" stopTime="10"'),
          "array_state": (4, ("me",), 'startTime="0" stopTime="10"'),
          "stiff_no_step": (5, ("cs", "me"), 'startTime="0" stopTime="1e8"'),
          "nan_through": (6, ("cs",), 'startTime="0" stopTime="2" stepSize="0.01"'),
          "ref_defects": (7, ("cs", "me"), 'startTime="0" stopTime="2" stepSize="0.01"'),
          "quiet_error": (8, ("cs",), 'startTime="0" stopTime="2" stepSize="0.1"'),
          "state_copy": (9, ("cs",), 'startTime="0" stopTime="2" stepSize="0.01"')}


def token(name: str) -> str:
    return "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"spacecraft_fmus/tests/mimic/{name}")


def _variables(name: str) -> tuple[list[str], list[str]]:
    """(variable elements, ModelStructure elements) of a Mimic3 unit (value references of mimic3.c)."""
    v = ['<Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>']
    s: list[str] = []
    if name in ("discrete_input", "nan_through", "ref_defects", "quiet_error", "state_copy"):
        v += ['<Float64 name="u" valueReference="1" causality="input" start="0"/>',
              '<Float64 name="y" valueReference="3" causality="output"/>']
        s += ['<Output valueReference="3"/>', '<InitialUnknown valueReference="3"/>']
    if name == "discrete_input":
        v += ['<Float64 name="d" valueReference="2" causality="input" variability="discrete" start="0"/>',
              '<Float64 name="yd" valueReference="4" causality="output" variability="discrete"/>']
        s = ['<Output valueReference="3"/>', '<Output valueReference="4"/>', '<InitialUnknown valueReference="3"/>',
             '<InitialUnknown valueReference="4"/>']
    if name == "terminate":
        v += ['<Int32 name="counter" valueReference="5" causality="output" variability="discrete" initial="exact" '
              'start="0"/>']
        s += ['<Output valueReference="5"/>']
    if name == "array_state":
        v += ['<Int32 name="n" valueReference="6" causality="structuralParameter" variability="fixed" start="3"/>',
              '<Float64 name="x" valueReference="7" causality="local" initial="exact" start="1 1 1">'
              '<Dimension valueReference="6"/></Float64>',
              '<Float64 name="der(x)" valueReference="8" causality="local" derivative="7">'
              '<Dimension valueReference="6"/></Float64>',
              '<Float64 name="y" valueReference="3" causality="output"/>']
        s += ['<Output valueReference="3"/>', '<ContinuousStateDerivative valueReference="8"/>',
              '<InitialUnknown valueReference="3"/>', '<InitialUnknown valueReference="8"/>']
    if name == "stiff_no_step":
        v += ['<Float64 name="x" valueReference="7" causality="local" initial="exact" start="0"/>',
              '<Float64 name="der(x)" valueReference="8" causality="local" derivative="7"/>',
              '<Float64 name="y" valueReference="3" causality="output"/>']
        s += ['<Output valueReference="3"/>', '<ContinuousStateDerivative valueReference="8"/>',
              '<InitialUnknown valueReference="3"/>', '<InitialUnknown valueReference="8"/>']
    return v, s


def model_description(name: str) -> str:
    _, itfs, experiment = MIMICS[name]
    model = f"Mimic_{name}"
    parts = []
    if "me" in itfs:
        parts.append(f'<ModelExchange modelIdentifier="{model}" canBeInstantiatedOnlyOncePerProcess="false"/>')
    if "cs" in itfs:
        state = ' canGetAndSetFMUState="true" canSerializeFMUState="true"' if name == "state_copy" else ""
        parts.append(f'<CoSimulation modelIdentifier="{model}" canHandleVariableCommunicationStepSize="true" '
                     f'canBeInstantiatedOnlyOncePerProcess="false"{state}/>')
    if not itfs:
        parts.append(f'<ScheduledExecution modelIdentifier="{model}"/>')
    variables, structure = _variables(name)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="3.0" modelName="{model}" instantiationToken="{token(name)}" '
            f'generationTool="hand-written (tests/foreign/mimic)">\n'
            + "".join(f"  {p}\n" for p in parts)
            + '  <LogCategories>\n    <Category name="logStatusError"/>\n  </LogCategories>\n'
            f'  <DefaultExperiment {experiment}/>\n'
            '  <ModelVariables>\n' + "".join(f"    {x}\n" for x in variables) + '  </ModelVariables>\n'
            '  <ModelStructure>\n' + "".join(f"    {x}\n" for x in structure) + '  </ModelStructure>\n'
            '</fmiModelDescription>\n')


def build_mimic(dest, name: str) -> Path:
    """dest/Mimic_<name>.fmu: mimic3.c compiled with MIMIC=<its number> (no binary for Scheduled Execution)."""
    if shutil.which("gcc") is None:
        raise RuntimeError("gcc is needed to build the Mimic3 units (scripts/setup.sh installs it)")
    number, itfs, _ = MIMICS[name]
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    model = f"Mimic_{name}"
    fmu = dest / f"{model}.fmu"
    with tempfile.TemporaryDirectory(prefix="mimic_") as tmp:
        so = Path(tmp) / f"{model}.so"
        if itfs:
            compile_shared(MIMIC_DIR / "mimic3.c", so, [f"-DMIMIC={number}", f'-DTOKEN="{token(name)}"'], model,
                           opt="-O1", libs=("-lm", "-lpthread"))
        part = fmu.with_suffix(".part")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", model_description(name))
            if itfs:
                z.writestr(f"binaries/x86_64-linux/{model}.so", so.read_bytes())
        os.replace(part, fmu)
    return fmu
