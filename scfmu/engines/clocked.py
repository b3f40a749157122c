"""Running FMI 3.0 clocked units on their clocks: the lean master's plan with each clocked unit's model
partitions activated at their ticks, in clocked Co-Simulation (``clocks="clocked"``) or Scheduled Execution
(``clocks="scheduled"``, :mod:`scfmu.engines.scheduler`). ``"sampled"`` (every other engine) runs the same
units as today: the unit samples inside ``doStep``.

What the plan knows (:attr:`scfmu.scenario.plan.Unit.clocks`): each unit's ``<Clock>`` variables and the
outputs each one clocks. A clocked run instantiates every unit with clocks for its mode (``eventModeUsed =
true``, or ``fmi3InstantiateScheduledExecution``), reads each clock's interval and shift in Initialization
Mode (``fmi3GetIntervalDecimal``/``fmi3GetShiftDecimal``; ``constant`` clocks: the description's values) and
schedules tick k of a clock at t_start + shift + k·interval from the integer k (never a sum of times). The
scenario's communication grid is unchanged, and so are the units without clocks (plants, FMI 2.0 units:
``doStep`` on the grid, as in a sampled run). At a grid point the plan's Gauss–Seidel exchange runs as in the
lean master; a unit's partitions due at that instant run right after its inputs are set (its place in the
exchange: before anything reads its outputs in a loop where it comes first), so every value crosses the
same way as in a sampled run and the results are bit-identical. Ticks between grid points (a sensor faster
than the grid, a delivery shifted by a latency) are activated on their own with the inputs held since the
last grid point, as the unit held them inside ``doStep`` in a sampled run.

Clocked Co-Simulation, at a tick of unit U: ``fmi3DoStep`` up to the tick, ``fmi3EnterEventMode``,
``fmi3SetClock`` of the clocks due, ``fmi3UpdateDiscreteStates`` (its ``nextEventTime`` must be the next tick
of the schedule), outputs read, ``fmi3EnterStepMode``. A clocked output read between ticks is the held
value (our units give it; FMI 3.0 lets a master keep it itself).
"""

from __future__ import annotations

import ctypes
import math
from pathlib import Path
from ctypes import c_bool, c_double, c_int, c_uint32

from .. import binding
from ..scenario.plan import Plan, PlanError
from .calls import SimulationError
from .instances import as_plan, build_fmus
from .lean import LeanMaster

CLOCK_MODES = ("sampled", "clocked", "scheduled")
REL_TOL, MAX_FRACTION = 1e-10, 1e-3  # the units' grid tolerance (src/math/sample_grid.rs), for a tick vs a grid time


def tolerance(t: float, period: float) -> float:
    """How far a time may be from a tick of period ``period`` near ``t`` and still be that tick."""
    return min(REL_TOL * max(abs(t), period), MAX_FRACTION * period)


def runnable_clocks(u) -> list:
    """The clocks of a unit a clocked run activates: periodic input clocks (``constant``, or ``fixed`` whose
    interval the unit gives in Initialization Mode)."""
    return [c for c in u.clocks if c.causality == "input" and c.interval_variability in ("constant", "fixed")]


def _label(u) -> str:
    return Path(u.model).name  # a model name, or an FMU file's name


def clock_problem(plan: Plan, mode: str) -> str | None:
    """Why ``plan`` cannot run with ``clocks=mode`` (None when it can), in one line."""
    if mode not in CLOCK_MODES:
        return f"clocks {mode!r}: expected one of {', '.join(CLOCK_MODES)}"
    if mode == "sampled":
        return None
    clocked = [u for u in plan.units if u.clocks]
    if not clocked:
        why = ("every unit is FMI 2.0, which has no clocks" if all(u.fmi == 2 for u in plan.units)
               else "no unit declares a <Clock> (clocks exist in FMI 3.0 only)")
        return (f"--clocks {mode}: {why}; give FMI 3.0 units with clocks (--fmu INSTANCE=fmus/fmi3/MODEL.fmu), "
                f"or run sampled")
    for u in clocked:
        if u.interface != "cs":
            return f"--clocks {mode}: {u.name} ({_label(u)}) runs as Model Exchange: its clocks run in Co-Simulation only"
        odd = [c.name for c in u.clocks if c not in runnable_clocks(u)]
        if odd:
            return (f"--clocks {mode}: {u.name} ({_label(u)}): clock(s) {', '.join(odd)} are not periodic input "
                    f"clocks of interval variability constant or fixed, the only ones this master schedules")
        if mode == "scheduled" and u.md.scheduledExecution is None:
            return f"--clocks scheduled: {u.name} ({_label(u)}) has clocks but no <ScheduledExecution> interface"
    return None


def clock_notice(plan: Plan, mode: str) -> str | None:
    """The one line a clocked run prints about the units that run without clocks (None when all have some)."""
    if mode == "sampled":
        return None
    plain = [f"{u.name}{' (FMI 2.0)' if u.fmi == 2 else ''}" for u in plan.units if not u.clocks]
    if not plain:
        return None
    return (f"--clocks {mode}: no clocks in {', '.join(plain)}: they step with doStep on the scenario's grid as "
            f"in a sampled run")


def order_notice(plan: Plan, mode: str) -> str | None:
    """The one line a clocked run prints when the Gauss–Seidel order reads a clocked output before its unit's
    inputs are set at the same instant (a loop through a sampled unit, e.g. a Mekf reading the ModeManager
    that reads the Mekf): there the reader gets the value of the unit's previous tick, where a sampled run
    computes it from the unit's previous inputs, so the runs may differ. None when the order has no such read."""
    from .lean import flat_ops
    if mode == "sampled":
        return None
    clocked = {u.name: {n for c in u.clocks for n in c.clocked} for u in plan.units if u.clocks}
    ops, _b = flat_ops(plan)
    last_set = {inst: i for i, (kind, _t, inst, *_r) in enumerate(ops) if kind == "set"}
    early = []
    for g in plan.groups:
        if g.src in clocked and g.src in last_set and plan.names.index(g.dst) < plan.names.index(g.src):
            early += [f"{g.src}.{n} (read by {g.dst})" for n in g.src_names if n in clocked[g.src]]
    if not early:
        return None
    return (f"--clocks {mode}: {', '.join(early)} read before their unit's inputs are set at its ticks: the reader "
            f"gets the previous tick's value, where a sampled run computes it from the previous inputs (a loop "
            f"through a sampled unit in the Gauss–Seidel order); the runs may differ there")


class ClockedMaster(LeanMaster):
    """The lean master with the plan's clocked units run on their clocks (module docstring). ``run()``
    returns what :meth:`LeanMaster.run` returns; ``activations`` counts the partitions run per (unit,
    clock); ``log_activations=True`` also keeps ``activation_log`` [(time, unit, clock)]."""

    mode = "clocked"
    clocking = "event"

    def __init__(self, scenario, path_of=None, reuse: bool = True, log_activations: bool = False):
        self.plan = as_plan(scenario, path_of)
        why = clock_problem(self.plan, self.mode)
        if why:
            raise PlanError(why)
        self.scenario = self.plan.scenario
        self.clocked = [u for u in self.plan.units if u.clocks]
        self.timing: dict = {}  # unit -> [(clock, interval, shift)] in priority order
        self.shortest: dict = {}  # unit -> its shortest clock interval
        self.activations: dict = {}
        self.activation_log = [] if log_activations else None
        self.fmus = {}
        try:
            self.fmus = build_fmus(self.plan, reuse=reuse, clocking={u.name: self.clocking for u in self.clocked},
                                   preemption=self._preemption(), in_init=self._read_timing)
            self._prepare()
            self._prepare_clocks()
        except Exception:
            self.close()
            raise

    def _preemption(self):
        return None

    # ----- set-up --------------------------------------------------------------------------------------
    def _fn(self, inst: str, name: str):
        f = binding.bind(self.fmus[inst].slave.dll, name, raw=True)
        comp = binding.instance_address(self.fmus[inst].slave)
        return lambda *a: f(comp, *a)

    def _read_timing(self, name: str, fmu) -> None:
        """In Initialization Mode: each clock's interval and shift (from the unit, or the description)."""
        u = self.plan.unit(name)
        if not u.clocks:
            return
        clocks = runnable_clocks(u)
        fixed = [c for c in clocks if c.interval_variability == "fixed" and c.interval is None]
        got = {}
        if fixed:
            sl = fmu.slave
            comp = binding.instance_address(sl)
            n = len(fixed)
            vrs = (c_uint32 * n)(*[c.vr for c in fixed])
            iv, q, sh = (c_double * n)(), (c_int * n)(), (c_double * n)()
            for fname, args in (("fmi3GetIntervalDecimal", (iv, q)), ("fmi3GetShiftDecimal", (sh,))):
                st = binding.bind(sl.dll, fname, raw=True)(comp, ctypes.addressof(vrs), n,
                                                           *[ctypes.addressof(a) for a in args])
                if st > 1:
                    raise SimulationError("fmu_error", f"{name} ({_label(u)}): {fname} failed: "
                                          + " | ".join(fmu.last_errors()))
            got = {c.vr: (iv[i], sh[i]) for i, c in enumerate(fixed)}
        timing = []
        for c in clocks:
            interval, shift = got.get(c.vr, (c.interval, c.shift or 0.0))
            if not (interval is not None and math.isfinite(interval) and interval > 0 and math.isfinite(shift)
                    and shift >= 0):
                raise SimulationError("fmu_error", f"{name} ({_label(u)}): clock {c.name} has interval {interval} and "
                                      f"shift {shift}: a periodic clock needs a finite interval > 0 and shift >= 0")
            timing.append((c, float(interval), float(shift)))
        timing.sort(key=lambda x: (x[0].priority if x[0].priority is not None else 1 << 31, x[0].vr))
        self.timing[name] = timing
        self.shortest[name] = min(i for _c, i, _s in timing)  # (the tolerance of the unit's ticks)

    def _prepare_clocks(self) -> None:
        """The place of each clocked unit's partitions in the exchange, and its FMI clock functions."""
        names = [u.name for u in self.clocked]
        last_set = {}
        for i, (kind, _t, inst, *_r) in enumerate(self.plan_ops):
            if kind == "set" and inst in names:
                last_set[inst] = i + 1
        self.marks: dict[int, list[str]] = {}
        for n in names:
            self.marks.setdefault(last_set.get(n, 0), []).append(n)
        self.rank = {u.name: i for i, u in enumerate(self.plan.units)}
        self.t0 = self.scenario.start_time
        self.next_k = {n: [0] * len(self.timing[n]) for n in names}
        self._plain_steps = [self.calls[u.name].step for u in self.plan.units if not u.clocks]
        self._unit_calls = {n: self._clock_calls(n) for n in names}

    def _clock_calls(self, n: str) -> dict:
        flags = (c_bool * 5)()
        nxt = c_double()
        keep = (flags, nxt)
        a = [ctypes.addressof(flags) + i for i in range(5)] + [ctypes.addressof(nxt)]
        update = self._fn(n, "fmi3UpdateDiscreteStates")
        set_clock = self._fn(n, "fmi3SetClock")
        arrays = {}

        def activate(vrs):
            key = tuple(vrs)
            arr = arrays.get(key)
            if arr is None:
                arr = arrays[key] = ((c_uint32 * len(vrs))(*vrs), (c_bool * len(vrs))(*([True] * len(vrs))))
            return set_clock(ctypes.addressof(arr[0]), len(vrs), ctypes.addressof(arr[1]))

        def update_states():
            for _ in range(100):
                st = update(*a)
                if st > 1 or not flags[0]:
                    return st, (nxt.value if flags[4] else None)
            return 3, None

        return {"keep": keep, "activate": activate, "update": update_states, "step": self.calls[n].step,
                "enter_event": self._fn(n, "fmi3EnterEventMode"), "enter_step": self._fn(n, "fmi3EnterStepMode")}

    # ----- the schedule ------------------------------------------------------------------------------------
    def tick_time(self, n: str, i: int, k: int) -> float:
        _c, interval, shift = self.timing[n][i]
        return self.t0 + shift + k * interval

    def due(self, n: str, t: float) -> list[int]:
        """The clocks (indices into ``timing[n]``) of unit n that tick at t (within the tolerance); each
        one's tick counter advances."""
        out = []
        for i, (_c, interval, _s) in enumerate(self.timing[n]):
            k = self.next_k[n][i]
            tk = self.tick_time(n, i, k)
            if abs(tk - t) <= tolerance(t, interval):
                out.append(i)
                self.next_k[n][i] = k + 1
            elif tk < t:
                raise SimulationError("fmu_error", f"{n}: tick {k} of {self.timing[n][i][0].name} at t = {tk} was "
                                      f"missed (now t = {t})", t)
        return out

    def next_tick(self, n: str) -> float:
        return min(self.tick_time(n, i, k) for i, k in enumerate(self.next_k[n]))

    def _record(self, n: str, idx: list[int], t: float) -> None:
        for i in idx:
            key = (n, self.timing[n][i][0].name)
            self.activations[key] = self.activations.get(key, 0) + 1
            if self.activation_log is not None:
                self.activation_log.append((t, n, key[1]))

    # ----- clocked Co-Simulation ------------------------------------------------------------------------
    def _tick(self, n: str, idx: list[int], t: float, in_event: bool) -> int:
        """Event Mode at t (entered unless ``in_event``), the due clocks set, the partitions run."""
        c = self._unit_calls[n]
        st = 0 if in_event else c["enter_event"]()
        if idx:
            st |= c["activate"]([self.timing[n][i][0].vr for i in idx])
        s2, nxt = c["update"]()
        st |= s2
        want = self.next_tick(n)
        if st <= 1 and nxt is not None and abs(nxt - want) > tolerance(want, self.shortest[n]):
            self.fmus[n].messages.append((3, "", f"fmi3UpdateDiscreteStates at t = {t}: nextEventTime {nxt}, but "
                                          f"the clocks' next tick is {want}"))
            st = 3
        self._record(n, idx, t)
        return st

    def _advance(self, n: str, t: float, t_end: float) -> int:
        """Unit n from t to t_end: doStep to each tick strictly inside, the tick, then doStep to t_end."""
        c = self._unit_calls[n]
        st = 0
        while True:
            tk = self.next_tick(n)
            if tk >= t_end - tolerance(t_end, self.shortest[n]):
                break
            st |= c["step"](t, tk - t)
            st |= self._tick(n, self.due(n, tk), tk, False)
            st |= c["enter_step"]()
            t = tk
            if st > 1:
                return st
        return st | c["step"](t, t_end - t)

    def _between(self, t: float, t_end: float) -> int:
        st = 0
        for u in self.timing:
            st |= self._advance(u, t, t_end)
        return st

    def run(self) -> dict:
        sc = self.scenario
        n, dt, t0 = self.n, sc.step, sc.start_time
        ops, log_ops, marks = self._ops, self._log_ops, self.marks
        end = len(ops)
        for k in range(n + 1):
            t = t0 + k * dt
            due = {u: self.due(u, t) for u in self.timing}
            ticking = [u for u, idx in due.items() if idx or k == 0]
            st = 0
            for i, (fn, vrs, m, buf) in enumerate(ops):
                if i in marks:
                    for u in marks[i]:
                        if u in ticking:
                            st |= self._partition(u, due[u], t, k == 0)
                st |= fn(vrs, m, buf)
            for u in marks.get(end, ()):
                if u in ticking:
                    st |= self._partition(u, due[u], t, k == 0)
            for fn, vrs, m, base, stride in log_ops:
                st |= fn(vrs, m, base + k * stride)
            st |= self._after_exchange(ticking)
            if k < n:
                for fn in self._plain_steps:
                    st |= fn(t, dt)
                st |= self._between(t, t + dt)
            if st > 1:
                self._fail(t)
        return self._result()

    def _partition(self, u: str, idx: list[int], t: float, first: bool) -> int:
        return self._tick(u, idx, t, first)

    def _after_exchange(self, ticking: list[str]) -> int:
        st = 0
        for u in ticking:
            st |= self._unit_calls[u]["enter_step"]()
        return st
