"""Stability margins of a black-box attitude loop, per axis, at the benchmark's operating point.

What is linearised. The loop the benchmark runs: the scenario's units under the lean Gauss–Seidel master
(:class:`scfmu.engines.lean.LeanMaster`, the same call sequence as every engine of the package), with the
controller, any sensors and sample-and-hold between them, exactly as they are: black boxes. The
operating point is the state of every unit at the end of the scenario's nominal run (``stop_time``; the
manoeuvre has settled for a controller that passes). The loop is broken at the plant's torque input of
one axis at a time (``torque_cmd_x``, ``_y``, ``_z``), the other two axes staying closed (loop-at-a-time
margins, as design reviews quote them).

How. All units' states are saved at the operating point (``fmi2GetFMUstate``; a unit that cannot save its
state is rebuilt and re-run to the operating point for every perturbation instead). From that state the
loop runs on twice per axis with a small torque pulse ±ε added to the plant's input i (the loop stays
closed: the response decays for a stabilising controller) and records the signal r that feeds the plant's
input i. Their central difference (r₊ − r₋)/2ε is the pulse response of −T_i, with T_i = L_i/(1 + L_i) the
complementary sensitivity of axis i (disturbances and sensor noise cancel in the difference), so the loop
transfer is L_i = T_i/(1 − T_i), evaluated exactly (finite DTFT of the recorded response) on a dense
frequency grid up to the Nyquist frequency. ε is 10⁻⁴ of the largest torque command of the nominal run
(10⁻⁶ N·m when it is zero).

Sampled loops. The master exchanges values every communication step h with the inputs held, so every
loop is a sampled one: its margins are those of the discrete loop L_i(e^{jωT}) (this equals the ZOH
discretisation of the plant at the sample time, in series with the discrete controller). When the signal
feeding the plant changes only every m-th step (a flight computer with a sample-and-hold), the sample
time is T = m h: the pulse is held over one sample period starting at a sample instant and the response is
read at the sample instants. A loop with units at other, slower rates inside (e.g. a 5 Hz star tracker in
a 10 Hz loop) is periodically time-varying; its margins here are those of the response to a pulse at the
first sample instant after the operating point (an approximation, flagged as "multi-rate").

Margins (python-control ``stability_margins`` on the frequency response, all crossings): gain margin
GM = 1/|L| at the phase crossover (−180°) where |L| < 1, in dB (inf: none below the Nyquist frequency);
gain-reduction margin where |L| > 1 at a phase crossover (a conditionally stable loop, e.g. the ZOH's
lag on a double integrator at very low frequency); phase margin PM at the gain crossover ω_c; delay
margin DM = PM [rad] / ω_c [s], the smallest over the gain crossovers.
"""

from __future__ import annotations

import ctypes
import math
from ctypes import c_double, c_uint
from dataclasses import dataclass, field

import numpy as np

from ..engines.lean import LeanMaster
from ..scenario.model import Scenario

AXES = ("x", "y", "z")


@dataclass
class AxisMargins:
    axis: str
    gm_db: float = math.inf  # gain (increase) margin [dB]
    gm_low_db: float = math.nan  # gain-reduction margin [dB] (negative), NaN if none
    pm_deg: float = math.nan
    wc: float = math.nan  # gain crossover [rad/s]
    wpc: float = math.nan  # phase crossover of GM [rad/s]
    dm_s: float = math.nan  # delay margin [s]
    sample_time: float = math.nan  # T of the discrete loop [s]
    note: str = ""
    omega: np.ndarray | None = field(default=None, repr=False)
    loop: np.ndarray | None = field(default=None, repr=False)  # L(e^{jωT})


class _Driver:
    """The scenario's loop under the lean master's plan: steps with a pulse are made from Python, the long
    stretches without one by the compiled loop when its library is available (the same calls, no Python
    per step), else from Python too."""

    def __init__(self, sc: Scenario, plant: str, ports):
        sc = sc.with_overrides({})
        sc.log = {f"_in{i}": f"{plant}.{p}" for i, p in enumerate(ports)}  # what feeds the plant, read each step
        self.sc = sc
        self.compiled = False
        try:
            from ..engines.compiled import CompiledLoop, available
            if available():
                self.m = CompiledLoop(sc, reuse=False)
                LeanMaster._build_calls(self.m)  # the Python form of the same plan, for the pulse steps
                CompiledLoop._build_calls(self.m)
                self.compiled = True
        except Exception:
            self.compiled = False
        if not self.compiled:
            self.m = LeanMaster(sc)
        self.plant = plant
        pl = self.m.fmus[plant]
        vr = {v.name: v.valueReference for v in pl.md.modelVariables}
        self.ports = ports
        self.vr = [vr[p] for p in ports]
        # where the master's buffer holds each plant input: the "set" op of the plant
        self.read_at = []
        for (kind, typ, inst, vrs, _b, _off), op in zip(self.m.plan_ops, self.m._ops):
            if kind == "set" and typ == "Real" and inst == plant:  # op = (fn, vr array, n, buffer address)
                for p, v in zip(ports, self.vr):
                    if v not in vrs:
                        raise KeyError(f"{plant}.{p} is not fed by another unit: no loop to break")
                    self.read_at.append(op[3] + ctypes.sizeof(c_double) * vrs.index(v))
        if len(self.read_at) != len(ports):
            raise KeyError(f"{plant}: torque inputs not connected")
        self._set = self.m.calls[plant].set["Real"]  # (vr array address, n, values address) -> status
        self._one_vr = (c_uint * 1)()
        self._one_val = (c_double * 1)()
        self.k = 0

    def value(self, i: int) -> float:
        return c_double.from_address(self.read_at[i]).value

    def run(self, n: int, axis: int = -1, pulse=None) -> np.ndarray:
        """n communication steps from the current one; returns the signals feeding the plant's inputs
        (n, 3) at each step, before the pulse ``pulse[j]`` (added to input ``axis`` at step j) is applied."""
        last = int(np.max(np.nonzero(pulse)[0])) + 1 if axis >= 0 and pulse is not None and np.any(pulse) else 0
        out = np.empty((n, len(self.read_at)))
        py = n if not self.compiled else min(n, last)
        self._python(out, py, axis, pulse)
        if py < n:
            self._compiled(out[py:])
        return out

    def _python(self, out, n, axis, pulse) -> None:
        sc, ops, steps = self.sc, self.m._ops, self.m._steps
        for j in range(n):
            t = sc.start_time + self.k * sc.step
            st = 0
            for fn, vrs, m, buf in ops:
                st |= fn(vrs, m, buf)
            for i in range(len(self.read_at)):
                out[j, i] = self.value(i)
            if axis >= 0 and pulse is not None and j < len(pulse) and pulse[j] != 0.0:
                self._one_vr[0] = self.vr[axis]
                self._one_val[0] = out[j, axis] + pulse[j]
                st |= self._set(ctypes.addressof(self._one_vr), 1, ctypes.addressof(self._one_val))
            for fn in steps:
                st |= fn(t, sc.step)
            if st > 1:
                self.m._fail(t)
            self.k += 1

    def _compiled(self, out) -> None:
        """len(out) steps in the compiled loop: it propagates, logs (the plant's inputs) and steps at each
        t_k; one more propagation and log at the end (no step), which the next call repeats unchanged."""
        sc, m = self.sc, self.m
        n = out.shape[0]
        buf = np.empty((n + 1, len(self.read_at)))
        st = m._lib.scfmu_loop_run(*m._args, n, sc.start_time + self.k * sc.step, sc.step, buf.ctypes.data, buf.size,
                                   1, m._fail_at)
        if st < 0 or st > 1:
            m._fail(sc.start_time + self.k * sc.step, f"compiled loop status {st}")
        out[:] = buf[:n]
        self.k += n

    def save(self):
        try:
            return {n: f.slave.getFMUState() for n, f in self.m.fmus.items()}, self.k
        except Exception:
            return None

    def restore(self, saved) -> None:
        states, k = saved
        for n, s in states.items():
            self.m.fmus[n].slave.setFMUState(s)
        self.k = k

    def free(self, saved) -> None:
        if saved is None:
            return
        for n, s in saved[0].items():
            try:
                self.m.fmus[n].slave.freeFMUState(s)
            except Exception:
                pass

    def close(self):
        self.m.close()


def _sample_steps(resp: np.ndarray, tol: float) -> tuple[int, int]:
    """(m, phase): the feeding signal changes only at steps k ≡ phase (mod m)."""
    d = np.abs(np.diff(resp, prepend=0.0))
    idx = np.nonzero(d > tol)[0]
    if idx.size < 2:
        return 1, 0
    m = int(np.gcd.reduce(idx - idx[0]))
    return max(1, m), int(idx[0] % max(1, m))


def _decayed(r: np.ndarray) -> bool:
    """The last tenth of the response below 10⁻⁴ of its peak."""
    peak = float(np.max(np.abs(r))) if r.size else 0.0
    return peak == 0.0 or float(np.max(np.abs(r[-max(1, r.size // 10):]))) <= 1e-4 * peak


def _dtft(r: np.ndarray, w: np.ndarray, T: float) -> np.ndarray:
    """Σ_k r_k e^{-jωTk} (Horner's scheme in e^{-jωT}: scipy.signal.freqz of the FIR r)."""
    from scipy.signal import freqz
    return freqz(r, [1.0], worN=w * T)[1]


def margins_of(L: np.ndarray, w: np.ndarray, T: float) -> dict:
    """Margins of a loop given by its frequency response ``L`` at ``w`` [rad/s] (python-control
    ``stability_margins`` on the frequency-response data, all crossings; the Nyquist point is added as a
    phase crossover when L is real and negative there)."""
    import control
    sys = control.frd(L, w)
    gm, pm, _sm, wpg, wpc, _wms = control.stability_margins(sys, returnall=True)
    gm, pm, wpg, wpc = (np.atleast_1d(np.asarray(x, dtype=float)) for x in (gm, pm, wpg, wpc))
    ln = L[-1]
    if abs(w[-1] - math.pi / T) < 1e-9 * w[-1] and ln.real < 0 and abs(ln.imag) <= 1e-6 * abs(ln):
        gm = np.append(gm, 1.0 / abs(ln))
        wpg = np.append(wpg, w[-1])
    out = {"gm_db": math.inf, "gm_low_db": math.nan, "wpc": math.nan, "pm_deg": math.nan, "wc": math.nan,
           "dm_s": math.nan}
    up = [(g, x) for g, x in zip(gm, wpg) if np.isfinite(g) and g > 1.0]
    low = [(g, x) for g, x in zip(gm, wpg) if np.isfinite(g) and 0.0 < g < 1.0]
    if up:
        g, x = min(up)
        out["gm_db"], out["wpc"] = 20 * math.log10(g), float(x)
    if low:
        g, _ = max(low)
        out["gm_low_db"] = 20 * math.log10(g)
    cross = [(p, x) for p, x in zip(pm, wpc) if np.isfinite(p) and np.isfinite(x) and x > 0]
    if cross:
        p, x = min(cross)  # the smallest phase margin over the gain crossovers
        out["pm_deg"], out["wc"] = float(p), float(x)
        dms = [math.radians(p) / x for p, x in cross if p > 0]
        out["dm_s"] = min(dms) if dms and min(p for p, _ in cross) > 0 else 0.0
    return out


def loop_margins(scenario: Scenario, plant: str = "plant", ports=tuple(f"torque_cmd_{a}" for a in AXES),
                 horizon: float = 20.0, eps: float | None = None, n_freq: int = 1500,
                 max_horizon: float = 200.0) -> list[AxisMargins]:
    """Per-axis margins of the scenario's loop broken at ``plant``'s inputs ``ports`` (see the module
    docstring). The pulse response is recorded in pieces of ``horizon`` [s] until it has decayed (its last
    tenth below 10⁻⁴ of its peak), at most ``max_horizon`` [s]; a response that has not decayed by then is
    noted (margins approximate)."""
    h = scenario.step
    n_op = scenario.n_steps
    n_h = int(round(horizon / h))
    n_max = int(round(max(horizon, max_horizon) / h))
    sc = scenario.with_overrides(stop_time=scenario.stop_time + (n_max + 2) * h)
    drv = _Driver(sc, plant, ports)
    try:
        nominal = drv.run(n_op)
        saved = drv.save()
        if eps is None:
            peak = float(np.max(np.abs(nominal))) if nominal.size else 0.0
            eps = 1e-4 * peak if peak > 0 and math.isfinite(peak) else 1e-6

        def fresh():
            nonlocal drv
            if saved is not None:
                drv.restore(saved)
            else:  # no FMU state: rebuild and re-run to the operating point
                drv.close()
                drv = _Driver(sc, plant, ports)
                drv.run(n_op)

        def response(i, pulse):
            """Central difference of the ± pulse runs, extended by ``n_h`` steps at a time (up to
            ``max_horizon``) until the response has decayed."""
            runs = []
            for sign in (1.0, -1.0):
                fresh()
                runs.append([drv.run(n_h, i, sign * pulse)[:, i], drv.save() if saved is not None else None])
            r = (runs[0][0] - runs[1][0]) / (2 * eps)
            while not _decayed(r) and r.size + n_h <= n_max and saved is not None:
                for run in runs:
                    drv.restore(run[1])
                    drv.free(run[1])
                    run[0] = np.concatenate([run[0], drv.run(n_h)[:, i]])
                    run[1] = drv.save()
                r = (runs[0][0] - runs[1][0]) / (2 * eps)
            for run in runs:
                drv.free(run[1])
            return r

        out = []
        for i, ax in enumerate(AXES[:len(ports)]):
            p1 = np.zeros(n_h)
            p1[0] = eps
            r = response(i, p1)
            note = []
            m, phase = _sample_steps(r, 1e-9 * max(1e-300, float(np.max(np.abs(r)))))
            if m > 1:  # sampled: a pulse over one sample period from a sample instant, read at sample instants
                start = phase % m
                pm_ = np.zeros(n_h)
                pm_[start:start + m] = eps
                r = response(i, pm_)
                r = r[start::m]
            T = m * h
            if not _decayed(r):
                note.append(f"pulse response not decayed within {r.size * T:g} s (a limit cycle, or a loop unstable "
                            f"at this operating point): margins unreliable")
            w = np.logspace(math.log10(1e-3 / T), math.log10(math.pi / T), n_freq)
            Tf = -_dtft(r, w, T)
            with np.errstate(divide="ignore", invalid="ignore"):
                L = Tf / (1.0 - Tf)
            res = margins_of(L, w, T)
            if not math.isfinite(res["wc"]):
                note.append("no gain crossover: |L| never reaches 1 below the Nyquist frequency")
            out.append(AxisMargins(ax, sample_time=T, note="; ".join(note), omega=w, loop=L, **res))
        return out
    finally:
        drv.close()
