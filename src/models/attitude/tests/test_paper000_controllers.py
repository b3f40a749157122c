"""Paper 000 controller family ([Navabi-2019]) against independent references:
python-control / scipy (LQR, pole placement), scikit-fuzzy membership functions and centroid
defuzzification (fuzzy PD), closed forms (reference model, double-pole response) and convergence
properties (MRAC). The FMUs are driven through fmpy by port name."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
import scipy.linalg
import skfuzzy as fuzz
from fmpy.validation import validate_fmu

from scfmu.engines.reference import CoSimulation
from scfmu.fmu import Fmu
from scfmu.fmu import fmu_path
from quat_oracle import q321, qconj, qmul  # independent helpers shared by the tests

NEW = ["LqrController", "PolePlacementController", "MracController", "FuzzyPdController", "AdaptiveFuzzyController"]
INERTIA = (1000.0, 500.0, 700.0)
LARGE = (math.radians(40.0), math.radians(-40.0), math.radians(-60.0))
SMALL = (math.radians(4.0), math.radians(-4.0), math.radians(-6.0))
AX = "xyz"


def set_att(ctrl: Fmu, q, w, q_ref):
    ctrl.set_reals(["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"],
                   list(q) + list(w) + list(q_ref))


def torque(ctrl: Fmu):
    return np.array(ctrl.get_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"]))


def closed_loop(controller: str, ctrl_params=None, plant_params=None, command=LARGE, t_end=30.0, dt=0.01,
                extra_log=()):
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": command[0], "ref_euler321_pitch": command[1],
                                  "ref_euler321_yaw": command[2]})
    ctrl = Fmu(controller, ctrl_params or {})
    plant = Fmu("AttitudePlant", {"max_internal_step": dt, **(plant_params or {})})
    sim = CoSimulation([cmd, ctrl, plant])
    log = {n: (plant, n) for n in ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z", "roll", "pitch", "yaw"]}
    log.update({n: (ctrl, n) for n in ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z", *extra_log]})
    try:
        return sim.run(t_end, dt, log)
    finally:
        sim.close()


def plant_has_kinematics(mode: int) -> bool:
    try:
        Fmu("AttitudePlant", {"kinematics": mode}).close()
        return True
    except Exception:
        return False


# ----- validation ---------------------------------------------------------------------------------
@pytest.mark.parametrize("model", NEW)
def test_fmu_validates(model):
    assert validate_fmu(str(fmu_path(model))) == []


def test_adaptive_fuzzy_rejects_complex_reference_roots():
    # λ1,min² = 8 < 4 λ2,max = 12 → fmi2Error at initialisation
    with pytest.raises(Exception):
        Fmu("AdaptiveFuzzyController", {"lambda2_max": 3.0})
    Fmu("AdaptiveFuzzyController").close()  # defaults pass (8 >= 8)


# ----- LQR ------------------------------------------------------------------------------------------
def test_lqr_gains_match_python_control_and_scipy():
    rng = np.random.default_rng(20261122)
    worst = 0.0
    for _ in range(25):
        m = rng.normal(size=(2, 2))
        qm = m @ m.T + 0.05 * np.eye(2)            # random SPD Q
        scale = 10 ** rng.uniform(-2, 2)            # R_i = scale / I_i²
        inertia = 10 ** rng.uniform(0, 3.5, size=3)
        params = {"q11": qm[0, 0], "q22": qm[1, 1], "q12": qm[0, 1], "lqr_r_scale": scale,
                  "inertia_xx": inertia[0], "inertia_yy": inertia[1], "inertia_zz": inertia[2]}
        f = Fmu("LqrController", params)
        try:
            for i, a in enumerate(AX):
                A = np.array([[0.0, 1.0], [0.0, 0.0]])
                B = np.array([[0.0], [1.0 / inertia[i]]])
                R = np.array([[scale / inertia[i] ** 2]])
                k_ctrl, _, _ = control.lqr(A, B, qm, R)
                p = scipy.linalg.solve_continuous_are(A, B, qm, R)
                k_scipy = np.linalg.solve(R, B.T @ p)
                got = np.array([f.get(f"k1_{a}"), f.get(f"k2_{a}")])
                for ref in (np.asarray(k_ctrl).ravel(), k_scipy.ravel()):
                    rel = np.max(np.abs(got - ref) / np.abs(ref))
                    worst = max(worst, rel)
                    assert rel <= 1e-9, (params, a, got, ref)
        finally:
            f.close()
    print(f"LQR: worst relative gain difference vs python-control/scipy = {worst:.3e} (bound 1e-9)")


def test_lqr_defaults_are_paper_gains():
    f = Fmu("LqrController")
    try:
        for i, a in enumerate(AX):
            assert abs(f.get(f"k1_{a}") - INERTIA[i]) <= 1e-12 * INERTIA[i]
            assert abs(f.get(f"k2_{a}") - 2 * INERTIA[i]) <= 1e-12 * INERTIA[i]
    finally:
        f.close()


# ----- pole placement ------------------------------------------------------------------------------
def _pp_gains(params):
    f = Fmu("PolePlacementController", params)
    try:
        return [np.array([f.get(f"k1_{a}"), f.get(f"k2_{a}")]) for a in AX]
    finally:
        f.close()


def test_pole_placement_closed_loop_poles_and_control_place():
    rng = np.random.default_rng(7)
    cases = []
    for _ in range(8):   # (wn, zeta): complex (ζ < 1), real (ζ > 1) and the double pole (ζ = 1)
        cases.append(("wz", rng.uniform(0.1, 3.0), rng.choice([rng.uniform(0.2, 0.95), 1.0, rng.uniform(1.05, 3.0)])))
    for _ in range(6):   # explicit real or conjugate pairs
        if rng.random() < 0.5:
            re, im = -rng.uniform(0.1, 3), rng.uniform(0.1, 2)
            cases.append(("poles", complex(re, im), complex(re, -im)))
        else:
            cases.append(("poles", complex(-rng.uniform(0.1, 3), 0), complex(-rng.uniform(0.1, 3), 0)))
    worst_pole = worst_place = 0.0
    for kind, a1, a2 in cases:
        inertia = 10 ** rng.uniform(0, 3.5, size=3)
        params = {"inertia_xx": inertia[0], "inertia_yy": inertia[1], "inertia_zz": inertia[2]}
        if kind == "wz":
            params.update(wn=a1, zeta=a2)
            want = np.roots([1.0, 2 * a2 * a1, a1 * a1])
        else:
            params.update(pole_mode=1, pole1_re=a1.real, pole1_im=a1.imag, pole2_re=a2.real, pole2_im=a2.imag)
            want = np.array([a1, a2])
        gains = _pp_gains(params)
        for i in range(3):
            A = np.array([[0.0, 1.0], [0.0, 0.0]])
            B = np.array([[0.0], [1.0 / inertia[i]]])
            k = gains[i].reshape(1, 2)
            got = np.linalg.eigvals(A - B @ k)
            # pair up (sorted by real then imaginary part); a double pole is sensitive (√eps), so compare
            # the characteristic polynomial coefficients as well
            gs = sorted(got, key=lambda z: (z.real, z.imag))
            ws = sorted(want, key=lambda z: (z.real, z.imag))
            scale = max(1.0, max(abs(w) for w in ws))
            err = max(abs(g - w) for g, w in zip(gs, ws)) / scale
            worst_pole = max(worst_pole, err)
            assert err <= (1e-6 if np.isclose(ws[0], ws[1]) else 1e-9), (params, got, want)
            cp = np.poly(A - B @ k).real
            assert np.allclose(cp, np.poly(want).real, rtol=1e-10, atol=1e-12 * scale ** 2)
            # python-control: place() (distinct poles) or acker() (any multiplicity)
            ref = control.acker(A, B, want) if np.isclose(ws[0], ws[1]) else control.place(A, B, want)
            ref = np.asarray(ref).ravel()
            rel = np.max(np.abs(gains[i] - ref) / np.abs(ref))
            worst_place = max(worst_place, rel)
            assert rel <= 1e-9, (params, gains[i], ref)
    print(f"pole placement: worst pole error {worst_pole:.3e} (relative), worst gain difference vs control.place/acker {worst_place:.3e}")


def test_pole_placement_rejects_unpaired_complex_poles():
    with pytest.raises(Exception):
        Fmu("PolePlacementController", {"pole_mode": 1, "pole1_re": -1, "pole1_im": 1, "pole2_re": -1, "pole2_im": 0.5})


# ----- PD = LQR = pole placement with ωn = 1, ξ = 1 -----------------------------------------------
def test_pd_lqr_pole_placement_same_gains_and_trajectories():
    pd = Fmu("PdController", {"wn": 1.0, "zeta": 1.0, "error_law": 0})
    lq = Fmu("LqrController")
    pp = Fmu("PolePlacementController", {"wn": 1.0, "zeta": 1.0})
    try:
        for a in AX:
            k = pd.get(f"k_{a}")
            kd = -pd.get(f"k_d_{a}")
            for f in (lq, pp):
                assert abs(f.get(f"k1_{a}") - k) <= 1e-12 * k
                assert abs(f.get(f"k2_{a}") - kd) <= 1e-12 * kd
    finally:
        for f in (pd, lq, pp):
            f.close()
    runs = {name: closed_loop(name, params) for name, params in
            [("PdController", {"error_law": 0}), ("LqrController", {}), ("PolePlacementController", {})]}
    ref = runs["PdController"]
    worst_q = worst_t = 0.0
    for name in ("LqrController", "PolePlacementController"):
        r = runs[name]
        dq = max(np.max(np.abs(r[k] - ref[k])) for k in ["q_w", "q_x", "q_y", "q_z"])
        dt = max(np.max(np.abs(r[f"torque_cmd_{a}"] - ref[f"torque_cmd_{a}"])) for a in AX)
        worst_q, worst_t = max(worst_q, dq), max(worst_t, dt)
        assert dq <= 1e-10 and dt <= 1e-8, (name, dq, dt)
    print(f"PD/LQR/PP on the large command: max |Δq| = {worst_q:.3e}, max |Δtorque| = {worst_t:.3e} N·m")


# ----- fuzzy PD against scikit-fuzzy ---------------------------------------------------------------
NAMES = ["NB", "NM", "NS", "ZO", "PS", "PM", "PB"]
KP_T = ["BBBBBBB", "SBBBBBS", "SSBBBSS", "SSSBSSS", "SSBBBSS", "SBBBBBS", "BBBBBBB"]
KD_T = ["SSSSSSS", "BSSSSSB", "BBSSSBB", "BBBSBBB", "BBSSSBB", "BSSSSSB", "SSSSSSS"]


def skfuzzy_infer(e_bar, edot_bar, defuzz, sigma=0.25, hw=1.0 / 3.0):
    """Product firing over skfuzzy triangles; weighted average of c(S) = 0, c(B) = 1 (defuzz 0) or
    product implication + sum aggregation + skfuzzy centroid on [0, 1] (defuzz 1)."""
    x = np.array([float(np.clip(e_bar, -1, 1))])
    y = np.array([float(np.clip(edot_bar, -1, 1))])
    centres = np.linspace(-1.0, 1.0, 7)
    mu_e = [fuzz.trimf(x, [c - hw, c, c + hw])[0] for c in centres]
    mu_d = [fuzz.trimf(y, [c - hw, c, c + hw])[0] for c in centres]
    out = []
    for table in (KP_T, KD_T):
        w = {"S": 0.0, "B": 0.0}
        for j in range(7):
            for k in range(7):
                w[table[j][k]] += mu_e[j] * mu_d[k]       # product firing, sum per output term
        if defuzz == 0:
            out.append((w["S"] * 0.0 + w["B"] * 1.0) / (w["S"] + w["B"]))
        else:
            u = np.linspace(0.0, 1.0, 4001)
            agg = w["S"] * fuzz.gaussmf(u, 0.0, sigma) + w["B"] * fuzz.gaussmf(u, 1.0, sigma)
            out.append(fuzz.defuzz(u, agg, "centroid"))
    return out


@pytest.mark.parametrize("defuzz", [0, 1])
def test_fuzzy_pd_matches_skfuzzy_on_grid(defuzz):
    e_scale, edot_scale = 0.8, 0.5
    f = Fmu("FuzzyPdController", {"defuzz": defuzz, "e_scale": e_scale, "edot_scale": edot_scale})
    rng = np.random.default_rng(3)
    try:
        kr = np.array(INERTIA)
        kp_min, kp_max, kd_min, kd_max = 0.28 * kr, 3 * kr, 0.08 * kr * 5.834, 0.15 * kr * 5.834
        n = 13 if defuzz == 1 else 25
        samples = []
        for e_bar in np.linspace(-1.15, 1.15, n):      # beyond ±1: clamping
            for ed_bar in np.linspace(-1.15, 1.15, n):
                e = e_bar * e_scale
                if abs(e) >= 1.0:
                    continue
                a = math.asin(e)                        # e^Q_x = sin α for a rotation of q_ref about x
                q_ref = [math.cos(a / 2), math.sin(a / 2), 0.0, 0.0]
                samples.append(([1.0, 0.0, 0.0, 0.0], [-ed_bar * edot_scale, 0.31, -0.62], q_ref))
        for _ in range(40 if defuzz == 1 else 150):     # random attitudes and rates
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            qr = rng.normal(size=4)
            qr /= np.linalg.norm(qr)
            samples.append((q, rng.uniform(-0.7, 0.7, size=3), qr))
        worst_k = worst_t = 0.0
        for q, w, qr in samples:
            set_att(f, q, w, qr)
            tq = torque(f)
            qe = qmul(qconj(np.asarray(q)), np.asarray(qr))
            e = 2 * qe[0] * qe[1:]
            for i, a in enumerate(AX):
                kpn, kdn = skfuzzy_infer(e[i] / e_scale, -w[i] / edot_scale, defuzz)
                kp = kp_min[i] + (kp_max[i] - kp_min[i]) * kpn
                kd = kd_min[i] + (kd_max[i] - kd_min[i]) * kdn
                t_ref = kp * e[i] - kd * w[i]
                got_kp = (f.get(f"kp_{a}") - kp_min[i]) / (kp_max[i] - kp_min[i])
                got_kd = (f.get(f"kd_{a}") - kd_min[i]) / (kd_max[i] - kd_min[i])
                dk = max(abs(got_kp - kpn), abs(got_kd - kdn))
                dt = abs(tq[i] - t_ref) / (kp_max[i] + kd_max[i])
                worst_k, worst_t = max(worst_k, dk), max(worst_t, dt)
                bound = 1e-12 if defuzz == 0 else 1e-7   # skfuzzy centroid: piecewise-linear quadrature, 4001 points
                assert dk <= bound and dt <= bound, (q, w, qr, a, got_kp, kpn, got_kd, kdn)
        print(f"fuzzy defuzz={defuzz}: {len(samples)} input sets, worst |Δk'| = {worst_k:.3e}, "
              f"worst |Δtorque|/(kp_max + kd_max) = {worst_t:.3e}")
    finally:
        f.close()


# ----- MRAC ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("coordinates,kinematics,command", [(0, 0, LARGE), (1, 3, SMALL)], ids=["quat-L", "linear-S"])
def test_mrac_exact_inertia_follows_reference_model(coordinates, kinematics, command):
    """With Î = I, x follows the ωn = 1, ξ = 1 reference model: x_m(t) = r − (r − x0)(1 + t)e^{−t}
    (coordinates 0: x = 2 q̄_v, r = 2 q̄_ref,v; coordinates 1: 321 angles on the linear plant)."""
    if not plant_has_kinematics(kinematics):
        pytest.skip(f"AttitudePlant kinematics {kinematics} not available")
    r = closed_loop("MracController", {"coordinates": coordinates}, {"kinematics": kinematics}, command,
                    t_end=20.0, dt=0.01, extra_log=[f"{p}_{a}" for p in ("xm", "track_err", "ihat", "x") for a in AX])
    t = r["time"]
    if coordinates == 0:
        qr = q321(*command)
        rr = 2 * np.sign(qr[0]) * qr[1:]
    else:
        rr = np.array(command)
    worst_m = worst_track = worst_i = 0.0
    for i, a in enumerate(AX):
        xm_ref = rr[i] - rr[i] * (1 + t) * np.exp(-t)
        worst_m = max(worst_m, np.max(np.abs(r[f"xm_{a}"] - xm_ref)))
        worst_track = max(worst_track, np.max(np.abs(r[f"track_err_{a}"])))
        worst_i = max(worst_i, np.max(np.abs(r[f"ihat_{a}"] - INERTIA[i])) / INERTIA[i])
    print(f"MRAC exact Î (coordinates {coordinates}, kinematics {kinematics}): max |x_m − closed form| = {worst_m:.3e}, "
          f"max |x − x_m| = {worst_track:.3e}, max |Î − I|/I = {worst_i:.3e}")
    assert worst_m <= 1e-8
    assert worst_track <= 5e-3 * np.max(np.abs(rr))   # O(Δ): the torque is held over each 0.01 s step
    assert worst_i <= 0.05


def test_mrac_converges_and_estimate_moves_to_truth_under_excitation():
    """Plant inertia scaled by 1.3 (controller nominal), sinusoidal command on all axes (persistent
    excitation), γ = 1e5 (the default 1000 adapts too slowly to show convergence in 120 s). Manual
    Gauss–Seidel loop: q_ref(t) is set by the test."""
    scale = 1.3
    dt, t_end = 0.01, 120.0
    ctrl = Fmu("MracController", {"gamma": 1e5})
    plant = Fmu("AttitudePlant", {"inertia_scale_x": scale, "inertia_scale_y": scale, "inertia_scale_z": scale})
    amp = np.radians([25.0, 20.0, 30.0])
    om = np.array([0.31, 0.43, 0.23])
    n = int(round(t_end / dt))
    track = np.zeros((n + 1, 3))
    ihat = np.zeros((n + 1, 3))
    try:
        for k in range(n + 1):
            t = k * dt
            ang = amp * np.sin(om * t)
            qr = q321(*ang)
            q = plant.get_reals(["q_w", "q_x", "q_y", "q_z"])
            w = plant.get_reals(["w_x", "w_y", "w_z"])
            set_att(ctrl, q, w, qr)
            plant.set_reals(["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"], torque(ctrl))
            track[k] = ctrl.get_reals(["track_err_x", "track_err_y", "track_err_z"])
            ihat[k] = ctrl.get_reals(["ihat_x", "ihat_y", "ihat_z"])
            if k < n:
                ctrl.do_step(t, dt)
                plant.do_step(t, dt)
    finally:
        ctrl.close()
        plant.close()
    true_i = scale * np.array(INERTIA)
    first = np.max(np.abs(track[: int(20 / dt)]), axis=0)
    last = np.max(np.abs(track[-int(20 / dt):]), axis=0)
    err0 = np.abs(np.array(INERTIA) - true_i)
    err_end = np.abs(ihat[-1] - true_i)
    print(f"MRAC excitation: max|x−x_m| first 20 s {first}, last 20 s {last}; "
          f"|Î−I_true| start {err0} -> end {err_end}; Î(end) = {ihat[-1]}")
    assert np.all(last <= 0.25 * first), (first, last)
    assert np.all(err_end <= 0.1 * err0), (ihat[-1], true_i)


# ----- adaptive fuzzy ----------------------------------------------------------------------------------
@pytest.mark.parametrize("command", [LARGE, (LARGE[0], -LARGE[1], -LARGE[2])], ids=["L", "L2"])
def test_adaptive_fuzzy_stable_on_large_command(command):
    r = closed_loop("AdaptiveFuzzyController", {}, {}, command, t_end=30.0, dt=0.01,
                    extra_log=[f"{p}_{a}" for p in ("lambda1", "lambda2", "ihat") for a in AX])
    qr = q321(*command)
    q_end = np.array([r[k][-1] for k in ["q_w", "q_x", "q_y", "q_z"]])
    qe = qmul(qconj(q_end), qr)
    alpha_end = math.degrees(2 * math.atan2(np.linalg.norm(qe[1:]), abs(qe[0])))
    w_end = max(abs(r[f"w_{a}"][-1]) for a in AX)
    for a in AX:
        assert np.all(np.isfinite(r[f"torque_cmd_{a}"]))
        assert np.all(r[f"lambda1_{a}"] >= 2 * math.sqrt(2) - 1e-12) and np.all(r[f"lambda1_{a}"] <= 4 + 1e-12)
        assert np.all(r[f"lambda2_{a}"] >= 0.5 - 1e-12) and np.all(r[f"lambda2_{a}"] <= 2 + 1e-12)
        assert np.all(r[f"ihat_{a}"] > 0)
    print(f"adaptive fuzzy: α(30 s) = {alpha_end:.3e} deg, max |ω(30 s)| = {w_end:.3e} rad/s")
    assert alpha_end <= 0.5 and w_end <= 1e-3


# ----- small-angle linear plant + PD: closed-form double-pole response --------------------------------
@pytest.mark.skipif(not plant_has_kinematics(3), reason="AttitudePlant kinematics mode 3 (issue 3) not merged")
def test_linear_plant_pd_double_pole_closed_form():
    """Mode 3 is a per-axis double integrator; the Euler-law PD closes it to s² + 2s + 1, i.e.
    θ(t) = θ_ref (1 − (1 + t) e^{−t}). The FMU loop holds the torque over each step (ZOH), so:
    (a) it equals the exact ZOH sampled-data recursion (closed form of the discretised system);
    (b) it converges to the continuous closed form at O(Δ), and the Richardson combination of
        Δ and Δ/2 runs (2 θ_{Δ/2} − θ_Δ) is within 1e-6 rad of it."""
    def run(dt, t_end=10.0):
        return closed_loop("PdController", {"error_law": 2}, {"kinematics": 3}, SMALL, t_end=t_end, dt=dt)

    res = {}
    worst_zoh = 0.0
    for dt in (0.01, 0.005):
        r = run(dt)
        res[dt] = r
        t = r["time"]
        for i, ang in enumerate(["roll", "pitch", "yaw"]):
            th_ref = SMALL[i]
            inertia = INERTIA[i]
            kp, kd = inertia, 2 * inertia
            # exact discretisation of I θ'' = u with u held: x+ = Φ x + Γ u, u = kp (θ_ref − θ) − kd θ'
            phi = np.array([[1.0, dt], [0.0, 1.0]])
            gam = np.array([dt * dt / (2 * inertia), dt / inertia])
            x = np.zeros(2)
            zoh = np.empty(len(t))
            for k in range(len(t)):
                zoh[k] = x[0]
                u = kp * (th_ref - x[0]) - kd * x[1]
                x = phi @ x + gam * u
            d_zoh = np.max(np.abs(r[ang] - zoh))
            worst_zoh = max(worst_zoh, d_zoh)
            assert d_zoh <= 1e-10, (dt, ang, d_zoh)
    t = res[0.01]["time"]
    worst_cont = {}
    worst_rich = 0.0
    for i, ang in enumerate(["roll", "pitch", "yaw"]):
        exact = SMALL[i] * (1 - (1 + t) * np.exp(-t))
        coarse = res[0.01][ang]
        fine = res[0.005][ang][::2]
        worst_cont[ang] = (np.max(np.abs(coarse - exact)), np.max(np.abs(fine - exact)))
        worst_rich = max(worst_rich, np.max(np.abs(2 * fine - coarse - exact)))
    print(f"linear plant + PD: max |θ − ZOH closed form| = {worst_zoh:.3e} rad; "
          f"max |θ − closed form| (Δ = 0.01, 0.005) = {worst_cont}; "
          f"Richardson 2θ_(Δ/2) − θ_Δ: {worst_rich:.3e} rad")
    assert worst_rich <= 1e-6


# ----- robustness of the FMU interface ---------------------------------------------------------------
@pytest.mark.parametrize("model", NEW)
def test_bad_parameters_are_errors(model):
    with pytest.raises(Exception):
        Fmu(model, {"inertia_xx": -1.0})


@pytest.mark.parametrize("model", ["MracController", "AdaptiveFuzzyController"])
def test_fmu_state_restore_reproduces_adaptive_run(model):
    """getFMUstate after 5 s, run 5 s more, setFMUstate on every FMU, rerun: bit-identical."""
    cmd = Fmu("AttitudeCommand", {"ref_euler321_roll": LARGE[0], "ref_euler321_pitch": LARGE[1],
                                  "ref_euler321_yaw": LARGE[2]})
    ctrl = Fmu(model, {"gamma": 1e4})
    plant = Fmu("AttitudePlant", {"inertia_scale_x": 1.2})
    sim = CoSimulation([cmd, ctrl, plant])
    log = {n: (ctrl, n) for n in ["torque_cmd_x", "torque_cmd_y", "torque_cmd_z", "ihat_x", "xm_y"]}
    try:
        sim.run(5.0, 0.01)
        states = [(f, f.slave.getFMUstate()) for f in (cmd, ctrl, plant)]
        a = sim.run(10.0, 0.01, log, t0=5.0)
        for f, s in states:
            f.slave.setFMUstate(s)
        b = sim.run(10.0, 0.01, log, t0=5.0)
        for k in log:
            assert np.array_equal(a[k], b[k]), k
        assert np.max(np.abs(a["ihat_x"] - 1000.0)) > 1.0   # the adaptation did move
    finally:
        sim.close()
