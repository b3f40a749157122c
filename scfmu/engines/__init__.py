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

A run that fails (FMU error status, non-finite logged value) raises ``SimulationError`` with a status
code and the FMUs' log messages.
"""

from __future__ import annotations

import numpy as np

from .lean import LeanMaster, SimulationError, build_fmus, ports_of
from ..scenario.model import Scenario
from ..scenario.resolve import resolve
from .reference import CoSimulation, _Link

ENGINES = ("reference", "lean", "native", "compiled")


def resolve_engine(engine: str) -> str:
    """The engine that runs for ``engine``: ``"auto"`` is ``"compiled"`` when its library is available,
    else ``"native"`` (the same results either way); any other name is returned as is."""
    if engine == "auto":
        from .compiled import available
        return "compiled" if available() else "native"
    return engine


def reference_master(scenario: Scenario, path_of=None, model_exchange=frozenset()) -> tuple[CoSimulation, dict, dict]:
    """(CoSimulation, {instance: Fmu}, log spec) for the scenario; the caller runs and closes it.
    ``path_of(model)`` gives the FMU file of a model (default ``fmus/<Model>.fmu``). The instances
    named in ``model_exchange`` run as FMI 2.0 Model Exchange units integrated by SciPy's solve_ivp
    between communication points (their inputs held over each step)."""
    if path_of is None:
        scenario = resolve(scenario)
    fmus = build_fmus(scenario, path_of=path_of, model_exchange=model_exchange)
    # the scenario's wiring (explicit exceptions included) replaces the master's own name matching
    sim = CoSimulation(list(fmus.values()), unconnected={n for f in fmus.values() for n in f.inputs()})
    sim.links = []
    groups: dict[tuple[str, str], _Link] = {}
    for d, di, s, so in scenario.wiring(ports_of(fmus)):
        link = groups.get((d, s))
        if link is None:
            link = groups[(d, s)] = _Link(fmus[d], [], fmus[s], [])
            sim.links.append(link)
        link.dst_names.append(di)
        link.src_names.append(so)
    log = {key: (fmus[inst], var) for key, inst, var in scenario.log_items()}
    return sim, fmus, log


def run_reference(scenario: Scenario, path_of=None, model_exchange=frozenset()) -> dict[str, np.ndarray]:
    sim, fmus, log = reference_master(scenario, path_of, model_exchange)
    try:
        try:
            return sim.run(scenario.stop_time, scenario.step, log, t0=scenario.start_time)
        except Exception as e:
            msgs = [f"{n}: {m[2]}" for n, f in fmus.items() for m in f.messages if m[0] >= 2]
            raise SimulationError("fmu_error", "; ".join(msgs) or str(e)) from e
    finally:
        sim.close()


class Result(dict):
    """The logged signals of one run: ``{"time": t_k, <log key>: values at t_k}`` (NumPy arrays), plus
    :meth:`to_pandas` and :meth:`to_csv`."""

    def to_pandas(self):
        """A pandas DataFrame indexed by time (pandas is not a dependency of scfmu: install it to use this)."""
        import pandas as pd
        return pd.DataFrame({k: v for k, v in self.items() if k != "time"}, index=pd.Index(self["time"], name="time"))

    def to_csv(self, path, keys=None, every: int = 1) -> None:
        from ..results import write_csv
        write_csv(path, self, keys, every)


def simulate(scenario, engine: str = "native", *, fmus: dict | None = None, overrides: dict | None = None,
             seed: int | None = None, **kw) -> Result:
    """Runs a scenario (a :class:`~scfmu.scenario.Scenario` or a registered name such as ``"default"``) on
    one of the engines (``"native"``, default; ``"compiled"``; ``"auto"``; ``"lean"``; ``"reference"``) and
    returns the logged signals.

    ``fmus``: ``{instance: model name or path to an .fmu}`` replaces components' models; ``overrides``:
    ``{"instance.parameter": value}``; ``seed``: sets the scenario's seed parameters. Engine options
    (``log_every``, ``reuse`` for native) pass through. A failing run raises :class:`SimulationError`
    with a status (``fmu_error``, ``nonfinite``, ...) and the FMUs' messages."""
    if isinstance(scenario, str):
        from ..scenario import get
        scenario = get(scenario)
    if fmus:
        scenario = scenario.with_models(fmus)
    if overrides:
        scenario = scenario.with_overrides(overrides)
    if seed is not None:
        scenario = scenario.with_seed(seed)
    engine = resolve_engine(engine)
    from ..scenario.values import timing_problems  # bounded before any engine allocates its rows
    problems = timing_problems(scenario.start_time, scenario.stop_time, scenario.step,
                               log_every=kw.get("log_every", 1) if engine == "native" else 1)
    if problems:
        raise ValueError(problems[0])
    if engine == "reference":
        out = run_reference(scenario)
    elif engine == "lean":
        with LeanMaster(scenario) as m:
            out = m.run()
    elif engine == "native":
        from .native import NativeLoop
        with NativeLoop(scenario, **kw) as m:
            out = m.run()
    elif engine == "compiled":
        from .compiled import CompiledLoop
        with CompiledLoop(scenario, **kw) as m:
            out = m.run()
    else:
        raise ValueError(f"engine {engine!r}: expected one of {ENGINES} or 'auto'")
    for k, v in out.items():
        if not np.all(np.isfinite(v)):
            i = int(np.argmin(np.isfinite(v)))
            raise SimulationError("nonfinite", f"{k} is not finite at t = {out['time'][i]}", float(out["time"][i]))
    return Result(out)
