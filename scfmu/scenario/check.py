"""Pre-flight check of a scenario before any run: every unit is an FMI 2.0 or FMI 3.0 FMU offering the
interface it will run with (Co-Simulation, or Model Exchange: ``Component.interface``) with a binary for
this platform that instantiates, every parameter the scenario sets exists, and every connection joins
an output to an input of the same type (the plan's one rule, :func:`scfmu.scenario.plan.link_problem`:
Real, Integer, Boolean; FMI 3.0 Float64, Int32, Boolean; no arrays) and unit.

:func:`check` returns the problems found (``errors``) and what is accepted with a warning (``warnings``,
e.g. a port without a unit); :func:`require` raises :class:`IncompatibleUnit` with every error at once.
A unit given by path (a user's FMU) is checked the same way as ours.
"""

from __future__ import annotations

import platform
import sys
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from fmpy import read_model_description

from ..fmu import ArchiveError, described, fmu_path, inspect_archive
from .model import Scenario
from .plan import Plan, PlanError, apply_params, link_problem, plan_units, remember, timing_problem, unit_terminals, values, wire
from .resolve import resolve
from .values import did_you_mean, value_problem


class IncompatibleUnit(ValueError):
    """A unit cannot take its place in the scenario; the message lists every reason (``errors``)."""

    def __init__(self, message: str, errors: list | None = None):
        super().__init__(message)
        self.errors = list(errors or [])

    def one_line(self) -> str:
        """The message on one line when there is one reason (the command line's form), else as is."""
        if len(self.errors) == 1:
            return str(self).split("\n", 1)[0] + " " + self.errors[0]
        return str(self)


@dataclass
class Report:
    errors: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    plan: object = None  # the scenario's plan when there is no error (scfmu.scenario.plan.Plan)

    @property
    def ok(self) -> bool:
        return not self.errors


def platform_folder() -> str:
    """FMI 2.0's binaries folder for this machine (linux64, win64, darwin64, ...)."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    return {"Linux": "linux", "Windows": "win", "Darwin": "darwin"}.get(platform.system(), platform.system().lower()) + bits


def _unit(md, v) -> str | None:
    """The unit of a Real variable: its own, else its declared type's (None when neither has one)."""
    unit = getattr(v, "unit", None)
    if unit:
        return unit
    dt = getattr(v, "declaredType", None)
    return getattr(dt, "unit", None) or None


def binary_folder(fmi: int) -> str:
    """The binaries folder of this machine for an FMI major version (FMI 2.0 ``linux64``, FMI 3.0
    ``x86_64-linux``)."""
    if fmi == 2:
        return platform_folder()
    from fmpy import platform_tuple
    return platform_tuple


def check_unit(model: str, instantiate: bool = True, interface: str = "") -> tuple[object | None, list[str]]:
    """(model description or None, errors) of one FMU: FMI 2.0 or 3.0, the interface it will run with
    (``interface``: "cs", "me", or "" for Co-Simulation when offered, else Model Exchange), a binary for
    this platform, and (``instantiate``) instantiation succeeding."""
    try:
        path = fmu_path(model)
    except FileNotFoundError as e:
        return None, [str(e)]
    try:
        if zipfile.is_zipfile(path):  # (not a zip: reported below as an unreadable modelDescription.xml)
            inspect_archive(path)  # archive limits before anything is inflated
    except ArchiveError as e:
        return None, [str(e)]
    try:  # the process's cached, schema-validated description; read unvalidated when it fails the schema
        try:
            md = described(path)
        except Exception:
            md = read_model_description(str(path), validate=False)
    except Exception as e:  # not a zip, no modelDescription.xml, XML errors
        return None, [f"{model}: cannot read its modelDescription.xml: {e}"]
    errs = []
    if md.fmiVersion not in ("2.0", "3.0"):
        errs.append(f"{model}: FMI {md.fmiVersion}, not FMI 2.0 or 3.0")
        return md, errs
    itf = interface or ("cs" if md.coSimulation is not None else "me")
    if itf == "cs" and md.coSimulation is None:
        errs.append(f"{model}: no Co-Simulation interface (Model Exchange only: run it as Model Exchange)")
    if itf == "me" and md.modelExchange is None:
        errs.append(f"{model}: no Model Exchange interface (Co-Simulation only)")
    if md.coSimulation is None and md.modelExchange is None:
        errs.append(f"{model}: neither a Co-Simulation nor a Model Exchange interface")
    if errs:
        return md, errs
    ident = (md.coSimulation if itf == "cs" else md.modelExchange).modelIdentifier
    fmi = int(md.fmiVersion[0])
    ext = {"linux": ".so", "win": ".dll", "darwin": ".dylib"}[platform_folder().rstrip("0123456789")]
    lib = f"binaries/{binary_folder(fmi)}/{ident}{ext}"
    with zipfile.ZipFile(path) as z:
        if lib not in z.namelist():
            have = sorted({n.split("/")[1] for n in z.namelist() if n.startswith("binaries/") and n.count("/") >= 2})
            return md, [f"{model}: no binary for this platform ({lib} missing; it has {have or 'no binaries'})"]
    if instantiate:
        from ..fmu import Fmu
        try:
            f = Fmu(str(model), path=path, name="preflight", initialize=False, interface=itf)
        except Exception as e:
            return md, [f"{model}: fmi{fmi}Instantiate failed: {e}"]
        f.close()
    return md, []


def check(scenario: Scenario, instantiate: bool = True, log_every: int | None = None,
          origins: dict | None = None, log_hint: bool = True) -> Report:
    """Builds the scenario's plan (:mod:`scfmu.scenario.plan`: resolved once, each unit's description read
    once, the values checked once) and reports what stops it, in the pre-flight's words (with the closest
    ``--map`` names for inputs left without a source, and units of measure compared across each link);
    with ``instantiate`` every unit is instantiated once: the units given values in a trial initialization
    with them, the others bare. ``rep.plan`` is the plan when there is no error. A timing the run cannot
    have (``log_every``: the logged rows too) raises :class:`~scfmu.scenario.plan.PlanError`."""
    why = timing_problem(scenario, log_every, log_hint)
    if why:
        raise PlanError(why)
    rep = Report()
    mds = {}
    for c in scenario.components:
        if c.model in mds:
            continue
        md, errs = check_unit(c.model, False, c.interface)
        rep.errors += errs
        mds[c.model] = md if not errs else None
    if rep.errors:
        return rep
    sc = resolve_safely(scenario, rep)
    paths = [fmu_path(c.model) for c in sc.components]
    try:
        units = plan_units(sc, paths)
    except PlanError as e:
        rep.errors.append(str(e))
        return rep
    plan = Plan(sc, units, [], [], [])
    values(plan, scenario, origins or {})
    rep.errors += plan.problems
    if rep.errors:
        return rep
    vars_of = {u.name: u.vars for u in units}
    ports = plan.ports()
    terms = unit_terminals(sc, units)
    try:  # the wiring, worked out once; when it fails, every reason and the closest names
        links = sc.wiring(ports, terms)
    except (KeyError, ValueError):
        problems = sc.wiring_problems(ports, terms)
        if not problems:
            raise
        rep.errors += [f"wiring: {x}" for x in problems]
        hint = suggest_maps(sc, vars_of, mds)
        if hint:
            rep.errors.append("wiring: closest names: " + " ".join(hint))
        return rep
    for d, di, s, so in links:
        vd, vs = vars_of[d][di], vars_of[s][so]
        what = f"{s}.{so} -> {d}.{di}"
        why = link_problem(plan.unit(d), di, plan.unit(s), so)
        if why:
            rep.errors.append(f"{what}: {why}")
            continue
        ud, us = _unit(None, vd), _unit(None, vs)
        if ud and us and ud != us:
            rep.errors.append(f"{what}: unit {us!r} does not match {ud!r}")
        elif bool(ud) != bool(us):  # one side without a unit (both without: a dimensionless signal)
            rep.warnings.append(f"{what}: no unit declared on {d + '.' + di if not ud else s + '.' + so} "
                                f"(accepted; expected {us or ud or 'a unit'})")
    for key, inst, var in sc.log_items():
        if inst in vars_of and var not in vars_of[inst]:
            rep.errors.append(f"logged signal {key!r}: {inst} has no variable {var!r}")
    rep.errors += plan.input_problems
    if rep.errors:
        return rep
    done = wire(sc, units, links)  # the rest of the plan (link groups, logged signals): PlanError, KeyError
    done.params, done.inputs, done.log_every = plan.params, plan.inputs, log_every
    remember(done, paths)
    if instantiate:
        rep.errors += trial_initialization(done, rep.warnings)
    if not rep.errors:
        rep.plan = done
    return rep


# names a unit may use for the family's ports (a hint only: the suggestion is still checked by unit and axis)
SYNONYMS = {"omega": ("w",), "rate": ("w",), "w_meas": ("w",), "tau": ("torque_cmd",), "torque": ("torque_cmd",),
            "u": ("torque_cmd",), "quat": ("q",), "att": ("q",), "q_meas": ("q",), "q_cmd": ("q_ref",),
            "w_cmd": ("w_ref",)}


def _split(name: str) -> tuple[str, str]:
    """(stem, axis suffix) of a port name: ``omega_x`` → (omega, x); no suffix → (name, "")."""
    from .resolve import VECTOR_SUFFIXES
    stem, sep, suf = name.rpartition("_")
    return (stem, suf) if sep and stem and suf in VECTOR_SUFFIXES else (name, "")


def suggest_maps(sc: Scenario, vars_of: dict, mds: dict) -> list[str]:
    """``--map`` flags (or ``connections`` entries) that would wire the inputs left without a source: for
    each, the other instances' outputs with the same axis suffix and unit and not already feeding that
    instance, the closest by name (difflib ratio of the stems, or a usual synonym such as omega → w); a
    vector whose elements all map the same way is one flag (``--map controller.omega=w``)."""
    import difflib
    names = [c.name for c in sc.components]
    ours = {n: {sc.alias(n, p): v for p, v in vars_of[n].items()} for n in names}
    outs = {n: [p for p, v in ours[n].items() if v.causality == "output"] for n in names}
    picks: dict = {}
    for d in names:
        wired = set()
        for p, v in ours[d].items():
            if v.causality == "input":
                src = [s for s in names if s != d and p in outs[s]]
                if len(src) == 1:
                    wired.add((src[0], p))
        for i, v in ours[d].items():
            q = f"{d}.{i}"
            if v.causality != "input" or q in sc.connections or q in sc.inputs or sc._is_unconnected(d, i):
                continue
            if any(i in outs[s] for s in names if s != d):
                continue
            si, ax = _split(i)
            ui = _unit(mds[sc.component(d).model], v)
            best = None
            for s in names:
                if s == d:
                    continue
                for o in outs[s]:
                    so, ox = _split(o)
                    if ox != ax or (s, o) in wired or _unit(mds[sc.component(s).model], ours[s][o]) != ui:
                        continue
                    score = max(difflib.SequenceMatcher(None, si, so).ratio(),
                                1.0 if so in SYNONYMS.get(si, ()) or si in SYNONYMS.get(so, ()) else 0.0)
                    if score >= 0.5 and (best is None or score > best[0]):
                        best = (score, s, o)
            if best is None:
                continue
            _, s, o = best
            if d in sc.swapped or s not in sc.swapped:
                inst, theirs, target = d, sc.native_name(d, i), o  # rename the input of the unit that has it
            else:
                inst, theirs, target = s, sc.native_name(s, o), i  # rename the output of the swapped unit
            if d not in sc.swapped and s not in sc.swapped:
                picks[(None, q, f"{s}.{o}")] = None
                continue
            (ts, tx), (gs, gx) = _split(theirs), _split(target)
            key = (inst, ts, gs) if tx and tx == gx else (inst, theirs, target)
            picks.setdefault(key, []).append(tx)
    out = []
    for (inst, a, b), axes in picks.items():
        if inst is None:
            out.append(f'connections "{a}" = "{b}"')
        else:
            out.append(f"--map {inst}.{a}={b}")
    return out


TRIAL_TIMEOUT = 60.0  # [s] wall time of the trial initialization of a unit given as a file


@dataclass
class Trial:
    """A unit of the plan to try alone, with the settings it is given."""
    name: str
    model: str
    path: Path
    fmi: int
    interface: str
    settings: list


def _trial(u: Trial, start_time: float) -> str | None:
    """The error of instantiating unit ``u`` alone, or of initializing it with its ``settings`` when it
    initializes with its defaults (None when it takes them, or when it refuses its defaults too: not the
    values' fault)."""
    from ..fmu import Fmu
    settings = u.settings
    try:
        f = Fmu(u.model, name=u.name, start_time=start_time, path=u.path, initialize=False, interface=u.interface)
    except Exception as e:
        return f"{u.model}: fmi{u.fmi}Instantiate failed: {e}"
    try:
        if not settings:
            return None
        f.enter_initialization_mode(start_time)
        apply_params(settings, f.set_refs)
        f.exit_initialization_mode()
        return None
    except Exception as e:
        refused = e
    finally:
        f.close()
    try:  # the same unit with its defaults: does it refuse the scenario's values, or everything?
        Fmu(u.model, name=u.name, start_time=start_time, path=u.path, interface=u.interface).close()
    except Exception:
        return None  # the run reports it
    msg = getattr(refused, "log", None)
    return (f"{u.name} ({Path(str(u.model)).name}) refuses the parameters it is given: "
            + (" | ".join(msg) if msg else str(refused)))


def trial_initialization(plan: Plan, warnings: list | None = None) -> list[str]:
    """Each unit of the plan is instantiated once: alone, and when it is given parameters initialized with
    them (through :func:`~scfmu.scenario.plan.apply_params`, as every engine sets them); when it refuses
    them but initializes with its defaults, the unit's own log message is the error (e.g. an exclusive bound
    the model description cannot declare). A model used by several instances is instantiated bare once. A
    unit given as a file is tried in a child process (``TRIAL_TIMEOUT``): a crash or a hang there is a
    warning (the runs, isolated, report it), not the end of this process."""
    from ..fmu import is_path, isolate
    errors, bare = [], set()
    sc = plan.scenario
    for u in plan.units:
        settings = plan.params.get(u.name, [])
        if not settings:
            if u.model in bare:
                continue
            bare.add(u.model)
        t = Trial(u.name, u.model, u.path, u.fmi, u.interface, settings)
        if is_path(u.model) and isolate.available():
            kind, result = isolate.in_child(lambda t=t: _trial(t, sc.start_time), TRIAL_TIMEOUT)
            if kind != "ok":
                if warnings is not None:
                    warnings.append(f"{u.name} ({Path(str(u.model)).name}): its trial initialization "
                                    + (f"did not end within {TRIAL_TIMEOUT:g} s" if kind == "timeout" else
                                       f"crashed ({result})") + "; the runs will report it")
                continue
        else:
            result = _trial(t, sc.start_time)
        if result:
            errors.append(result)
    return errors


def override_problems(scenario: Scenario, sets: list[dict], limit: int = 5) -> list[str]:
    """The values of override sets (a campaign's list, grid or sample) checked against the declared
    variables they set, without running anything; at most ``limit`` problems (the first ones)."""
    from .resolve import declared
    out = []
    names = {c.name: c.model for c in scenario.components}
    cache: dict = {}
    for i, ov in enumerate(sets):
        for key, val in ov.items():
            q = key[len("input:"):] if key.startswith("input:") else key
            inst, _, var = q.partition(".")
            if inst not in names:
                out.append(f"set {i}: {key}: no instance {inst!r}{did_you_mean(inst, names)}")
                continue
            if names[inst] not in cache:
                try:
                    cache[names[inst]] = declared(names[inst])
                except Exception:
                    cache[names[inst]] = None
            vs = cache[names[inst]]
            if vs is None:
                continue
            v = vs.get(scenario.native_name(inst, var), vs.get(var))
            if v is None:
                out.append(f"set {i}: {key}: {inst} has no variable {var!r}{did_you_mean(var, vs)}")
            else:
                problem = value_problem(key, v, val)
                if problem:
                    out.append(f"set {i}: {problem}")
            if len(out) >= limit:
                return out
    return out


def resolve_safely(scenario: Scenario, rep: Report) -> Scenario:
    try:
        return resolve(scenario)
    except FileNotFoundError:
        return scenario  # reported by check_unit
    except Exception as e:
        rep.errors.append(f"resolving the scenario: {e}")
        return scenario


def require(scenario: Scenario, instantiate: bool = True, warn=None, **plan) -> Report:
    """Runs :func:`check` (``plan``: its ``log_every``, ``origins``, ``log_hint``); raises
    :class:`IncompatibleUnit` listing every error; passes warnings to ``warn(text)`` (default: nothing).
    The report's ``plan`` is the scenario's plan, ready for an engine."""
    rep = check(scenario, instantiate, **plan)
    if warn is not None:
        for w in rep.warnings:
            warn(w)
    if rep.errors:
        raise IncompatibleUnit(f"scenario {scenario.name!r} cannot run:\n  " + "\n  ".join(rep.errors), rep.errors)
    return rep
