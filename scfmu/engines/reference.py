"""The reference master: a fixed-step Gauss-Seidel co-simulation on :class:`scfmu.fmu.Fmu` (fmpy's
high-level calls, FMI 2.0 or 3.0, Co-Simulation or Model Exchange), kept simple and name-based as the
tests' oracle for the faster engines.

At each communication point t_k the master walks the FMUs in the given order, sets each one's inputs
from the current outputs of their sources, logs the requested variables, then calls doStep on every
FMU from t_k to t_k + dt. Give the order so that an FMU whose outputs depend directly on its inputs
comes after its sources (e.g. command, controller, plant, metrics): plant state outputs have no
direct feed-through, so reading them first is exact.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fmu import Fmu, scalar_type
from ..scenario.model import DEFAULT_UNCONNECTED, matches_input


@dataclass
class _Link:
    dst: Fmu
    dst_names: list[str]
    src: Fmu
    src_names: list[str]


@dataclass
class CoSimulation:
    """FMUs in Gauss-Seidel order, wired by port name, or by ``links`` when given (a plan's wiring: then no
    name is matched, so two units with an output of the same name, such as a plant's and an estimate gate's
    ``w_x``, do not make an input ambiguous)."""

    fmus: list[Fmu]
    unconnected: set[str] = field(default_factory=set)
    links: list[_Link] | None = None

    def __post_init__(self):
        if self.links is not None:
            return
        self.links = []
        for dst in self.fmus:
            by_src: dict[int, _Link] = {}
            for name in dst.inputs():
                sources = [s for s in self.fmus if s is not dst and name in s.outputs()]
                if len(sources) > 1:
                    raise ValueError(f"input {dst.model}.{name} has several sources: {[s.model for s in sources]}")
                if not sources:
                    if name in self.unconnected or not self._required(dst, name):
                        continue
                    raise ValueError(f"input {dst.model}.{name} has no source; list it in unconnected=")
                src = sources[0]
                link = by_src.setdefault(id(src), _Link(dst, [], src, []))
                link.dst_names.append(name)
                link.src_names.append(name)
            self.links.extend(by_src.values())

    @staticmethod
    def _required(dst: Fmu, name: str) -> bool:
        # The optional inputs (disturbances, wheel momenta, reference derivatives, the magnetorquer dipole
        # command, ...) may stay at their start value: the scenarios' one list of them.
        # A pattern "x_*" also covers the scalar port "x" (SingleAxisPlant's torque_dist).
        return not matches_input(name, DEFAULT_UNCONNECTED, stems=True, model=dst.model)

    def propagate(self) -> None:
        for dst in self.fmus:
            for link in self.links:
                if link.dst is dst:
                    dst.set_values(link.dst_names, link.src.get_values(link.src_names))

    def run(self, t_end: float, dt: float, log: dict[str, tuple[Fmu, str]] | None = None,
            t0: float = 0.0, on_step=None) -> dict[str, np.ndarray]:
        """Runs from t0 to t_end with step dt; returns logged signals at every t_k (incl. t_end)."""
        n = int(round((t_end - t0) / dt))
        if abs(n * dt - (t_end - t0)) > 1e-9 * max(1.0, abs(t_end)):
            raise ValueError(f"t_end - t0 = {t_end - t0} is not a multiple of dt = {dt}")
        log = log or {}
        out = {"time": np.empty(n + 1)}
        for k in log:
            out[k] = np.empty(n + 1)
        groups: dict[tuple, tuple[Fmu, list[str], list[str]]] = {}
        for key, (f, name) in log.items():  # one read per instance and type
            g = groups.setdefault((id(f), scalar_type(f.var(name))), (f, [], []))
            g[1].append(key)
            g[2].append(name)
        for k in range(n + 1):
            t = t0 + k * dt
            self.propagate()
            out["time"][k] = t
            for f, keys, names in groups.values():
                for key, val in zip(keys, f.get_values(names)):
                    out[key][k] = val
            if on_step is not None:
                on_step(k, t)
            if k < n:
                for f in self.fmus:
                    f.do_step(t, dt)
        return out

    def close(self) -> None:
        for f in self.fmus:
            f.close()
