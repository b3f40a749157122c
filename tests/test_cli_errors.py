"""A user's mistake on the command line ends in ONE line naming the field, the value and what is allowed,
exit status 2, never a traceback (issue 33 items 4-5, issue 34 item 4). One case per message, each run as
the user runs it (``python -m scfmu ...`` in a subprocess).

Also here: integers are never wrapped (the declared type's range and min/max are checked before any FMU
sees the value), run lengths are bounded (steps, logged rows: ``--log-every``), model paths in scenario
files must name an FMU file, unknown names get "did you mean", a missing extra names its ``pip install``,
an FMU's error carries the FMU's own log message, and Ctrl-C on ``run``, ``campaign`` and ``benchmark``
stops the workers, says how to resume and exits 130."""

from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from scfmu.scenario import files, get
from scfmu.scenario.values import INT32, parse_cli, timing_problems, value_problem

from cli_run import refused, scfmu  # tests/ is on the path (pyproject.toml)

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def base_toml(tmp_path_factory) -> tuple[Path, str]:
    d = tmp_path_factory.mktemp("scenario_files")
    return d, files.dumps_toml(get("default"))


def scenario_file(base_toml, name: str, old: str, new: str) -> Path:
    d, text = base_toml
    assert old in text
    p = d / name
    p.write_text(text.replace(old, new, 1))
    return p


# ----- one case per message: --set, --params and scenario-file values ------------------------------------
SET_CASES = [
    # (arguments after `scfmu run default`, pieces the one line must hold)
    (["--set", "controller.error_law=4294967297"],
     ["controller.error_law = 4294967297", "outside the Integer range", "an Integer in [0, 2]"]),
    (["--set", "controller.error_law=3"], ["controller.error_law = 3", "above the declared maximum 2"]),
    (["--set", "controller.error_law=-1"], ["controller.error_law = -1", "below the declared minimum 0"]),
    (["--set", "controller.error_law=1.5"], ["controller.error_law = 1.5", "not a whole number"]),
    (["--set", "controller.error_law=true"], ["controller.error_law = true", "not a whole number"]),
    (["--set", "controller.wn=abc"], ["controller.wn = 'abc'", "not a number", "a finite Real [rad/s]"]),
    (["--set", "controller.wn=nan"], ["controller.wn = nan", "not finite"]),
    (["--set", "controller.wn=-inf"], ["controller.wn = -inf", "not finite"]),
    (["--set", "plant.effectiveness_x=1.5"], ["plant.effectiveness_x = 1.5", "above the declared maximum 1",
                                              "in [0, 1]"]),
    (["--set", "plant.max_internal_step=0"], ["plant.max_internal_step = 0", "below the declared minimum 1e-06"]),
    # a bound the model description cannot declare (wn > 0): the unit's own message, in the pre-flight
    (["--set", "controller.wn=-1"], ["controller (PdController) refuses the parameters", "wn = -1 must be > 0"]),
    (["--set", "controller.wnn=1"], ["no parameter 'wnn'", "did you mean 'wn'?"]),
    (["--set", "controler.wn=1"], ["no instance 'controler'", "did you mean 'controller'?"]),
    (["--set", "controller.wn"], ["--set 'controller.wn'", "expected NAME=VALUE"]),
    (["--fmu", "controller=PdControler"], ["unknown model 'PdControler'", "did you mean 'PdController'?"]),
    (["--fmu", "controler=PdController"], ["no instance 'controler'", "did you mean 'controller'?"]),
    (["--t-end", "1e12"], ["stop_time = 1e+12 with step = 0.01", "at most 1000000000 steps", "SCFMU_MAX_STEPS"]),
    (["--t-end", "1e308"], ["stop_time = 1e+308", "at most 1000000000 steps"]),
    (["--t-end", "-5"], ["stop_time = -5", "a time after start_time = 0"]),
    (["--dt", "1e-300"], ["step = 1e-300", "at most 1000000000 steps"]),
    (["--dt", "nan"], ["--dt nan", "not finite"]),
    (["--dt", "0"], ["step = 0", "a positive number of seconds"]),
    (["--dt", "0.07"], ["not a positive multiple of step = 0.07"]),
    (["--t-end", "1e6"], ["5000000 rows per run", "SCFMU_MAX_LOG_ROWS", "use --log-every 21 or more"]),
    (["--log-every", "0"], ["--log-every 0", "a whole number in [1, 1000000000]"]),
    (["--log-every", "10", "--engine", "lean"], ["--log-every 10: allowed only with --engine native"]),
]


@pytest.mark.parametrize("args, pieces", SET_CASES, ids=[" ".join(a) for a, _ in SET_CASES])
def test_run_refuses_with_one_line(tmp_path, args, pieces):
    line = refused(scfmu("run", "default", *args, "--no-plot", "--out", tmp_path))
    for p in pieces:
        assert p in line, line
    assert not list(tmp_path.iterdir())  # nothing ran, nothing written


UP = "../" * 24  # enough ".." to reach / from any temporary folder (the root's ".." is the root)
FILE_CASES = [
    # (file name, text replaced, replacement, pieces)
    ("big_int.toml", "error_law = 0", "error_law = 99999999999999999999999",
     ["controller.error_law = 99999999999999999999999", "outside the Integer range"]),
    ("fast.toml", "error_law = 0", 'error_law = 0\nwn = "fast"', ["controller.wn = 'fast'", "not a number"]),
    ("inf.toml", "error_law = 0", "error_law = 0\nwn = inf", ["params.wn = inf", "not finite"]),
    ("array.toml", "error_law = 0", "error_law = [1, 2]", ["params.error_law = [1, 2]", "a list"]),
    ("passwd.toml", 'model = "PdController"', 'model = "' + UP + 'etc/passwd"',
     ["model = '" + UP + "etc/passwd'", "resolved to /etc/passwd", "a path to an .fmu file"]),
    ("missing.toml", 'model = "PdController"', 'model = "Mine.fmu"', ["model = 'Mine.fmu'", "no such file",
                                                                        "relative to the scenario file"]),
    ("bad_name.toml", 'model = "PdController"', 'model = ".."', ["model = '..'", "a model name"]),
    ("stop.toml", "stop_time = 30.0", "stop_time = 1e12", ["stop_time = 1e+12", "SCFMU_MAX_STEPS"]),
    ("huge.toml", "stop_time = 30.0", "stop_time = 1e308", ["stop_time = 1e+308", "steps"]),
    ("tiny.toml", "step = 0.01", "step = 1e-300", ["step = 1e-300", "steps"]),
    ("nan_step.toml", "step = 0.01", "step = nan", ["step = nan", "not finite"]),
    ("neg_step.toml", "step = 0.01", "step = -0.01", ["step = -0.01", "a positive number"]),
    ("str_stop.toml", "stop_time = 30.0", 'stop_time = "30"', ["field 'stop_time' must be a number"]),
    ("unknown_model.toml", 'model = "PdController"', 'model = "PdControler"', ["did you mean 'PdController'?"]),
]


@pytest.mark.parametrize("name, old, new, pieces", FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_scenario_file_values_are_refused_with_one_line(base_toml, tmp_path, name, old, new, pieces):
    f = scenario_file(base_toml, name, old, new)
    line = refused(scfmu("run", f, "--no-plot", "--out", tmp_path / "o"))
    for p in pieces:
        assert p in line, line


def test_scenario_file_model_directory_named_fmu(base_toml, tmp_path):
    d, _ = base_toml
    (d / "Dir.fmu").mkdir(exist_ok=True)
    f = scenario_file(base_toml, "dir.toml", 'model = "PdController"', 'model = "Dir.fmu"')
    line = refused(scfmu("run", f, "--no-plot"))
    assert "a directory, not an FMU file" in line


def test_scenario_file_that_is_not_a_table_or_not_text(tmp_path):
    (tmp_path / "list.json").write_text("[1, 2]")
    assert "expected a table of fields, not a list" in refused(scfmu("run", tmp_path / "list.json"))
    (tmp_path / "bin.toml").write_bytes(b"\xff\xfe\x00binary")
    assert "not a text file" in refused(scfmu("run", tmp_path / "bin.toml"))


def test_params_file_values_are_checked(tmp_path):
    p = tmp_path / "p.toml"
    p.write_text('[controller]\nwn = "fast"\n')
    assert "controller.wn = 'fast': not a number" in refused(scfmu("run", "default", "--params", p))
    p.write_text('"controller.error_law" = 4294967297\n')
    assert "outside the Integer range" in refused(scfmu("run", "default", "--params", p))
    p.write_text("[controller\n")
    assert "--params" in refused(scfmu("run", "default", "--params", p)) and "not valid TOML" in refused(
        scfmu("run", "default", "--params", p))
    assert "no such file" in refused(scfmu("run", "default", "--params", tmp_path / "none.toml")).lower()


def test_a_fixed_input_value_is_checked(base_toml, tmp_path):
    f = scenario_file(base_toml, "input.toml", "[[components]]", '[inputs]\n"plant.torque_dist_x" = "strong"\n\n'
                      '[[components]]')
    assert "fixed input plant.torque_dist_x = 'strong': not a number" in refused(scfmu("run", f, "--no-plot"))


def test_the_row_limit_asks_for_log_every_and_log_every_runs(tmp_path):
    """3001 rows (30 s at 0.01 s) against a limit of 1000: refused with the --log-every that fits; with it
    the native engine runs, and logs 1001 rows."""
    env = {"SCFMU_MAX_LOG_ROWS": "1000"}
    line = refused(scfmu("run", "default", "--no-plot", "--out", tmp_path, env=env))
    assert "3001 logged rows" in line and "use --log-every 4 or more" in line
    r = scfmu("run", "default", "--no-plot", "--log-every", "4", "--out", tmp_path, env=env)
    assert r.returncode == 0, r.stderr
    assert "3000 steps" not in r.stdout
    n = sum(1 for _ in open(tmp_path / "default.csv")) - 1
    assert n == 751  # rows at k = 0, 4, ..., 3000


# ----- names: did you mean -----------------------------------------------------------------------------
def test_unknown_scenario_did_you_mean():
    assert refused(scfmu("run", "defualt")) == ("scfmu run: unknown scenario 'defualt'; did you mean 'default'? "
                                                 "(`scfmu scenarios` lists them)")


def test_unknown_command_did_you_mean():
    line = refused(scfmu("rnu", "default"))
    assert line.startswith("scfmu: unknown command 'rnu'; did you mean 'run'?")


def test_unknown_paper_command_did_you_mean():
    r = scfmu("paper", "002", "tunee")
    assert r.returncode == 2 and "did you mean 'tune'?" in r.stderr and "Traceback" not in r.stderr


def test_missing_scenario_file():
    assert "scenario file 'nothere.toml' not found" in refused(scfmu("run", "nothere.toml"))


# ----- campaign options ----------------------------------------------------------------------------------
CAMPAIGN_CASES = [
    (["--seeds", "0:99999999999"], ["--seeds", "[0, 2147483647]"]),
    (["--seeds", "a,b"], ["--seeds", "'a'"]),
    (["--seeds", "5:2"], ["END must be greater than FIRST"]),
    (["--samples", "0", "--random", "controller.wn=uniform:0.5:1"], ["--samples 0", "[1, 10000000]"]),
    (["--random", "controller.wn=unifrom:0.5:1"], ["unknown distribution 'unifrom'", "did you mean 'uniform'?"]),
    (["--random", "controller.wn=uniform:2:1"], ["A = 2 must not exceed B = 1"]),
    (["--random", "controller.wn=loguniform:0:1"], ["loguniform needs 0 < A"]),
    (["--grid", "controller.error_law=0,1,4294967297"], ["set 2: controller.error_law = 4294967297",
                                                         "outside the Integer range"]),
    (["--grid", "controller.wn=1,abc"], ["set 1: controller.wn = 'abc': not a number"]),
    (["--grid", "controller.wnn=1,2"], ["has no variable 'wnn'", "did you mean 'wn'?"]),
    (["--workers", "0"], ["--workers 0", "[1, 1024]"]),
    (["--timeout", "nan"], ["--timeout nan"]),
    (["--ts-every", "-1"], ["--ts-every -1"]),
]


@pytest.mark.parametrize("args, pieces", CAMPAIGN_CASES, ids=[" ".join(a) for a, _ in CAMPAIGN_CASES])
def test_campaign_refuses_with_one_line(tmp_path, args, pieces):
    line = refused(scfmu("campaign", "default", *args, "--out", tmp_path / "c", "--no-progress"))
    for p in pieces:
        assert p in line, line
    assert not (tmp_path / "c").exists()


# ----- missing extras ------------------------------------------------------------------------------------
BLOCKER = '''
import sys
class _Blocker:
    """Simulates an installation without the 'campaigns' extra."""
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {MODULES!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None
sys.meta_path.insert(0, _Blocker())
'''


@pytest.mark.parametrize("command, blocked", [
    (["campaign", "default", "--grid", "controller.wn=1,2"], ("pyarrow",)),
    (["campaign", "default", "--grid", "controller.wn=1,2"], ("dask", "distributed")),
    (["benchmark", "--cases", "x"], ("dask", "distributed")),
])
def test_a_missing_extra_names_its_pip_install(tmp_path, command, blocked):
    (tmp_path / "sitecustomize.py").write_text(BLOCKER.format(MODULES=set(blocked)))
    env = {"PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    check = subprocess.run([sys.executable, "-c", f"import {blocked[0]}"], capture_output=True, text=True, env=dict(
        os.environ, **env))
    assert check.returncode != 0  # the blocker works
    line = refused(scfmu(*command, env=env))
    assert line == (f"scfmu {command[0]} needs the 'campaigns' extra ({blocked[0]} is not installed): "
                    f"pip install 'scfmu[campaigns]'")


# ----- values, in process: the parsing and the checks the lines above come from -------------------------
def var(type_, min_=None, max_=None, unit=None):
    return SimpleNamespace(type=type_, min=min_, max=max_, unit=unit, declaredType=None, name="x")


def test_parse_cli_is_strict():
    assert parse_cli("4294967297") == 4294967297 and isinstance(parse_cli("-3"), int)
    assert parse_cli("1e-3") == 1e-3 and parse_cli(".5") == 0.5 and math.isnan(parse_cli("NaN"))
    assert parse_cli("True") is True and parse_cli("false") is False
    for text in ("abc", "1.2.3", "0x10", "1,5", "yes", "1e", ""):
        assert isinstance(parse_cli(text), str), text


def test_integer_range_is_int32_and_never_wrapped():
    assert value_problem("a.n", var("Integer"), INT32[1]) is None
    assert value_problem("a.n", var("Integer"), INT32[0]) is None
    assert "outside the Integer range" in value_problem("a.n", var("Integer"), INT32[1] + 1)
    assert "outside the Integer range" in value_problem("a.n", var("Integer"), INT32[0] - 1)
    assert value_problem("a.n", var("Integer"), 3.0) is None  # a whole number written as 3.0
    assert "not a whole number" in value_problem("a.n", var("Integer"), 3.5)


def test_booleans_are_strict():
    """No Boolean parameter in our FMUs: the check on a declared Boolean variable."""
    b = var("Boolean")
    assert value_problem("a.flag", b, True) is None and value_problem("a.flag", b, False) is None
    for v in (1, 0, "yes", "true", 1.0):
        assert value_problem("a.flag", b, v) == f"a.flag = {v!r}: not a Boolean; allowed: true or false" or \
            "not a Boolean" in value_problem("a.flag", b, v)


def test_reals_against_declared_bounds():
    r = var("Real", "0.0", "1.0", "1")
    assert value_problem("a.e", r, 0.0) is None and value_problem("a.e", r, 1) is None
    assert value_problem("a.e", r, 1.0000001).startswith("a.e = 1.0000001: above the declared maximum 1")
    assert "too large" in value_problem("a.e", var("Real"), 10 ** 400)


def test_timing_limits():
    assert timing_problems(0.0, 30.0, 0.01) == []
    assert "not finite" in timing_problems(0.0, math.inf, 0.01)[0]
    assert "steps" in timing_problems(0.0, 1e12, 0.01)[0]
    assert "logged rows" in timing_problems(0.0, 1e6, 0.01)[0]
    assert timing_problems(0.0, 1e6, 0.01, log_every=100) == []
    assert timing_problems(0.0, 1e6, 0.01, log_every=None) == []


# ----- an FMU's error carries its own message --------------------------------------------------------------
def test_fmu_errors_carry_the_units_log_message():
    """fmpy's FMICallException names the function and the status only; scfmu's FmuError (still an
    FMICallException) adds the unit's last error messages."""
    from fmpy.fmi1 import FMICallException
    from scfmu.engines import simulate
    from scfmu.fmu import Fmu
    with pytest.raises(FMICallException) as e:
        Fmu("PdController", params={"wn": math.inf})
    assert "fmi2SetReal failed with status 3 (error): " in str(e.value) and "wn" in str(e.value)
    assert "inf" in str(e.value).lower() or "finite" in str(e.value).lower()
    with pytest.raises(FMICallException) as e:
        simulate(get("default", stop_time=1.0), "reference", overrides={"controller.wn": math.inf})
    assert "PdController" in str(e.value) and "wn" in str(e.value)


@pytest.mark.parametrize("engine", ["reference", "lean", "native", "compiled"])
def test_no_engine_wraps_an_integer_or_hides_the_units_message(engine):
    """The Python API too: an integer outside fmi2Integer is refused before any FMU call (it used to run as
    error_law = 1), and an FMU's refusal carries the unit's message, on every engine."""
    from fmpy.fmi1 import FMICallException
    from scfmu.engines import SimulationError, simulate
    if engine == "compiled":
        from scfmu.engines.compiled import available
        if not available():
            pytest.skip("the compiled engine's library is not built")
    sc = get("default", stop_time=1.0)
    with pytest.raises(ValueError, match="error_law = 4294967297 is outside the Integer range"):
        simulate(sc, engine, overrides={"controller.error_law": 2 ** 32 + 1})
    with pytest.raises(FMICallException, match="value inf for wn is not finite"):
        simulate(sc, engine, overrides={"controller.wn": math.inf})
    with pytest.raises(SimulationError, match="parameter wn = -1 must be > 0"):
        simulate(sc, engine, overrides={"controller.wn": -1.0})


def test_a_foreign_units_trial_initialization_runs_in_a_child(tmp_path, monkeypatch):
    """A unit given as a file is tried in a forked child: its refusal is still reported with its own
    message; a crash or a hang there costs a warning, not the process running the check."""
    import shutil
    import scfmu.scenario.check as chk
    from scfmu.fmu import fmu_path
    mine = tmp_path / "MyPd.fmu"
    shutil.copyfile(fmu_path("PdController"), mine)
    sc = get("default", stop_time=1.0).with_models({"controller": str(mine)})
    rep = chk.check(sc.with_overrides({"controller.wn": -1.0}))
    assert rep.errors == ["controller (MyPd.fmu) refuses the parameters it is given: fmi2ExitInitializationMode: "
                          "parameter wn = -1 must be > 0"]
    real = chk._trial  # (our own units are tried in this process: only the foreign one misbehaves)
    monkeypatch.setattr(chk, "_trial", lambda c, t: os.kill(os.getpid(), signal.SIGSEGV) if c.name == "controller"
                        else real(c, t))
    rep = chk.check(sc.with_overrides({"controller.wn": 1.0}))
    assert rep.ok and any("its trial initialization crashed (SIGSEGV)" in w for w in rep.warnings), rep
    monkeypatch.setattr(chk, "_trial", lambda c, t: time.sleep(60) if c.name == "controller" else real(c, t))
    monkeypatch.setattr(chk, "TRIAL_TIMEOUT", 1.0)
    t0 = time.monotonic()
    rep = chk.check(sc.with_overrides({"controller.wn": 1.0}))
    assert rep.ok and any("did not end within 1 s" in w for w in rep.warnings), rep
    assert time.monotonic() - t0 < 30


def test_a_failing_campaign_run_row_carries_the_units_message(tmp_path):
    from scfmu import campaign
    c = campaign.Campaign(get("default", stop_time=1.0), [{"controller.wn": -1.0}], isolate=False)
    row, _ = campaign.run_one(c.runs()[0])
    assert row["status"] != "ok" and "wn = -1 must be > 0" in row["message"], row


# ----- Ctrl-C ---------------------------------------------------------------------------------------------
class Started:
    """``scfmu args`` in a session of its own (so that a SIGINT to its group is what a terminal sends), its
    output read by two threads."""

    def __init__(self, args, cwd):
        import threading
        # SIGINT back at its default in the child: a test run started in the background (`cmd &` without job
        # control) ignores SIGINT, and a Python started with SIGINT ignored never raises KeyboardInterrupt
        self.p = subprocess.Popen([sys.executable, "-m", "scfmu", *map(str, args)], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True, start_new_session=True, cwd=cwd,
                                  preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        self.out, self.err = [], []
        self.threads = [threading.Thread(target=self._read, args=(f, buf), daemon=True)
                        for f, buf in ((self.p.stdout, self.out), (self.p.stderr, self.err))]
        for t in self.threads:
            t.start()

    @staticmethod
    def _read(f, buf):
        while True:
            c = f.read(1)
            if not c:
                return
            buf.append(c)

    def wait_for(self, pattern: str, stream: str = "err", timeout: float = 180.0) -> None:
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            if re.search(pattern, "".join(getattr(self, stream))):
                return
            assert self.p.poll() is None, "".join(self.err)
            time.sleep(0.2)
        raise AssertionError(f"no {pattern!r} within {timeout} s: {''.join(self.err)}")

    def interrupt(self) -> str:
        """SIGINT to the whole process group (what Ctrl-C in a terminal does); returns stderr."""
        os.killpg(self.p.pid, signal.SIGINT)
        self.p.wait(timeout=120)
        for t in self.threads:
            t.join(timeout=30)
        return "".join(self.err)


def session_processes(sid: int) -> list[int]:
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                if os.getsid(int(d)) == sid:
                    out.append(int(d))
            except OSError:
                pass
    return out


def assert_no_processes_left(sid: int) -> None:
    t0 = time.monotonic()
    while session_processes(sid) and time.monotonic() - t0 < 20:
        time.sleep(0.5)
    assert session_processes(sid) == [], "worker processes survived the interrupt"


def test_ctrl_c_on_run(tmp_path):
    s = Started(["run", "default", "--t-end", "3000", "--engine", "reference", "--no-plot", "--out",
                 tmp_path / "o"], tmp_path)
    time.sleep(6.0)  # set-up done, stepping
    assert s.p.poll() is None
    err = s.interrupt()
    assert s.p.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.strip().splitlines()[-1] == ("scfmu run: interrupted (Ctrl-C); nothing was written; run the same "
                                            "command again to start over")
    assert not (tmp_path / "o" / "default.csv").exists()


def test_ctrl_c_on_a_campaign_stops_the_workers_and_it_resumes(tmp_path):
    args = ["campaign", "default", "--t-end", "10", "--grid", "controller.wn=" + ",".join(f"{0.5 + 0.1 * i:g}" for i in range(10)),
            "--seeds", "0:2", "--workers", "1", "--chunk", "1", "--engine", "reference", "--out", tmp_path / "c",
            "--no-plots"]
    s = Started(args, tmp_path)
    s.wait_for(r"\| ([3-9]|1\d)/20")
    err = s.interrupt()
    assert s.p.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    last = err.strip().splitlines()[-1]
    m = re.fullmatch(r"scfmu campaign: interrupted \(Ctrl-C\) after (\d+) of 20 runs; the workers were stopped "
                     r"and the rows are kept in .*; run the same command again to resume", last)
    assert m, last
    assert 3 <= int(m.group(1)) < 20
    assert_no_processes_left(s.p.pid)
    r = scfmu(*args, "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "20 of 20 runs ok" in r.stdout
    # the resumed rows are those of runs made on their own (first and last run, by the reference engine)
    import pyarrow.parquet as pq
    from scfmu import metrics
    from scfmu.engines import simulate
    rows = {row["run"]: row for row in pq.read_table(tmp_path / "c" / "results.parquet").to_pylist()}
    assert sorted(rows) == list(range(20))
    for run in (0, 19):
        wn, seed = 0.5 + 0.1 * (run // 2), run % 2
        sc = get("default", stop_time=10.0).with_overrides({"controller.wn": float(f"{wn:g}")}).with_seed(seed)
        m = metrics.compute(sc.metrics, simulate(sc, "reference"))
        assert rows[run]["eulerint_deg_s"] == m["eulerint_deg_s"], run


def test_ctrl_c_on_the_benchmark(tmp_path):
    s = Started(["benchmark", "--family", "single_axis", "--workers", "1", "--out", tmp_path / "b"], tmp_path)
    s.wait_for(r"ok, ", stream="out")  # the first case is done
    err = s.interrupt()
    assert s.p.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert err.strip().splitlines()[-1] == ("scfmu benchmark: interrupted (Ctrl-C); the workers were stopped; run "
                                            "the same command again to start over")
    assert_no_processes_left(s.p.pid)
