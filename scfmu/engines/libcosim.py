"""A Scenario on libcosim (DNV Open Simulation Platform, via libcosimpy): a second, independent native
master, used to cross-check the project's masters and in the benchmarks.

libcosim's fixed-step algorithm steps all instances over [t_k, t_k + Δ] and then transfers the
connected values (a Jacobi scheme): an output computed at t_k reaches its destination for the step
that starts at t_k + Δ, one step later than in the project's Gauss–Seidel masters. Results therefore
differ by that coupling delay (run 000-6: EULERINT 155.76 vs 156.41 deg·s), not by round-off.

Times and step sizes are integer nanoseconds in libcosim (a float step such as 0.01 would be truncated
to 0 by the C API and make it dereference a null execution), so they are converted here.
"""

from __future__ import annotations

import time

import numpy as np

from ..scenario.model import Scenario
from .instances import apply_params, as_plan

NS = 10**9


def _libcosimpy_version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("libcosimpy")
    except PackageNotFoundError:
        return "(not installed)"


def _last_error() -> str:
    try:
        from libcosimpy._internal import get_last_error_message
        return get_last_error_message() or "(no message)"
    except Exception as e:  # a libcosimpy without it
        return f"(no message: {e})"


def _initial_values(ex, slave: int, inst: str, settings):
    """``set_values`` of :func:`~scfmu.scenario.plan.apply_params` for a libcosim slave: its initial values."""
    init = {"Real": (ex.real_initial_value, float), "Integer": (ex.integer_initial_value, int),
            "Boolean": (ex.boolean_initial_value, bool)}
    names = {s.vr: s.name for s in settings}

    def set_values(fmi_type, vrs, values):
        fn, conv = init[fmi_type]
        for vr, v in zip(vrs, values):
            if not fn(slave, vr, conv(v)):
                raise RuntimeError(f"libcosim: cannot set {inst}.{names[vr]}")
    return set_values


def run_libcosim(scenario: Scenario) -> dict:
    """Runs the scenario (or its plan) to its stop time; returns the final value of every logged key plus
    ``wall_s`` (the simulate_until call only). Co-Simulation units only (libcosim hosts no Model Exchange
    unit); the plan's Real, Integer and Boolean connections."""
    plan = as_plan(scenario)
    scenario = plan.scenario
    if plan.model_exchange:
        raise ValueError(f"libcosim runs Co-Simulation units only: {sorted(plan.model_exchange)} are Model Exchange")
    fmi3 = [u.name for u in plan.units if u.fmi == 3]
    if fmi3:  # libcosimpy 0.0.6: FMI 1.0/2.0 importers only; add_local_slave of an FMI 3.0 unit is a SIGSEGV
        raise ValueError(f"libcosim runs FMI 1.0/2.0 units only: {fmi3} are FMI 3.0 (the libcosim of libcosimpy "
                         f"{_libcosimpy_version()} has no FMI 3.0 importer: adding one is a segmentation fault)")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    step_ns = int(round(scenario.step * NS))
    if step_ns <= 0 or scenario.start_time != 0.0:
        raise ValueError("libcosim run: step must be >= 1 ns and start_time 0")
    ex = CosimExecution.from_step_size(step_size=step_ns)
    idx, mds = {}, {}
    for u in plan.units:
        slave = CosimLocalSlave(fmu_path=str(u.path), instance_name=u.name)
        if not slave.ptr():  # libcosimpy hands a NULL slave on to libcosim: a segmentation fault, not an error
            raise RuntimeError(f"libcosim cannot load {u.name} ({u.path}): {_last_error()}")
        idx[u.name] = ex.add_local_slave(slave)
        mds[u.name] = u.vars
    for u in plan.units:  # parameters, then fixed inputs, as initial values (one function, every engine)
        for settings in (plan.params[u.name], plan.inputs[u.name]):
            apply_params(settings, _initial_values(ex, idx[u.name], u.name, settings))
    connect = {"Real": ex.connect_real_variables, "Integer": ex.connect_integer_variables,
               "Boolean": ex.connect_boolean_variables}
    for g in plan.groups:
        for so, di in zip(g.src_vrs, g.dst_vrs):
            connect[g.type](idx[g.src], so, idx[g.dst], di)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    t = time.perf_counter()
    if not ex.simulate_until(target_time=int(round(scenario.stop_time * NS))):
        raise RuntimeError("libcosim: simulate_until failed")
    wall = time.perf_counter() - t
    out = {"wall_s": wall}
    for key, inst, var in scenario.log_items():
        out[key] = _last(obs, idx[inst], mds[inst][var])
    return out


def _last(obs, i: int, v):
    """The last value of variable ``v`` (a model-description variable) of slave ``i``, read by its type."""
    read = {"Integer": obs.last_integer_values, "Boolean": obs.last_boolean_values}.get(v.type, obs.last_real_values)
    return read(i, [v.valueReference])[0]


def run_libcosim_ssp(ssp_path, stop_time: float | None = None, series=()) -> dict:
    """Runs an ``.ssp`` written by ``scfmu.ssp`` on libcosim's own SSP loader (components, parameter
    bindings and connections all come from the archive; the fixed step from the scfmu annotation).
    Returns the final value of every logged key of the scenario, like :func:`run_libcosim` (each read by its
    type); ``series``: logged keys also recorded at every step by libcosim's time-series observer,
    returned as ``out["series"][key] = (times [s], values)`` (the values after each step, step 1 on)."""
    import shutil

    from fmpy import read_model_description
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    from ..fmu import scratch
    from ..scenario.ssp import read_ssp

    log_output_level(CosimLogLevel.WARNING)
    work = scratch.mkdtemp(prefix="scfmu_lcssp_")
    try:
        sc, files = read_ssp(ssp_path, work)
        t_end = sc.stop_time if stop_time is None else stop_time
        ex = CosimExecution.from_ssp_file(str(ssp_path), step_size=int(round(sc.step * NS)))
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        model = {c.name: c.model for c in sc.components}
        mvs = {m: {v.name: v for v in read_model_description(str(p)).modelVariables} for m, p in files.items()}
        items = {key: (ex.slave_index_from_instance_name(inst), mvs[model[inst]][var])
                 for key, inst, var in sc.log_items()}
        n = int(round(t_end / sc.step))
        ts = CosimObserver.create_time_series(buffer_size=n + 2) if series else None
        if ts is not None:
            ex.add_observer(ts)
            for key in series:
                i, v = items[key]
                kind = CosimVariableType.INTEGER if v.type == "Integer" else CosimVariableType.REAL
                if not ts.start_time_series(i, v.valueReference, kind):
                    raise RuntimeError(f"libcosim: cannot observe {key}")
        if not ex.simulate_until(target_time=int(round(t_end * NS))):
            raise RuntimeError("libcosim: simulate_until failed")
        out = {}
        for key, (i, v) in items.items():
            out[key] = _last(obs, i, v)
        if ts is not None:
            out["series"] = {key: _samples(ts, *items[key], n) for key in series}
        return out
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _samples(ts, i: int, v, n: int, chunk: int = 50_000):
    """(times [s], values) of steps 1 … n of a time-series observer."""
    read = ts.time_series_integer_samples if v.type == "Integer" else ts.time_series_real_samples
    t, y = [], []
    for first in range(1, n + 1, chunk):
        tt, _, yy = read(i, v.valueReference, from_step=first, sample_count=min(chunk, n + 1 - first))
        t += tt
        y += yy
    return np.asarray(t, dtype=float) / NS, np.asarray(y, dtype=float)
