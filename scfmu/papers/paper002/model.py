"""Paper 002 building blocks: the single-axis closed loop (SingleAxisPlant + PidController or
FopidController), its cost, an independent numpy reference of the same difference equations, and the
PSO driver (the tuning on the campaign engine is in ``tuning.py``).

One closed-loop run is one function, ``run_case(controller, gains, scenario)`` -> dict of metrics
(+ optional time series), so that any process pool or campaign engine can map it.

Loop (Gauss-Seidel, Δ = h): at t_n read θ_n from the plant (no feed-through), set θ_n and θ_ref on the
controller, read u_n, set u_n on the plant, doStep both from t_n to t_n + h.
"""

from __future__ import annotations

import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy.fmi1 import FMICallException

from ...engines import SimulationError, simulate
from ...metrics import overshoot_percent, settling_time, single_axis
from ...scenario.model import DEFAULT_UNCONNECTED, Component
from ...scenario.model import Scenario as EngineScenario
from .data import data_file

GAINS_FILE = data_file("gains.json")

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
LATE_T = 10.0  # start of the steady-state window of the penalty [s]
PENALTY_LATE, PENALTY_NONFINITE = 1000.0, 1e6


def cost_from_series(t: np.ndarray, theta: np.ndarray, theta_ref_deg: float) -> dict:
    """PSO cost terms of one run sampled at every step t_0 … t_N: MAE (deg) over the samples n < N, the
    largest error over t_n >= 10 s (n < N) and cost = MAE + 1000 if that exceeds 0.5°; a non-finite
    trajectory costs 1e6 + 1000."""
    theta = np.asarray(theta, float)
    if not np.all(np.isfinite(theta)):
        return {"mae_deg": math.inf, "late_max_deg": math.inf, "cost": PENALTY_NONFINITE + PENALTY_LATE}
    n = len(theta) - 1
    e_deg = np.abs(theta_ref_deg - np.degrees(theta[:n]))
    mae = float(np.mean(e_deg))
    h = (float(t[-1]) - float(t[0])) / n
    late = e_deg[int(round((LATE_T - float(t[0])) / h)):]
    late_max = float(np.max(late)) if late.size else 0.0
    return {"mae_deg": mae, "late_max_deg": late_max, "cost": mae + (PENALTY_LATE if late_max > 0.5 else 0.0)}


def cost_terms(theta: np.ndarray, sc: Scenario) -> dict:
    """MAE (deg) over samples n < N, the steady-state check over t_n >= 10 s and the PSO cost."""
    return cost_from_series(np.array([0.0, sc.t_end]), np.asarray(theta, float)[: sc.n + 1], sc.theta_ref_deg)


def step_metrics(t: np.ndarray, theta: np.ndarray, sc: Scenario) -> dict:
    ref = math.radians(sc.theta_ref_deg)
    return {"overshoot_pct": float(overshoot_percent(theta, ref)), "settling_s": float(settling_time(t, theta, ref))}


# ----- FMU closed loop ---------------------------------------------------------------------------
LOG = {"theta": "plant.theta", "omega": "plant.omega", "applied_torque": "plant.applied_torque",
       "theta_deg": "plant.theta_deg", "u": "controller.u", "theta_ref": "controller.theta_ref"}
RECORDED = ("omega", "u", "applied_torque")


def loop_scenario(controller: str, gains: dict, sc: Scenario = Scenario()) -> EngineScenario:
    """The paper 002 loop as a declared scenario (``paper002/<controller>``): the controller (PidController
    or FopidController with `gains`) → SingleAxisPlant (explicit Euler, internal step = communication step
    = the controller's sample time), θ_ref a fixed input, metric set ``paper002``."""
    model, cparams = controller_params(controller, gains, sc)
    return EngineScenario(
        name=f"paper002/{controller}",
        components=[Component("controller", model, cparams),
                    Component("plant", "SingleAxisPlant", {**sc.plant, "integrator": 1, "max_internal_step": sc.h})],
        stop_time=sc.t_end, step=sc.h, log=dict(LOG),
        inputs={"controller.theta_ref": math.radians(sc.theta_ref_deg)},
        unconnected=[*DEFAULT_UNCONNECTED, "torque_dist"],
        metrics="paper002",  # single-axis step metrics + the PSO cost terms (mae_deg, late_max_deg, cost)
        description=f"paper 002 single-axis loop, {controller}, {sc.theta_ref_deg:g} deg step")


def run_case(controller: str, gains: dict, sc: Scenario = Scenario(), record: bool = False) -> dict:
    """One closed-loop FMU run: :func:`loop_scenario` on the native engine (Gauss–Seidel: at t_n θ_n read
    from the plant, θ_n set on the controller, u_n read and set on the plant, both stepped), θ logged at
    every step. Returns the cost terms (and t, theta, omega, u, applied_torque when `record`). A failing run
    (FMU error status, non-finite value) gives the non-finite cost (and all-NaN series)."""
    loop = loop_scenario(controller, gains, sc)
    keys = ("theta", *RECORDED) if record else ("theta",)
    loop.log = {k: LOG[k] for k in keys}
    n = sc.n
    try:
        r = simulate(loop, "native")
    except (SimulationError, FMICallException):  # an FMU error status, in initialization or stepping
        r = {k: np.full(n + 1, np.nan) for k in keys}
    out = cost_terms(r["theta"], sc)
    if record:
        out.update(t=np.arange(n + 1) * sc.h, **{k: r[k] for k in keys})
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
class Pso:
    """Global-best PSO over the box [lower, upper] as an ask/tell object (``positions()`` → evaluate →
    ``tell(costs)``), so that several swarms can share one batch of evaluations.

    Positions live in the unit cube (x = lower + z (upper - lower)), so the velocity clamp is `vclamp` of
    each range; uniform initial positions, positions clipped to the box ("nearest"), inertia weight linear
    from w_start (first iteration) to w_end (last possible iteration), stop when the best cost improved by
    less than `stall_tol` over `stall_iters` iterations. The swarm update is pyswarms' backend (star
    topology). pyswarms draws from numpy's global generator; each swarm keeps its own generator state
    (seeded by `seed`) and swaps it in only for its own draws, so a swarm's trajectory depends on its seed
    and its costs only, whatever other swarms run beside it. ``state()`` / ``from_state()`` give a JSON-ready
    checkpoint from which the run continues bit-identically."""

    def __init__(self, lower, upper, n_particles=30, max_iter=400, seed=0, stall_iters=50, stall_tol=1e-6,
                 w_start=0.9, w_end=0.4, c1=2.0, c2=2.0, vclamp=0.2):
        import pyswarms.backend as P
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.cfg = dict(n_particles=int(n_particles), max_iter=int(max_iter), seed=int(seed),
                        stall_iters=int(stall_iters), stall_tol=float(stall_tol), w_start=float(w_start),
                        w_end=float(w_end), c1=float(c1), c2=float(c2), vclamp=float(vclamp))
        d = self.lower.size
        self._bounds = (np.zeros(d), np.ones(d))
        self._clamp = (-vclamp, vclamp)
        keep = np.random.get_state()
        try:
            np.random.seed(seed)
            self.swarm = P.create_swarm(n_particles=n_particles, dimensions=d,
                                        options={"c1": c1, "c2": c2, "w": w_start}, bounds=self._bounds,
                                        clamp=self._clamp)
            self._rng = np.random.get_state()
        finally:
            np.random.set_state(keep)
        self.it = 0  # iterations evaluated
        self.history: list[float] = []  # best cost after each iteration
        self.done = False
        self.stalled = False

    def positions(self) -> np.ndarray:
        """The particles to evaluate in the current iteration, in the box."""
        return self.lower + self.swarm.position * (self.upper - self.lower)

    def tell(self, costs) -> None:
        from pyswarms.backend import compute_pbest
        from pyswarms.backend.handlers import BoundaryHandler, VelocityHandler
        from pyswarms.backend.topology import Star
        c = self.cfg
        sw, it = self.swarm, self.it
        sw.options["w"] = c["w_start"] - (c["w_start"] - c["w_end"]) * it / max(1, c["max_iter"] - 1)
        sw.current_cost = np.asarray(costs, float)
        if it == 0:
            sw.pbest_pos, sw.pbest_cost = sw.position.copy(), sw.current_cost.copy()
        else:
            sw.pbest_pos, sw.pbest_cost = compute_pbest(sw)
        topo = Star()
        sw.best_pos, sw.best_cost = topo.compute_gbest(sw)
        self.history.append(float(sw.best_cost))
        self.it = it + 1
        if it >= c["stall_iters"] and self.history[it - c["stall_iters"]] - self.history[it] < c["stall_tol"]:
            self.done = self.stalled = True
            return
        if self.it >= c["max_iter"]:
            self.done = True
            return
        keep = np.random.get_state()
        try:
            np.random.set_state(self._rng)
            sw.velocity = topo.compute_velocity(sw, self._clamp, VelocityHandler(strategy="unmodified"), self._bounds)
            sw.position = topo.compute_position(sw, self._bounds, BoundaryHandler(strategy="nearest"))
            self._rng = np.random.get_state()
        finally:
            np.random.set_state(keep)

    @property
    def best_x(self) -> list[float]:
        return (self.lower + np.asarray(self.swarm.best_pos) * (self.upper - self.lower)).tolist()

    @property
    def best_cost(self) -> float:
        return float(self.swarm.best_cost)

    def state(self) -> dict:
        sw = self.swarm
        arrays = {k: np.asarray(getattr(sw, k)).tolist() for k in
                  ("position", "velocity", "pbest_pos", "pbest_cost", "best_pos", "current_cost")}
        r = self._rng
        return {"cfg": self.cfg, "lower": self.lower.tolist(), "upper": self.upper.tolist(), "it": self.it,
                "history": self.history, "done": self.done, "stalled": self.stalled, "swarm": arrays,
                "best_cost": float(sw.best_cost) if np.size(sw.best_cost) else None, "w": sw.options["w"],
                "rng": [r[0], np.asarray(r[1]).tolist(), int(r[2]), int(r[3]), float(r[4])]}

    @classmethod
    def from_state(cls, st: dict) -> "Pso":
        p = cls(st["lower"], st["upper"], **st["cfg"])
        sw = p.swarm
        for k, v in st["swarm"].items():
            setattr(sw, k, np.asarray(v, float))
        if st["best_cost"] is not None:
            sw.best_cost = np.float64(st["best_cost"])
        sw.options["w"] = st["w"]
        r = st["rng"]
        p._rng = (r[0], np.asarray(r[1], np.uint32), r[2], r[3], r[4])
        p.it, p.history, p.done, p.stalled = st["it"], list(st["history"]), st["done"], st["stalled"]
        return p


def _eval_chunk(args):
    fn, rows = args
    return [fn(r) for r in rows]


def pso_minimize(cost, lower, upper, n_particles=30, max_iter=400, seed=0, workers=1,
                 stall_iters=50, stall_tol=1e-6, w_start=0.9, w_end=0.4, c1=2.0, c2=2.0, vclamp=0.2,
                 progress=True, desc="PSO"):
    """:class:`Pso` driven by a plain function ``cost(x) -> float``, evaluated in `workers` processes
    (cost must be picklable). Reproducible by `seed` for any worker count (all random draws happen in
    this process). Returns dict(x, cost, iterations, history, evaluations, seconds, stalled)."""
    from tqdm import tqdm

    pso = Pso(lower, upper, n_particles, max_iter, seed, stall_iters, stall_tol, w_start, w_end, c1, c2, vclamp)
    t0 = time.perf_counter()
    pool = ProcessPoolExecutor(workers) if workers > 1 else None
    bar = tqdm(total=max_iter, desc=desc, disable=not progress, leave=False)
    try:
        while not pso.done:
            xs = pso.positions()
            if pool is None:
                costs = [cost(x) for x in xs]
            else:
                chunks = np.array_split(np.arange(n_particles), workers)
                parts = pool.map(_eval_chunk, [(cost, xs[c]) for c in chunks])
                costs = [c for part in parts for c in part]
            pso.tell(costs)
            bar.update(1)
            bar.set_postfix(best=f"{pso.best_cost:.6g}")
    finally:
        bar.close()
        if pool is not None:
            pool.shutdown()
    return {"x": pso.best_x, "cost": pso.best_cost, "iterations": pso.it, "history": pso.history,
            "evaluations": pso.it * n_particles, "seconds": time.perf_counter() - t0, "stalled": pso.stalled}


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


__all__ = ["CONTROLLERS", "BOUNDS", "Scenario", "run_case", "reference_loop", "Pso", "pso_minimize", "TuneCost",
           "cost_from_series", "load_gains", "cost_terms", "step_metrics", "gl_weights", "full_gains"]


# ----- the metric set of the paper002/<controller> scenarios -----------------------------------------
METRIC_COLUMNS = ("mae_deg", "late_max_deg", "cost")


def metrics_row(r: dict) -> dict:
    """Metric set ``paper002``: the single-axis step metrics plus the PSO cost terms of
    :func:`cost_from_series` (MAE over the samples of [t0, t_end), max error for t >= 10 s, cost)."""
    out = single_axis(r)
    out.update(cost_from_series(r["time"], r["theta"], math.degrees(float(r["theta_ref"][-1]))))
    return out
