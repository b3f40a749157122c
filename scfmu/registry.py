"""The registry that plug-ins fill: scenarios, metric sets, paper commands and report sections.

Everything that crosses a process boundary (a Dask worker, a campaign manifest, a scenario file) names
scenarios and metric sets by *name*; this module resolves a name to the code that builds or computes it.
It imports nothing else of the package: the engines and the campaign engine look names up here and
never import a paper.

Plug-ins are modules listed under the entry-point group ``scfmu.plugins`` (``pyproject.toml``; a user's
own package can add its own). Each exposes ``register(registry: Registry)``. They are loaded once, the
first time a name is looked up that is not yet known, or when :func:`load_plugins` is called.

Adding a paper is one folder, ``scfmu/papers/paperNNN/``, whose ``__init__.py`` has ``register``, plus
one line in ``[project.entry-points."scfmu.plugins"]``.
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass, field
from importlib import metadata
from typing import Callable

GROUP = "scfmu.plugins"


@dataclass
class ScenarioSource:
    """Scenarios whose names start with ``prefix`` (``"paper000"``, or a whole name such as ``"default"``).

    ``build(name, **kw)`` returns the :class:`scfmu.scenario.Scenario` of a full name (it may accept names
    not listed, e.g. a parameter in the name); ``names()`` lists ``(name, description)`` of the standard
    ones."""
    prefix: str
    build: Callable
    names: Callable[[], list]
    exported: tuple = ()
    plugin: str = ""


@dataclass
class MetricSet:
    """A metric set: ``compute(logged: dict) -> dict`` and the ``columns`` it returns (the schema of a
    failed run's row). ``logs`` lists the log keys it reads (``None``: it may read any logged key)."""
    name: str
    compute: Callable[[dict], dict]
    columns: tuple
    logs: tuple | None = None
    plugin: str = ""


@dataclass
class Paper:
    """A paper plug-in: ``key`` ("000"), ``title``, ``commands`` ({name: (help, main)}), ``report`` (the
    section builder ``build(ctx) -> PaperSection``, or None) and ``docs`` (its page in the repository's
    docs/). ``main`` and ``report`` are callables or ``"module:function"`` strings, imported only when
    used (:func:`resolve`), so that loading the plug-ins stays cheap."""
    key: str
    title: str
    commands: dict = field(default_factory=dict)
    report: Callable | None = None
    docs: str = ""
    plugin: str = ""


@dataclass
class BenchmarkCase:
    """A scenario of a family's controller benchmark: the unit under test takes the place ``slot``;
    ``seeds`` > 0 makes it a Monte Carlo over that many seeds (0 … seeds-1) of the scenario's seed
    parameters; ``primary`` is the metric that ranks the controllers (lower is better)."""
    family: str
    scenario: str
    label: str
    slot: str = "controller"
    seeds: int = 0
    primary: str = "eulerint_deg_s"
    signal: str = "alpha_deg"  # the logged signal the response figure overlays
    overrides: dict = field(default_factory=dict)  # fixed overrides of the scenario for this case
    monte_carlo: str = ""  # "module:function" (n) -> n override dicts; else `seeds` go to the seed parameters
    plugin: str = ""


@dataclass
class MissionCase:
    """A mission scenario of a family's benchmark (``scfmu benchmark --mission``): each controller takes the
    place ``slot`` (the FINE_POINTING law) in ``runs`` dispersed runs of ``scenario`` (its registered
    dispersions, the same draws for every controller); ``metric`` (seconds, lower is better; never reached:
    not finite) ranks them by its p95, ``handover`` is reported beside it."""
    family: str
    scenario: str
    label: str
    slot: str = "controller"
    runs: int = 20
    quick_runs: int = 4
    metric: str = "t_on_target_s"
    handover: str = "t_fine_pointing_s"
    plugin: str = ""


@dataclass
class BuiltinController:
    """A controller of the family that the benchmark runs beside the user's: a model, its parameters (its
    paper's tuning) and its design envelope, i.e. how it is configured on each benchmark scenario:

    * ``home``: glob patterns of the scenario names its paper's tuning was made for (default: the scenarios
      the same plug-in registers); there it runs with ``params`` (plus the place's slot values);
    * ``retune``: elsewhere, ``"module:function"`` (or a callable) ``(slot: dict, scenario) -> (params,
      rule)``: the parameters for that plant from the place's slot values and the scenario (inertia, run
      length, …) and one sentence stating the rule; it may raise ``ValueError(reason)`` for a plant it has
      no rule for;
    * ``outside``: without ``retune`` (or when it refuses), the reason shown as "not designed for this
      plant" (the pair is listed, not run);
    * ``unused``: slot values its law does not take (e.g. products of inertia for a diagonal-inertia law),
      stated on the page instead of warned about."""
    family: str
    model: str
    label: str
    params: dict = field(default_factory=dict)
    plugin: str = ""
    home: tuple = ()
    retune: object = None
    outside: str = ""
    unused: tuple = ()


class Registry:
    def __init__(self):
        self.scenario_sources: dict[str, ScenarioSource] = {}
        self.metric_sets: dict[str, MetricSet] = {}
        self.papers: dict[str, Paper] = {}
        self.benchmark_cases: list[BenchmarkCase] = []
        self.controllers: list[BuiltinController] = []
        self.mission_cases: list[MissionCase] = []
        self.dispersion_sets: dict[str, dict] = {}
        self._loaded = False
        self._current = ""

    # ----- filled by plug-ins ---------------------------------------------------------------------
    def scenarios(self, prefix: str, build: Callable, names: Callable[[], list], exported=()) -> None:
        """Scenarios named ``prefix`` or ``prefix/...``; ``exported``: the names written as SSP files and
        loop FMUs by ``scfmu export`` (and ``scripts/build_fmus.sh``)."""
        if prefix in self.scenario_sources:
            raise ValueError(f"scenario prefix {prefix!r} registered twice "
                             f"({self.scenario_sources[prefix].plugin} and {self._current})")
        self.scenario_sources[prefix] = ScenarioSource(prefix, build, names, tuple(exported), self._current)

    def dispersions(self, scenario: str, space: dict) -> None:
        """The default dispersions of ``scenario``'s Monte Carlo campaign (``scfmu campaign NAME --runs N``):
        ``{"instance.parameter": "DIST:A:B"}`` in the syntax of ``scfmu campaign --random``."""
        if scenario in self.dispersion_sets:
            raise ValueError(f"dispersions of {scenario!r} registered twice")
        self.dispersion_sets[scenario] = dict(space)

    def dispersions_of(self, scenario: str) -> dict:
        """The registered dispersions of ``scenario`` ({} when it has none)."""
        self.load()
        return dict(self.dispersion_sets.get(scenario, {}))

    def metrics(self, name: str, compute: Callable, columns, logs=None) -> None:
        if name in self.metric_sets and self.metric_sets[name].compute is not compute:
            raise ValueError(f"metric set {name!r} registered twice")
        self.metric_sets[name] = MetricSet(name, compute, tuple(columns), None if logs is None else tuple(logs),
                                           self._current)

    def paper(self, key: str, title: str, commands: dict | None = None, report: Callable | None = None,
              docs: str = "") -> None:
        if key in self.papers:
            raise ValueError(f"paper {key!r} registered twice")
        self.papers[key] = Paper(key, title, dict(commands or {}), report, docs, self._current)

    def benchmark(self, family: str, scenario: str, label: str, slot: str = "controller", seeds: int = 0,
                  primary: str = "eulerint_deg_s", signal: str = "alpha_deg", overrides: dict | None = None,
                  monte_carlo: str = "") -> None:
        """A scenario of ``family``'s controller benchmark (``scfmu benchmark --family``)."""
        self.benchmark_cases.append(BenchmarkCase(family, scenario, label, slot, seeds, primary, signal,
                                                  dict(overrides or {}), monte_carlo, self._current))

    def mission(self, family: str, scenario: str, label: str, **kw) -> None:
        """A mission scenario of ``family``'s benchmark (``scfmu benchmark --mission``; :class:`MissionCase`)."""
        self.mission_cases.append(MissionCase(family, scenario, label, **kw, plugin=self._current))

    def controller(self, family: str, model: str, label: str, params: dict | None = None, home=(), retune=None,
                   outside: str = "", unused=()) -> None:
        """A built-in controller the benchmark compares a user's unit with (see :class:`BuiltinController`
        for its design envelope: ``home``, ``retune``, ``outside``, ``unused``)."""
        self.controllers.append(BuiltinController(family, model, label, dict(params or {}), self._current,
                                                  tuple(home), retune, outside, tuple(unused)))

    def families(self) -> list[str]:
        self.load()
        return sorted({c.family for c in self.benchmark_cases})

    # ----- loading ----------------------------------------------------------------------------------
    def load(self) -> None:
        if self._loaded:
            return
        self._loaded = True
        eps = sorted(metadata.entry_points(group=GROUP), key=lambda e: e.name)
        if not eps:
            raise RuntimeError("no scfmu plug-ins found: the package is not installed (pip install -e . in a "
                               "checkout, or pip install the wheel)")
        for ep in eps:
            self._current = ep.value
            try:
                ep.load()(self)
            finally:
                self._current = ""

    # ----- look-ups ---------------------------------------------------------------------------------
    def scenario(self, name: str, **kw):
        src = self._source(name)
        return src.build(name, **kw)

    def _source(self, name: str) -> ScenarioSource:
        self.load()
        head = name.split("/")[0]
        for key in (name, head):
            if key in self.scenario_sources:
                return self.scenario_sources[key]
        raise KeyError(f"unknown scenario {name!r}; known prefixes: {', '.join(sorted(self.scenario_sources))} "
                       f"(`scfmu scenarios` lists them)")

    def scenario_names(self, pattern: str = "*") -> list[tuple[str, str]]:
        """(name, description) of every standard scenario, optionally filtered by a glob pattern."""
        self.load()
        out = []
        for src in self.scenario_sources.values():
            out.extend((n, d) for n, d in src.names() if fnmatch.fnmatchcase(n, pattern))
        return out

    def exported_scenarios(self) -> list[str]:
        """The scenarios written as SSP files and loop FMUs, in plug-in order."""
        self.load()
        return [n for src in self.scenario_sources.values() for n in src.exported]

    def metric_set(self, name: str) -> MetricSet:
        if name not in self.metric_sets:
            self.load()
        try:
            return self.metric_sets[name]
        except KeyError:
            raise KeyError(f"unknown metric set {name!r}; known: {', '.join(sorted(self.metric_sets))}") from None

    def paper_plugin(self, key: str) -> Paper:
        self.load()
        key = key.zfill(3) if key.isdigit() else key
        try:
            return self.papers[key]
        except KeyError:
            raise KeyError(f"no paper {key} registered; known: {', '.join(sorted(self.papers))}") from None

    def all_papers(self) -> list[Paper]:
        self.load()
        return [self.papers[k] for k in sorted(self.papers)]


def resolve(ref):
    """A callable, or the object named by a ``"module:attribute"`` string."""
    if callable(ref):
        return ref
    import importlib
    mod, _, attr = str(ref).partition(":")
    return getattr(importlib.import_module(mod), attr)


REGISTRY = Registry()


def load_plugins() -> Registry:
    REGISTRY.load()
    return REGISTRY
