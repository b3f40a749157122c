"""Foreign units for the tests: FMI 2.0 Co-Simulation FMUs that were NOT made by our exporter, built by the
tests themselves, to plug into our scenarios in place of `PdController` (issue 21, "bring your own unit").

- `build_c_pd(dest, variant)`: a quaternion PD controller written by hand in C against the FMI 2.0 headers
  that fmpy ships (tests/foreign/c_pd/c_pd.c) with a hand-written modelDescription
  (tests/foreign/c_pd/modelDescription.xml), compiled with gcc; healthy or broken on purpose (`C_VARIANTS`).
- `build_c3(dest, model)`: FMI 3.0 units written by hand in C against the FMI 3.0 headers that fmpy ships
  (tests/foreign/c3/c3_units.c, modelDescription written here): "C3PdController" (Co-Simulation only, the PD
  law plus Int32/Boolean ports), "C3AxisBody" (Model Exchange only, a one-axis rigid body with a state event
  and a time event) and "C3PdControllerME" (Model Exchange only: the PD law as a continuous-time controller
  with direct feedthrough, no states, no event indicators, no Int32/Boolean ports).
- `build_python_pd(dest)`: the same law as a PythonFMU (tests/foreign/python_pd/PyPdController.py).
- `python_fmu_loadable(path)`: whether this host can run a PythonFMU, with the reason when it cannot.
- `pd_law(...)`: the PD law in numpy, the tests' independent oracle.
- `ForeignUnits(root)`: the same builders with a per-session cache (wrap it in a session fixture).

All the units share PdController's port names and units: inputs q_w..q_z, w_x..w_z (rad/s), q_ref_w..q_ref_z,
w_ref_x..w_ref_z (rad/s, unused); outputs torque_cmd_x/_y/_z (N.m); parameters wn (rad/s), zeta,
inertia_xx/_yy/_zz (kg.m2); defaults wn = 1, zeta = 1, inertia diag(1000, 500, 700). Their value references
are their own (not ours): a master must go by name.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FOREIGN = HERE / "foreign"
C_DIR = FOREIGN / "c_pd"
PY_SCRIPT = FOREIGN / "python_pd" / "PyPdController.py"

C_MODEL = "CPdController"
PY_MODEL = "PyPdController"

# variant -> what it does. "ok" is the healthy unit; the failures happen from FAIL_TIME (default 0.5 s) on.
C_VARIANTS = {
    "ok": "the quaternion PD law, FMI 2.0 CS, same ports and units as PdController",
    "crash": "fmi2DoStep from t >= fail_time writes through a NULL pointer (SIGSEGV, the process dies)",
    "hang": "fmi2DoStep from t >= fail_time never returns (endless loop)",
    "nan": "torque_cmd_* are NaN once the model time >= fail_time (every call returns fmi2OK)",
    "error": "fmi2DoStep from t >= fail_time logs a message and returns fmi2Error",
    "wrong_ports": "outputs tau_x/_y/_z instead of torque_cmd_*, inputs omega_x/_y/_z instead of w_x/_y/_z",
    "j_names": "the nominal inertia parameters are named J1/J2/J3 (not inertia_xx/_yy/_zz); law and ports unchanged",
    "bad_unit": "torque_cmd_* declared in unit 'N' instead of 'N.m'",
    "no_unit": "no unit on any port (w_*, w_ref_*, torque_cmd_*)",
    "no_binary": "the FMU has no binaries/ folder at all (nothing to load on any platform)",
    "me_only": "the modelDescription declares ModelExchange only (no CoSimulation element)",
    "me": ("Model Exchange only and implemented (the binary has the FMI 2.0 Model Exchange functions for 0 "
           "states and 0 event indicators; fmi2Instantiate refuses Co-Simulation): the PD law as a continuous-"
           "time controller"),
}
_FAIL_MODE = {"ok": 0, "crash": 1, "hang": 2, "nan": 3, "error": 4}

# reasons of python_fmu_loadable() that are this host's limits, not bugs of ours (the tests skip on them
# even in CI; any other reason fails there)
HOST_LIMITS = ("libpython", "undefined symbol: Py", "python interpreter")


# ------------------------------------------------------------------------------------------------ oracle

def pd_law(q, w, q_ref, wn=1.0, zeta=1.0, inertia=(1000.0, 500.0, 700.0)) -> np.ndarray:
    """PdController's law with error_law = 0: q_E = conj(q) (x) q_ref, e = 2 q_E,w q_E,v,
    T = wn^2 I e - 2 zeta wn I w (numpy, written independently of the units under test)."""
    q, w, q_ref, inertia = (np.asarray(x, dtype=float) for x in (q, w, q_ref, inertia))
    qc = np.array([q[0], -q[1], -q[2], -q[3]])
    ew = qc[0] * q_ref[0] - qc[1:] @ q_ref[1:]
    ev = qc[0] * q_ref[1:] + q_ref[0] * qc[1:] + np.cross(qc[1:], q_ref[1:])
    return wn ** 2 * inertia * (2.0 * ew * ev) - 2.0 * zeta * wn * inertia * w


# ------------------------------------------------------------------------------------------------ C unit

def fmi_headers_dir() -> Path:
    """The FMI 2.0 headers that fmpy ships (fmi2Functions.h, fmi2FunctionTypes.h, fmi2TypesPlatform.h)."""
    import fmpy
    d = Path(fmpy.__file__).parent / "c-code"
    if not (d / "fmi2Functions.h").is_file():
        raise FileNotFoundError(f"fmpy ships no FMI 2.0 headers in {d}")
    return d


def c_guid(variant: str, fail_time: float) -> str:
    return "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"spacecraft_fmus/tests/foreign/{C_MODEL}/{variant}/{fail_time!r}")


def c_model_description(variant: str = "ok", guid: str | None = None, fail_time: float = 0.5) -> str:
    """The hand-written modelDescription, with the textual changes of `variant`."""
    if variant not in C_VARIANTS:
        raise ValueError(f"unknown variant {variant!r}: one of {', '.join(C_VARIANTS)}")
    xml = (C_DIR / "modelDescription.xml").read_text()
    xml = xml.replace("@GUID@", guid or c_guid(variant, fail_time))

    def sub(pattern, repl, count_expected):
        nonlocal xml
        xml, n = re.subn(pattern, repl, xml)
        assert n == count_expected, (variant, pattern, n)

    if variant == "wrong_ports":
        sub(r'name="torque_cmd_([xyz])"', r'name="tau_\1"', 3)
        sub(r'name="w_([xyz])"', r'name="omega_\1"', 3)
    elif variant == "j_names":
        for i, a in enumerate(("xx", "yy", "zz"), 1):
            sub(f'name="inertia_{a}"', f'name="J{i}"', 1)
    elif variant == "bad_unit":
        sub(r'(name="torque_cmd_[xyz]"[^>]*>\s*<Real) unit="N.m"', r'\1 unit="N"', 3)
        sub(r"(\s*)<Unit name=\"N.m\">", r'\1<Unit name="N">\1  <BaseUnit kg="1" m="1" s="-2"/>\1</Unit>\g<0>', 1)
    elif variant == "no_unit":
        sub(r'(name="(?:w_|w_ref_|torque_cmd_)[xyz]"[^>]*>\s*<Real) unit="[^"]*"', r"\1", 9)
        sub(r'\s*<Unit name="N.m">\s*<BaseUnit[^>]*/>\s*</Unit>', "", 1)
    elif variant in ("me_only", "me"):
        sub(r"<CoSimulation modelIdentifier=\"CPdController\"[^>]*/>",
            '<ModelExchange modelIdentifier="CPdController" canNotUseMemoryManagementFunctions="true"/>', 1)
    return xml


def compile_shared(source: Path, out: Path, defines: list[str], what: str, *, opt: str = "-O2",
                   libs: tuple[str, ...] = ("-lm",)) -> Path:
    """gcc `opt` -shared -fPIC (hidden visibility, gnu11, every warning an error, the FMI headers) of one C
    unit `source` into `out` with the `-D` defines; a failure names `what` with gcc's messages."""
    cmd = ["gcc", opt, "-shared", "-fPIC", "-fvisibility=hidden", "-std=gnu11", "-Wall", "-Wextra", "-Werror",
           f"-I{fmi_headers_dir()}", *defines, "-o", str(out), str(source), *libs]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"gcc failed for {what}:\n{p.stderr}")
    return out


def compile_c_pd(out: Path, variant: str = "ok", guid: str | None = None, fail_time: float = 0.5) -> Path:
    """gcc -O2 -shared -fPIC the C controller into `out` (a .so) with the variant's failure mode."""
    if shutil.which("gcc") is None:
        raise RuntimeError("gcc is needed to build the C foreign unit (scripts/setup.sh installs it)")
    mode = _FAIL_MODE.get(variant, 0)
    return compile_shared(C_DIR / "c_pd.c", out,
                          [f'-DMODEL_GUID="{guid or c_guid(variant, fail_time)}"', f"-DFAIL_MODE={mode}",
                           f"-DFAIL_TIME={float(fail_time)!r}", f"-DMODEL_EXCHANGE={int(variant == 'me')}"],
                          f"the C foreign unit ({variant})")


def build_c_pd(dest, variant: str = "ok", *, fail_time: float = 0.5) -> Path:
    """Build the C PD controller FMU of `variant` (see C_VARIANTS) into the folder `dest` and return its path:
    dest/CPdController.fmu for "ok", dest/CPdController_<variant>.fmu otherwise. The model name and
    modelIdentifier are CPdController in every variant; the GUID differs per variant and fail_time."""
    if variant not in C_VARIANTS:
        raise ValueError(f"unknown variant {variant!r}: one of {', '.join(C_VARIANTS)}")
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    guid = c_guid(variant, fail_time)
    fmu = dest / (f"{C_MODEL}.fmu" if variant == "ok" else f"{C_MODEL}_{variant}.fmu")
    with tempfile.TemporaryDirectory(prefix="cpd_") as tmp:
        files = {"modelDescription.xml": c_model_description(variant, guid, fail_time).encode()}
        if variant != "no_binary":
            so = compile_c_pd(Path(tmp) / f"{C_MODEL}.so", variant, guid, fail_time)
            files[f"binaries/linux64/{C_MODEL}.so"] = so.read_bytes()
        part = fmu.with_suffix(".part")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            for name, data in files.items():
                z.writestr(name, data)
        os.replace(part, fmu)
    return fmu


# ------------------------------------------------------------------------------------------------ FMI 3.0 C units

C3_DIR = FOREIGN / "c3"
C3_MODELS = ("C3PdController", "C3AxisBody", "C3PdControllerME")
C3_PD_MODELS = ("C3PdController", "C3PdControllerME")
_C3_UNITS = """  <UnitDefinitions>
    <Unit name="rad"><BaseUnit rad="1"/></Unit>
    <Unit name="deg"><BaseUnit rad="1" factor="0.017453292519943295"/></Unit>
    <Unit name="s"><BaseUnit s="1"/></Unit>
    <Unit name="rad/s"><BaseUnit s="-1" rad="1"/></Unit>
    <Unit name="kg.m2"><BaseUnit kg="1" m="2"/></Unit>
    <Unit name="N.m"><BaseUnit kg="1" m="2" s="-2"/></Unit>
  </UnitDefinitions>
"""


def _c3_variables(model: str) -> tuple[list[str], list[str]]:
    """(variable elements, ModelStructure elements) of a C3 unit (value references of c3_units.c)."""
    v = ['<Float64 name="time" valueReference="999" causality="independent" variability="continuous"/>']
    if model in C3_PD_MODELS:
        names = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z",
                 "w_ref_x", "w_ref_y", "w_ref_z"]
        for i, n in enumerate(names):
            unit = ' unit="rad/s"' if n.startswith("w") else ""
            start = "1" if n in ("q_w", "q_ref_w") else "0"
            v.append(f'<Float64 name="{n}" valueReference="{i}" causality="input"{unit} start="{start}"/>')
        for i, a in enumerate("xyz"):
            v.append(f'<Float64 name="torque_cmd_{a}" valueReference="{14 + i}" causality="output" unit="N.m"/>')
        v.append('<Float64 name="wn" valueReference="17" causality="parameter" variability="fixed" unit="rad/s" start="1"/>')
        v.append('<Float64 name="zeta" valueReference="18" causality="parameter" variability="fixed" start="1"/>')
        for i, (a, x) in enumerate(zip(("xx", "yy", "zz"), ("1000", "500", "700"))):
            v.append(f'<Float64 name="inertia_{a}" valueReference="{19 + i}" causality="parameter" variability="fixed" '
                     f'unit="kg.m2" start="{x}"/>')
        outs = [14, 15, 16]
        if model == "C3PdController":  # the Model Exchange controller has no Int32/Boolean ports
            v += ['<Boolean name="enable" valueReference="22" causality="input" start="true"/>',
                  '<Int32 name="count_in" valueReference="23" causality="input" start="0"/>',
                  '<Int32 name="step_count" valueReference="24" causality="output"/>',
                  '<Boolean name="active" valueReference="25" causality="output"/>',
                  '<Int32 name="count_echo" valueReference="26" causality="output"/>',
                  '<Boolean name="enable_echo" valueReference="27" causality="output"/>']
            outs += [24, 25, 26, 27]
        structure = [f'<Output valueReference="{r}"/>' for r in outs] + [f'<InitialUnknown valueReference="{r}"/>' for r in outs]
    else:
        v += ['<Float64 name="u" valueReference="0" causality="input" start="0"/>',
              '<Float64 name="torque_dist" valueReference="1" causality="input" unit="N.m" start="0"/>',
              '<Float64 name="theta" valueReference="2" causality="output" unit="rad" initial="exact" start="0"/>',
              '<Float64 name="omega" valueReference="3" causality="output" unit="rad/s" initial="exact" start="0"/>',
              '<Float64 name="applied_torque" valueReference="4" causality="output" unit="N.m"/>',
              '<Float64 name="theta_deg" valueReference="5" causality="output" unit="deg"/>',
              '<Float64 name="inertia" valueReference="6" causality="parameter" variability="fixed" unit="kg.m2" start="7.7"/>',
              '<Float64 name="torque_limit" valueReference="7" causality="parameter" variability="fixed" unit="N.m" start="1"/>',
              '<Float64 name="theta_mark" valueReference="8" causality="parameter" variability="fixed" unit="rad" start="0.1"/>',
              '<Float64 name="kick_time" valueReference="9" causality="parameter" variability="fixed" unit="s" start="-1"/>',
              '<Float64 name="kick_domega" valueReference="10" causality="parameter" variability="fixed" unit="rad/s" start="0"/>',
              '<Float64 name="t_cross" valueReference="11" causality="output" variability="discrete" unit="s"/>',
              '<Float64 name="der(theta)" valueReference="12" causality="local" derivative="2"/>',
              '<Float64 name="der(omega)" valueReference="13" causality="local" derivative="3"/>',
              '<Int32 name="crossings" valueReference="14" causality="output"/>',
              '<Float64 name="z_mark" valueReference="15" causality="local"/>']
        structure = ([f'<Output valueReference="{r}"/>' for r in (2, 3, 4, 5, 11, 14)]
                     + ['<ContinuousStateDerivative valueReference="12"/>', '<ContinuousStateDerivative valueReference="13"/>']
                     + [f'<InitialUnknown valueReference="{r}"/>' for r in (4, 5, 11, 12, 13, 14)]
                     + ['<EventIndicator valueReference="15"/>'])
    return v, structure


def c3_token(model: str) -> str:
    return "{%s}" % uuid.uuid5(uuid.NAMESPACE_URL, f"spacecraft_fmus/tests/foreign/{model}")


def c3_model_description(model: str) -> str:
    if model not in C3_MODELS:
        raise ValueError(f"unknown C3 model {model!r}: one of {C3_MODELS}")
    variables, structure = _c3_variables(model)
    itf = (f'<CoSimulation modelIdentifier="{model}" canHandleVariableCommunicationStepSize="true" '
           f'canBeInstantiatedOnlyOncePerProcess="false"/>' if model == "C3PdController" else
           f'<ModelExchange modelIdentifier="{model}" canBeInstantiatedOnlyOncePerProcess="false" '
           f'needsCompletedIntegratorStep="true"/>')  # C3AxisBody, C3PdControllerME: Model Exchange only
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="3.0" modelName="{model}" instantiationToken="{c3_token(model)}" '
            f'description="written by hand in C (a foreign FMI 3.0 unit for the tests)" '
            f'generationTool="hand-written (tests/foreign/c3)" variableNamingConvention="structured">\n'
            f'  {itf}\n{_C3_UNITS}'
            f'  <LogCategories>\n    <Category name="logStatusError"/>\n  </LogCategories>\n'
            f'  <DefaultExperiment startTime="0" stopTime="10" stepSize="0.01"/>\n'
            f'  <ModelVariables>\n' + "".join(f"    {x}\n" for x in variables) + '  </ModelVariables>\n'
            '  <ModelStructure>\n' + "".join(f"    {x}\n" for x in structure) + '  </ModelStructure>\n'
            '</fmiModelDescription>\n')


def build_c3(dest, model: str) -> Path:
    """Build the FMI 3.0 C unit `model` (C3_MODELS) into dest/<model>.fmu (binary under
    binaries/x86_64-linux, FMI 3.0's platform folder) and return its path."""
    if shutil.which("gcc") is None:
        raise RuntimeError("gcc is needed to build the C foreign units (scripts/setup.sh installs it)")
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    fmu = dest / f"{model}.fmu"
    with tempfile.TemporaryDirectory(prefix="c3_") as tmp:
        so = Path(tmp) / f"{model}.so"
        compile_shared(C3_DIR / "c3_units.c", so,
                       [f"-DMODEL={C3_MODELS.index(model) + 1}", f'-DMODEL_TOKEN="{c3_token(model)}"'], model)
        part = fmu.with_suffix(".part")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", c3_model_description(model))
            z.writestr(f"binaries/x86_64-linux/{model}.so", so.read_bytes())
        os.replace(part, fmu)
    return fmu


# ------------------------------------------------------------------------------------------------ PythonFMU

_UNIT_DEFS = """  <UnitDefinitions>
    <Unit name="rad/s"><BaseUnit s="-1" rad="1"/></Unit>
    <Unit name="kg.m2"><BaseUnit kg="1" m="2"/></Unit>
    <Unit name="N.m"><BaseUnit kg="1" m="2" s="-2"/></Unit>
  </UnitDefinitions>
"""


def _unit_of(name: str) -> str | None:
    if name == "wn":
        return "rad/s"
    if re.fullmatch(r"(w|w_ref)_[xyz]", name):
        return "rad/s"
    if re.fullmatch(r"torque_cmd_[xyz]", name):
        return "N.m"
    if re.fullmatch(r"inertia_(xx|yy|zz)", name):
        return "kg.m2"
    return None


def _add_units(xml: str) -> str:
    """Give PythonFMU's modelDescription (which has no units) PdController's units."""
    def one(m):
        unit = _unit_of(m.group(2))
        return m.group(0) if unit is None else f'{m.group(1)}<Real unit="{unit}"'
    xml, n = re.subn(r'(<ScalarVariable\s[^>]*name="([^"]+)"[^>]*>\s*)<Real', one, xml)
    assert n >= 20, n
    # FMI 2.0 order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ...
    xml, n = re.subn(r"<CoSimulation\s[^>]*/>", lambda m: m.group(0) + "\n" + _UNIT_DEFS.rstrip("\n"), xml, count=1)
    assert n == 1
    return xml


def build_python_pd(dest, *, units: bool = False) -> Path:
    """Build the PythonFMU PD controller into the folder `dest` with `python -m pythonfmu build` and return
    dest/PyPdController.fmu. PythonFMU writes no units: with units=True the modelDescription is rewritten with
    PdController's units (UnitDefinitions + unit attributes), as a user would after exporting."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pypd_") as tmp:
        out = Path(tmp)
        p = subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(PY_SCRIPT), "-d", str(out)],
                           capture_output=True, text=True, cwd=tmp)
        built = out / f"{PY_MODEL}.fmu"
        if p.returncode != 0 or not built.is_file():
            raise RuntimeError(f"pythonfmu build failed (exit {p.returncode}):\n{p.stdout}\n{p.stderr}")
        fmu = dest / (f"{PY_MODEL}.fmu" if not units else f"{PY_MODEL}_units.fmu")
        if units:
            with zipfile.ZipFile(built) as zin, zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as zout:
                for item in zin.infolist():
                    data = zin.read(item)
                    if item.filename == "modelDescription.xml":
                        data = _add_units(data.decode()).encode()
                    zout.writestr(item, data)
        else:
            shutil.copyfile(built, fmu)
    return fmu


# A PythonFMU's binary (libpythonfmu-export.so) does not link libpython: it takes the Python C API (Py_Initialize,
# ...) from the process that loads it. So it runs in a Python process whose interpreter exports that API (a
# shared-libpython build such as pyenv's with --enable-shared, or Debian's python3), not in a plain C/C++ master.
_PROBE = r"""
import sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
path = sys.argv[1]
md = read_model_description(path)
d = extract(path)
fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="probe")
fmu.instantiate()
vr = {v.name: v.valueReference for v in md.modelVariables}
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
fmu.setReal([vr["q_ref_x"], vr["q_ref_w"]], [0.6, 0.8])
fmu.doStep(0.0, 0.1)
t = fmu.getReal([vr["torque_cmd_x"]])[0]
fmu.terminate()
fmu.freeInstance()
print("PROBE-OK", repr(t))
"""


def python_fmu_loadable(path, *, python: str | None = None, timeout: float = 120.0) -> tuple[bool, str]:
    """Try to instantiate, initialise and step the PythonFMU at `path` with fmpy in a subprocess (a failing
    load can kill the process). Returns (True, "") or (False, reason); `is_host_limit(reason)` tells whether
    the reason is this host's (no usable libpython) rather than a bug."""
    python = python or sys.executable
    try:
        p = subprocess.run([python, "-c", _PROBE, str(path)], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"the PythonFMU did not answer within {timeout:g} s"
    out = p.stdout + p.stderr
    m = re.search(r"PROBE-OK (\S+)", p.stdout)
    if p.returncode == 0 and m:
        expected = pd_law([1, 0, 0, 0], [0, 0, 0], [0.8, 0.6, 0, 0])[0]
        got = float(m.group(1))
        if abs(got - expected) > 1e-9 * abs(expected):
            return False, f"the PythonFMU loads but computes torque_cmd_x = {got}, expected {expected}"
        return True, ""
    if p.returncode < 0:
        return False, f"loading the PythonFMU killed the process (signal {-p.returncode}): {out.strip()[-400:]}"
    m = re.search(r"(libpython[\w.]*\.so[\w.]*): cannot open shared object file", out)
    if m:
        return False, f"{m.group(1)} not found (the PythonFMU binary needs a shared libpython)"
    m = re.search(r"undefined symbol: (Py\w+)", out)
    if m:
        return False, (f"undefined symbol: {m.group(1)}: the loading process does not export the Python C API "
                       f"(libpython not linked in; PythonFMU needs a Python interpreter in the process)")
    last = [line for line in out.strip().splitlines() if line.strip()][-3:]
    return False, f"the PythonFMU could not be run (exit {p.returncode}): " + " | ".join(last)


def is_host_limit(reason: str) -> bool:
    """Whether a python_fmu_loadable() reason is the host's (no usable libpython) rather than a bug of ours."""
    return any(k in reason for k in HOST_LIMITS)


def python_info(python: str | None = None) -> dict:
    """The interpreter facts that decide whether a PythonFMU can load (Py_ENABLE_SHARED, LDLIBRARY, LIBDIR)."""
    code = ("import sys, sysconfig, json; g = sysconfig.get_config_var; print(json.dumps({'version': sys.version"
            ".split()[0], 'executable': sys.executable, 'Py_ENABLE_SHARED': g('Py_ENABLE_SHARED'), "
            "'LDLIBRARY': g('LDLIBRARY'), 'INSTSONAME': g('INSTSONAME'), 'LIBDIR': g('LIBDIR')}))")
    import json
    p = subprocess.run([python or sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(p.stdout)


# ------------------------------------------------------------------------------------------------ cache

class ForeignUnits:
    """The builders with a cache: each unit is built once into `root` (a session's tmp folder), e.g.

        @pytest.fixture(scope="session")
        def foreign(tmp_path_factory):
            return foreign_units.ForeignUnits(tmp_path_factory.mktemp("foreign"))
    """

    def __init__(self, root):
        self.root = Path(root)
        self._cache: dict = {}

    def _get(self, key, build):
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def c_pd(self, variant: str = "ok", fail_time: float = 0.5) -> Path:
        return self._get(("c", variant, fail_time),
                         lambda: build_c_pd(self.root / f"c_{fail_time!r}", variant, fail_time=fail_time))

    def c3(self, model: str) -> Path:
        return self._get(("c3", model), lambda: build_c3(self.root / "c3", model))

    def python_pd(self, units: bool = False) -> Path:
        return self._get(("py", units), lambda: build_python_pd(self.root / "py", units=units))

    def python_loadable(self, units: bool = False) -> tuple[bool, str]:
        return self._get(("py-loadable", units), lambda: python_fmu_loadable(self.python_pd(units)))
