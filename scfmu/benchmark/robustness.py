"""Robustness Monte Carlo of the controller benchmark: seeded dispersions of the plant a GNC engineer
expects, and the percentiles of each metric over the runs.

Dispersions (all project choices, per run, drawn with NumPy's PCG64 from ``seed``; the same draws for
every controller of a scenario, so the controllers meet the same spacecraft):

* **inertia ±20 % with products of inertia**: the nominal inertia matrix I₀ (the scenario's plant, full
  matrix) is diagonalised, I₀ = R₀ diag(λ₀) R₀ᵀ; each principal moment is scaled by U(0.8, 1.2) and the
  principal axes are turned by a random rotation of angle U(0, 10°) about a uniformly random axis:
  I = R R₀ diag(λ) R₀ᵀ Rᵀ. A draw whose moments break a triangle inequality (λ_i ≤ λ_j + λ_k, a physical
  body) is drawn again; I is then symmetric positive definite and physically valid by construction;
* **actuator misalignment**: a rotation vector δ of the actuator triad, each component N(0, (0.5°)²);
* **actuator scale factor**: k_i = 1 + U(−5 %, +5 %) per actuator;
* **initial attitude**: the plant's initial 3-2-1 angles plus N(0, (2°)²) each; **initial rate**: the
  plant's initial body rate plus N(0, (0.1 °/s)²) per axis;
* **disturbance amplitude**: every disturbance torque of the scenario (constant, sinusoidal amplitude,
  white-noise σ) times one factor U(0.5, 2.0) per run (a scenario without disturbance torques has none
  to scale).

The plant receives these through its parameters (``inertia_*``, ``actuator_misalignment_*``,
``actuator_scale_*``, ``init_euler321_*``, ``init_w_*``, ``dist_*``).
"""

from __future__ import annotations

import math

import numpy as np

from ..fmu import described, fmu_path

INERTIA_SPREAD = 0.20
AXIS_TILT_DEG = 10.0
MISALIGN_DEG = 0.5
SCALE_SPREAD = 0.05
ATTITUDE_DEG = 2.0
RATE_DEG_S = 0.1
DIST_RANGE = (0.5, 2.0)
DIST_PARAMS = [f"dist_{k}_{a}" for k in ("const", "sin_amp", "noise_std") for a in "xyz"]
DEFAULT_RUNS = 32
QUICK_RUNS = 8


def _defaults(model: str) -> dict:
    md = described(fmu_path(model))
    out = {}
    for v in md.modelVariables:
        if v.causality == "parameter" and v.start is not None:
            try:
                out[v.name] = float(v.start)
            except (TypeError, ValueError):
                pass
    return out


def plant_values(sc, plant: str = "plant") -> dict:
    """The plant's parameter values in the scenario (its own, over the FMU's start values)."""
    c = sc.component(plant)
    return {**_defaults(c.model), **{k: v for k, v in c.params.items() if isinstance(v, (int, float))}}


def inertia_matrix(p: dict) -> np.ndarray:
    """The plant's nominal inertia matrix (matrix entries; the uncertainty scale S I S applied)."""
    i = np.array([[p["inertia_xx"], p["inertia_xy"], p["inertia_xz"]],
                  [p["inertia_xy"], p["inertia_yy"], p["inertia_yz"]],
                  [p["inertia_xz"], p["inertia_yz"], p["inertia_zz"]]], dtype=float)
    s = np.sqrt([p.get(f"inertia_scale_{a}", 1.0) for a in "xyz"])
    return s[:, None] * i * s[None, :]


def _rotation(axis_angle: np.ndarray) -> np.ndarray:
    th = float(np.linalg.norm(axis_angle))
    if th == 0.0:
        return np.eye(3)
    k = axis_angle / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K


def draw_inertia(i0: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    lam0, r0 = np.linalg.eigh(i0)
    while True:
        lam = lam0 * rng.uniform(1 - INERTIA_SPREAD, 1 + INERTIA_SPREAD, 3)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        r = _rotation(axis * math.radians(rng.uniform(0.0, AXIS_TILT_DEG)))
        if all(lam[i] <= lam[(i + 1) % 3] + lam[(i + 2) % 3] for i in range(3)):
            break
    rr = r @ r0
    m = rr @ np.diag(lam) @ rr.T
    return (m + m.T) / 2


def dispersions(sc, n: int, seed: int = 0, plant: str = "plant") -> list[dict]:
    """``n`` override dicts (``"plant.<parameter>"`` → value) of the dispersions above, seeded."""
    p = plant_values(sc, plant)
    i0 = inertia_matrix(p)
    rng = np.random.Generator(np.random.PCG64(seed))
    out = []
    for _ in range(n):
        m = draw_inertia(i0, rng)
        d = {"inertia_xx": m[0, 0], "inertia_yy": m[1, 1], "inertia_zz": m[2, 2], "inertia_xy": m[0, 1],
             "inertia_xz": m[0, 2], "inertia_yz": m[1, 2], "inertia_scale_x": 1.0, "inertia_scale_y": 1.0,
             "inertia_scale_z": 1.0}
        mis = rng.normal(0.0, math.radians(MISALIGN_DEG), 3)
        sf = 1 + rng.uniform(-SCALE_SPREAD, SCALE_SPREAD, 3)
        att = rng.normal(0.0, math.radians(ATTITUDE_DEG), 3)
        rate = rng.normal(0.0, math.radians(RATE_DEG_S), 3)
        dist = rng.uniform(*DIST_RANGE)
        for j, a in enumerate("xyz"):
            d[f"actuator_misalignment_{a}"] = mis[j]
            d[f"actuator_scale_{a}"] = sf[j]
            d[f"init_w_{a}"] = p.get(f"init_w_{a}", 0.0) + rate[j]
        for j, a in enumerate(("roll", "pitch", "yaw")):
            d[f"init_euler321_{a}"] = p.get(f"init_euler321_{a}", 0.0) + att[j]
        for k in DIST_PARAMS:
            if p.get(k, 0.0):
                d[k] = p[k] * dist
        d["_dist_factor"] = dist
        out.append({f"{plant}.{k}": float(v) for k, v in d.items() if not k.startswith("_")})
    return out


def percentiles(values) -> dict:
    """median, p95 and p99 (NumPy's linear interpolation) of the finite values; NaN when there are none."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"median": math.nan, "p95": math.nan, "p99": math.nan, "n": 0}
    return {"median": float(np.median(v)), "p95": float(np.percentile(v, 95)), "p99": float(np.percentile(v, 99)),
            "n": int(v.size)}
