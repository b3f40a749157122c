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

from ..fmu import fmu_path, unpacked
from ..scenario.model import Scenario
from ..scenario.resolve import resolve

NS = 10**9


def run_libcosim(scenario: Scenario) -> dict:
    """Runs the scenario to its stop time; returns the final value of every logged key plus
    ``wall_s`` (the simulate_until call only)."""
    scenario = resolve(scenario)
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
    for c in scenario.components:
        mds[c.name] = {v.name: v for v in unpacked(fmu_path(c.model))[0].modelVariables}  # archive limits first
        idx[c.name] = ex.add_local_slave(CosimLocalSlave(fmu_path=str(fmu_path(c.model)), instance_name=c.name))
    for c in scenario.components:
        for k, v in c.params.items():
            var = mds[c.name][k]
            if var.type == "Integer":
                ok = ex.integer_initial_value(idx[c.name], var.valueReference, int(v))
            elif var.type == "Boolean":
                ok = ex.boolean_initial_value(idx[c.name], var.valueReference, bool(v))
            else:
                ok = ex.real_initial_value(idx[c.name], var.valueReference, float(v))
            if not ok:
                raise RuntimeError(f"libcosim: cannot set {c.name}.{k}")
    for q, v in scenario.inputs.items():
        inst, _, var = q.partition(".")
        ex.real_initial_value(idx[inst], mds[inst][var].valueReference, float(v))
    ports = {n: ([v.name for v in m.values() if v.causality == "input"], [v.name for v in m.values() if v.causality == "output"])
             for n, m in mds.items()}
    for d, di, s, so in scenario.wiring(ports):
        ex.connect_real_variables(idx[s], mds[s][so].valueReference, idx[d], mds[d][di].valueReference)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    t = time.perf_counter()
    if not ex.simulate_until(target_time=int(round(scenario.stop_time * NS))):
        raise RuntimeError("libcosim: simulate_until failed")
    wall = time.perf_counter() - t
    out = {"wall_s": wall}
    for key, inst, var in scenario.log_items():
        out[key] = obs.last_real_values(idx[inst], [mds[inst][var].valueReference])[0]
    return out


def run_libcosim_ssp(ssp_path, stop_time: float | None = None) -> dict:
    """Runs an ``.ssp`` written by ``scfmu.ssp`` on libcosim's own SSP loader (components, parameter
    bindings and connections all come from the archive; the fixed step from the scfmu annotation).
    Returns the final value of every logged key of the scenario, like :func:`run_libcosim`."""
    import shutil
    import tempfile

    from fmpy import read_model_description
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    from ..scenario.ssp import read_ssp

    log_output_level(CosimLogLevel.WARNING)
    work = tempfile.mkdtemp(prefix="scfmu_lcssp_")
    try:
        sc, files = read_ssp(ssp_path, work)
        t_end = sc.stop_time if stop_time is None else stop_time
        ex = CosimExecution.from_ssp_file(str(ssp_path), step_size=int(round(sc.step * NS)))
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        if not ex.simulate_until(target_time=int(round(t_end * NS))):
            raise RuntimeError("libcosim: simulate_until failed")
        model = {c.name: c.model for c in sc.components}
        vrs = {m: {v.name: v.valueReference for v in read_model_description(str(p)).modelVariables}
               for m, p in files.items()}
        out = {}
        for key, inst, var in sc.log_items():
            i = ex.slave_index_from_instance_name(inst)
            out[key] = obs.last_real_values(i, [vrs[model[inst]][var]])[0]
        return out
    finally:
        shutil.rmtree(work, ignore_errors=True)
