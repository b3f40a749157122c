"""What a new user met in the first hour, fixed (issue 42, item 5). Each test runs the command as the user runs
it (``python -m scfmu ...`` in a subprocess) unless it checks a file:

a. the benchmark's optional imports (python-control for the stability margins) come with the extra its
   messages name (``campaigns``), and without it the benchmark refuses in one line naming the extra;
b. ``--map controller.J1=inertia_xx`` (the form the benchmark's warning prints) and ``--map J1=inertia_xx`` bind
   the same; an unknown name or a map that binds nothing is refused by name;
c. ``scfmu benchmark|campaign|report --help`` need no extra (no import of dask, pyswarms, control, …);
d. ``scfmu check NAME`` takes a shipped model's name as ``scfmu verify NAME`` does;
e. a missing file, a truncated or garbage .fmu, a misspelled name and a bad option value end in one line and
   exit status 2 in every subcommand;
f. Ctrl-C on ``scfmu check`` leaves no child process behind;
g. Ctrl-C while a campaign's Dask cluster starts: exit 130, one line, no traceback;
h. the number of FMUs the docs name is the number of FMUs there are.
"""

from __future__ import annotations

import ast
import os
import re
import signal
import subprocess
import sys
import time
import tomllib
import zipfile
from importlib import metadata
from pathlib import Path

import pytest

from scfmu import cli
from scfmu.fmu import fmu_dir

from cli_run import refused, scfmu  # tests/ is on the path (pyproject.toml)

ROOT = Path(__file__).resolve().parents[1]


BLOCKER = '''
import sys
class _Blocker:
    """An installation without these modules; every attempt to import one is written to stderr."""
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {MODULES!r}:
            sys.stderr.write(f"BLOCKED IMPORT {{name}}\\n")
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None
sys.meta_path.insert(0, _Blocker())
'''


def blocked_env(tmp_path: Path, modules) -> dict:
    (tmp_path / "sitecustomize.py").write_text(BLOCKER.format(MODULES=set(modules)))
    env = {"PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    probe = subprocess.run([sys.executable, "-c", f"import {sorted(modules)[0]}"], capture_output=True, text=True,
                           env=dict(os.environ, **env))
    assert probe.returncode != 0 and "BLOCKED IMPORT" in probe.stderr  # the blocker works
    return env


# ----- a. the benchmark's extra ---------------------------------------------------------------------------------
def _module_file(name: str) -> Path | None:
    p = ROOT / Path(*name.split("."))
    for f in (p / "__init__.py", p.with_suffix(".py")):
        if f.is_file():
            return f
    return None


def imports_of(start: str) -> dict:
    """{top-level module outside scfmu and the standard library: [scfmu modules importing it]} over every
    scfmu module ``start`` imports, directly or through others, at the top or inside functions (ast)."""
    seen, ext, todo = set(), {}, [start]
    while todo:
        m = todo.pop()
        f = _module_file(m)
        if m in seen or f is None:
            continue
        seen.add(m)
        pkg = m if f.name == "__init__.py" else m.rpartition(".")[0]
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = pkg.split(".")
                    base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
                names = [base] + [f"{base}.{a.name}" for a in node.names]
            else:
                continue
            for n in names:
                if n.split(".")[0] == "scfmu":
                    todo.append(n)
                elif n.split(".")[0] not in sys.stdlib_module_names and n != "__future__":
                    ext.setdefault(n.split(".")[0], set()).add(m)
    return ext


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def extra_requirements(extra: str | None) -> set:
    """Normalized distribution names the core dependencies plus ``extra`` (with the extras it includes) install."""
    from packaging.requirements import Requirement
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    out = {_norm(Requirement(r).name) for r in project["dependencies"]}
    todo = [extra] if extra else []
    while todo:
        for r in map(Requirement, project["optional-dependencies"][todo.pop()]):
            if _norm(r.name) == "scfmu":
                todo += sorted(r.extras)
            else:
                out.add(_norm(r.name))
    return out


# modules the benchmark's import graph reaches that the benchmark never calls: (module importing it, extra)
NOT_FOR_THE_BENCHMARK = {"pandas": ("scfmu.engines", "pandas")}  # Result.to_pandas()


def test_every_module_the_benchmark_imports_comes_with_the_extra_it_names():
    extra, modules = cli.NEEDS["benchmark"]
    assert extra == "campaigns"
    have = extra_requirements(extra)
    dists = metadata.packages_distributions()
    found = imports_of("scfmu.benchmark.cli")
    assert "control" in found and "dask" in found  # the graph walk sees the lazy imports
    for mod, where in sorted(found.items()):
        if mod in NOT_FOR_THE_BENCHMARK:
            importer, other = NOT_FOR_THE_BENCHMARK[mod]
            assert where == {importer} and _norm(dists[mod][0]) in extra_requirements(other), (mod, where)
            continue
        dist = _norm(dists[mod][0])
        assert dist in have, f"{mod} (imported by {sorted(where)}) is not installed by scfmu[{extra}]"
        if dist not in extra_requirements(None):  # an optional module: checked before the benchmark starts
            assert mod in modules or mod == "distributed", (mod, modules)
    # and every module a message names as part of an extra comes with that extra
    for name, mods in cli.EXTRAS.items():
        for mod in mods:
            if mod != "libcosim":  # libcosimpy's import name
                assert _norm(dists[mod][0]) in extra_requirements(name), (name, mod)
    # the hardening table names that extra for the benchmark
    assert "`scfmu campaign`/`benchmark`/`report` without the `campaigns` extra" in (ROOT / "docs" / "hardening.md").read_text()


def test_the_benchmark_without_python_control_names_the_extra(tmp_path):
    env = blocked_env(tmp_path, ["control"])
    line = refused(scfmu("benchmark", "--cases", "default", "--out", tmp_path / "b", env=env))
    assert line == "scfmu benchmark needs the 'campaigns' extra (control is not installed): pip install 'scfmu[campaigns]'"
    assert not (tmp_path / "b").exists()


def test_the_benchmark_api_without_python_control_refuses_before_any_run(tmp_path, monkeypatch):
    from scfmu import benchmark
    monkeypatch.setitem(sys.modules, "control", None)  # `import control` raises ImportError
    with pytest.raises(ModuleNotFoundError, match=r"python-control: pip install 'scfmu\[campaigns\]'") as e:
        benchmark.run(None, "attitude", tmp_path / "b", cases=["default"], client=object())
    assert e.value.name == "control"
    assert not (tmp_path / "b").exists()  # refused before anything ran, no "not linearised" row


# ----- b. one --map syntax in the benchmark -----------------------------------------------------------------------
CASE = "paper003/SMC/N"


@pytest.fixture(scope="module")
def j_unit(tmp_path_factory) -> str:
    """The tests' C PD controller whose nominal inertia parameters are called J1, J2, J3 (test_byo_binding.py)."""
    import foreign_units as fu
    return str(fu.ForeignUnits(tmp_path_factory.mktemp("foreign")).c_pd("j_names"))


def test_benchmark_map_takes_the_qualified_and_the_bare_form_alike(j_unit):
    from scfmu.benchmark import selected_cases, unit_scenario
    from scfmu.benchmark.options import unit_options
    from scfmu.scenario import get
    from scfmu.scenario.resolve import resolve, unbound_slots
    cases = selected_cases("attitude", [CASE])
    params, maps = unit_options(j_unit, cases, {"controller.wn": 1.0},
                                {"controller.J1": "inertia_xx", "J2": "inertia_yy", "controller.J3": "inertia_zz"})
    assert params == {"wn": 1.0} and maps == {"J1": "inertia_xx", "J2": "inertia_yy", "J3": "inertia_zz"}
    sc = unit_scenario(get(CASE), cases[0], j_unit, params, maps)
    assert resolve(sc).component("controller").params["J1"] == 4.0  # the place's inertia_xx on 003-N
    assert {"J2": 5.0, "J3": 3.5}.items() <= resolve(sc).component("controller").params.items()
    left = {u.slot for u in unbound_slots(sc, ["controller"])}
    assert not left & {"inertia_xx", "inertia_yy", "inertia_zz"}, left


def test_benchmark_map_in_the_form_its_warning_prints_binds_the_unit(j_unit, tmp_path):
    r = scfmu("benchmark", j_unit, "--label", "CJ", "--controllers", "PdController", "--cases", CASE, "--workers", "1",
              "--map", "controller.J1=inertia_xx", "--map", "controller.J2=inertia_yy", "--map", "controller.J3=inertia_zz",
              "--out", tmp_path / "b", timeout=900)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "inertia_xx = 4 not passed" not in r.stderr, r.stderr
    import csv
    rows = {x["controller"]: x for x in csv.DictReader(open(tmp_path / "b" / "results.csv"))}
    mine, pd = rows["CJ"], rows["PD, quaternion error"]
    assert mine["status"] == "" and "inertia_xx" not in mine["unbound slot values"], mine
    ise = [k for k in mine if k.startswith("ise")][0]
    assert float(mine[ise]) == pytest.approx(float(pd[ise]), rel=1e-6)  # bound: the same law, the same inertia


MAP_REFUSALS = [
    (["--map", "controller.J9=inertia_xx"], ["--map controller.J9=inertia_xx", "no variable or vector stem 'J9'"]),
    (["--map", "J9=inertia_xx"], ["--map J9=inertia_xx", "no variable or vector stem 'J9'"]),
    (["--map", "ctrl.J1=inertia_xx"], ["--map ctrl.J1=inertia_xx", "instance 'controller', not 'ctrl'"]),
    (["--map", "controller.J1=inertia_q"], ["--map controller.J1=inertia_q", "binds nothing", "inertia_q"]),
    (["--map", "controller.q=qq"], ["--map controller.q=qq", "binds nothing", "'qq'"]),
    (["--set", "controller.wnn=1"], ["--set controller.wnn=1", "no parameter 'wnn'", "did you mean 'wn'?"]),
    (["--set", "q_w=1"], ["--set q_w=1", "'q_w' is the unit's input, not a parameter"]),
]


@pytest.mark.parametrize("args, pieces", MAP_REFUSALS, ids=[" ".join(a) for a, _ in MAP_REFUSALS])
def test_benchmark_refuses_a_name_the_unit_lacks_or_a_map_that_binds_nothing(j_unit, tmp_path, args, pieces):
    line = refused(scfmu("benchmark", j_unit, "--cases", CASE, *args, "--out", tmp_path / "b"))
    for p in pieces:
        assert p in line, line
    assert not (tmp_path / "b").exists()


# ----- c. --help without the extras ----------------------------------------------------------------------------
@pytest.mark.parametrize("command", ["benchmark", "campaign", "report"])
def test_help_needs_no_extra(tmp_path, command):
    env = blocked_env(tmp_path, ["dask", "distributed", "pyarrow", "pyswarms", "pygad", "control", "pandas"])
    r = scfmu(command, "--help", env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"usage: scfmu {command}"), r.stdout[:200]
    assert "BLOCKED IMPORT" not in r.stderr, r.stderr


# ----- d. scfmu check NAME --------------------------------------------------------------------------------------
def test_check_takes_a_model_name_as_verify_does(tmp_path):
    # two classic checks: the stale-handle check fails today's FMUs (issue 45), which is not this test's point
    r = scfmu("check", "PidController", "--quick", "--json", "--check", "nominal_run", "--check", "state_machine",
              cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    import json
    rep = json.loads(r.stdout)
    assert rep["model"] == "PidController" and rep["ok"] and Path(rep["fmu"]) == fmu_dir() / "PidController.fmu"
    assert len(rep["rows"]) >= 10
    line = refused(scfmu("check", "PidControler", cwd=tmp_path))
    assert "unknown model 'PidControler'" in line and "did you mean 'PidController'?" in line


# ----- e. every subcommand: one line, exit 2 ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def bad(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("bad_fmus")
    (d / "garbage.fmu").write_bytes(bytes(range(256)) * 3)
    (d / "trunc.fmu").write_bytes((fmu_dir() / "PidController.fmu").read_bytes()[:5000])
    with zipfile.ZipFile(d / "crc.fmu", "w", zipfile.ZIP_STORED) as z:  # a zip whose entry fails its CRC
        z.writestr("modelDescription.xml", "<fmiModelDescription/>" * 20)
    data = bytearray((d / "crc.fmu").read_bytes())
    data[60] ^= 0xFF
    (d / "crc.fmu").write_bytes(bytes(data))
    return d


G, T = "{bad}/garbage.fmu", "{bad}/trunc.fmu"
MISTAKES = [
    # (arguments, pieces of the one line)
    (["run", "nothere.toml"], ["scenario file 'nothere.toml' not found"]),
    (["run", "defualt"], ["unknown scenario 'defualt'", "did you mean 'default'?"]),
    (["run", "default", "--fmu", f"controller={G}"], ["garbage.fmu", "not an FMU archive"]),
    (["run", "default", "--fmu", f"controller={T}"], ["trunc.fmu", "not an FMU archive"]),
    (["run", "default", "--fmu", "controller=nothere.fmu"], ["nothere.fmu: no such file"]),
    (["run", "default", "--fmu", "controller=PdControler"], ["unknown model 'PdControler'", "'PdController'"]),
    (["run", "default", "--dt", "abc"], ["--dt", "invalid float value: 'abc'"]),
    (["scenarios", "--show", "defualt"], ["unknown scenario 'defualt'", "did you mean 'default'?"]),
    (["scenarios", "--bogus"], ["unrecognized arguments: --bogus"]),
    (["verify", "nothere.fmu"], ["nothere.fmu", "no such file"]),
    (["verify", G], ["garbage.fmu", "is not an FMU archive"]),
    (["verify", T], ["trunc.fmu", "is not an FMU archive"]),
    (["verify", "{bad}/crc.fmu"], ["crc.fmu", "fails its CRC check"]),
    (["verify", "PidControler"], ["unknown model 'PidControler'", "did you mean 'PidController'?"]),
    (["verify", "PidController", "--importer", "fmusm"], ["--importer 'fmusm'", "fmpy, fmusim"]),
    (["check", "nothere.fmu"], ["nothere.fmu", "not found"]),
    (["check", G], ["garbage.fmu", "is not an FMU archive"]),
    (["check", T], ["trunc.fmu", "is not an FMU archive"]),
    (["check", "PidControler"], ["unknown model 'PidControler'", "did you mean 'PidController'?"]),
    (["check", "PidController", "--seed", "x"], ["--seed", "invalid int value: 'x'"]),
    (["check", "PidController", "--interface", "xx"], ["--interface", "invalid choice: 'xx'"]),
    (["benchmark", "nothere.fmu"], ["nothere.fmu: no such file"]),
    (["benchmark", G], ["garbage.fmu", "not an FMU archive"]),
    (["benchmark", T], ["trunc.fmu", "not an FMU archive"]),
    (["benchmark", "PidControler"], ["unknown model 'PidControler'", "did you mean 'PidController'?"]),
    (["benchmark", "--family", "atitude"], ["no family 'atitude'"]),
    (["benchmark", "--cases", "defualt"], ["--cases defualt", "did you mean 'default'?"]),
    (["benchmark", "--controllers", "PdControler"], ["--controllers PdControler", "did you mean 'PdController'?"]),
    (["benchmark", "--workers", "0"], ["--workers 0", "[1, 1024]"]),
    (["benchmark", "--workers", "abc"], ["--workers", "invalid int value: 'abc'"]),
    (["benchmark", "--map", "J1=inertia_xx"], ["--map needs a unit under test"]),
    (["benchmark", "--set", "wn=2"], ["--set needs a unit under test"]),
    (["campaign", "nothere.toml"], ["scenario file 'nothere.toml' not found"]),
    (["campaign", "defualt"], ["unknown scenario 'defualt'", "did you mean 'default'?"]),
    (["campaign", "default", "--fmu", f"controller={T}"], ["trunc.fmu", "not an FMU archive"]),
    (["campaign", "default", "--workers", "0"], ["--workers 0"]),
    (["export", "ssp", "defualt"], ["unknown scenario 'defualt'"]),
    (["export", "sspp"], ["invalid choice: 'sspp'"]),
    (["export", "loop", "default", "--fmu", f"controller={G}"], ["garbage.fmu", "not an FMU archive"]),
    (["report", "--papers", "999"], ["--papers", "no paper 999"]),
    (["report", "--papers", "9x"], ["--papers 9x", "'9x' is not a paper number"]),
    (["report", "--workers", "0"], ["--workers 0", "[1, 1024]"]),
    (["report", "--bogus"], ["unrecognized arguments: --bogus"]),
    (["paper", "00x"], ["no paper 00x"]),
    (["paper", "000", "stdy"], ["no command 'stdy'", "did you mean 'study'?"]),
    (["rnu"], ["unknown command 'rnu'", "did you mean 'run'?"]),
    (["--bogus"], ["unrecognized arguments: --bogus"]),
]


@pytest.mark.parametrize("args, pieces", MISTAKES, ids=[" ".join(a) for a, _ in MISTAKES])
def test_every_command_refuses_a_mistake_in_one_line(bad, tmp_path, args, pieces):
    args = [a.format(bad=bad) for a in args]
    line = refused(scfmu(*args, cwd=tmp_path, timeout=600))
    assert line.startswith("scfmu"), line
    for p in pieces:
        assert p in line, line
    assert not (tmp_path / "out").exists()  # nothing ran


# ----- f, g. Ctrl-C -----------------------------------------------------------------------------------------------
def start(args, cwd) -> subprocess.Popen:
    """``scfmu args`` in a session of its own (a SIGINT to its group is what a terminal sends), SIGINT at its
    default (a test run started in the background ignores it, and so would the command)."""
    return subprocess.Popen([sys.executable, "-m", "scfmu", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True, cwd=cwd,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _stat(pid: int) -> tuple[int, int, int, str] | None:
    """(parent, process group, session, state) of a live process, None when it is gone (or a zombie)."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    f = text[text.rindex(")") + 2:].split()
    return (int(f[1]), int(f[2]), int(f[3]), f[0]) if f[0] != "Z" else None


def descendants(pid: int) -> set[int]:
    """Every live process below ``pid`` (through /proc's parent links)."""
    kids: dict = {}
    for d in os.listdir("/proc"):
        if d.isdigit() and (s := _stat(int(d))) is not None:
            kids.setdefault(s[0], []).append(int(d))
    out, todo = set(), [pid]
    while todo:
        for k in kids.get(todo.pop(), []):
            out.add(k)
            todo.append(k)
    return out


def survivors(pids: set[int], groups: set[int], timeout: float = 20.0) -> list[int]:
    """The processes of ``pids`` still alive, plus any live process in one of the process groups or sessions
    ``groups``, after waiting up to ``timeout`` s for them to go."""
    t0 = time.monotonic()
    while True:
        left = [p for p in pids if _stat(p) is not None]
        for d in os.listdir("/proc"):
            s = _stat(int(d)) if d.isdigit() else None
            if s is not None and (s[1] in groups or s[2] in groups) and int(d) not in left:
                left.append(int(d))
        if not left or time.monotonic() - t0 > timeout:
            return left
        time.sleep(0.3)


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="walks /proc")
def test_ctrl_c_on_check_leaves_no_child_running(tmp_path):
    # a check that runs for minutes: a million random call sequences on one interface
    p = start(["check", "PidController", "--interface", "cs", "--sequences", "1000000", "--timeout", "3600"], tmp_path)
    seen: set[int] = set()
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120 and not seen:  # the isolated child process has started
        assert p.poll() is None, p.stderr.read()
        seen = descendants(p.pid)
        time.sleep(0.2)
    assert seen, "no child process started"
    time.sleep(1.5)  # the child is running checks (busy)
    seen |= descendants(p.pid)
    groups = {p.pid} | {s[1] for q in seen if (s := _stat(q)) is not None}
    os.killpg(p.pid, signal.SIGINT)  # Ctrl-C: the terminal's foreground group (the child has its own)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("scfmu check: interrupted (Ctrl-C)"), err
    assert survivors(seen, groups) == [], "a child process of scfmu check outlived it"


@pytest.mark.parametrize("delay", [0.6, 1.2, "cluster"])
def test_ctrl_c_while_the_campaign_cluster_starts(tmp_path, delay):
    args = ["campaign", "default", "--t-end", "5", "--grid", "controller.wn=1,2,3", "--workers", "2", "--out",
            tmp_path / "c", "--no-plots", "--no-progress"]
    p = start(args, tmp_path)
    seen: set[int] = set()
    if delay == "cluster":  # the first worker process exists: the cluster is starting
        t0 = time.monotonic()
        while time.monotonic() - t0 < 120 and len(descendants(p.pid)) < 2:
            assert p.poll() is None, p.stderr.read()
            time.sleep(0.05)
        seen = descendants(p.pid)
        assert seen, "no worker started"
    else:
        time.sleep(delay)
    os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, (p.returncode, out[-500:], err[-3000:])  # never ignored, never a traceback
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and re.match(r"scfmu( campaign)?: interrupted \(Ctrl-C\)", lines[0]), err
    assert survivors(seen, {p.pid}) == []


# ----- h. the count of FMUs in the docs -------------------------------------------------------------------------
COUNT = re.compile(r"\b(\d{2,})\s+(?:FMI [23]\.0\s+)?(?:FMUs|models)\b")


def doc_files() -> list[Path]:
    """The hand-written docs (the generated model pages aside). README.md is left out while it is rewritten
    (issue 42); add it back then."""
    return [p for p in sorted((ROOT / "docs").rglob("*.md")) if "models" not in p.relative_to(ROOT / "docs").parts] \
        + [ROOT / "CONTRIBUTING.md"]


def test_the_docs_name_the_number_of_fmus_there_are():
    n = len(list(fmu_dir().glob("*.fmu")))
    assert n == len(list((fmu_dir() / "fmi3").glob("*.fmu"))) and n >= 20
    from scfmu.fmu import models
    assert len(models()) == n
    wrong = []
    for f in doc_files():
        text = f.read_text()
        for m in COUNT.finditer(text):
            if int(m.group(1)) != n and not text[m.end():m.end() + 20].startswith(" at the time"):  # dated, said so
                line = text.count("\n", 0, m.start()) + 1
                wrong.append(f"{f.relative_to(ROOT)}:{line}: {m.group(0)!r}")
    assert not wrong, f"the project has {n} FMUs; the docs say: {wrong}"
