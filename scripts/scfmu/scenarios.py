"""The project's standard scenarios, declared once (see scenario.py).

* ``paper000(run_id)``: paper 000 runs 000-1 … 000-11 and the robustness runs R1 (10 N·m constant
  disturbance) and R2 (inertia ×1.2 / ×0.8): AttitudeCommand → controller → AttitudePlant →
  AttitudeMetrics, inertia diag(1000, 500, 700) kg·m², RK4 0.01 s, Δ = 0.01 s, 30 s.
  ``default()`` is run 000-6 (quaternion PD, large command), the set-up of ``scripts/run_default.py``.
* ``paper001(case, dist)``: formation flying with the nonlinear predictive PID (cases a–d).
* ``wheel_fault()``: paper 003 plant with reaction-wheel saturation and an x-wheel fault.
* ``paper002(controller)``: single-axis wheel plant with a tuned PD, PID, FOPD or FOPID.
* ``paper004(case)``: fault-tolerant control by reference correction, cases 1–3.
* ``paper003/<SMC|T2FSMC>/<N|C|S|W|U>``: GA-SMC or T2F-SMC (tuned), cases 003-N … 003-U
  (builder in ``scfmu.paper003``; keyword ``seed`` picks the 003-U inertia scaling).

``get(name)`` looks a scenario up by name: ``"default"``, ``"paper000/<run_id>"``,
``"paper001/<case>"`` or ``"paper001/<case>/dist<d>"``, ``"wheel_fault"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .scenario import DEFAULT_UNCONNECTED, Component, Scenario, log_of

D = math.radians
COMMANDS = {
    "S": (D(4.0), D(-4.0), D(-6.0)),
    "L": (D(40.0), D(-40.0), D(-60.0)),
    "L2": (D(40.0), D(40.0), D(60.0)),
}
KIN_NAMES = {0: "quat", 1: "dcm", 2: "eul213", 3: "linear"}
ATTITUDE_LOG = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
                "torque_applied_x", "torque_applied_y", "torque_applied_z"]
METRICS_LOG = ["alpha_deg", "eulerint_deg_s", "effort_abs", "effort_sq", "ise", "isf"]


@dataclass
class Paper000Run:
    run_id: str
    controller: str
    command: str
    kinematics: int = 0
    ctrl_params: dict = field(default_factory=dict)
    plant_params: dict = field(default_factory=dict)
    label: str = ""


def paper000_runs() -> list[Paper000Run]:
    """The run table of paper 000 (runs 000-1 … 000-11, R1, R2)."""
    R = Paper000Run
    runs = [
        R("000-1", "PdController", "S", 3, {"error_law": 2}, label="PD Euler"),
        R("000-2", "PdController", "L", 2, {"error_law": 2}, label="PD Euler"),
        R("000-3", "PdController", "S", 3, {"error_law": 1}, label="PD DCM"),
        R("000-4", "PdController", "L", 1, {"error_law": 1}, label="PD DCM"),
        R("000-5", "PdController", "S", 3, {"error_law": 0}, label="PD quat"),
        R("000-6", "PdController", "L", 0, {"error_law": 0}, label="PD quat"),
        R("000-7S", "LqrController", "S", 3, label="LQR"),
        R("000-7L", "LqrController", "L", 0, label="LQR"),
        R("000-8S", "PolePlacementController", "S", 3, label="PolePl"),
        R("000-8L", "PolePlacementController", "L", 0, label="PolePl"),
        R("000-9S", "MracController", "S", 3, {"coordinates": 1}, label="MRAC lin"),
        R("000-9L", "MracController", "L", 0, {"coordinates": 0}, label="MRAC quat"),
        R("000-10L", "FuzzyPdController", "L", 0, label="FuzzyPD"),
        R("000-10L2", "FuzzyPdController", "L2", 0, label="FuzzyPD"),
        R("000-11L", "AdaptiveFuzzyController", "L", 0, label="AdaptFuzzy"),
        R("000-11L2", "AdaptiveFuzzyController", "L2", 0, label="AdaptFuzzy"),
    ]
    robust = [("PdController", {"error_law": 0}, "PD quat"), ("MracController", {}, "MRAC quat"),
              ("FuzzyPdController", {}, "FuzzyPD"), ("AdaptiveFuzzyController", {}, "AdaptFuzzy")]
    for cmd in ("L", "L2"):
        for name, cp, label in robust:
            runs.append(R(f"R1-{label.split()[0]}-{cmd}", name, cmd, 0, cp,
                          {f"dist_const_{a}": 10.0 for a in "xyz"}, label=label))
    for scale in (1.2, 0.8):
        for cmd in ("L", "L2"):
            for name, cp, label in robust:
                runs.append(R(f"R2-{scale}-{label.split()[0]}-{cmd}", name, cmd, 0, cp,
                              {f"inertia_scale_{a}": scale for a in "xyz"}, label=label))
    return runs


def attitude_loop(name: str, controller: str, command, ctrl_params: dict | None = None,
                  plant_params: dict | None = None, stop_time: float = 30.0, step: float = 0.01,
                  kinematics: int = 0, description: str = "") -> Scenario:
    """AttitudeCommand → <controller> → AttitudePlant → AttitudeMetrics (paper 000 set-up: inertia
    diag(1000, 500, 700) kg·m² from the plant's defaults, no torque limit, RK4 with internal step 0.01 s)."""
    pp = {"max_internal_step": 0.01}
    if kinematics != 0:  # only set when not the default, so plants without the option still load
        pp["kinematics"] = kinematics
    pp.update(plant_params or {})
    return Scenario(
        name=name,
        components=[
            Component("command", "AttitudeCommand", {"ref_euler321_roll": command[0], "ref_euler321_pitch": command[1],
                                                     "ref_euler321_yaw": command[2]}),
            Component("controller", controller, dict(ctrl_params or {})),
            Component("plant", "AttitudePlant", pp),
            Component("metrics", "AttitudeMetrics", {}),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", ATTITUDE_LOG), **log_of("metrics", METRICS_LOG),
             **log_of("command", ["roll_ref", "pitch_ref", "yaw_ref"])},
        metrics="attitude",
        seed_params=["plant.dist_noise_seed"],
        description=description,
    )


def paper000(run_id: str = "000-6", stop_time: float = 30.0, step: float = 0.01) -> Scenario:
    for r in paper000_runs():
        if r.run_id == run_id:
            return attitude_loop(f"paper000/{run_id}", r.controller, COMMANDS[r.command], r.ctrl_params,
                                 r.plant_params, stop_time, step, r.kinematics,
                                 description=f"paper 000 run {run_id}: {r.label}, kinematics "
                                             f"{KIN_NAMES[r.kinematics]}, command {r.command}")
    raise KeyError(f"no paper 000 run {run_id!r}")


def default(stop_time: float = 30.0, step: float = 0.01) -> Scenario:
    """Paper 000 run 000-6: quaternion PD, command (40, -40, -60) deg from rest."""
    s = paper000("000-6", stop_time, step)
    s.name = "default"
    return s


PAPER001_CASES = {"a": (5.0, 5.0), "b": (25.0, 5.0), "c": (25.0, 25.0), "d": (25.0, 150.0)}
PAPER001_REF = (50.0, 40.0, 60.0)


def paper001(case: str = "a", dist: float = 0.0, stop_time: float = 300.0, step: float = 0.001) -> Scenario:
    """RelativePositionCommand → PredictivePidController → RelativeOrbitPlant; step to (50, 40, 60) m,
    T1 = 0, (T2, c) of the case, RK4 internal step = Δ, constant disturbance ``dist`` N per axis."""
    t2, c = PAPER001_CASES[case]
    log = {}
    for a in "xyz":
        log[f"pos_{a}"] = f"plant.pos_{a}"
        log[f"pos_ref_{a}"] = f"command.pos_ref_{a}"
        log[f"vel_{a}"] = f"plant.vel_{a}"
        log[f"force_{a}"] = f"controller.force_{a}"
        log[f"dist_est_{a}"] = f"controller.dist_est_{a}"
    return Scenario(
        name=f"paper001/{case}/dist{dist:g}",
        components=[
            Component("command", "RelativePositionCommand", {f"target_pos_{a}": v for a, v in zip("xyz", PAPER001_REF)}),
            Component("controller", "PredictivePidController", {"T1": 0.0, "T2": t2, "c": c}),
            Component("plant", "RelativeOrbitPlant", {"max_internal_step": step, "integrator": 0}),
        ],
        stop_time=stop_time, step=step, log=log,
        inputs={f"plant.dist_{a}": dist for a in "xyz"},
        metrics="formation",
        description=f"paper 001 case {case}: T2 = {t2:g} s, c = {c:g} 1/s, dist = {dist:g} N per axis",
    )


WHEEL_FAULT_COMMAND = (D(30.0), D(-20.0), D(45.0))
I003 = {"inertia_xx": 4.0, "inertia_yy": 5.0, "inertia_zz": 3.5, "inertia_xy": 0.05, "inertia_xz": -0.03,
        "inertia_yz": 0.02}


def wheel_fault(stop_time: float = 120.0, step: float = 0.1, fault_time: float = 4.0, effectiveness_x: float = 0.3,
                bias_z: float = 0.01) -> Scenario:
    """Paper 003 plant with three reaction wheels, magnetorquer dumping, gravity gradient and a constant
    disturbance; PD retuned (ω_n = 0.3 rad/s, ξ = 0.9); x wheel loses 70 % at fault_time, z wheel biased."""
    names = ["roll", "pitch", "yaw"] + [f"{v}_{a}" for v in ["torque_applied", "h_wheel", "wheel_speed", "dipole", "w"]
                                        for a in "xyz"]
    c = WHEEL_FAULT_COMMAND
    return Scenario(
        name="wheel_fault",
        components=[
            Component("command", "AttitudeCommand", {"ref_euler321_roll": c[0], "ref_euler321_pitch": c[1],
                                                     "ref_euler321_yaw": c[2]}),
            Component("controller", "PdController", {"wn": 0.3, "zeta": 0.9, "inertia_xx": 4.0, "inertia_yy": 5.0,
                                                     "inertia_zz": 3.5}),
            Component("plant", "AttitudePlant", dict(I003, actuator_mode=1, mtq_enable=1, gg_enable=1,
                                                     dist_const_x=5e-4, dist_const_y=5e-4, dist_const_z=5e-4,
                                                     effectiveness_x=effectiveness_x, fault_bias_z=bias_z,
                                                     fault_time=fault_time)),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", names), **log_of("controller", [f"torque_cmd_{a}" for a in "xyz"]),
             **log_of("command", ["roll_ref", "pitch_ref", "yaw_ref"])},
        metrics="attitude_nometrics",
        description="reaction-wheel saturation and actuator fault (paper 003 plant)",
    )


def paper004(case: str = "1", stop_time: float = 20.0, step: float = 0.01) -> Scenario:
    """Paper 004 closed loop ReferenceCorrector → FeedbackLinearizingController → AttitudePlant:
    case "1" healthy actuators, "2" 90 % loss of effectiveness, "3" the same fault with the reference
    corrected by the committed optimised spline (scripts/data/paper004_nodes.json); initial 321 angles
    (6, -4, 8) deg, at rest."""
    import json
    from pathlib import Path

    import numpy as np

    from . import paper004 as p4
    eff = 1.0 if case == "1" else p4.A_FAULT
    nodes = None
    if case == "3":
        rep = json.loads((Path(__file__).resolve().parents[1] / "data" / "paper004_nodes.json").read_text())
        nodes = np.array([rep["nodes_N_m"][a] for a in p4.AXES], dtype=float)
    mode = 1 if case == "3" else 0
    names = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
             "torque_applied_x", "torque_applied_y", "torque_applied_z"]
    return Scenario(
        name=f"paper004/{case}",
        components=[
            Component("corrector", "ReferenceCorrector", p4.corrector_params(mode, nodes, eff, p4.INIT_DEFAULT_DEG)),
            Component("controller", "FeedbackLinearizingController", p4.controller_params()),
            Component("plant", "AttitudePlant", p4.plant_params(eff, p4.INIT_DEFAULT_DEG)),
        ],
        stop_time=stop_time, step=step,
        log={**log_of("plant", names), **log_of("controller", [f"torque_cmd_{a}" for a in "xyz"])},
        metrics="attitude_nometrics",
        description=f"paper 004 case 004-{case}",
    )


def paper002(controller: str = "FOPID", theta_ref_deg: float = 30.0, stop_time: float = 20.0,
             step: float = 0.001) -> Scenario:
    """Paper 002 single-axis loop: PidController or FopidController (PD, PID, FOPD, FOPID with the
    committed PSO-tuned gains of scripts/paper002_gains.json) → SingleAxisPlant (explicit Euler, internal
    step = communication step = the controller's sample time), step command theta_ref."""
    import json
    from pathlib import Path

    from . import paper002 as p2
    tuned = json.loads((Path(__file__).resolve().parents[1] / "paper002_gains.json").read_text())
    sc = p2.Scenario(theta_ref_deg=theta_ref_deg, t_end=stop_time, h=step)
    model, cparams = p2.controller_params(controller, tuned["controllers"][controller]["gains"], sc)
    return Scenario(
        name=f"paper002/{controller}",
        components=[
            Component("controller", model, cparams),
            Component("plant", "SingleAxisPlant", {"integrator": 1, "max_internal_step": step}),
        ],
        stop_time=stop_time, step=step,
        log=log_of("plant", ["theta", "omega", "applied_torque", "theta_deg"]) | log_of("controller", ["u", "theta_ref"]),
        inputs={"controller.theta_ref": math.radians(theta_ref_deg)},
        unconnected=[*DEFAULT_UNCONNECTED, "torque_dist"],
        metrics="single_axis",  # PSO cost terms (mae_deg, late_max_deg, cost) per run
        description=f"paper 002 single-axis loop, {controller} with the tuned gains, {theta_ref_deg:g} deg step",
    )


def get(name: str, **kw) -> Scenario:
    """A standard scenario by name (see the module docstring); keyword arguments go to its builder."""
    parts = name.split("/")
    if parts[0] == "default":
        return default(**kw)
    if parts[0] == "paper000" and len(parts) == 2:
        return paper000(parts[1], **kw)
    if parts[0] == "paper001" and len(parts) in (2, 3):
        dist = float(parts[2][4:]) if len(parts) == 3 else kw.pop("dist", 0.0)
        return paper001(parts[1], dist, **kw)
    if parts[0] == "wheel_fault":
        return wheel_fault(**kw)
    if parts[0] == "paper002" and len(parts) == 2:
        return paper002(parts[1], **kw)
    if parts[0] == "paper004" and len(parts) == 2:
        return paper004(parts[1], **kw)
    if parts[0] == "paper003" and len(parts) == 3:  # paper003/<SMC|T2FSMC>/<N|C|S|W|U>
        from .paper003 import scenario as paper003
        return paper003(parts[1], parts[2], **kw)
    raise KeyError(f"unknown scenario {name!r}; known: default, paper000/<run id>, paper001/<a|b|c|d>[/dist<N>], "
                   f"wheel_fault, paper002/<PD|PID|FOPD|FOPID>, paper004/<1|2|3>, paper003/<SMC|T2FSMC>/<N|C|S|W|U>")


def names() -> list[str]:
    return (["default"] + [f"paper000/{r.run_id}" for r in paper000_runs()]
            + [f"paper001/{c}" for c in PAPER001_CASES] + ["wheel_fault"] + [f"paper002/{c}" for c in ("PD", "PID", "FOPD", "FOPID")]
            + [f"paper004/{c}" for c in "123"]
            + [f"paper003/{c}/{k}" for c in ("SMC", "T2FSMC") for k in "NCSWU"])
