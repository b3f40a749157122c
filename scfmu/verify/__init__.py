"""Reference results inside the FMUs (FMI layered standard ``fmi-ls-ref``) and ``scfmu verify``.

Every FMU carries, under ``extra/org.fmi-standard.fmi-ls-ref/``:

* ``fmi-ls-manifest.xml``: the layered-standard manifest (``fmiReferences``, one ``Related`` element per
  file below, with its MIME type and role);
* ``<Model>_ref.csv`` (role ``result``): the outputs of our own run of the reference experiment;
* ``<Model>_ref.opt`` (role ``experiment``): the experiment (start, stop, communication step) and the
  tolerances a replay is judged by;
* ``<Model>_in.csv`` (role ``experiment``, units with inputs only): the input signals of the experiment;
* ``<Model>_ref.ssv`` (role ``parameter``, SSP parameter set; only the units in ``REF_PARAMS``, whose
  outputs are all constant with the defaults): parameter values the experiment sets.

and ``documentation/fmi-ls-ref.txt`` says the same in words.

**The reference experiment** is the FMU's default experiment (start and stop time) run as Co-Simulation
with a communication step of the default step times m, the smallest whole m that keeps it to at most
``MAX_ROWS`` steps (so a 300 s run at 1 ms is recorded every 0.3 s; a sampled unit then takes m samples
per step with its inputs held). Parameters keep their start values, except ``REF_PARAMS``. Inputs (units with inputs, which
includes every controller, so their outputs move) are given at every communication point as

* each quaternion input group ``<p>_w, <p>_x, <p>_y, <p>_z``: the unit quaternion of a rotation by
  0.3 sin(0.2 t + 0.5 j) rad about (1, 2, 2)/3 (j = the group's index);
* every other Real input number i (in modelDescription order): 0.1 sin((0.5 + 0.1 i) t + 0.3 i) + 0.01 i,
  plus the unit's offset in ``REF_INPUT_OFFSETS`` where the signal alone is not a valid input (a position
  that must lie outside the Earth), except an atmospheric density ``rho`` (kg/m3, the Orbit unit's), which is
  thin and non-negative: 1e-12 (1.1 + sin((0.5 + 0.1 i) t + 0.3 i)).

The rows of ``<Model>_in.csv`` are exactly those values at the communication points, so an importer that
interpolates the table linearly applies them unchanged. Row k of ``<Model>_ref.csv`` holds the outputs at
t_k: the outputs after initialization (k = 0), then after doStep(t_(k-1), h) with the inputs of row k-1
held over the step — what fmpy's ``simulate_fmu``, fmusim and fmi-rs record.

**Verify.** :func:`verify` replays the experiment in an importer (``fmpy``: fmpy's ``simulate_fmu``;
``fmusim``: an fmusim-compatible command line, ``fmusim`` on PATH or ``SCFMU_FMUSIM``) and reports, per
output, the largest deviation |y − y_ref| and its allowance ``AbsTol + RelTol · max|y_ref|``; it fails
when any deviation exceeds its allowance (or the replay fails).
"""

from __future__ import annotations

import csv
import io
import math
import os
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

REF_DIR = "extra/org.fmi-standard.fmi-ls-ref"
DOC_FILE = "documentation/fmi-ls-ref.txt"
MANIFEST = f"{REF_DIR}/fmi-ls-manifest.xml"
LS_NS = "http://fmi-standard.org/fmi-ls-manifest"
LS_VERSION = "1.0.0-alpha.1"
LS_DESCRIPTION = "Layered Standard providing information on related files included in an FMU."
# at most MAX_ROWS rows; a loop FMU's scenario of more than LONG_RUN_STEPS steps: its first MAX_ROWS steps
MAX_ROWS, LONG_RUN_STEPS = 1000, 500_000
# Parameter values of the reference experiment where the defaults leave every output constant (a command
# with a zero step, a sun sensor whose sun is outside its field of view): written as <Model>_ref.ssv
REF_PARAMS = {
    "AttitudeCommand": {"ref_euler321_roll": 0.3, "ref_euler321_pitch": -0.2, "ref_euler321_yaw": 0.5, "step_time": 1.0},
    "RelativePositionCommand": {"target_pos_x": 10.0, "target_pos_y": -5.0, "target_pos_z": 2.0, "step_time": 10.0},
    "ReferenceCorrector": {"mode": 1, "init_euler321_roll": 0.3, "init_w_x": 0.02, "node_x_1": 0.01, "node_y_2": -0.01, "node_x_4": 0.005},
    "SunSensor": {"fov": math.pi, "shadow": 0},
}
# an input of this name is an atmospheric density (kg/m3): the documented signal keeps it in orbit's range
DENSITY_INPUT = "rho"
# Offsets to input signals a unit would refuse. Environment: 500 km above the equator (|r| < Earth's radius
# refused); ModeManager: variances around 0.2 rad²; CommandSwitch: safe torque and B-dot dipole (codes 1)
REF_INPUT_OFFSETS = {"Environment": {"r_x": 6_878_137.0}, "ModeManager": {f"p_att_{a}": 0.2 for a in "xyz"},
                     "CommandSwitch": {"torque_select": 1.0, "dipole_select": 1.0}}
REL_TOL, ABS_TOL = 1e-6, 1e-12
IMPORTERS = ("fmpy", "fmusim")
# fixed entry metadata: the injected files are byte-identical from build to build
_DATE = (1980, 1, 1, 0, 0, 0)


class VerifyError(Exception):
    """A replay that could not run, or an FMU without reference results (one-line message)."""


@dataclass
class Experiment:
    start: float
    stop: float
    step: float
    rel_tol: float = REL_TOL
    abs_tol: float = ABS_TOL
    params: dict = None
    inputs: bool = True  # whether the experiment gives the documented input signals (False: loop FMUs)

    def points(self) -> np.ndarray:
        n = int(round((self.stop - self.start) / self.step))
        return self.start + np.arange(n + 1) * self.step

    def opt_text(self) -> str:
        return (f"StartTime, {self.start!r}\nStopTime, {self.stop!r}\nStepSize, {self.step!r}\n"
                f"RelTol, {self.rel_tol!r}\nAbsTol, {self.abs_tol!r}\n")

    @classmethod
    def parse(cls, text: str) -> "Experiment":
        kv = {k.strip(): float(v) for k, v in (line.split(",", 1) for line in text.splitlines() if "," in line)}
        try:
            return cls(kv["StartTime"], kv["StopTime"], kv["StepSize"], kv.get("RelTol", REL_TOL), kv.get("AbsTol", ABS_TOL))
        except KeyError as e:
            raise VerifyError(f"reference options: no {e.args[0]}") from None


def _md(path: Path):
    from fmpy import read_model_description
    return read_model_description(str(path))


def reference_experiment(md, inputs: bool = True) -> Experiment:
    de = md.defaultExperiment
    start = float(de.startTime or 0.0) if de else 0.0
    stop = float(de.stopTime) if de and de.stopTime is not None else 1.0
    base = float(de.stepSize) if de and de.stepSize else (stop - start) / 100
    n, params = round((stop - start) / base), dict(REF_PARAMS.get(md.coSimulation.modelIdentifier, {}))
    if not inputs and n > LONG_RUN_STEPS:  # a loop FMU of a long scenario (a day of leo/nadir): its first steps
        return Experiment(start, start + round(base * MAX_ROWS, 12), base, params=params, inputs=inputs)
    m0 = max(1, math.ceil(n / MAX_ROWS))  # m steps per row, m dividing n: fmi-rs refuses an interval that does not
    m = next(k for k in range(m0, n + 1) if n % k == 0)
    return Experiment(start, stop, base * m if m == m0 else round(base * m, 12), params=params, inputs=inputs)


def _real_type(md) -> str:
    return "Float64" if md.fmiVersion.startswith("3") else "Real"


def input_names(md) -> list[str]:
    return [v.name for v in md.modelVariables if v.causality == "input" and v.type == _real_type(md)]


def output_names(md) -> list[str]:
    return [v.name for v in md.modelVariables if v.causality == "output" and v.type == _real_type(md)]


def input_signals(names: list[str], t: np.ndarray, model: str = "") -> np.ndarray:
    """The documented input sequence (module docstring) of ``model`` at the times t: one column per input."""
    cols = {}
    groups = [n[:-2] for n in names if n.endswith("_w") and all(f"{n[:-2]}_{c}" in names for c in "xyz")]
    for j, g in enumerate(groups):
        a = 0.3 * np.sin(0.2 * t + 0.5 * j)
        cols[f"{g}_w"] = np.cos(a / 2)
        for c, ax in zip("xyz", (1 / 3, 2 / 3, 2 / 3)):
            cols[f"{g}_{c}"] = np.sin(a / 2) * ax
    i = 0
    for n in names:
        if n not in cols:
            wave = np.sin((0.5 + 0.1 * i) * t + 0.3 * i)
            cols[n] = (1e-12 * (1.1 + wave) if n == DENSITY_INPUT
                       else 0.1 * wave + 0.01 * i + REF_INPUT_OFFSETS.get(model, {}).get(n, 0.0))
            i += 1
    return np.column_stack([cols[n] for n in names]) if names else np.zeros((len(t), 0))


def _csv_text(names: list[str], rows: np.ndarray) -> str:
    out = io.StringIO()
    out.write(",".join(f'"{n}"' for n in names) + "\n")
    for r in rows:
        out.write(",".join(repr(float(x)) for x in r) + "\n")
    return out.getvalue()


def read_csv_text(text: str) -> tuple[list[str], np.ndarray]:
    rd = csv.reader(io.StringIO(text))
    head = [h.strip().strip('"') for h in next(rd)]
    rows = [[float(x) for x in r] for r in rd if r]
    return head, np.array(rows, dtype=float).reshape(len(rows), len(head))


# ----- running the experiment ------------------------------------------------------------------------
def _run_fmpy(fmu: Path, md, exp: Experiment, ins: list[str], outs: list[str]) -> np.ndarray:
    from fmpy import simulate_fmu
    t = exp.points()
    kw = {}
    if ins:
        u = input_signals(ins, t, md.coSimulation.modelIdentifier)
        dtype = [("time", np.float64)] + [(n, np.float64) for n in ins]
        table = np.array([tuple([tk, *row]) for tk, row in zip(t, u)], dtype=dtype)
        kw["input"] = table
    res = simulate_fmu(str(fmu), fmi_type="CoSimulation", start_time=exp.start, stop_time=exp.stop,
                       output_interval=exp.step, output=outs, start_values=dict(exp.params or {}), **kw)
    return np.column_stack([res["time"]] + [res[n] for n in outs])


def _run_fmusim(fmu: Path, md, exp: Experiment, ins: list[str], outs: list[str], exe: str) -> np.ndarray:
    from ..fmu import scratch
    work = Path(scratch.mkdtemp(prefix="scfmu_verify_"))
    try:
        cmd = [exe, "--interface-type", "cs", "--start-time", repr(exp.start), "--stop-time", repr(exp.stop),
               "--output-interval", repr(exp.step), "--output-file", str(work / "out.csv")]
        if ins:
            t = exp.points()
            (work / "in.csv").write_text(_csv_text(["time", *ins], np.column_stack([t, input_signals(ins, t, md.coSimulation.modelIdentifier)])))
            cmd += ["--input-file", str(work / "in.csv")]
        for k, v in (exp.params or {}).items():
            cmd += ["--start-value", k, repr(v)]
        cmd.append(str(fmu))
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if p.returncode != 0:
            tail = (p.stderr or p.stdout).strip().splitlines()[-1:] or [""]
            raise VerifyError(f"{exe} exited with {p.returncode}: {tail[0]}")
        head, data = read_csv_text((work / "out.csv").read_text())
        missing = [n for n in ["time", *outs] if n not in head]
        if missing:
            raise VerifyError(f"{exe}: output file has no column {missing[0]}")
        return data[:, [head.index(n) for n in ["time", *outs]]]
    finally:
        shutil.rmtree(work, ignore_errors=True)


def fmusim_exe() -> str | None:
    return os.environ.get("SCFMU_FMUSIM") or shutil.which("fmusim")


def run_experiment(fmu: Path, exp: Experiment, importer: str = "fmpy") -> tuple[list[str], np.ndarray]:
    """(["time", outputs…], rows) of the reference experiment run in ``importer``."""
    md = _md(fmu)
    ins, outs = (input_names(md) if exp.inputs else []), output_names(md)
    if importer == "fmpy":
        data = _run_fmpy(fmu, md, exp, ins, outs)
    elif importer == "fmusim":
        exe = fmusim_exe()
        if not exe:
            raise VerifyError("importer fmusim: no fmusim on PATH (set SCFMU_FMUSIM to an fmusim-compatible command)")
        data = _run_fmusim(fmu, md, exp, ins, outs, exe)
    else:
        raise VerifyError(f"importer {importer!r}: expected one of {', '.join(IMPORTERS)}")
    return ["time", *outs], data


# ----- writing the files into the FMU -------------------------------------------------------------------
def _manifest(model: str, has_inputs: bool, has_params: bool = False) -> bytes:
    ET.register_namespace("fmi-ls", LS_NS)
    root = ET.Element("fmiReferences", {f"{{{LS_NS}}}fmi-ls-name": "org.fmi-standard.fmi-ls-ref",
                                        f"{{{LS_NS}}}fmi-ls-version": LS_VERSION,
                                        f"{{{LS_NS}}}fmi-ls-description": LS_DESCRIPTION})
    ET.SubElement(root, "Related", {"type": "text/csv", "source": f"{model}_ref.csv", "role": "result",
                                    "description": "Outputs of the exporter's own run of the reference experiment"})
    ET.SubElement(root, "Related", {"type": "text/plain", "source": f"{model}_ref.opt", "role": "experiment",
                                    "description": "Reference experiment: StartTime, StopTime, StepSize (communication "
                                                   "step) and the tolerances RelTol, AbsTol a replay is judged by"})
    if has_inputs:
        ET.SubElement(root, "Related", {"type": "text/csv", "source": f"{model}_in.csv", "role": "experiment",
                                        "description": "Input signals of the reference experiment, at every communication point"})
    if has_params:
        ET.SubElement(root, "Related", {"type": "application/x-ssp-parameter-set", "source": f"{model}_ref.ssv",
                                        "role": "parameter", "description": "Parameter values of the reference experiment"})
    ET.SubElement(root, "Related", {"type": "text/plain", "source": f"../../{DOC_FILE}", "role": "document",
                                    "description": "How the reference results were made and how to replay them"})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def _doc(model: str, exp: Experiment, ins: list[str]) -> str:
    text = (f"Reference results of {model} (FMI layered standard fmi-ls-ref, files in {REF_DIR}/).\n\n"
            f"Experiment: Co-Simulation from {exp.start!r} s to {exp.stop!r} s with a communication step of "
            f"{exp.step!r} s, every parameter at its start value"
            + (f" except those in {model}_ref.ssv ({', '.join(f'{k} = {v!r}' for k, v in exp.params.items())})" if exp.params else "")
            + ".\n")
    if ins:
        text += (f"Inputs ({model}_in.csv): given at every communication point and held over the step; quaternion "
                 "groups <p>_w.._z turn by 0.3 sin(0.2 t + 0.5 j) rad about (1, 2, 2)/3, every other input i is "
                 "0.1 sin((0.5 + 0.1 i) t + 0.3 i) + 0.01 i"
                 + "".join(f", {k} plus {v!r}" for k, v in REF_INPUT_OFFSETS.get(model, {}).items())
                 + (f", except the density {DENSITY_INPUT}: 1e-12 (1.1 + sin((0.5 + 0.1 i) t + 0.3 i))" if DENSITY_INPUT in ins else "")
                 + ".\n")
    elif not exp.inputs:
        text += "Inputs: none given (the FMU runs as it is; a loop FMU runs its scenario).\n"
    text += (f"Results ({model}_ref.csv): the outputs at every communication point, row 0 after initialization, row k "
             "after doStep(t_(k-1), h). Made by the exporter with fmpy's simulate_fmu on x86-64 Linux.\n"
             f"A replay agrees when every output y satisfies max |y - y_ref| <= AbsTol + RelTol max |y_ref| "
             f"(RelTol = {exp.rel_tol!r}, AbsTol = {exp.abs_tol!r}; {model}_ref.opt). Replay: scfmu verify {model}.fmu "
             "[--importer fmpy|fmusim].\n")
    return text


def reference_files(fmu: Path, inputs: bool = True) -> dict[str, bytes]:
    """The fmi-ls-ref files of ``fmu`` (archive path → bytes), from a run of its reference experiment in fmpy
    (``inputs=False``: no input is given, the FMU runs as it is, e.g. a loop FMU's scenario)."""
    md = _md(fmu)
    model = md.coSimulation.modelIdentifier
    exp = reference_experiment(md, inputs)
    ins = input_names(md) if inputs else []
    names, data = run_experiment(fmu, exp, "fmpy")
    files = {f"{REF_DIR}/{model}_ref.csv": _csv_text(names, data).encode(),
             f"{REF_DIR}/{model}_ref.opt": exp.opt_text().encode(),
             MANIFEST: _manifest(model, bool(ins), bool(exp.params)),
             DOC_FILE: _doc(model, exp, ins).encode()}
    if exp.params:
        from ..scenario.ssp import _ssv
        as_ssv = {"Float64": "Real", "Int32": "Integer", "Boolean": "Boolean"}
        types = {v.name: as_ssv.get(v.type, v.type) for v in md.modelVariables}
        files[f"{REF_DIR}/{model}_ref.ssv"] = _ssv([(k, types[k], v) for k, v in exp.params.items()], f"{model}_ref")
    if ins:
        t = exp.points()
        files[f"{REF_DIR}/{model}_in.csv"] = _csv_text(["time", *ins], np.column_stack([t, input_signals(ins, t, model)])).encode()
    return files


def inject(fmu: Path, files: dict[str, bytes]) -> None:
    """Rewrites the archive ``fmu`` with ``files`` added (replacing earlier versions of them and any other
    file under the reference folder); the other entries keep their bytes, order and metadata."""
    fmu = Path(fmu)
    tmp = fmu.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w") as dst:
        for info in src.infolist():
            if info.filename in files or info.filename.startswith(REF_DIR + "/"):
                continue
            dst.writestr(info, src.read(info.filename), compress_type=info.compress_type)
        for name in sorted(files):
            zi = zipfile.ZipInfo(name, date_time=_DATE)
            zi.compress_type = zipfile.ZIP_DEFLATED
            zi.external_attr = 0o644 << 16
            dst.writestr(zi, files[name])
    tmp.replace(fmu)


def write_references(fmus: list[Path], log=print, inputs: bool = True) -> None:
    for f in fmus:
        files = reference_files(Path(f), inputs)
        inject(Path(f), files)
        log(f"reference results: {f} ({len(files)} files)")


# ----- verifying ---------------------------------------------------------------------------------------
@dataclass
class Deviation:
    name: str
    max_dev: float
    allowed: float

    @property
    def ok(self) -> bool:
        return self.max_dev <= self.allowed


def read_references(fmu: Path) -> tuple[Experiment, list[str], np.ndarray]:
    with zipfile.ZipFile(fmu) as z:
        names = set(z.namelist())
        if MANIFEST not in names:
            raise VerifyError(f"{fmu}: no reference results ({MANIFEST} missing)")
        root = ET.fromstring(z.read(MANIFEST))
        rel = {r.get("source"): r for r in root.findall("Related")}
        res = [s for s, r in rel.items() if r.get("role") == "result"]
        opt = [s for s in rel if s.endswith(".opt")]
        if not res or not opt:
            raise VerifyError(f"{fmu}: the manifest names no result or no options file")
        exp = Experiment.parse(z.read(f"{REF_DIR}/{opt[0]}").decode())
        exp.inputs = any(src.endswith("_in.csv") for src in rel)
        exp.params = {}
        for src in (s for s, r in rel.items() if r.get("role") == "parameter"):
            ps = ET.fromstring(z.read(f"{REF_DIR}/{src}"))
            for prm in ps.iter("{http://ssp-standard.org/SSP1/SystemStructureParameterValues}Parameter"):
                val = next(iter(prm))
                text = val.get("value")
                exp.params[prm.get("name")] = float(text) if val.tag.endswith("Real") else int(text)
        head, data = read_csv_text(z.read(f"{REF_DIR}/{res[0]}").decode())
    return exp, head, data


def verify(fmu: Path, importer: str = "fmpy") -> list[Deviation]:
    """Replays the reference experiment of ``fmu`` in ``importer``; the largest deviation per output."""
    fmu = Path(fmu)
    exp, head, ref = read_references(fmu)
    names, out = run_experiment(fmu, exp, importer)
    if out.shape[0] != ref.shape[0]:
        raise VerifyError(f"{importer} gave {out.shape[0]} rows, the reference has {ref.shape[0]}")
    devs = [Deviation("time", float(np.max(np.abs(out[:, 0] - ref[:, 0]))), 1e-9 * max(1.0, abs(exp.stop)))]
    for j, n in enumerate(head[1:], start=1):
        if n not in names:
            raise VerifyError(f"{importer} did not record output {n}")
        y, yr = out[:, names.index(n)], ref[:, j]
        dev = float(np.max(np.abs(y - yr))) if np.all(np.isfinite(y)) else math.inf
        devs.append(Deviation(n, dev, exp.abs_tol + exp.rel_tol * float(np.max(np.abs(yr)))))
    return devs


def _fmu_problem(text: str) -> Path | str:
    """The FMU file a command-line argument names (a path to an .fmu, or a model name of the package), or the
    one line saying why it names none: no such file, a folder, an unknown model (with the closest name), or a
    file that is not a readable zip archive (truncated, damaged, another kind of file)."""
    from ..fmu import UnknownModel, fmu_path
    p = Path(text).expanduser()
    if not p.exists() and not text.lower().endswith(".fmu") and "/" not in text:
        try:
            p = fmu_path(text)
        except UnknownModel as e:
            return str(e)
    if p.is_dir():
        return f"FMU {text!r} is a directory; allowed: an .fmu file or a model name"
    if not p.is_file():
        return f"FMU {text!r}: no such file; allowed: an .fmu file or a model name"
    try:
        with zipfile.ZipFile(p) as z:
            bad = z.testzip()
    except (zipfile.BadZipFile, OSError, EOFError) as e:
        return f"FMU {text!r} is not an FMU archive ({e}: truncated, or another kind of file)"
    if bad is not None:
        return f"FMU {text!r} is damaged: entry {bad!r} fails its CRC check (a truncated or corrupted copy)"
    return p


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="scfmu verify", description="Replay the reference results an FMU carries "
                                 "(fmi-ls-ref) in an importer and report the largest deviation per output; exit 1 "
                                 "when one exceeds the tolerance in the FMU's options file.")
    ap.add_argument("fmus", nargs="+", metavar="FMU", help="FMU files (or model names of the package's FMUs)")
    ap.add_argument("--importer", default="fmpy", help=f"one of {', '.join(IMPORTERS)} (default fmpy)")
    ap.add_argument("--write", action="store_true", help="(build step) run the reference experiment in fmpy and "
                    "write the reference files into each FMU")
    ap.add_argument("--no-inputs", action="store_true", help="with --write: give no inputs (loop FMUs run their "
                    "scenario as it is)")
    a = ap.parse_args(argv)
    if a.importer not in IMPORTERS:
        print(f"scfmu verify: --importer {a.importer!r}: expected one of {', '.join(IMPORTERS)}", file=sys.stderr)
        return 2
    paths = []
    for f in a.fmus:
        problem = _fmu_problem(f)
        if isinstance(problem, str):
            print(f"scfmu verify: {problem}", file=sys.stderr)
            return 2
        paths.append(problem)
    if a.write:
        write_references(paths, inputs=not a.no_inputs)
        return 0
    failed = False
    for p in paths:
        try:
            devs = verify(p, a.importer)
        except VerifyError as e:
            print(f"{p}: FAILED: {e}")
            failed = True
            continue
        bad = [d for d in devs if not d.ok]
        print(f"{p} [{a.importer}]: {'OK' if not bad else 'FAILED'} ({len(devs) - 1} outputs)")
        for d in devs:
            print(f"  {d.name:24s} max |dev| = {d.max_dev:.3e}  allowed {d.allowed:.3e}{'' if d.ok else '  <-- beyond'}")
        failed |= bool(bad)
    return 1 if failed else 0
