"""Paper 001 scenarios: RelativePositionCommand → PredictivePidController → RelativeOrbitPlant, cases a–d
with an optional constant disturbance (``paper001/<case>`` or ``paper001/<case>/dist<N>``)."""

from __future__ import annotations

from ...scenario.model import Component, Scenario

PAPER001_CASES = {"a": (5.0, 5.0), "b": (25.0, 5.0), "c": (25.0, 25.0), "d": (25.0, 150.0)}
PAPER001_REF = (50.0, 40.0, 60.0)


PLANT_STEP = 0.001     # the plant's RK4 step (s); the communication step is the controller's sample step


def paper001(case: str = "a", dist: float = 0.0, stop_time: float = 300.0, step: float = 0.001,
             internal_step: float | None = None) -> Scenario:
    """RelativePositionCommand → PredictivePidController → RelativeOrbitPlant; step to (50, 40, 60) m,
    T1 = 0, (T2, c) of the case, constant disturbance ``dist`` N per axis. ``step`` = Δ is the controller's
    sample step (the force is held over it); the plant integrates with RK4 at ``internal_step`` (default
    min(Δ, 1 ms)), so Δ = 1 ms is the continuous reading and e.g. Δ = 0.0125 s a sampled controller."""
    internal = min(step, PLANT_STEP) if internal_step is None else internal_step
    t2, c = PAPER001_CASES[case]
    log = {}
    for a in "xyz":
        log[f"pos_{a}"] = f"plant.pos_{a}"
        log[f"pos_ref_{a}"] = f"command.pos_ref_{a}"
        log[f"vel_{a}"] = f"plant.vel_{a}"
        log[f"force_{a}"] = f"controller.force_{a}"
        log[f"dist_est_{a}"] = f"controller.dist_est_{a}"
    return Scenario(
        name=f"paper001/{case}/dist{dist:g}" + ("" if step == 0.001 else f"/step{step:g}"),
        components=[
            Component("command", "RelativePositionCommand", {f"target_pos_{a}": v for a, v in zip("xyz", PAPER001_REF)}),
            Component("controller", "PredictivePidController", {"T1": 0.0, "T2": t2, "c": c}),
            Component("plant", "RelativeOrbitPlant", {"max_internal_step": internal, "integrator": 0}),
        ],
        stop_time=stop_time, step=step, log=log,
        inputs={f"plant.dist_{a}": dist for a in "xyz"},
        metrics="formation",
        description=f"paper 001 case {case}: T2 = {t2:g} s, c = {c:g} 1/s, dist = {dist:g} N per axis"
                    + ("" if step == 0.001 else f", controller sampled every {step:g} s"),
    )




def build(name: str, **kw) -> Scenario:
    """``paper001/<case>[/dist<N>][/step<Δ>]``: Δ the controller's sample step (default 0.001 s)."""
    parts = name.split("/")
    bad = KeyError(f"unknown scenario {name!r}: expected paper001/<a|b|c|d>[/dist<N>][/step<seconds>]")
    if len(parts) not in (2, 3, 4) or parts[1] not in PAPER001_CASES:
        raise bad
    opts = {"dist": kw.pop("dist", 0.0)}
    for p in parts[2:]:
        key = "dist" if p.startswith("dist") else "step" if p.startswith("step") else None
        try:
            opts[key] = float(p[4:])
        except (TypeError, ValueError):
            raise bad from None
        if key is None or not opts[key] >= 0 or (key == "step" and not opts[key] > 0):
            raise bad
    if "step" in opts:
        kw["step"] = opts["step"]
    return paper001(parts[1], opts["dist"], **kw)


def names() -> list[tuple[str, str]]:
    return [(f"paper001/{c}", f"paper 001 formation case {c}: T2 = {t2:g} s, c = {cc:g} 1/s, no disturbance")
            for c, (t2, cc) in PAPER001_CASES.items()]


EXPORTED = tuple(f"paper001/{c}" for c in PAPER001_CASES)
