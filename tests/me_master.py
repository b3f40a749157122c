"""A second Model Exchange master (tests only): a whole loop of FMI 2.0 ME units integrated as ONE ODE, the
way OMSimulator, Dymola or Simulink integrate connected ME FMUs (unlike ``run_reference(model_exchange=…)``,
which integrates each ME unit on its own over a held communication step).

At every right-hand-side evaluation it sets time and states of every unit, propagates outputs to inputs in
the scenario's order (twice, so a direct feed-through chain settles), and reads the derivatives. Explicit
Euler with a fixed step h (OMSimulator's explicit Euler) or classic RK4; after each accepted step it calls
``fmi2CompletedIntegratorStep`` on every unit; at the earliest ``nextEventTime`` of any unit (the step is
shortened to land on it) or when a unit asks for an event, every unit enters event mode and the event
iteration runs: ``fmi2NewDiscreteStates`` on every unit, then outputs propagated, repeated while any unit
says ``newDiscreteStatesNeeded`` or any output changed — the strictest rule a master may apply (it loops
forever on a unit whose event update keeps changing its values). ``max_iterations`` bounds it and the run
fails with the count. ``stats`` reports the number of steps, events and event iterations.
"""

from __future__ import annotations

import shutil
from ctypes import POINTER, c_double

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model

from scfmu.fmu import fmu_path
from scfmu.scenario.resolve import resolve


class Stall(RuntimeError):
    pass


class MeLoop:
    def __init__(self, scenario, path_of=None, tolerance=None, connector_defaults=False, callbacks=None):
        """``connector_defaults``: initialise the way OMSimulator initialises a subsystem: every connected
        input first gets its connector's default 0 and every unit's outputs are read in Initialization Mode
        before the values flow (a quaternion input then reads [0, 0, 0, 0]); ``callbacks(name)`` gives each
        unit's fmi2CallbackFunctions (to record its log)."""
        self.sc = resolve(scenario)
        path_of = path_of or fmu_path
        self.units, self.dirs, self.vr, self.nx, self.outs = {}, [], {}, {}, {}
        ports = {}
        for c in self.sc.components:
            p = str(path_of(c.model))
            md = read_model_description(p)
            d = extract(p)
            self.dirs.append(d)
            u = FMU2Model(guid=md.guid, unzipDirectory=d, modelIdentifier=md.modelExchange.modelIdentifier, instanceName=c.name)
            u.instantiate(callbacks=callbacks(c.name) if callbacks else None, loggingOn=callbacks is not None)
            u.setupExperiment(tolerance=tolerance, startTime=self.sc.start_time, stopTime=self.sc.stop_time)
            u.enterInitializationMode()
            vr = {v.name: v for v in md.modelVariables}
            for k, val in c.params.items():
                v = vr[k]
                (u.setReal if v.type == "Real" else u.setInteger)([v.valueReference], [val if v.type == "Real" else int(val)])
            self.units[c.name], self.vr[c.name] = u, vr
            self.nx[c.name] = sum(1 for v in md.modelVariables if v.derivative is not None)
            ports[c.name] = ([v.name for v in md.modelVariables if v.causality == "input"],
                             [v.name for v in md.modelVariables if v.causality == "output"])
            self.outs[c.name] = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        self.links = [(d, self.vr[d][di].valueReference, s, self.vr[s][so].valueReference) for d, di, s, so in self.sc.wiring(ports)]
        if connector_defaults:
            for d, dvr, _, _ in self.links:
                self.units[d].setReal([dvr], [0.0])
            self.initial_outputs = {n: self.units[n].getReal(vrs) for n, vrs in self.outs.items() if vrs}
        for q, value in self.sc.inputs.items():
            inst, _, var = q.partition(".")
            self.units[inst].setReal([self.vr[inst][var].valueReference], [float(value)])
        self.propagate()
        for u in self.units.values():
            u.exitInitializationMode()
        self.stats = {"steps": 0, "events": 0, "iterations": 0, "max_iterations_per_event": 0}
        self.next_event = None
        self.t = self.sc.start_time
        self.event_iteration(self.t)
        for u in self.units.values():
            u.enterContinuousTimeMode()

    def propagate(self):
        for _ in range(2):
            for d, dvr, s, svr in self.links:
                self.units[d].setReal([dvr], self.units[s].getReal([svr]))

    def outputs(self):
        return np.concatenate([np.array(self.units[n].getReal(vrs)) for n, vrs in self.outs.items() if vrs])

    def event_iteration(self, t, max_iterations=100):
        self.stats["events"] += 1
        before = self.outputs()
        for k in range(1, max_iterations + 1):
            needed, t_next = False, []
            for name, u in self.units.items():
                need, terminate, _, _, defined, te = u.newDiscreteStates()
                if terminate:
                    raise Stall(f"{name} asked to terminate at t = {t}")
                needed |= bool(need)
                if defined:
                    if te <= t:
                        raise Stall(f"{name}: nextEventTime {te!r} is not after the event time {t!r}")
                    t_next.append(te)
            self.propagate()
            after = self.outputs()
            self.stats["iterations"] += 1
            self.stats["max_iterations_per_event"] = max(self.stats["max_iterations_per_event"], k)
            if not needed and np.array_equal(after, before):
                self.next_event = min(t_next) if t_next else None
                return
            before = after
        raise Stall(f"event iteration at t = {t} did not settle in {max_iterations} passes")

    def _states(self):
        xs = []
        for name, u in self.units.items():
            n = self.nx[name]
            x = np.zeros(n)
            if n:
                u.getContinuousStates(x.ctypes.data_as(POINTER(c_double)), n)
            xs.append(x)
        return xs

    def _set(self, t, xs):
        for (name, u), x in zip(self.units.items(), xs):
            u.setTime(t)
            if self.nx[name]:
                x = np.ascontiguousarray(x)
                u.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), self.nx[name])

    def _rhs(self, t, xs):
        self._set(t, xs)
        self.propagate()
        out = []
        for name, u in self.units.items():
            n = self.nx[name]
            dx = np.zeros(n)
            if n:
                u.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), n)
            out.append(dx)
        return out

    def run(self, t_end, h, method="euler", log=None):
        rows = []
        while self.t < t_end - 1e-12 * max(1.0, abs(t_end)):
            t0 = self.t
            t1 = min(t0 + h, t_end)
            at_event = self.next_event is not None and self.next_event <= t1
            if at_event:
                t1 = self.next_event
            xs = self._states()
            dt = t1 - t0
            if method == "euler":
                k1 = self._rhs(t0, xs)
                x1 = [x + dt * a for x, a in zip(xs, k1)]
            else:
                k1 = self._rhs(t0, xs)
                k2 = self._rhs(t0 + dt / 2, [x + dt / 2 * a for x, a in zip(xs, k1)])
                k3 = self._rhs(t0 + dt / 2, [x + dt / 2 * a for x, a in zip(xs, k2)])
                k4 = self._rhs(t1, [x + dt * a for x, a in zip(xs, k3)])
                x1 = [x + dt / 6 * (a + 2 * b + 2 * c + d) for x, a, b, c, d in zip(xs, k1, k2, k3, k4)]
            self._set(t1, x1)
            self.propagate()
            self.t = t1
            self.stats["steps"] += 1
            step_event = False
            for u in self.units.values():
                enter, terminate = u.completedIntegratorStep()
                if terminate:
                    raise Stall(f"terminateSimulation at t = {t1}")
                step_event |= bool(enter)
            if at_event or step_event:
                for u in self.units.values():
                    u.enterEventMode()
                self.event_iteration(t1)
                for u in self.units.values():
                    u.enterContinuousTimeMode()
            if log is not None:
                rows.append((t1, *[self.units[i].getReal([self.vr[i][v].valueReference])[0] for i, v in log]))
        return rows

    def close(self):
        for u in self.units.values():
            try:
                u.terminate()
            except Exception:
                pass
            u.freeInstance()
        for d in self.dirs:
            shutil.rmtree(d, ignore_errors=True)
