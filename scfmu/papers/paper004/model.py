"""Paper 004 (fault-tolerant attitude control by reference correction): setup, the open-loop spline
optimisation and the closed-loop cases, shared by the commands ``scfmu paper 004 optimize`` and
``scfmu paper 004 cases``, the report section and the tests.

Setup: AttitudePlant with I = diag(449.5, 264.5, 312.5) kg m^2, actuator_mode 0, u_max = 10 N m per
axis, effectiveness a_i = 1 (healthy) or 0.1 (faulty, limit 1 N m) from t = 0, no disturbance; RK4
0.01 s; communication step 0.01 s; t_f = 20 s. Initial state at rest with 321 angles
(yaw, pitch, roll) = (6, -4, 8) deg (default) or (15, -10, 20) deg (stress run 004-X).

Open-loop torque: one not-a-knot cubic spline per axis through 6 nodes at t = 0, 4, ..., 20 s; the
last node is fixed at 0 and the torque is 0 after 20 s. The optimisation chooses nodes 0-4 of each
axis (15 variables, |node_i| <= a_i u_max_i) to minimise the integral of |u_applied|^2 subject to
|w_i(t_f)| <= 0.01 deg/s and |roll|, |pitch|, |yaw| (321) <= 0.1 deg at t_f, each as two smooth
inequalities (12), with SciPy SLSQP and a budget of 300 simulations (finite-difference gradients
included). Every simulation runs the AttitudePlant FMU open loop with the spline sampled at the
communication points and held over each step (zero-order hold, as the master holds inputs).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ...engines.lean import OpenLoop
from ...engines.reference import CoSimulation
from ...fmu import Fmu

INERTIA = (449.5, 264.5, 312.5)
U_MAX = 10.0
A_FAULT = 0.1
T_F = 20.0
DT = 0.01
N_NODES = 6
NODE_TIMES = np.linspace(0.0, T_F, N_NODES)
W_REQ_DEG_S = 0.01
EULER_REQ_DEG = 0.1
INIT_DEFAULT_DEG = {"yaw": 6.0, "pitch": -4.0, "roll": 8.0}
INIT_STRESS_DEG = {"yaw": 15.0, "pitch": -10.0, "roll": 20.0}
# CALIBRATION (paper 004 gives no initial attitude): the default direction scaled by this factor is the start
# whose case-2 run ends closest to the paper's case-2 largest final Euler angle (≈ 0.7 deg); the report
# recomputes it on its grid and stops if it no longer agrees. The standard scenarios paper004/<1|2|3> start there.
INIT_SCALE_CALIBRATED = 1.25


def init_deg_scaled(scale: float) -> dict:
    """The default initial direction (yaw, pitch, roll) scaled by ``scale`` (deg)."""
    return {k: v * scale for k, v in INIT_DEFAULT_DEG.items()}
K_Q, K_QDOT = 0.5, 2.0
BUDGET = 300
MARGIN = 0.01   # project choice: the optimiser's terminal bounds are 1 % inside the requirements
AXES = "xyz"


def plant_params(effectiveness: float, init_deg: dict) -> dict:
    p = {"inertia_xx": INERTIA[0], "inertia_yy": INERTIA[1], "inertia_zz": INERTIA[2], "actuator_mode": 0,
         "kinematics": 0, "integrator": 0, "max_internal_step": DT, "fault_time": 0.0,
         "init_euler321_roll": math.radians(init_deg["roll"]),
         "init_euler321_pitch": math.radians(init_deg["pitch"]),
         "init_euler321_yaw": math.radians(init_deg["yaw"])}
    for a in AXES:
        p[f"u_max_{a}"] = U_MAX
        p[f"effectiveness_{a}"] = effectiveness
    return p


def node_param_names() -> list[str]:
    return [f"node_{a}_{j}" for a in AXES for j in range(N_NODES)]


def full_nodes(x: np.ndarray) -> np.ndarray:
    """15 free node values (axis-major, nodes 0-4) -> (3, 6) array with the fixed last node 0."""
    return np.column_stack([np.asarray(x, float).reshape(3, N_NODES - 1), np.zeros(3)])


def spline_basis(times: np.ndarray) -> np.ndarray:
    """B with u(times) = B @ node_values (the spline is linear in the node values); 0 after t_f."""
    from scipy.interpolate import CubicSpline  # here, not at import: loading the plug-ins (every scfmu command)
    b = CubicSpline(NODE_TIMES, np.eye(N_NODES), bc_type="not-a-knot")(times)
    b[np.asarray(times) > NODE_TIMES[-1]] = 0.0
    return b


def spline_torque(nodes: np.ndarray, times: np.ndarray) -> np.ndarray:
    """(len(times), 3) spline torque of a (3, 6) node array."""
    return spline_basis(times) @ np.asarray(nodes).T


def terminal_metrics(w_end: np.ndarray, euler_end: np.ndarray) -> dict:
    """Paper 004 requirement check at t_f (rad/s and rad in, deg/s and deg out)."""
    w_deg = np.degrees(np.abs(w_end))
    e_deg = np.degrees(np.abs(euler_end))
    wmax, emax = float(w_deg.max()), float(e_deg.max())
    return {"w_end_max_deg_s": wmax, "euler_end_max_deg": emax,
            "pass": bool(wmax <= W_REQ_DEG_S and emax <= EULER_REQ_DEG)}


PLANT_OUT = ["w_x", "w_y", "w_z", "roll", "pitch", "yaw"]


def open_loop_plant(params: dict) -> OpenLoop:
    """The AttitudePlant driven open loop by the spline torque (``run(u, DT)`` -> w_x, w_y, w_z, roll,
    pitch, yaw at the end), from its initialised state restored before every run."""
    return OpenLoop("AttitudePlant", params, [f"torque_cmd_{a}" for a in AXES], PLANT_OUT, stop_time=T_F)


class BudgetExhausted(Exception):
    pass


@dataclass
class OptResult:
    nodes: np.ndarray            # (3, 6)
    status: str                  # converged / budget hit / infeasible / failed
    message: str
    evaluations: int             # plant simulations, finite differences included
    iterations: int
    objective: float             # integral of |u_applied|^2 dt, N^2 m^2 s
    constraints: np.ndarray      # 12 values, >= 0 when satisfied (scaled by the requirement)
    terminal: dict               # terminal_metrics of the final nodes
    seconds: float
    x0: np.ndarray = field(default=None)


class SplineProblem:
    """Objective, 12 terminal constraints and their gradients for the SLSQP solver."""

    def __init__(self, init_deg: dict, effectiveness: float = A_FAULT, budget: int = BUDGET, fd_step: float = 1e-6,
                 margin: float = MARGIN):
        self.limit = effectiveness * U_MAX
        self.n = int(round(T_F / DT))
        self.times = np.arange(self.n) * DT          # held samples t_0 .. t_{n-1}
        self.basis = spline_basis(self.times)        # (n, 6)
        self.plant = open_loop_plant(plant_params(effectiveness, init_deg))
        self.budget = budget
        self.fd_step = fd_step
        self.evals = 0
        self._cache: dict[bytes, np.ndarray] = {}
        self._jcache: dict[bytes, np.ndarray] = {}
        self.history: list[tuple[np.ndarray, float, float]] = []   # (x, objective, worst violation)
        # constraints at (1 - margin) x the requirement, so that the optimum (which lies on the
        # constraint boundary) passes the requirement check with room for round-off
        self.scale_w = math.radians(W_REQ_DEG_S) * (1.0 - margin)
        self.scale_e = math.radians(EULER_REQ_DEG) * (1.0 - margin)
        self.j_scale = 1.0 / (3 * T_F * self.limit ** 2)

    def close(self):
        self.plant.close()

    def torque(self, x: np.ndarray) -> np.ndarray:
        return self.basis @ full_nodes(x).T          # (n, 3) spline samples before clipping

    def simulate(self, x: np.ndarray) -> np.ndarray:
        key = np.asarray(x, float).tobytes()
        y = self._cache.get(key)
        if y is None:
            if self.evals >= self.budget:
                raise BudgetExhausted
            self.evals += 1
            y = self.plant.run(self.torque(x), DT)
            self._cache[key] = y
            c = self.constraints_from(y)
            self.history.append((np.array(x, float), self.objective_raw(x), float(max(0.0, -c.min()))))
        return y

    def constraints_from(self, y: np.ndarray) -> np.ndarray:
        w, e = y[:3] / self.scale_w, y[3:] / self.scale_e
        return np.concatenate([1.0 - w, 1.0 + w, 1.0 - e, 1.0 + e])

    # ---- objective: integral of the applied (clipped) torque squared, left rectangle ---------------
    def objective_raw(self, x: np.ndarray) -> float:
        u = np.clip(self.torque(x), -self.limit, self.limit)
        return float(np.sum(u * u) * DT)

    def objective(self, x):
        return self.objective_raw(x) * self.j_scale

    def objective_grad(self, x):
        u = self.torque(x)
        inside = np.abs(u) < self.limit
        g = 2.0 * DT * (self.basis[:, :N_NODES - 1].T @ (u * inside))   # (5, 3)
        return g.T.reshape(-1) * self.j_scale

    # ---- constraints ---------------------------------------------------------------------------
    def constraints(self, x):
        return self.constraints_from(self.simulate(x))

    def constraints_jac(self, x):
        key = np.asarray(x, float).tobytes()
        jac = self._jcache.get(key)
        if jac is None:
            y0 = self.simulate(x)
            jy = np.empty((6, len(x)))
            for i in range(len(x)):
                xp = np.array(x, float)
                h = self.fd_step if xp[i] + self.fd_step <= self.limit else -self.fd_step
                xp[i] += h
                jy[:, i] = (self.simulate(xp) - y0) / h
            scale = np.concatenate([np.full(3, 1 / self.scale_w), np.full(3, 1 / self.scale_e)])
            js = jy * scale[:, None]
            jac = np.vstack([-js[:3], js[:3], -js[3:], js[3:]])
            self._jcache[key] = jac
        return jac

    def solve(self, x0: np.ndarray, maxiter: int = 100, ftol: float = 1e-7) -> OptResult:
        """SLSQP from x0. Status: the solver outcome — "converged" (SLSQP success), "budget hit" (the
        simulation budget ran out; the best point tried is returned: the feasible one with the
        lowest objective, else the least violating one) or "failed" (SLSQP stopped without success,
        e.g. incompatible constraints) — prefixed "infeasible (...)" when the returned point misses
        the terminal requirement."""
        t0 = time.perf_counter()
        x0 = np.clip(np.asarray(x0, float), -self.limit, self.limit)
        # Variables z = R x with R^T R = the objective's Hessian (unclipped spline): the objective is
        # then a plain sum of squares, which SLSQP's quasi-Newton start (the identity) already
        # matches, so few iterations (each 1 + 15 plant runs) are needed. The bounds on x become 30
        # linear inequalities in z.
        b5 = self.basis[:, :N_NODES - 1]
        h5 = 2.0 * DT * self.j_scale * (b5.T @ b5)
        r = np.kron(np.eye(3), np.linalg.cholesky(h5).T)
        r_inv = np.linalg.inv(r)
        lim = self.limit

        def xz(z):
            return r_inv @ z

        cons = [
            {"type": "ineq", "fun": lambda z: self.constraints(xz(z)), "jac": lambda z: self.constraints_jac(xz(z)) @ r_inv},
            {"type": "ineq", "fun": lambda z: np.concatenate([lim - xz(z), lim + xz(z)]),
             "jac": lambda z: np.vstack([-r_inv, r_inv])},
        ]
        iters = [0]

        def count(_zk):
            iters[0] += 1

        from scipy.optimize import minimize  # here, not at import (see spline_basis)
        success, budget_hit = False, False
        try:
            res = minimize(lambda z: self.objective(xz(z)), r @ x0, jac=lambda z: r_inv.T @ self.objective_grad(xz(z)),
                           constraints=cons, method="SLSQP", callback=count, options={"maxiter": maxiter, "ftol": ftol})
            x, message, success = xz(res.x), f"SLSQP: {res.message} (exit mode {res.status})", bool(res.success)
        except BudgetExhausted:
            budget_hit = True
            x = self.best()
            message = f"evaluation budget of {self.budget} simulations exhausted; best point tried returned"
        # final values come from the cache (x was simulated); allow one run if it was not
        budget, self.budget = self.budget, self.budget + 1
        c = self.constraints(x)
        self.budget = budget
        y = self.simulate(x)
        term = terminal_metrics(y[:3], y[3:])
        outcome = "converged" if success else ("budget hit" if budget_hit else "failed")
        status = outcome if term["pass"] else f"infeasible ({outcome})"
        return OptResult(nodes=full_nodes(x), status=status, message=message, evaluations=self.evals, iterations=iters[0],
                         objective=self.objective_raw(x), constraints=c, terminal=term,
                         seconds=time.perf_counter() - t0, x0=x0)

    def best(self) -> np.ndarray:
        """Lowest objective among the feasible points tried, else the least violating one."""
        feas = [h for h in self.history if h[2] <= 1e-6]
        if feas:
            return min(feas, key=lambda h: h[1])[0]
        return min(self.history, key=lambda h: h[2])[0]


# ---- closed-loop runs with the FMUs -------------------------------------------------------------
def controller_params() -> dict:
    p = {f"inertia_{a}{a}": i for a, i in zip(AXES, INERTIA)}
    for a in AXES:
        p[f"k_q_{a}"] = K_Q
        p[f"k_qdot_{a}"] = K_QDOT
    return p


def corrector_params(mode: int, nodes: np.ndarray | None, effectiveness: float, init_deg: dict) -> dict:
    p = controller_params()
    p["mode"] = mode
    p["max_internal_step"] = DT
    for a in AXES:
        p[f"u_max_{a}"] = U_MAX
        p[f"effectiveness_{a}"] = effectiveness
    p["init_euler321_roll"] = math.radians(init_deg["roll"])
    p["init_euler321_pitch"] = math.radians(init_deg["pitch"])
    p["init_euler321_yaw"] = math.radians(init_deg["yaw"])
    if nodes is not None:
        for ai, a in enumerate(AXES):
            for j in range(N_NODES):
                p[f"node_{a}_{j}"] = float(nodes[ai, j])
    return p


PLANT_LOG = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
             "torque_cmd_x", "torque_cmd_y", "torque_cmd_z", "torque_applied_x", "torque_applied_y", "torque_applied_z"]


def run_closed_loop(mode: int, effectiveness: float, init_deg: dict, nodes: np.ndarray | None = None,
                    t_end: float = T_F, dt: float = DT) -> dict:
    """ReferenceCorrector (mode 0 or 1) + FeedbackLinearizingController + AttitudePlant, wired by port
    name. Returns the logged signals (time, plant outputs, commanded/applied torque, reference)."""
    corr = Fmu("ReferenceCorrector", corrector_params(mode, nodes, effectiveness, init_deg), stop_time=t_end)
    ctrl = Fmu("FeedbackLinearizingController", controller_params(), stop_time=t_end)
    plant = Fmu("AttitudePlant", plant_params(effectiveness, init_deg), stop_time=t_end)
    sim = CoSimulation([corr, ctrl, plant])
    try:
        log = {n: (plant, n) for n in PLANT_LOG if n.startswith(("q_", "w_", "roll", "pitch", "yaw", "torque_applied"))}
        log.update({f"torque_cmd_{a}": (ctrl, f"torque_cmd_{a}") for a in AXES})
        log.update({f"q_ref_{c}": (corr, f"q_ref_{c}") for c in "wxyz"})
        log.update({f"u_ol_{a}": (corr, f"u_ol_{a}") for a in AXES})
        return sim.run(t_end, dt, log)
    finally:
        sim.close()


def run_open_loop(nodes: np.ndarray, effectiveness: float, init_deg: dict, t_end: float = T_F, dt: float = DT) -> dict:
    """Case 004-3ol: the spline torque (sampled at the communication points and held) applied directly
    to the plant; logs the same signals as run_closed_loop (torque_cmd = the spline)."""
    plant = Fmu("AttitudePlant", plant_params(effectiveness, init_deg), stop_time=t_end)
    n = int(round(t_end / dt))
    times = np.arange(n + 1) * dt
    u = spline_torque(nodes, times)
    out = {"time": times}
    names = [n_ for n_ in PLANT_LOG if not n_.startswith("torque_cmd")]
    for k in names:
        out[k] = np.empty(n + 1)
    try:
        for k in range(n + 1):
            plant.set_reals([f"torque_cmd_{a}" for a in AXES], u[k])
            for key, val in zip(names, plant.get_reals(names)):
                out[key][k] = val
            if k < n:
                plant.do_step(k * dt, dt)
    finally:
        plant.close()
    for i, a in enumerate(AXES):
        out[f"torque_cmd_{a}"] = u[:, i]
        out[f"u_ol_{a}"] = u[:, i]
    return out


def initial_guess_from_case2(init_deg: dict, effectiveness: float = A_FAULT) -> np.ndarray:
    """The case-2 closed-loop applied torque sampled at the node times 0..16 s, clipped to the bounds
    (the last node is fixed at 0): 15 values, axis-major."""
    r = run_closed_loop(0, effectiveness, init_deg, t_end=T_F)
    lim = effectiveness * U_MAX
    idx = [int(round(t / DT)) for t in NODE_TIMES[:-1]]
    x = [np.clip(r[f"torque_applied_{a}"][idx], -lim, lim) for a in AXES]
    return np.concatenate(x)


def optimise(init_deg: dict, x0: np.ndarray | None = None, effectiveness: float = A_FAULT, budget: int = BUDGET,
             margin: float = MARGIN) -> OptResult:
    if x0 is None:
        x0 = initial_guess_from_case2(init_deg, effectiveness)
    prob = SplineProblem(init_deg, effectiveness, budget, margin=margin)
    try:
        return prob.solve(x0)
    finally:
        prob.close()


# ----- the metric set of the paper004/<case> scenarios ---------------------------------------------
METRIC_COLUMNS = ("w_end_max_deg_s", "euler_end_max_deg", "requirement_met")


def metrics_row(r: dict) -> dict:
    """Metric set ``paper004``: the attitude columns without an AttitudeMetrics instance (effort from the
    applied torques), with the target attitude (321 angles 0, at rest) as reference: settling of the slowest
    angle into 2 % of its initial value, final error = largest final angle [deg], and the paper's terminal
    requirement (rates ≤ 0.01 deg/s, angles ≤ 0.1 deg at t_f)."""
    from ...metrics import attitude_nometrics, settling_time
    ref = {f"{a}_ref": np.zeros_like(np.asarray(r[a], dtype=float)) for a in ("roll", "pitch", "yaw")}
    out = attitude_nometrics({**r, **ref})
    term = terminal_metrics(np.array([r[f"w_{a}"][-1] for a in AXES]),
                            np.array([r[a][-1] for a in ("roll", "pitch", "yaw")]))
    out.update(w_end_max_deg_s=term["w_end_max_deg_s"], euler_end_max_deg=term["euler_end_max_deg"],
               requirement_met=1.0 if term["pass"] else 0.0)
    out["final_error"] = term["euler_end_max_deg"]
    st = [settling_time(r["time"], np.asarray(r[a], dtype=float), 0.0) for a in ("roll", "pitch", "yaw")]
    out["settling_s"] = max(st) if all(math.isfinite(x) for x in st) else math.nan
    return out
