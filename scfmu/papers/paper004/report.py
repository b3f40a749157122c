"""Report section of paper 004: fault-tolerant attitude control by reference correction (C004-1 … 4).

Campaigns on the standard scenarios ``paper004/<1|2|3>`` (ReferenceCorrector → FeedbackLinearizingController
→ AttitudePlant, t_f = 20 s, Δ = RK4 step = 0.01 s): the three cases, the case-3 spline also applied open
loop (scfmu.paper004.run_open_loop), and sweeps of the values paper 004 does not give: the initial
attitude (scaled from the default (yaw, pitch, roll) = (6, −4, 8) deg; 2.5 × is the stress run 004-X,
re-optimised for case 3), the fault effectiveness, the fault onset time, the optimiser's 1 % margin inside
the requirement, and the requirement tolerances themselves (computed from the terminal values).

``build`` is one helper per part (calibration, optimisations, campaigns, one per claim); the figures are in
``report_tables.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ... import campaign
from . import scenarios
from . import model as P
from . import report_tables
from .numbers import (CAL_GRID, CAL_TARGET, OPTIMISED_CASE, calibrate_scale, capped_verdict,  # noqa: F401
                      grid_sensitivity, number_rows, optimiser_bounds, reported, row_precision)
from ...scenario.model import log_of
from ...report import common, rules
from ...report.types import Claim, Figure, PaperSection, Sensitivity, Table

ANG = ("roll", "pitch", "yaw")
TS_KEYS = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw",
           "torque_applied_x", "torque_applied_y", "torque_applied_z",
           "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z", "q_ref_dot_x", "q_ref_dot_y", "q_ref_dot_z"]
ROUNDOFF = 1e-9      # C004-4: closed loop with the corrected reference = open loop, to this (rad, rad/s)
FD_REL = 0.01        # C004-4: the corrector's q_ref_dot agrees with central differences of q_ref to 1 %
SAT_FRAC = 0.99      # C004-2: "saturates" = peak applied torque ≥ 99 % of the faulty limit


def plan(quick: bool) -> dict:
    if quick:
        return {"scales": [0.5, 1.0, 2.0, 2.5], "opt_scales": [2.5], "eff": [0.05, 0.1, 0.3, 1.0],
                "fault_time": [0.0, 5.0], "margins": []}
    return {"scales": [0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5], "opt_scales": [0.5, 1.5, 2.0, 2.5],
            "eff": [0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.75, 1.0], "fault_time": [0.0, 1.0, 2.0, 5.0, 10.0],
            "margins": [0.0, 0.05, 0.1]}


def init_ov(scale: float) -> dict:
    d = {}
    for a in ANG:
        v = math.radians(P.INIT_DEFAULT_DEG[a] * scale)
        d[f"plant.init_euler321_{a}"] = v
        d[f"corrector.init_euler321_{a}"] = v
    return d


def eff_ov(a: float) -> dict:
    return {f"{inst}.effectiveness_{x}": float(a) for inst in ("plant", "corrector") for x in P.AXES}


def nodes_ov(nodes) -> dict:
    return {f"corrector.node_{a}_{j}": float(nodes[i][j]) for i, a in enumerate(P.AXES) for j in range(P.N_NODES)}


# ----- verdict rules (pure, unit-tested) -----------------------------------------------------------
def requirement_ratio(w_end_max_deg_s: float, euler_end_max_deg: float, w_req: float = P.W_REQ_DEG_S,
                      e_req: float = P.EULER_REQ_DEG) -> float:
    """How far a run is from the terminal requirement: max(w/w_req, euler/e_req); passes iff ≤ 1.
    With tolerances scaled by k the run passes iff ratio ≤ k."""
    return max(w_end_max_deg_s / w_req, euler_end_max_deg / e_req)


def tolerance_window(r_healthy: float, r_faulty: float, r_corrected: float) -> tuple[float, float]:
    """Tolerance factors k (both requirements × k) for which C004-1, 2 and 3 all hold: the healthy and the
    corrected runs pass (k ≥ their ratios) and the uncorrected faulty run fails (k < its ratio).
    Returns (k_lo, k_hi): the claims hold together for k_lo ≤ k < k_hi (empty when k_lo ≥ k_hi)."""
    return max(r_healthy, r_corrected), r_faulty


def _terminal(ts: dict) -> dict:
    w = np.array([ts[f"w_{a}"][-1] for a in P.AXES])
    e = np.array([ts[n][-1] for n in ANG])
    t = P.terminal_metrics(w, e)
    t["ratio"] = requirement_ratio(t["w_end_max_deg_s"], t["euler_end_max_deg"])
    t["peak_torque"] = float(max(np.max(np.abs(ts[f"torque_applied_{a}"])) for a in P.AXES))
    return t


def _committed_nodes(scale: float = 1.0) -> np.ndarray:
    return scenarios.committed_nodes(scale)


def _optimise(scale: float, margin: float) -> dict:
    """One spline optimisation (runs on a Dask worker): nodes, status, evaluations."""
    init = {a: P.INIT_DEFAULT_DEG[a] * scale for a in ANG}
    r = P.optimise(init, margin=margin)
    return {"nodes": r.nodes.tolist(), "status": r.status, "evaluations": r.evaluations, "objective": r.objective,
            "pass_openloop": r.terminal["pass"]}


def _calibrate(ctx, suffix: str) -> tuple[float, float, dict, Table, dict]:
    """Calibration of the initial attitude against case 2 (the same grid in both modes), with case 1 (healthy)
    on the same grid for the sensitivity of the calibrated rows: (S0, the paper's target, case-2 max|Euler(t_f)|
    per scale, the calibration table, {(case, reported key): {scale: value}})."""
    cal_sets = [{**init_ov(sc), **eff_ov(a)} for a in (P.A_FAULT, 1.0) for sc in CAL_GRID]
    cal_dir = "paper004_calibration" + suffix
    common.rows(ctx.campaign(campaign.Campaign(scenarios.paper004("1"), cal_sets, timeseries=["roll", "pitch", "yaw",
                                                                                                "w_x", "w_y", "w_z"]),
                             cal_dir))
    grid: dict = {}
    for i, (case, sc) in enumerate([(c, sc) for c in ("2", "1") for sc in CAL_GRID]):
        r = campaign.read_timeseries(ctx.runs_dir(cal_dir), i)
        t = P.terminal_metrics(np.array([r[f"w_{a}"][-1] for a in P.AXES]), np.array([r[n][-1] for n in ANG]))
        grid.setdefault((case, "w_deg_s"), {})[sc] = t["w_end_max_deg_s"]
        grid.setdefault((case, "euler_deg"), {})[sc] = t["euler_end_max_deg"]
    cal_euler = dict(grid[CAL_TARGET])
    target = float(next(c for c in reported()["cases"] if c["case"] == CAL_TARGET[0])[CAL_TARGET[1]])
    S0 = calibrate_scale(cal_euler, target)
    if S0 != P.INIT_SCALE_CALIBRATED:
        raise RuntimeError(f"paper 004: the calibration now gives the start scale {S0:g}, but the scenarios and the "
                           f"committed spline use model.INIT_SCALE_CALIBRATED = {P.INIT_SCALE_CALIBRATED:g}: update it "
                           f"and re-run `scfmu paper 004 optimize --initial calibrated`")
    tab_cal = Table(f"Calibration of the initial attitude: case 2 (a = 0.1, uncorrected) from the default direction "
                    f"scaled by s; the paper's case-2 largest final Euler angle is ≈ {target:g} deg; chosen s = {S0:g}. "
                    f"The case-1 and case-2 rates on the same grid show how the calibrated rows move with s",
                    ["scale s", "(yaw, pitch, roll) (deg)", "case 2 max|Euler(t_f)| (deg)", "case 2 max|ω(t_f)| (deg/s)",
                     "case 1 max|ω(t_f)| (deg/s)", "case 1 max|Euler(t_f)| (deg)", "chosen"],
                    [[sc, f"({6 * sc:g}, {-4 * sc:g}, {8 * sc:g})", cal_euler[sc], grid[("2", "w_deg_s")][sc],
                      grid[("1", "w_deg_s")][sc], grid[("1", "euler_deg")][sc], "yes" if sc == S0 else ""]
                     for sc in CAL_GRID])
    return S0, target, cal_euler, tab_cal, grid


def _optimisations(ctx, pl: dict, S0: float, committed: dict) -> tuple[dict, int]:
    """The open-loop spline optimisations for the faulty plant on the shared Dask client, plus the committed
    splines (``committed``: {scale: (nodes, report)}). Returns (opt, number of optimisations run)."""
    jobs = {("scale", s): (s, P.MARGIN) for s in pl["opt_scales"]}
    jobs.update({("margin", m): (S0, m) for m in pl["margins"]})
    futs = {k: ctx.client.submit(_optimise, *v, pure=False) for k, v in jobs.items()}
    opt = {k: f.result() for k, f in futs.items()}
    if hasattr(ctx, "add_runs"):
        ctx.add_runs(sum(o["evaluations"] for o in opt.values()))
    for sc_, (nd, rp) in committed.items():
        opt[("scale", sc_)] = {"nodes": nd.tolist(), "status": rp["optimiser"]["status"] + " (committed)",
                               "evaluations": rp["optimiser"]["evaluations"],
                               "objective": rp["optimiser"]["objective_N2m2s"], "pass_openloop": True}
    return opt, len(jobs)


def _run_sets(pl: dict, S0: float, opt: dict) -> tuple[list, list, list, list]:
    """The settings of the two campaigns (cases 1/2 share the mode-0 loop; case 3 the mode-1 loop) and their
    labels: (sets0, lab0, sets3, lab3)."""
    sets0, lab0 = [], []
    for s in pl["scales"]:
        for a in (1.0, P.A_FAULT):
            sets0.append({**init_ov(s), **eff_ov(a)})
            lab0.append(("scale", s, a))
    for a in pl["eff"]:
        sets0.append({**init_ov(S0), **eff_ov(a)})
        lab0.append(("eff", 1.0, a))
    for tf in pl["fault_time"]:
        sets0.append({**init_ov(S0), **eff_ov(P.A_FAULT), "plant.fault_time": float(tf)})
        lab0.append(("fault_time", tf, P.A_FAULT))
    sets3, lab3 = [], []
    for s in sorted({1.0, S0, *pl["opt_scales"]}):
        sets3.append({**init_ov(s), **eff_ov(P.A_FAULT), **nodes_ov(opt[("scale", s)]["nodes"])})
        lab3.append(("scale", s))
    nodes_s0 = np.array(opt[("scale", S0)]["nodes"], dtype=float)
    for a in pl["eff"]:
        sets3.append({**init_ov(S0), **eff_ov(a), **nodes_ov(nodes_s0)})
        lab3.append(("eff", a))
    for m in pl["margins"]:
        sets3.append({**init_ov(S0), **eff_ov(P.A_FAULT), **nodes_ov(opt[("margin", m)]["nodes"])})
        lab3.append(("margin", m))
    return sets0, lab0, sets3, lab3


def _scenario(case):
    sc = scenarios.paper004(case)
    sc.log.update(log_of("corrector", [n for n in TS_KEYS if n.startswith("q_ref")]))
    return sc


def _run_cases(ctx, suffix: str, sets0: list, lab0: list, sets3: list, lab3: list) -> tuple[dict, dict]:
    """Runs both campaigns; returns the time series per label of mode 0 and of mode 1."""
    tab0 = common.rows(ctx.campaign(campaign.Campaign(_scenario("1"), sets0, timeseries=TS_KEYS), "paper004_mode0" + suffix))
    tab3 = common.rows(ctx.campaign(campaign.Campaign(_scenario("3"), sets3, timeseries=TS_KEYS), "paper004_mode1" + suffix))
    bad = common.failed(tab0) + common.failed(tab3)
    if bad:
        raise RuntimeError("paper 004 runs failed:\n" + "\n".join(bad))
    d0, d3 = ctx.runs_dir("paper004_mode0" + suffix), ctx.runs_dir("paper004_mode1" + suffix)
    ts0 = {lab: campaign.read_timeseries(d0, i) for i, lab in enumerate(lab0)}
    ts3 = {lab: campaign.read_timeseries(d3, i) for i, lab in enumerate(lab3)}
    return ts0, ts3


def _claim1(t1: dict, scales: list, term0: dict, S0: float, main: Table, fig_main: Figure, tab_init: Table,
            fig_init: Figure) -> Claim:
    c1_hold = [term0[("scale", s, 1.0)]["pass"] for s in scales]
    return Claim("C004-1", "With healthy actuators the feedback-linearising controller meets the terminal requirements "
                           "without correction (marginally).",
                 rules.verdict(t1["pass"]),
                 f"Case 004-1 ends at max|ω| = {t1['w_end_max_deg_s']:.3g} deg/s and max|Euler| = "
                 f"{t1['euler_end_max_deg']:.3g} deg, ratio {t1['ratio']:.3g} to the requirement "
                 f"({'pass' if t1['pass'] else 'fail'}). Rule: confirmed iff it passes from the default start. The "
                 f"initial attitude is not given by the paper; the margin shrinks as the start grows (it passes for "
                 f"scales {rules.holds_where(scales, c1_hold, 'scale')}), which is consistent with 'marginally'.",
                 tables=[main], figures=[fig_main],
                 sensitive_to=["initial attitude (not in the paper)", "requirement tolerances"],
                 sensitivity=[Sensitivity("initial attitude scale (× (6, −4, 8) deg)", scales, S0,
                                          rules.holds_where(scales, c1_hold, "scale"), figure=fig_init, table=tab_init),
                              Sensitivity("requirement tolerance factor k (× 0.01 deg/s and × 0.1 deg)", [1.0], 1.0,
                                          f"k ≥ {t1['ratio']:.3g} (computed from the terminal values, no extra runs)")])


def _claim2(t2: dict, pl: dict, term0: dict, term3: dict, S0: float) -> Claim:
    scales, effs = pl["scales"], pl["eff"]
    eff_rows = [[a, term0[("eff", 1.0, a)]["ratio"], term0[("eff", 1.0, a)]["peak_torque"], term3[("eff", a)]["ratio"]]
                for a in effs]
    tab_eff = Table("Fault effectiveness a (all three axes; 0.1 is the paper's 90 % loss): ratio to the requirement "
                    "without correction (mode 0) and with the committed spline (optimised for a = 0.1)",
                    ["effectiveness a", "uncorrected ratio", "uncorrected peak |τ| (N·m)", "corrected ratio"], eff_rows)
    ft_rows = [[tf, term0[("fault_time", tf, P.A_FAULT)]["ratio"]] for tf in pl["fault_time"]]
    tab_ft = Table("Fault onset time (project choice: from t = 0), a = 0.1, no correction", ["fault time (s)", "ratio"],
                   ft_rows)
    sat = t2["peak_torque"] >= SAT_FRAC * P.A_FAULT * P.U_MAX
    c2_eff = [not term0[("eff", 1.0, a)]["pass"] for a in effs]
    c2_ft = [not term0[("fault_time", tf, P.A_FAULT)]["pass"] for tf in pl["fault_time"]]
    return Claim("C004-2", "With 90 % loss of effectiveness on every axis it cannot meet them (the torques saturate at "
                           "the faulty limit).",
                 rules.verdict((not t2["pass"]) and sat),
                 f"Case 004-2 ends at max|ω| = {t2['w_end_max_deg_s']:.3g} deg/s and max|Euler| = "
                 f"{t2['euler_end_max_deg']:.3g} deg (ratio {t2['ratio']:.3g}, {'pass' if t2['pass'] else 'fail'}); "
                 f"peak applied torque {t2['peak_torque']:.4g} N·m against the faulty limit {P.A_FAULT * P.U_MAX:g} "
                 f"N·m. Rule: confirmed iff it fails and the peak torque reaches {SAT_FRAC:.0%} of the limit.",
                 sensitive_to=["initial attitude (not in the paper)", "fault onset time", "requirement tolerances"],
                 sensitivity=[Sensitivity("fault effectiveness a", effs, P.A_FAULT, "fails (claim holds) for " +
                                          rules.holds_where(effs, c2_eff, "a"), table=tab_eff),
                              Sensitivity("fault onset time (s)", pl["fault_time"], 0.0, "fails (claim holds) for "
                                          + rules.holds_where(pl["fault_time"], c2_ft, "t_fault", "s"), table=tab_ft),
                              Sensitivity("initial attitude scale", scales, S0, "fails (claim holds) for " +
                                          rules.holds_where(scales, [not term0[("scale", s, P.A_FAULT)]["pass"]
                                                                     for s in scales], "scale")),
                              Sensitivity("initial attitude scale, C004-1 and C004-2 together", scales, S0,
                                          rules.holds_where(scales, [term0[("scale", s, 1.0)]["pass"] and
                                                                     not term0[("scale", s, P.A_FAULT)]["pass"]
                                                                     for s in scales], "scale"))])


def _claim3(t3: dict, pl: dict, term0: dict, term3: dict, opt: dict, rep_cal: dict, S0: float,
            tol_holds: str) -> Claim:
    effs = pl["eff"]
    s3 = sorted(k[1] for k in term3 if k[0] == "scale")
    c3_s = [term3[("scale", s)]["pass"] for s in s3]
    c3_e = [term3[("eff", a)]["pass"] for a in effs]
    mrows = [[m, opt[("margin", m)]["status"], term3[("margin", m)]["ratio"],
              "PASS" if term3[("margin", m)]["pass"] else "FAIL"] for m in pl["margins"]]
    mrows.insert(0, [P.MARGIN, rep_cal["optimiser"]["status"] + " (committed nodes)", t3["ratio"],
                     "PASS" if t3["pass"] else "FAIL"])
    tab_margin = Table("Optimiser margin (project choice: its terminal bounds are this fraction inside the requirement); "
                       "case 3 re-run with the nodes optimised for each margin",
                       ["margin", "optimiser", "004-3 ratio", "requirement"], mrows)
    return Claim(
        "C004-3", "With the reference corrected from the optimised open-loop spline, the faulty spacecraft meets them.",
        rules.verdict(t3["pass"]),
        f"Case 004-3 (corrector mode 1 with the committed nodes, optimiser status "
        f"{rep_cal['optimiser']['status']}) ends at max|ω| = {t3['w_end_max_deg_s']:.3g} deg/s and max|Euler| = "
        f"{t3['euler_end_max_deg']:.3g} deg (ratio {t3['ratio']:.3g}, {'pass' if t3['pass'] else 'fail'}). Rule: "
        f"confirmed iff it passes. Since the optimiser puts the terminal state on its bounds "
        f"({P.MARGIN:.0%} inside the requirement), the pass has only that margin and the terminal values are "
        f"fixed by construction (no evidence on their own): what the claim rests on is that the optimiser "
        f"finds a spline meeting its constraints within the paper's budget (status "
        f"{rep_cal['optimiser']['status']}) and that the closed loop with the corrected reference keeps it (C004-4). "
        f"The three claims hold together for requirement tolerances scaled by k with {tol_holds}.",
        tables=[tab_margin],
        sensitive_to=["initial attitude (feasibility)", "optimiser margin", "requirement tolerances"],
        sensitivity=[Sensitivity("initial attitude scale, spline re-optimised (≤ 300 plant runs)", s3, S0,
                                 rules.holds_where(s3, c3_s, "scale")),
                     Sensitivity("initial attitude scale, C004-1, 2 and 3 together", s3, S0, rules.holds_where(
                         s3, [term0[("scale", s, 1.0)]["pass"] and not term0[("scale", s, P.A_FAULT)]["pass"]
                              and term3[("scale", s)]["pass"] for s in s3], "scale")),
                     Sensitivity("fault effectiveness a (committed spline, optimised for a = 0.1)", effs, P.A_FAULT,
                                 rules.holds_where(effs, c3_e, "a")),
                     Sensitivity("optimiser margin", [P.MARGIN, *pl["margins"]], P.MARGIN,
                                 rules.holds_at([f"{m:g}" for m in [P.MARGIN, *pl["margins"]]],
                                                [r[-1] == "PASS" for r in mrows]), table=tab_margin),
                     Sensitivity("requirement tolerance factor k (× 0.01 deg/s and × 0.1 deg), claims 1–3 together",
                                 [1.0], 1.0, tol_holds + " (computed from the terminal values, no extra runs)")])


def _claim4(r3: dict, r3ol: dict) -> Claim:
    """C004-4: the corrected closed loop reproduces the open loop, and q_ref_dot is consistent with q_ref."""
    keys = ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]
    dmax = max(float(np.max(np.abs(r3[k] - r3ol[k]))) for k in keys)
    # relative to the compared signals' size (|q| = 1): the agreement of two runs by different routes (the closed
    # loop through the controller, the open-loop spline run); at rounding level the corrector's own plant copy
    # fixes it (the claim holds by construction, decided from this number)
    size = max(float(np.max(np.abs(r3ol[k]))) for k in keys)
    h = r3["time"][1] - r3["time"][0]
    fd_err, scale_qd = 0.0, 0.0
    for a in P.AXES:
        fd = (r3[f"q_ref_{a}"][2:] - r3[f"q_ref_{a}"][:-2]) / (2 * h)
        fd_err = max(fd_err, float(np.max(np.abs(fd - r3[f"q_ref_dot_{a}"][1:-1]))))
        scale_qd = max(scale_qd, float(np.max(np.abs(r3[f"q_ref_dot_{a}"]))))
    c4_ok = dmax <= ROUNDOFF and fd_err <= FD_REL * scale_qd
    return Claim(
        "C004-4", "The corrected reference needs no numerical differentiation: its derivatives come from "
                  "integrating Eq. 17.",
        rules.verdict(c4_ok),
        f"The ReferenceCorrector FMU outputs q_ref and its first and second derivatives from the state of its "
        f"own integrator of Eq. 17 (no differencing in the FMU). Checks: (1) case 004-3 in closed loop reproduces "
        f"the open-loop spline run 004-3ol: largest difference of q and ω {dmax:.3g} (rule: ≤ {ROUNDOFF:g}); "
        f"(2) the output q_ref_dot agrees with central differences of the logged q_ref to {fd_err:.3g} 1/s, "
        f"against max|q_ref_dot| = {scale_qd:.3g} 1/s (rule: ≤ {FD_REL:.0%} of it). Confirmed iff both hold.",
        tables=[Table("Closed loop with the corrected reference vs open loop", ["quantity", "value"],
                      [["max |Δq|, |Δω| (004-3 vs 004-3ol)", dmax],
                       ["max |q_ref_dot − central difference| (1/s)", fd_err],
                       ["max |q_ref_dot| (1/s)", scale_qd]], digits=3)],
        agreement=dmax / size if size > 0 else None)


def _setup(S0: float, n0: int, n3: int, n_opt: int) -> str:
    return (f"FMUs ReferenceCorrector → FeedbackLinearizingController (k_q = 0.5, k_q̇ = 2: error poles −1 ± √2/2 = "
            f"{-1 + math.sqrt(0.5):.3f} and {-1 - math.sqrt(0.5):.3f} 1/s while no torque saturates) → AttitudePlant, "
            f"I = diag(449.5, 264.5, 312.5) kg·m², u_max = 10 N·m per axis, fault (effectiveness 0.1 on every axis) "
            f"from t = 0, start at rest at 321 (yaw, pitch, roll) = ({6 * S0:g}, {-4 * S0:g}, {8 * S0:g}) deg "
            f"(the default direction × {S0:g}, calibrated), RK4 step = communication step = "
            f"0.01 s, t_f = 20 s. Campaign engine 'native': {n0} mode-0 runs and {n3} mode-1 runs, "
            f"plus the open-loop run 004-3ol and {n_opt} spline optimisation(s) (SLSQP, ≤ 300 plant runs each) on the "
            f"Dask workers. Case 3 uses the committed spline optimised for the calibrated start "
            f"(paper004/data/nodes_calibrated.json; nodes.json is the one for scale 1). The standard scenarios "
            f"paper004/1, 2, 3 start at the calibrated attitude with these nodes, so `scfmu run paper004/N` "
            f"reproduces the case rows.")


def _notes(quick: bool) -> str:
    return ("Project choices checked here: initial attitude (paper gives none), fault onset at t = 0, 321 Euler angles "
            "for the attitude requirement, the optimiser's 1 % margin inside the requirement, and the 99 % saturation "
            "threshold. An optimiser status 'infeasible (budget hit)' means SLSQP did not reach the requirement within "
            "the paper's budget of 300 plant runs; it is not a proof that no spline exists (the bang-bang bound of the "
            "faulty plant allows about 12.7 deg about x in 20 s). The requirement tolerances (0.01 deg/s, 0.1 deg) are "
            "the paper's; the tolerance factor k shows how far each verdict is from flipping. "
            + ("Quick mode: 4 initial-attitude scales, 4 effectiveness values, 2 fault onset times, one re-optimisation "
               "(the stress start) and no optimiser-margin sweep." if quick else
               "Full mode: 9 initial-attitude scales, 8 effectiveness values, 5 onset times, 4 re-optimised starts, "
               "3 optimiser margins."))


def _calibrations(S0: float, target: float, cal_euler: dict) -> str:
    return (f"Calibration: paper 004 does not give the initial attitude. The start is the project's "
            f"direction (yaw, pitch, roll) = (6, −4, 8) deg scaled by s = {S0:g}, the value of the grid "
            f"{', '.join(f'{x:g}' for x in CAL_GRID)} whose case-2 run ends closest to the paper's case-2 "
            f"largest final Euler angle (≈ {target:g} deg; ours {cal_euler[S0]:.3g} deg). Every row is computed "
            f"from that calibrated start, so every row is calibrated (the one fitted and the others, shown with "
            f"how they move across the calibration grid): none is an independent check. The two case-3 values "
            f"are moreover fixed by construction: the spline optimiser puts them on its terminal constraints "
            f"({P.MARGIN:.0%} inside the requirement, model.MARGIN). At scale 1 (the earlier default) case 2 ends "
            f"at {cal_euler.get(1.0, math.nan):.3g} deg, far milder than the paper's. Each row states its "
            f"precision rule: half a unit of the printed last digit, never wider than the requirement the paper "
            f"says the case meets (≈ 0.01 deg/s for a case that meets 0.01 deg/s allows nothing above 0.01), "
            f"5 % as the floor.")


def build(ctx) -> PaperSection:
    t0 = time.time()
    pl = plan(ctx.quick)
    suffix = "_quick" if ctx.quick else ""
    S0, target, cal_euler, tab_cal, grid = _calibrate(ctx, suffix)
    nodes_cal, rep_cal = _committed_nodes(S0)
    pl["scales"] = sorted({*pl["scales"], S0})
    pl["opt_scales"] = sorted(set(pl["opt_scales"]) - {1.0, S0})     # both have a committed spline
    opt, n_opt = _optimisations(ctx, pl, S0, {1.0: _committed_nodes(), S0: (nodes_cal, rep_cal)})
    sets0, lab0, sets3, lab3 = _run_sets(pl, S0, opt)
    ts0, ts3 = _run_cases(ctx, suffix, sets0, lab0, sets3, lab3)
    term0 = {lab: _terminal(t) for lab, t in ts0.items()}
    term3 = {lab: _terminal(t) for lab, t in ts3.items()}
    r1, r2, r3 = ts0[("scale", S0, 1.0)], ts0[("scale", S0, P.A_FAULT)], ts3[("scale", S0)]
    t1, t2, t3 = term0[("scale", S0, 1.0)], term0[("scale", S0, P.A_FAULT)], term3[("scale", S0)]
    r3ol = P.run_open_loop(np.array(opt[("scale", S0)]["nodes"], dtype=float), P.A_FAULT,
                           {a: P.INIT_DEFAULT_DEG[a] * S0 for a in ANG})
    if hasattr(ctx, "add_runs"):
        ctx.add_runs(1)
    t3ol = _terminal(r3ol)
    main = report_tables.main_table(t1, t2, t3, t3ol, rep_cal)
    fig_main = report_tables.plot_cases(ctx, r1, r2, r3, S0)
    fig_init = report_tables.plot_init_scale(ctx, pl["scales"], term0, term3, S0)
    k_lo, k_hi = tolerance_window(t1["ratio"], t2["ratio"], t3["ratio"])
    tol_holds = f"{k_lo:.3g} ≤ k < {k_hi:.3g}" if k_lo < k_hi else "nowhere (the window is empty)"
    claims = [_claim1(t1, pl["scales"], term0, S0, main, fig_main, report_tables.init_table(pl, term0, term3, opt), fig_init),
              _claim2(t2, pl, term0, term3, S0),
              _claim3(t3, pl, term0, term3, opt, rep_cal, S0, tol_holds),
              _claim4(r3, r3ol)]
    return PaperSection(
        paper="004", title="Design of an active fault-tolerant controller for a spacecraft under actuator fault "
                           "(translated title)",
        setup=_setup(S0, len(sets0), len(sets3), n_opt), claims=claims, notes=_notes(ctx.quick),
        runtime_s=time.time() - t0,
        tables=[tab_cal], doc_tables={"cases": main},
        numbers=number_rows({"1": t1, "2": t2, "3": t3}, grid=grid),
        calibrations=_calibrations(S0, target, cal_euler))
