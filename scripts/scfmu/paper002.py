"""Paper 002 building blocks: the single-axis closed loop (SingleAxisPlant + PidController or
FopidController), its cost, an independent numpy reference of the same difference equations, and the
PSO driver used by scripts/paper002_tune.py.

One closed-loop run is one function, ``run_case(controller, gains, scenario)`` -> dict of metrics
(+ optional time series), so that any process pool or campaign engine can map it.

Loop (Gauss-Seidel, Δ = h): at t_n read θ_n from the plant (no feed-through), set θ_n and θ_ref on the
controller, read u_n, set u_n on the plant, doStep both from t_n to t_n + h.
"""

from __future__ import annotations

import ctypes
import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .master import Fmu

ROOT = Path(__file__).resolve().parents[2]
GAINS_FILE = ROOT / "scripts" / "paper002_gains.json"

# controller name -> (FMU, tuned variables); PD and FOPD are the I-free cases (ki = 0)
CONTROLLERS = {
    "PD": ("PidController", ["kp", "kd"]),
    "PID": ("PidController", ["kp", "ki", "kd"]),
    "FOPD": ("FopidController", ["kp", "kd", "mu"]),
    "FOPID": ("FopidController", ["kp", "ki", "kd", "lambda", "mu"]),
}
BOUNDS = {"kp": (0.0, 20.0), "ki": (0.0, 20.0), "kd": (0.0, 20.0), "lambda": (0.0, 2.0), "mu": (0.0, 2.0)}
DEFAULT_GAINS = {"kp": 2.0, "ki": 0.1, "kd": 8.0, "lambda": 1.0, "mu": 1.0}


@dataclass(frozen=True)
class Scenario:
    """Nominal paper 002 setup; plant parameters use the SingleAxisPlant names."""

    theta_ref_deg: float = 30.0
    t_end: float = 20.0
    h: float = 0.001
    plant: dict = field(default_factory=dict)  # overrides of SingleAxisPlant parameters
    gl_memory: int = 0
    history_before_start: int = 0

    @property
    def n(self) -> int:
        return int(round(self.t_end / self.h))


PLANT_DEFAULTS = {"inertia": 7.7, "inertia_scale": 1.0, "wheel_gain": 1.0, "wheel_time_constant": 0.2,
                  "torque_limit": 1.0, "md_amp": 0.01, "md_freq": 0.1, "md_const": 0.0001}


def full_gains(controller: str, gains: dict) -> dict:
    """All five law parameters for `controller` (PD/FOPD: ki = 0; integer controllers: λ = μ = 1)."""
    g = {"kp": 0.0, "ki": 0.0, "kd": 0.0, "lambda": 1.0, "mu": 1.0}
    for k in CONTROLLERS[controller][1]:
        g[k] = float(gains[k])
    return g


def controller_params(controller: str, gains: dict, sc: Scenario) -> tuple[str, dict]:
    model, _ = CONTROLLERS[controller]
    g = full_gains(controller, gains)
    p = {"kp": g["kp"], "ki": g["ki"], "kd": g["kd"], "step": sc.h, "gl_memory": sc.gl_memory,
         "history_before_start": sc.history_before_start}
    if model == "FopidController":
        p.update({"lambda": g["lambda"], "mu": g["mu"]})
    return model, p


# ----- metrics -----------------------------------------------------------------------------------
def cost_terms(theta: np.ndarray, sc: Scenario) -> dict:
    """MAE (deg) over samples n < N, the steady-state check over t_n >= 10 s and the PSO cost."""
    n = sc.n
    e_deg = np.abs(sc.theta_ref_deg - np.degrees(theta[:n]))
    if not np.all(np.isfinite(theta)):
        return {"mae_deg": math.inf, "late_max_deg": math.inf, "cost": 1e6 + 1000.0}
    mae = float(np.mean(e_deg))
    late = e_deg[int(round(10.0 / sc.h)):]
    late_max = float(np.max(late)) if late.size else 0.0
    return {"mae_deg": mae, "late_max_deg": late_max, "cost": mae + (1000.0 if late_max > 0.5 else 0.0)}


def step_metrics(t: np.ndarray, theta: np.ndarray, sc: Scenario) -> dict:
    from .metrics import overshoot_percent, settling_time
    ref = math.radians(sc.theta_ref_deg)
    return {"overshoot_pct": float(overshoot_percent(theta, ref)), "settling_s": float(settling_time(t, theta, ref))}


# ----- FMU closed loop ---------------------------------------------------------------------------
class _Raw:
    """Direct fmi2GetReal / fmi2SetReal / fmi2DoStep calls with pre-built ctypes buffers."""

    def __init__(self, fmu: Fmu, inputs: list[str], outputs: list[str]):
        s = fmu.slave
        self.s = s
        self.vr_in = (ctypes.c_uint * len(inputs))(*[fmu.var(n).valueReference for n in inputs])
        self.vr_out = (ctypes.c_uint * len(outputs))(*[fmu.var(n).valueReference for n in outputs])
        self.buf_in = (ctypes.c_double * len(inputs))()
        self.buf_out = (ctypes.c_double * len(outputs))()
        self.n_in, self.n_out = len(inputs), len(outputs)

    def set(self, *values):
        for i, v in enumerate(values):
            self.buf_in[i] = v
        self.s.fmi2SetReal(self.s.component, self.vr_in, self.n_in, self.buf_in)

    def get(self):
        self.s.fmi2GetReal(self.s.component, self.vr_out, self.n_out, self.buf_out)
        return self.buf_out

    def step(self, t, h):
        self.s.fmi2DoStep(self.s.component, t, h, 1)


def run_case(controller: str, gains: dict, sc: Scenario = Scenario(), record: bool = False) -> dict:
    """One closed-loop FMU run. Returns the cost terms (and t, theta, omega, u, applied_torque when
    `record`). An FMU error (e.g. a non-finite value) gives the non-finite cost."""
    model, cparams = controller_params(controller, gains, sc)
    pparams = {**sc.plant, "integrator": 1, "max_internal_step": sc.h}
    n = sc.n
    theta = np.full(n + 1, np.nan)
    rec = {k: np.full(n + 1, np.nan) for k in ("omega", "u", "applied_torque")} if record else None
    plant = ctrl = None
    try:
        plant = Fmu("SingleAxisPlant", pparams, stop_time=sc.t_end)
        ctrl = Fmu(model, cparams, stop_time=sc.t_end)
        ref = math.radians(sc.theta_ref_deg)
        p_out = _Raw(plant, ["u"], ["theta", "omega", "applied_torque"])
        c_io = _Raw(ctrl, ["theta", "theta_ref"], ["u"])
        h = sc.h
        for k in range(n + 1):
            t = k * h
            y = p_out.get()
            th = y[0]
            theta[k] = th
            c_io.set(th, ref)
            u = c_io.get()[0]
            if record:
                rec["omega"][k], rec["applied_torque"][k], rec["u"][k] = y[1], y[2], u
            if k < n:
                p_out.set(u)
                c_io.step(t, h)
                p_out.step(t, h)
    except Exception:  # FMU error status (fmpy raises): keep the NaN tail
        pass
    finally:
        for f in (ctrl, plant):
            if f is not None:
                f.close()
    out = cost_terms(theta, sc)
    if record:
        out.update(t=np.arange(n + 1) * sc.h, theta=theta, **rec)
    return out


# ----- independent numpy reference of the same difference equations -------------------------------
def gl_weights(alpha: float, n: int) -> np.ndarray:
    """(-1)^j binom(α, j), j < n, independent of the recursion: scipy.special.binom for non-integer α,
    exact integer binomials for integer α (scipy returns nan for negative integer arguments)."""
    j = np.arange(n)
    if float(alpha).is_integer():
        a = int(alpha)
        if a >= 0:
            return np.array([(-1) ** k * math.comb(a, k) if k <= a else 0.0 for k in range(n)], float)
        return np.array([float(math.comb(-a + k - 1, k)) for k in range(n)])
    from scipy.special import binom
    return (-1.0) ** j * binom(alpha, j)


def reference_loop(controller: str, gains: dict, sc: Scenario = Scenario()) -> dict:
    """Explicit-Euler plant + PID / PI^λD^μ law with direct GL sums (full or short memory), in numpy.
    Slow for FOPID (O(N²)); meant as a test oracle."""
    g = full_gains(controller, gains)
    p = {**PLANT_DEFAULTS, **sc.plant}
    h, n, ref = sc.h, sc.n, math.radians(sc.theta_ref_deg)
    jt = p["inertia"] * p["inertia_scale"]
    mem = sc.gl_memory
    wi = gl_weights(-g["lambda"], n + 1)[::-1].copy()
    wd = gl_weights(g["mu"], n + 1)[::-1].copy()
    if mem:
        wi[: max(0, n + 1 - mem)] = 0.0
        wd[: max(0, n + 1 - mem)] = 0.0
    e = np.zeros(n + 1)
    th = np.zeros(n + 1)
    u_log = np.zeros(n + 1)
    x = np.array([0.0, 0.0, 0.0])  # θ, ω, T_c
    for k in range(n + 1):
        th[k] = x[0]
        e[k] = ref - x[0]
        # Σ_{j=0}^{k} w_j e_{k-j} = dot(w reversed tail, e[0..k])
        integ = h ** g["lambda"] * float(np.dot(wi[n - k:], e[: k + 1]))
        deriv = h ** (-g["mu"]) * float(np.dot(wd[n - k:], e[: k + 1]))
        if sc.history_before_start:
            w_full = gl_weights(g["mu"], (mem if mem else k + 1))
            s_end = float(np.sum(w_full)) if mem else (1.0 if g["mu"] == 0 else 0.0)
            s_k = float(np.sum(w_full[: k + 1]))
            deriv += h ** (-g["mu"]) * e[0] * (s_end - s_k if (not mem or k + 1 < mem) else 0.0)
        u = g["kp"] * e[k] + g["ki"] * integ + g["kd"] * deriv
        u_log[k] = u
        if k < n:
            t = k * h
            mc = min(max(x[2], -p["torque_limit"]), p["torque_limit"])
            md = p["md_amp"] * math.sin(p["md_freq"] * t) + p["md_const"]
            x = x + h * np.array([x[1], (mc + md) / jt, (p["wheel_gain"] * u - x[2]) / p["wheel_time_constant"]])
    out = cost_terms(th, sc)
    out.update(t=np.arange(n + 1) * h, theta=th, u=u_log)
    return out


# ----- PSO (pyswarms backend, in the unit cube) -------------------------------------------------
def _eval_chunk(args):
    fn, rows = args
    return [fn(r) for r in rows]


def pso_minimize(cost, lower, upper, n_particles=30, max_iter=400, seed=0, workers=1,
                 stall_iters=50, stall_tol=1e-6, w_start=0.9, w_end=0.4, c1=2.0, c2=2.0, vclamp=0.2,
                 progress=True, desc="PSO"):
    """Global-best PSO of `cost(x) -> float` over the box [lower, upper].

    Positions live in the unit cube (x = lower + z (upper - lower)), so the velocity clamp is
    `vclamp` of each range; uniform initial positions, positions clipped to the box ("nearest"),
    inertia weight linear from w_start (first iteration) to w_end (last possible iteration),
    stop when the best cost improved by less than `stall_tol` over `stall_iters` iterations.
    Particles are evaluated in `workers` processes (cost must be picklable). Reproducible by `seed`
    (for any worker count: the random draws all happen in this process).
    Returns dict(x, cost, iterations, history, evaluations, seconds)."""
    import pyswarms.backend as P
    from pyswarms.backend.handlers import BoundaryHandler, VelocityHandler
    from pyswarms.backend.topology import Star
    from tqdm import tqdm

    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    d = lower.size
    state = np.random.get_state()
    np.random.seed(seed)
    bounds = (np.zeros(d), np.ones(d))
    clamp = (-vclamp, vclamp)
    swarm = P.create_swarm(n_particles=n_particles, dimensions=d,
                           options={"c1": c1, "c2": c2, "w": w_start}, bounds=bounds, clamp=clamp)
    topo, vh, bh = Star(), VelocityHandler(strategy="unmodified"), BoundaryHandler(strategy="nearest")
    history = []
    t0 = time.perf_counter()
    pool = ProcessPoolExecutor(workers) if workers > 1 else None
    bar = tqdm(total=max_iter, desc=desc, disable=not progress, leave=False)
    try:
        it = 0
        for it in range(max_iter):
            swarm.options["w"] = w_start - (w_start - w_end) * it / max(1, max_iter - 1)
            xs = lower + swarm.position * (upper - lower)
            if pool is None:
                costs = [cost(x) for x in xs]
            else:
                chunks = np.array_split(np.arange(n_particles), workers)
                parts = pool.map(_eval_chunk, [(cost, xs[c]) for c in chunks])
                costs = [c for part in parts for c in part]
            swarm.current_cost = np.asarray(costs, float)
            if it == 0:
                swarm.pbest_pos, swarm.pbest_cost = swarm.position.copy(), swarm.current_cost.copy()
            else:
                swarm.pbest_pos, swarm.pbest_cost = P.compute_pbest(swarm)
            swarm.best_pos, swarm.best_cost = topo.compute_gbest(swarm)
            history.append(float(swarm.best_cost))
            bar.update(1)
            bar.set_postfix(best=f"{swarm.best_cost:.6g}")
            if it >= stall_iters and history[it - stall_iters] - history[it] < stall_tol:
                break
            swarm.velocity = topo.compute_velocity(swarm, clamp, vh, bounds)
            swarm.position = topo.compute_position(swarm, bounds, bh)
    finally:
        bar.close()
        if pool is not None:
            pool.shutdown()
        np.random.set_state(state)
    best = lower + swarm.best_pos * (upper - lower)
    return {"x": best.tolist(), "cost": float(swarm.best_cost), "iterations": len(history), "history": history,
            "evaluations": len(history) * n_particles, "seconds": time.perf_counter() - t0}


@dataclass(frozen=True)
class TuneCost:
    """Picklable PSO cost of one controller on one scenario: x (tuned variables) -> cost."""

    controller: str
    scenario: Scenario = Scenario()

    def __call__(self, x) -> float:
        names = CONTROLLERS[self.controller][1]
        return run_case(self.controller, dict(zip(names, map(float, x))), self.scenario)["cost"]


def load_gains(path: Path = GAINS_FILE) -> dict:
    """Tuned gains per controller from the JSON written by the tuner; defaults when absent."""
    if Path(path).exists():
        data = json.loads(Path(path).read_text())
        return {c: data["controllers"][c]["gains"] for c in CONTROLLERS if c in data.get("controllers", {})}
    return {c: {k: DEFAULT_GAINS[k] for k in CONTROLLERS[c][1]} for c in CONTROLLERS}


__all__ = ["CONTROLLERS", "BOUNDS", "Scenario", "run_case", "reference_loop", "pso_minimize", "TuneCost",
           "load_gains", "cost_terms", "step_metrics", "gl_weights", "full_gains"]
