"""The engines that run a Scenario, and :func:`simulate`, the one entry point to them.

* ``"native"`` (default): ``native.NativeLoop``, the whole loop inside fmpy's native container FMU (no
  Python per step when ``log_every`` is 0); same coupling as the reference master, bit-identical;
* ``"reference"``: ``reference.CoSimulation`` (fmpy high-level calls, name-based), the tests' oracle;
* ``"lean"``: ``lean.LeanMaster``, same Gauss–Seidel algorithm, bit-identical results, much less overhead;
* ``"compiled"``: ``compiled.CompiledLoop``, the lean master's plan run, logging of every step included,
  by a small compiled library (``scfmu/engines/native_loop``, Rust): no Python per step, bit-identical;
  available when the library is (``compiled.available()``: shipped in the wheel, or built by
  ``cargo build --release`` in a source checkout);
* ``"auto"`` (the campaigns' default): ``"compiled"`` when available, else ``"native"``.

Every engine executes one :class:`~scfmu.scenario.plan.Plan` (built once by :func:`simulate`): units of FMI
2.0 or 3.0, Co-Simulation or Model Exchange, in every engine (fmpy's container, hence the native engine and
loop FMUs, nests a Model Exchange unit as its Co-Simulation face: :mod:`scfmu.engines.cs_face`).

A run that fails (FMU error status, non-finite logged value) raises ``SimulationError`` with a status
code and the FMUs' log messages.
"""

from __future__ import annotations

import numpy as np

from ..scenario.model import Scenario  # noqa: F401  (re-exported)
from ..scenario.plan import Plan, PlanError, build_plan, timing_problem  # noqa: F401  (PlanError re-exported)
from .calls import SimulationError
from .instances import as_plan, build_fmus, ports_of  # noqa: F401
from .lean import LeanMaster
from .reference import CoSimulation, _Link

ENGINES = ("reference", "lean", "native", "compiled")


def resolve_engine(engine: str) -> str:
    """The engine that runs for ``engine``: ``"auto"`` is ``"compiled"`` when its library is available,
    else ``"native"`` (the same results either way); any other name is returned as is."""
    if engine == "auto":
        from .compiled import available
        return "compiled" if available() else "native"
    return engine


def reference_master(scenario, path_of=None, model_exchange=frozenset()) -> tuple[CoSimulation, dict, dict]:
    """(CoSimulation, {instance: Fmu}, log spec) for a scenario or a plan; the caller runs and closes it.
    ``path_of(model)`` gives the FMU file of a model (default ``fmus/<Model>.fmu``). The instances
    named in ``model_exchange`` (or Model Exchange in the plan) run as Model Exchange units integrated by
    SciPy's solve_ivp between communication points (their inputs held over each step)."""
    plan = as_plan(scenario, path_of, model_exchange)
    fmus = build_fmus(plan)
    # the plan's wiring (explicit exceptions included) replaces the master's own name matching
    sim = CoSimulation(list(fmus.values()),
                       links=[_Link(fmus[g.dst], list(g.dst_names), fmus[g.src], list(g.src_names)) for g in plan.groups])
    log = {key: (fmus[g.inst], var) for g in plan.log for key, var in zip(g.keys, g.names)}
    log = {k: log[k] for k in plan.scenario.log}
    return sim, fmus, log


def run_reference(scenario, path_of=None, model_exchange=frozenset()) -> dict[str, np.ndarray]:
    plan = as_plan(scenario, path_of, model_exchange)
    sim, fmus, log = reference_master(plan)
    sc = plan.scenario
    try:
        try:
            return sim.run(sc.stop_time, sc.step, log, t0=sc.start_time)
        except Exception as e:
            msgs = [f"{n}: {m[2]}" for n, f in fmus.items() for m in f.messages if m[0] >= 2]
            raise SimulationError("fmu_error", "; ".join(msgs) or str(e)) from e
    finally:
        sim.close()


class Result(dict):
    """The logged signals of one run: ``{"time": t_k, <log key>: values at t_k}`` (NumPy arrays), plus

    * ``units``: ``{key: unit}`` of every logged signal as its unit declares it ("" when it declares none;
      ``time`` is in s);
    * ``metrics``: the run's metrics of the scenario's metric set (:mod:`scfmu.metrics`), the same numbers
      ``scfmu run`` prints (EULERINT, ISE, settling time, overshoot, final error, ...), and
      ``metric_units``;
    * ``scenario``: the resolved scenario that ran; ``units_of_instances``: ``{instance: model}``;
    * :meth:`to_pandas` (the ``pandas`` extra: ``pip install 'scfmu[pandas]'``) and :meth:`to_csv`."""

    scenario = None
    units: dict = {}

    @property
    def metrics(self) -> dict:
        cached = self.__dict__.get("_metrics")
        if cached is None:
            from .. import metrics as run_metrics
            sc = self.scenario
            cached = self.__dict__["_metrics"] = dict(run_metrics.compute(sc.metrics, self)) if sc is not None and sc.metrics else {}
        return cached

    @property
    def metric_units(self) -> dict:
        from ..results import metric_unit
        return {k: metric_unit(k, self.units, self.scenario.metrics if self.scenario else "") for k in self.metrics}

    @property
    def units_of_instances(self) -> dict:
        return {c.name: c.model for c in self.scenario.components} if self.scenario is not None else {}

    def to_pandas(self):
        """A pandas DataFrame indexed by time (column names carry no units; see ``units``)."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("Result.to_pandas needs pandas: pip install 'scfmu[pandas]'") from None
        return pd.DataFrame({k: v for k, v in self.items() if k != "time"}, index=pd.Index(self["time"], name="time"))

    def to_csv(self, path, keys=None, every: int = 1) -> None:
        from ..results import write_csv
        write_csv(path, self, keys, every)


def log_units(plan: Plan) -> dict:
    """``{log key: unit}`` of a plan's logged signals as their units declare them ("" for none)."""
    from ..results import declared_unit
    out = {"time": "s"}
    for g in plan.log:
        u = plan.unit(g.inst)
        for key, name in zip(g.keys, g.names):
            out[key] = declared_unit(u.vars[name])
    return out


def simulate(scenario, engine: str | None = None, *, fmus: dict | None = None, overrides: dict | None = None,
             seed: int | None = None, model_exchange=frozenset(), clocks: str = "sampled", **kw) -> Result:
    """Runs a scenario (a :class:`~scfmu.scenario.Scenario` or a registered name such as ``"default"``) on
    one of the engines (``"native"``, default; ``"compiled"``; ``"auto"``; ``"lean"``; ``"reference"``) and
    returns the logged signals.

    ``fmus``: ``{instance: model name or path to an .fmu}`` replaces components' models (FMI 2.0 or 3.0,
    Co-Simulation or Model Exchange); ``overrides``: ``{"instance.parameter": value}``; ``seed``: sets the
    scenario's seed parameters; ``model_exchange``: instances to run as Model Exchange units (also
    ``Component.interface = "me"``; a unit that offers Model Exchange only always is). Engine options
    (``log_every``, ``reuse`` for native) pass through. The scenario is resolved once, into one
    :class:`~scfmu.scenario.plan.Plan` that the engine executes. A failing run raises
    :class:`SimulationError` with a status (``fmu_error``, ``nonfinite``, ...) and the FMUs' messages.

    ``clocks``: ``"sampled"`` (default: every unit samples inside ``doStep``), ``"clocked"`` (FMI 3.0 units
    with clocks run on them in clocked Co-Simulation) or ``"scheduled"`` (in Scheduled Execution, by a small
    scheduler): both on the lean master (the default engine then; another engine is a ``ValueError``), with
    bit-identical results (:mod:`scfmu.engines.clocked`). A plan without clocked units is a ``PlanError``."""
    if isinstance(scenario, str):
        from ..scenario import get
        scenario = get(scenario)
    if isinstance(scenario, Plan) and (fmus or overrides or seed is not None or model_exchange):
        raise ValueError("simulate(plan, ...): a plan is fixed; give fmus, overrides, seed and model_exchange "
                         "with a scenario")
    if fmus:
        scenario = scenario.with_models(fmus)
    if overrides:
        scenario = scenario.with_overrides(overrides)
    if seed is not None:
        scenario = scenario.with_seed(seed)
    if clocks not in ("sampled", "clocked", "scheduled"):
        raise ValueError(f"clocks {clocks!r}: expected 'sampled', 'clocked' or 'scheduled'")
    if clocks != "sampled" and engine not in (None, "lean"):
        raise ValueError(f"clocks {clocks!r} runs on the lean engine (its clocked master), not {engine!r}")
    engine = resolve_engine(engine or ("native" if clocks == "sampled" else "lean"))
    if engine not in ENGINES:
        raise ValueError(f"engine {engine!r}: expected one of {ENGINES} or 'auto'")
    log_every = kw.get("log_every", 1) if engine == "native" else 1
    if isinstance(scenario, Plan):  # its timing was checked when it was built; a coarser log grid has fewer rows
        plan = scenario
        if log_every != plan.log_every:  # (the rows bounded before an engine allocates them)
            why = timing_problem(plan.scenario, log_every)
            if why:
                raise PlanError(why)
    else:  # the timing, the logged rows among it, is checked before any engine allocates its rows
        plan = build_plan(scenario, model_exchange=model_exchange, log_every=log_every)
    if engine == "reference":
        out = run_reference(plan)
    elif clocks != "sampled":
        from .clocked import ClockedMaster
        from .scheduler import Scheduler
        with (ClockedMaster if clocks == "clocked" else Scheduler)(plan) as m:
            out = m.run()
    elif engine == "lean":
        with LeanMaster(plan) as m:
            out = m.run()
    elif engine == "native":
        from .native import NativeLoop
        with NativeLoop(plan, **kw) as m:
            out = m.run()
    else:
        from .compiled import CompiledLoop
        with CompiledLoop(plan, **kw) as m:
            out = m.run()
    for k, v in out.items():
        if not np.all(np.isfinite(v)):
            i = int(np.argmin(np.isfinite(v)))
            raise SimulationError("nonfinite", f"{k} is not finite at t = {out['time'][i]}", float(out["time"][i]))
    res = Result(out)
    res.scenario = plan.scenario
    res.units = log_units(plan)
    return res
