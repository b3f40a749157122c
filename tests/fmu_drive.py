"""Driving one packaged unit through fmpy (scfmu.fmu.Fmu) in the FMU tests, written once: the FMI 2.0 or 3.0
file of a model, the communication-step loop (set the inputs, step, read the outputs), and the FMU-state round
trip mid-run (set the state taken before, and the same state serialized and deserialized) in either FMI version.
On the tests' ``pythonpath`` (pyproject.toml), like ``quat_oracle``: ``from fmu_drive import drive``."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from scfmu.fmu import Fmu, fmu_path, scalar_type


def fmu_file(model: str, fmi: int) -> Path:
    """The packaged FMI 2.0 (``fmus/``) or FMI 3.0 (``fmus/fmi3/``) file of ``model``."""
    p = fmu_path(model)
    return p if fmi == 2 else p.parent / "fmi3" / p.name


def drive(f: Fmu, k0: int, k1: int, h: float, inputs: Callable[[int], dict], read: Callable[[Fmu, float], object],
          read_before_step: bool = False) -> list:
    """Communication points k = k0..k1-1 of ``f`` at t = k h with the step ``h``: set ``inputs(k)`` (``{name:
    value}``: the Real ports in one call, in the dict's order, then any other port by its declared type), step to
    t + h and keep ``read(f, t)``, read after the step, or before it with ``read_before_step`` (the outputs at t
    under the inputs just set; ``read`` may also drive other units coupled to ``f`` there). Returns the rows."""
    rows = []
    for k in range(k0, k1):
        t = k * h
        u = inputs(k)
        reals = [n for n in u if scalar_type(f.var(n)) == "Real"]
        f.set_reals(reals, [u[n] for n in reals])
        for n in u:
            if n not in reals:
                f.set(n, u[n])
        if read_before_step:
            rows.append(read(f, t))
        f.do_step(t, h)
        if not read_before_step:
            rows.append(read(f, t))
    return rows


def restored_runs(f: Fmu, run: Callable[[Fmu, int, int], object], k0: int, k1: int) -> tuple:
    """``run(f, k0, k1)`` three times from the present state of ``f``: as it is, after setting the FMU state taken
    before the first (fmi2GetFMUstate / fmi3GetFMUState), and after setting that state serialized and
    deserialized. Returns (first, second, third, the serialized bytes); both states are freed."""
    s = f.slave
    get, put, ser, des, free = ((s.getFMUstate, s.setFMUstate, s.serializeFMUstate, s.deSerializeFMUstate,
                                 s.freeFMUstate) if f.fmi == 2 else
                                (s.getFMUState, s.setFMUState, s.serializeFMUState, s.deserializeFMUState,
                                 s.freeFMUState))
    state = get()
    blob = ser(state)
    a = run(f, k0, k1)
    put(state)
    b = run(f, k0, k1)
    restored = des(blob)
    put(restored)
    c = run(f, k0, k1)
    free(state)
    free(restored)
    return a, b, c, blob
