"""A small Scheduled Execution scheduler, as a real-time platform runs model partitions: the plan's clocked
units instantiated with ``fmi3InstantiateScheduledExecution``, each clock's partition activated with
``fmi3ActivateModelPartition(clock, tick time)`` from a time-ordered queue of ticks, the units without clocks
(plants, FMI 2.0 units) stepped with ``doStep`` on the scenario's grid between them.

The queue orders ticks by time, then by task priority: the unit's rank in the plan's Gauss–Seidel order
(the data flow: a producer before its consumers, as a platform derives priorities from precedence), then
the clock's own ``priority`` (FMI 3.0: a lower value runs first). At a grid point the exchange and the
partitions interleave as in :class:`scfmu.engines.clocked.ClockedMaster` (a unit's due partitions right
after its inputs are set), so the results are those of the sampled and the clocked run, bit for bit.

Virtual time has no concurrency: a partition runs to its end before the next one starts, so nothing is
preempted. The FMU still brackets its critical sections with the importer's ``lockPreemption`` /
``unlockPreemption`` callbacks; this scheduler counts them and checks that they nest (never an unlock
without a lock, no section left locked when ``fmi3ActivateModelPartition`` returns): ``preemption``
holds the counts and the deepest nesting seen.
"""

from __future__ import annotations

import heapq

from .clocked import ClockedMaster, tolerance


class Scheduler(ClockedMaster):
    """The plan run by the Scheduled Execution scheduler (module docstring); ``run()``, ``activations`` and
    ``activation_log`` as :class:`ClockedMaster`; ``preemption``: {"locks", "unlocks", "max_depth",
    "errors"}."""

    mode = "scheduled"
    clocking = "scheduled"

    def _preemption(self):
        p = self.preemption = {"locks": 0, "unlocks": 0, "depth": 0, "max_depth": 0, "errors": []}

        def lock():
            p["locks"] += 1
            p["depth"] += 1
            p["max_depth"] = max(p["max_depth"], p["depth"])

        def unlock():
            p["unlocks"] += 1
            p["depth"] -= 1
            if p["depth"] < 0:
                p["errors"].append(f"unlockPreemption without lockPreemption (call {p['unlocks']})")
                p["depth"] = 0
        return lock, unlock

    def _clock_calls(self, n: str) -> dict:
        return {"activate": self._fn(n, "fmi3ActivateModelPartition")}

    def _activate(self, n: str, i: int, t: float) -> int:
        st = self._unit_calls[n]["activate"](self.timing[n][i][0].vr, t)
        p = self.preemption
        if p["depth"] != 0 or p["errors"]:
            why = p["errors"][-1] if p["errors"] else f"{p['depth']} preemption lock(s) still held"
            self.fmus[n].messages.append((3, "", f"fmi3ActivateModelPartition({self.timing[n][i][0].name}, {t}): "
                                          f"{why} when it returned"))
            st = 3
        self._record(n, [i], t)
        return st

    def _partition(self, u: str, idx: list[int], t: float, first: bool) -> int:
        st = 0
        for i in idx:  # (timing is in priority order)
            st |= self._activate(u, i, t)
        return st

    def _after_exchange(self, ticking: list[str]) -> int:
        return 0

    def _between(self, t: float, t_end: float) -> int:
        """Every tick strictly between two grid points, from the queue (time, unit rank, clock priority)."""
        queue = []

        def push(u, i):
            tk = self.tick_time(u, i, self.next_k[u][i])
            if tk < t_end - tolerance(t_end, self.timing[u][i][1]):
                prio = self.timing[u][i][0].priority
                heapq.heappush(queue, (tk, self.rank[u], prio if prio is not None else 1 << 31, i, u))

        for u in self.timing:
            for i in range(len(self.timing[u])):
                push(u, i)
        st = 0
        while queue and st <= 1:
            tk, _r, _p, i, u = heapq.heappop(queue)
            self.next_k[u][i] += 1
            st |= self._activate(u, i, tk)
            push(u, i)
        return st
