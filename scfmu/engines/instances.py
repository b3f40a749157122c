"""Instantiating and initializing the units of a plan, the same way for every engine that holds the
instances itself (reference, lean, compiled). A plan's parameters and fixed inputs are set through
:func:`~scfmu.scenario.settings.apply_params` (imported here for every engine: native, libcosim too), with
:func:`fmu_setter` for an instance."""

from __future__ import annotations

from ..fmu import Fmu, unpacked
from ..scenario.model import Scenario
from ..scenario.plan import Plan, apply_params, build_plan  # noqa: F401  (apply_params: every engine's)
from .calls import SimulationError


def as_plan(scenario, path_of=None, model_exchange=frozenset()) -> Plan:
    """A :class:`Plan` as given, or the plan of a scenario (resolved once here)."""
    if isinstance(scenario, Plan):
        if model_exchange and not set(model_exchange) <= scenario.model_exchange:
            raise ValueError("model_exchange: give it to build_plan (the plan fixes each instance's interface)")
        return scenario
    return build_plan(scenario, path_of=path_of, model_exchange=model_exchange)


def build_fmus(plan, path_of=None, reuse: bool = False, model_exchange=frozenset(), clocking: dict | None = None,
               preemption=None, in_init=None) -> dict[str, Fmu]:
    """Instantiates and initializes every instance of the plan (or of a scenario: its plan is built),
    parameters in initialization mode, then writes the fixed ``inputs``. Returns {instance name: Fmu}
    in Gauss–Seidel order. With ``reuse`` the FMUs are unpacked once per process. Model Exchange
    instances run under SciPy's solve_ivp (:class:`scfmu.fmu.Fmu`) with their plan's solver settings.
    ``clocking``: ``{instance: "event" | "scheduled"}``, the FMI 3.0 units instantiated to run on their clocks
    (``eventModeUsed = true``, or Scheduled Execution with the ``preemption`` callbacks); ``in_init(name,
    fmu)`` is called in Initialization Mode after the parameters (where clock intervals are read)."""
    plan = as_plan(plan, path_of, model_exchange)
    fmus: dict[str, Fmu] = {}
    try:
        for u in plan.units:
            kw = {}
            if u.interface == "me":
                kw = {"me_method": u.solver["method"], "me_rtol": u.solver["rtol"], "me_atol": u.solver["atol"],
                      "me_max_step": u.solver["max_step"]}
            fmus[u.name] = Fmu(u.model, name=u.name, start_time=plan.scenario.start_time, path=u.path,
                               initialize=False, unpacked=unpacked(u.path) if reuse else None,
                               interface=u.interface, clocking=(clocking or {}).get(u.name, ""),
                               preemption=preemption, **kw)
        initialize_fmus(fmus, plan, in_init)
    except Exception:
        for f in fmus.values():
            f.close()
        raise
    return fmus


def fmu_setter(f: Fmu):
    """``set_values`` of :func:`apply_params` for an :class:`~scfmu.fmu.Fmu` (its by-reference setter)."""
    return f.set_refs


def initialize_fmus(fmus: dict[str, Fmu], plan, in_init=None) -> None:
    """Initializes instantiated (or reset) FMUs: set-up, parameters in initialization mode, then the
    fixed ``inputs`` (both through :func:`apply_params`). Raises SimulationError when an FMU refuses to
    initialize."""
    plan = as_plan(plan)
    scenario: Scenario = plan.scenario
    for c in scenario.components:
        f = fmus[c.name]
        f.enter_initialization_mode(scenario.start_time)
        apply_params(plan.params[c.name], fmu_setter(f))
        if in_init is not None:
            in_init(c.name, f)
        try:
            f.exit_initialization_mode()
        except Exception as e:
            msgs = "; ".join(m[2] for m in f.messages if m[0] >= 2)
            what = "fmi2ExitInitializationMode" if f.fmi == 2 else "fmi3ExitInitializationMode"
            raise SimulationError("fmu_error", f"{c.name} ({c.model}): {what} failed"
                                  + (f": {msgs}" if msgs else (f": {e}" if f.interface == "me" else ""))) from None
    for c in scenario.components:
        apply_params(plan.inputs[c.name], fmu_setter(fmus[c.name]))


def ports_of(fmus: dict[str, Fmu]) -> dict[str, tuple[list[str], list[str]]]:
    return {name: (f.inputs(), f.outputs()) for name, f in fmus.items()}
