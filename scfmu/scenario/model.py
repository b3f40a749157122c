"""A closed-loop scenario declared once, as plain data.

A :class:`Scenario` names the FMUs of a loop (instance name + model), their order for the Gauss–Seidel
master, the parameters of each instance, the wiring, the stop time and communication step, and the
signals to log. It holds only dataclasses, dicts, lists, strings and numbers, so the same declaration
feeds every master of this package (the reference fmpy master, the lean master, the native container
path), the campaign engine, and later an SSP description (``to_dict`` gives a JSON-ready form).

Wiring. With ``auto_connect`` (default) every input of an instance is fed from the output of the same
name of exactly one *other* instance. Exceptions are explicit:

* ``connections``: ``{"dst_instance.input": "src_instance.output"}``, which takes precedence over the
  name match (use it when names differ or when several instances have the output);
* ``terminals``: ``{"dst_instance.terminal": "src_instance.terminal"}``, FMI 3.0 terminals connected as
  one, expanded into their scalar links by the terminals' matching rule (:mod:`scfmu.scenario.terminals`;
  e.g. ``{"controller.attitude": "plant.attitude", "plant.torque_cmd": "controller.torque_cmd"}``);
* ``unconnected``: glob patterns (``fnmatch``) of inputs, bare (``"torque_dist_*"``) or qualified
  (``"plant.torque_dist_*"``), left at their start value (or at the value given in ``inputs``).
  ``DEFAULT_UNCONNECTED`` lists the optional inputs of the current FMUs (disturbance inputs, wheel
  momentum, reference-rate feed-forward, leader anomaly, the plant's magnetorquer command, used only with
  mtq_mode = 1 or 2, the Mekf's coarse re-initialisation) that the historical master left open.

An input that has no source and matches no ``unconnected`` pattern is an error.

Parameters are set in initialization mode (``Component.params``, name → value; integers stay
integers). ``inputs`` are values written once after initialization into unconnected inputs (e.g. a
constant disturbance). Overrides use qualified names ``"instance.variable"``: a parameter of an
instance or a fixed input (see :meth:`Scenario.with_overrides`).
"""

from __future__ import annotations

import copy
import fnmatch
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

DEFAULT_UNCONNECTED = ("torque_dist_*", "dist_*", "h_wheel*", "q_ref_dot*", "q_ref_ddot*", "leader_true_anomaly",
                       "m_cmd_*",
                       # PdController's reference acceleration, read with rate_feedforward = 2 only
                       "w_ref_dot_*",
                       # the environment inputs of AttitudePlant, Magnetometer (b_eci), SunSensor (sun_eci,
                       # eclipse) and Ephemeris (r, jd_utc), read with environment_inputs = 1 only (which refuses an
                       # unwired r, b_eci, sun_eci or jd_utc), and Orbit's density (0 = no drag); r, v and jd_utc
                       # by model, as Environment's r must stay wired
                       "AttitudePlant:r_*", "AttitudePlant:v_*", "Ephemeris:r_*", "Ephemeris:jd_utc", "b_eci_*",
                       "sun_eci_*", "eclipse", "rho", "sun_distance",
                       # AttitudeCommand's orbit inputs, read with reference = 1 (nadir) only (which refuses them unwired)
                       "AttitudeCommand:r_*", "AttitudeCommand:v_*",
                       # the Mekf's coarse re-initialisation, read only while init_request >= 0.5 (start 0)
                       "Mekf:q_coarse_*", "Mekf:init_request")


def matches_input(port: str, patterns, instance: str | None = None, *, stems: bool = False,
                  model: str | None = None) -> bool:
    """Whether input ``port`` (of ``instance``, when given) matches one of the glob ``patterns`` (``fnmatch``,
    case-sensitive): the one matcher of the ``unconnected`` lists.

    A bare pattern (``"torque_dist_*"``) names that port of any instance; a qualified one
    (``"plant.torque_dist_*"``) names it in one instance and matches only when ``instance`` is given; a
    model-qualified one (``"AttitudePlant:r_*"``) names it in every instance of that model (the file name
    without ``.fmu`` of a path) and matches only when ``model`` is given. With
    ``stems``, a pattern ``"x_*"`` also covers the scalar port ``"x"`` (SingleAxisPlant's ``torque_dist``
    against ``"torque_dist_*"``): the reference master's reading of the optional inputs; a scenario's own
    ``unconnected`` list names such a port as it is (paper002 lists ``"torque_dist"``)."""
    for pat in patterns:
        if ":" in pat:
            if model is not None and fnmatch.fnmatchcase(f"{Path(str(model)).name.removesuffix('.fmu')}:{port}", pat):
                return True
        elif "." in pat:
            if instance is not None and fnmatch.fnmatchcase(f"{instance}.{port}", pat):
                return True
        elif fnmatch.fnmatchcase(port, pat) or (stems and port == pat.removesuffix("_*")):
            return True
    return False


@dataclass
class Component:
    """One FMU instance in a place of the loop.

    * ``name``: instance name, unique in the scenario;
    * ``model``: a model name (``<FMU folder>/<model>.fmu``) or a path to any FMI 2.0 or 3.0 FMU;
    * ``params``: parameters of *that model* (set in initialization mode; an unknown name is an error).
      They belong to the model: swapping the model (:meth:`Scenario.with_models`) drops them;
    * ``slot``: parameters that any unit in this place is given *if it declares them* (e.g. the nominal
      inertia an attitude controller should assume); they survive a swap;
    * ``ports``: renames ``{"the unit's port name": "the scenario's port name"}`` for a unit whose port
      names differ from the family's (``--map``); a vector stem (``"omega": "w"``) renames every element
      (``omega_x`` plays ``w_x``, …), and a name that is a *parameter* of the unit binds it to a slot value
      (``"J1": "inertia_xx"``; see ``bind``);
    * ``bind``: ``{"the unit's parameter": slot name, number or expression of slot values}`` (a unit
      profile, :mod:`scfmu.scenario.profile`), evaluated when the scenario is resolved;
    * ``unused``: slot names the unit is declared not to take (no "not passed" warning for them).
    ``bind`` and ``unused`` belong to the model like ``params``: a swap drops them.
    * ``interface``: ``"cs"`` (Co-Simulation), ``"me"`` (Model Exchange, integrated by the engine) or
      ``""`` (default: Co-Simulation when the unit offers it, else Model Exchange);
    * ``solver``: for a Model Exchange instance, ``{"method": ..., "rtol": ..., "atol": ...}`` (default
      DOP853, 1e-10, 1e-12; see :mod:`scfmu.scenario.plan`).
    """

    name: str
    model: str
    params: dict = field(default_factory=dict)
    slot: dict = field(default_factory=dict)
    ports: dict = field(default_factory=dict)
    bind: dict = field(default_factory=dict)
    unused: list = field(default_factory=list)
    interface: str = ""
    solver: dict = field(default_factory=dict)


@dataclass
class Scenario:
    name: str
    components: list[Component]  # Gauss–Seidel order
    stop_time: float
    step: float
    log: dict = field(default_factory=dict)  # key -> "instance.variable"
    connections: dict = field(default_factory=dict)  # "dst.input" -> "src.output" (exceptions to name matching)
    terminals: dict = field(default_factory=dict)  # "dst.terminal" -> "src.terminal" (FMI 3.0 terminals)
    unconnected: list = field(default_factory=lambda: list(DEFAULT_UNCONNECTED))
    inputs: dict = field(default_factory=dict)  # "instance.input" -> value, written after initialization
    auto_connect: bool = True
    seed_params: list = field(default_factory=list)  # "instance.param" (Integer) that receive a run's seed
    start_time: float = 0.0
    metrics: str = ""  # name of a registered metric set ("attitude", "formation", "paper003", ...)
    description: str = ""
    swapped: list = field(default_factory=list)  # instances whose model was replaced (with_models)

    # ----- access ---------------------------------------------------------------------------------------
    def component(self, name: str) -> Component:
        for c in self.components:
            if c.name == name:
                return c
        raise KeyError(f"scenario {self.name!r} has no instance {name!r} (has {[c.name for c in self.components]})")

    @property
    def n_steps(self) -> int:
        from .values import timing_problems  # finite, positive, bounded (never an OverflowError/MemoryError)
        problems = timing_problems(self.start_time, self.stop_time, self.step, log_every=None)
        if problems:
            raise ValueError(problems[0])
        n = int(round((self.stop_time - self.start_time) / self.step))
        if n <= 0 or abs(n * self.step - (self.stop_time - self.start_time)) > 1e-9 * max(1.0, abs(self.stop_time)):
            raise ValueError(f"stop_time - start_time = {self.stop_time - self.start_time} is not a positive "
                             f"multiple of step = {self.step}")
        return n

    def with_seed(self, seed: int | None) -> "Scenario":
        """A copy whose ``seed_params`` are set to ``seed`` (unchanged copy when seed is None)."""
        if seed is None:
            return copy.deepcopy(self)
        return self.with_overrides({p: int(seed) for p in self.seed_params})

    def to_dict(self) -> dict:
        d = asdict(self)
        if not d["terminals"]:  # likewise a scenario without terminal connections
            del d["terminals"]
        for c in d["components"]:  # empty bindings left out: the plain data (and campaign ids) of scenarios
            for k in ("bind", "unused"):  # without them are what they were before they existed
                if not c[k]:
                    del c[k]
        return d

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_dict(cls, d: dict) -> "Scenario":
        d = dict(d)
        d["components"] = [Component(**c) for c in d["components"]]
        return cls(**d)

    def alias(self, inst: str, port: str) -> str:
        """The scenario's name of ``inst``'s port ``port`` (after the component's ``ports`` renames)."""
        return self.component(inst).ports.get(port, port)

    def native_name(self, inst: str, port: str) -> str:
        """The unit's own name of the scenario's port ``port`` of ``inst`` (inverse of :meth:`alias`)."""
        for theirs, ours in self.component(inst).ports.items():
            if ours == port:
                return theirs
        return port

    # ----- variations -----------------------------------------------------------------------------------
    def with_models(self, models: dict) -> "Scenario":
        """A copy whose instances use other models: ``{instance: model name or path to an .fmu}``. An
        instance whose model changes loses the parameters of its old model (``params``; see
        :meth:`dropped_params`) and keeps its ``slot`` parameters and wiring; set the new model's own
        parameters with :meth:`with_overrides`."""
        s = copy.deepcopy(self)
        for inst, model in models.items():
            c = s.component(inst)
            if str(model) != c.model:
                c.model = str(model)
                c.params = {}
                c.ports = {}
                c.bind = {}
                c.unused = []
                if inst not in s.swapped:
                    s.swapped.append(inst)
        return s

    def dropped_params(self, models: dict) -> dict:
        """``{instance: [parameter names]}`` that :meth:`with_models` with these models would drop."""
        out = {}
        for inst, model in models.items():
            c = self.component(inst)
            if str(model) != c.model and c.params:
                out[inst] = sorted(c.params)
        return out

    def with_port_map(self, maps: dict) -> "Scenario":
        """A copy with port renames ``{"instance.their_name": "our_name"}`` (``--map``)."""
        s = copy.deepcopy(self)
        for key, ours in maps.items():
            inst, sep, theirs = key.partition(".")
            if not sep or not theirs or not ours:
                raise KeyError(f"port map {key!r}={ours!r}: expected INSTANCE.THEIR_NAME=OUR_NAME")
            s.component(inst).ports[theirs] = ours
        return s

    def with_overrides(self, overrides: dict | None = None, **fields) -> "Scenario":
        """A copy with ``overrides`` applied: ``"instance.name" -> value`` sets a parameter of that instance,
        or, when ``instance.name`` is a key of ``inputs`` (or an unconnected input listed with ``input:``
        prefix, ``"input:plant.torque_dist_x"``), a fixed input. Scenario fields (``stop_time``, ``step``...)
        can be changed by keyword."""
        s = copy.deepcopy(self)
        for k, v in fields.items():
            if not hasattr(s, k):
                raise KeyError(f"Scenario has no field {k!r}")
            setattr(s, k, v)
        for key, value in (overrides or {}).items():
            if key.startswith("input:"):
                s.inputs[key[len("input:"):]] = value
                continue
            if key in s.inputs:
                s.inputs[key] = value
                continue
            inst, sep, var = key.partition(".")
            if not sep or not var:
                raise KeyError(f"override {key!r}: expected 'instance.variable'")
            s.component(inst).params[var] = value
        return s

    # ----- wiring ---------------------------------------------------------------------------------------
    def _connections(self, terminals) -> dict:
        """``connections`` with the scalar links of the ``terminals`` entries (:mod:`.terminals`)."""
        from .terminals import expand
        links, problems = expand(self, terminals)
        if problems:
            raise ValueError(problems[0])
        return {**links, **self.connections}

    def wiring(self, ports: dict[str, tuple[list[str], list[str]]],
               terminals: dict | None = None) -> list[tuple[str, str, str, str]]:
        """Resolves the connections given each instance's (inputs, outputs) port names (``ports[name]``)
        and, for the ``terminals`` entries, each instance's FMI 3.0 terminals (``terminals[name]``).
        Returns ``(dst_instance, dst_input, src_instance, src_output)`` in Gauss–Seidel order: grouped by
        destination in component order, and within a destination by source (in the order sources first
        appear among the destination's inputs), each group keeping the destination's input order: the
        order the reference master (``master.CoSimulation``) uses."""
        names = [c.name for c in self.components]
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate instance names in {names}")
        connections = self._connections(terminals)
        # match on the scenario's names (a unit's own port names renamed by its ``ports`` map); links are
        # returned with the units' own names
        ports = {n: ([self.alias(n, p) for p in ports[n][0]], [self.alias(n, p) for p in ports[n][1]])
                 for n in names}
        for dst, src in connections.items():
            for q in (dst, src):
                inst, _, var = q.partition(".")
                if inst not in ports:
                    raise KeyError(f"connection {dst} <- {src}: unknown instance {inst!r}")
            di, _, dv = dst.partition(".")
            si, _, sv = src.partition(".")
            if dv not in ports[di][0]:
                raise KeyError(f"connection {dst} <- {src}: {di} has no input {dv!r}")
            if sv not in ports[si][1]:
                raise KeyError(f"connection {dst} <- {src}: {si} has no output {sv!r}")
        links = []
        for dst in names:
            per_src: dict[str, list[tuple[str, str]]] = {}
            for inp in ports[dst][0]:
                q = f"{dst}.{inp}"
                if q in connections:
                    si, _, sv = connections[q].partition(".")
                    per_src.setdefault(si, []).append((inp, sv))
                    continue
                if q in self.inputs or f"{dst}.{self.native_name(dst, inp)}" in self.inputs:
                    continue
                sources = [s for s in names if s != dst and inp in ports[s][1]] if self.auto_connect else []
                if len(sources) > 1:
                    raise ValueError(f"input {q} has several sources {sources}: add it to connections")
                if not sources:
                    # the unconnected patterns only name inputs that may stay open when nothing feeds them
                    if self._is_unconnected(dst, inp):
                        continue
                    raise ValueError(f"input {q} has no source: add it to connections, unconnected or inputs")
                per_src.setdefault(sources[0], []).append((inp, inp))
            for src, pairs in per_src.items():  # sources in order of first appearance among dst's inputs
                for inp, out in pairs:
                    links.append((dst, self.native_name(dst, inp), src, self.native_name(src, out)))
        return links

    def wiring_problems(self, ports: dict[str, tuple[list[str], list[str]]], terminals: dict | None = None) -> list[str]:
        """Every reason :meth:`wiring` would refuse, not only the first (terminal connections that do not
        match, inputs without a source or with several, explicit connections naming unknown ports)."""
        from .terminals import expand
        try:
            self.wiring(ports, terminals)
            return []
        except (KeyError, ValueError):
            pass
        by_terminal, out = expand(self, terminals)
        connections = {**by_terminal, **self.connections}
        names = [c.name for c in self.components]
        ours = {n: ([self.alias(n, p) for p in ports[n][0]], [self.alias(n, p) for p in ports[n][1]]) for n in names}
        for dst, src in connections.items():
            di, _, dv = dst.partition(".")
            si, _, sv = src.partition(".")
            if di not in ours or dv not in ours[di][0]:
                out.append(f"connection {dst} <- {src}: no input {dst}")
            if si not in ours or sv not in ours[si][1]:
                out.append(f"connection {dst} <- {src}: no output {src}")
        for dst in names:
            for inp in ours[dst][0]:
                q = f"{dst}.{inp}"
                if q in connections or q in self.inputs:
                    continue
                sources = [s for s in names if s != dst and inp in ours[s][1]] if self.auto_connect else []
                if len(sources) > 1:
                    out.append(f"input {q} has several sources {sources}")
                elif not sources and not self._is_unconnected(dst, inp):
                    out.append(f"input {q} has no source")
        return out

    def _is_unconnected(self, inst: str, port: str) -> bool:
        model = next((c.model for c in self.components if c.name == inst), None)
        return matches_input(port, self.unconnected, inst, model=model)

    def log_items(self) -> list[tuple[str, str, str]]:
        """(key, instance, variable) of every logged signal."""
        out = []
        for key, q in self.log.items():
            inst, sep, var = q.partition(".")
            if not sep:
                raise ValueError(f"log entry {key!r}: {q!r} is not 'instance.variable'")
            out.append((key, inst, var))
        return out


def log_of(instance: str, names) -> dict:
    """``{name: "instance.name"}`` for each name: the usual way to log an instance's ports under their names."""
    return {n: f"{instance}.{n}" for n in names}


def load(path: str | Path) -> Scenario:
    return Scenario.from_dict(json.loads(Path(path).read_text()))
