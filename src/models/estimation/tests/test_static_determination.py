"""`Triad` and `Quest` (src/models/estimation) through the packaged FMUs, FMI 2.0 and 3.0, against the
``ahrs`` package's TRIAD, QUEST and Davenport estimators (an independent implementation) and against the
exact attitude of noise-free observations.

Conventions, converted explicitly:

* ours: scalar-first q of the body frame B relative to the reference frame R, A(q) maps R-components to
  B-components (b = A r for an exact observation), A(q) = (q_w² − |q_v|²) I + 2 q_v q_vᵀ − 2 q_w [q_v×],
  output sign q_w ≥ 0.
* ``ahrs.filters.TRIAD``: ``estimate(w1, w2)`` returns the matrix M_B M_Rᵀ of the body triad (w1, w2) and the
  reference triad (v1, v2); M_B M_Rᵀ v1 = w1, so it is our A directly. Its quaternion output
  (``representation='quaternion'``, Chiaverini's conversion) is of the *active* rotation matrix
  R(p) = (p_w² − |p_v|²) I + 2 p_v p_vᵀ + 2 p_w [p_v×], i.e. R(p) = A(q) for p = q* (the conjugate).
* ``ahrs.filters.QUEST`` and ``ahrs.filters.Davenport``: the attitude profile matrix B = Σ a_i b_i r_iᵀ (body ⊗
  reference) and the scalar-first K matrix of the q-method: the eigenvector is our q as it is (Markley's
  convention), up to sign. Their reference vectors are fixed: gravity [0, 0, 1] (Davenport: [0, 0, g], so
  ``gravity=1.0``) and a magnetic reference [cos δ, 0, sin δ] from the dip angle δ (QUEST also takes a
  vector); the random geometry comes from random attitudes, dips and measurement noise.

Quaternions are compared up to sign (q and −q are one attitude) to 1e-9.
"""

from __future__ import annotations

import numpy as np
import pytest
from ahrs.filters import QUEST, TRIAD, Davenport
from fmpy.fmi1 import FMICallException

from fmu_drive import fmu_file
from scfmu.fmu import Fmu
from scfmu.metrics import attitude_matrix  # A(q), v_B = A v_R (numpy, tested against SciPy)

TOL = 1e-9
N_CASES = 40
AX = "xyz"


def random_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def qdist(q, p):
    """Distance of two attitudes' quaternions up to sign."""
    q, p = np.asarray(q, float), np.asarray(p, float)
    return min(np.linalg.norm(q - p), np.linalg.norm(q + p))


def conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


class Unit:
    """One instance of a static determination FMU, evaluated for many input sets."""

    def __init__(self, model: str, fmi: int, params: dict | None = None):
        self.f = Fmu(model, params or {}, path=fmu_file(model, fmi))

    def estimate(self, sun_meas, b_meas, sun_ref, b_ref, extra: dict | None = None):
        names, vals = [], []
        for name, vec in (("sun_meas", sun_meas), ("b_meas", b_meas), ("sun_ref", sun_ref), ("b_ref", b_ref)):
            names += [f"{name}_{a}" for a in AX]
            vals += list(map(float, vec))
        for name, vec in (extra or {}).items():
            names += [f"{name}_{a}" for a in AX]
            vals += list(map(float, vec))
        self.f.set_reals(names, vals)
        return np.array(self.f.get_reals([f"q_est_{c}" for c in "wxyz"]))

    def get(self, name):
        return self.f.get(name)

    def close(self):
        self.f.close()


def noisy(rng, v, sigma):
    """v rotated by a small random rotation (angle ~ sigma) and scaled: an inconsistent observation."""
    u = v + sigma * rng.normal(size=3) * np.linalg.norm(v)
    return u * rng.uniform(0.5, 3.0)


@pytest.mark.parametrize("fmi", [2, 3])
def test_triad_matches_ahrs_triad_and_the_exact_attitude(fmi):
    rng = np.random.default_rng(3701)
    u0, u1 = Unit("Triad", fmi, {"anchor": 0}), Unit("Triad", fmi, {"anchor": 1})
    worst = worst_q = worst_exact = 0.0
    try:
        for _ in range(N_CASES):
            q = random_quaternion(rng)
            a = attitude_matrix(q)
            r1, r2 = rng.normal(size=3), rng.normal(size=3) * 4e-5  # sun direction, field in tesla
            # exact observations: the true attitude
            q_est = u0.estimate(a @ r1, a @ r2, r1, r2)
            worst_exact = max(worst_exact, qdist(q_est, q))
            assert q_est[0] >= 0
            # noisy observations: ahrs' TRIAD on the same (normalised) vectors
            b1, b2 = noisy(rng, a @ r1, 0.02), noisy(rng, a @ r2, 0.05)
            q_est = u0.estimate(b1, b2, r1, r2)
            tri = TRIAD(v1=r1 / np.linalg.norm(r1), v2=r2 / np.linalg.norm(r2))
            a_ahrs = tri.estimate(b1, b2)  # our A (maps R to B)
            worst = max(worst, np.abs(attitude_matrix(q_est) - a_ahrs).max())
            p_ahrs = tri.estimate(b1, b2, representation="quaternion")  # active-rotation quaternion: q*
            worst_q = max(worst_q, qdist(q_est, conj(p_ahrs)))
            # anchor 1: the field is matched exactly (ahrs with the pairs swapped)
            q_est1 = u1.estimate(b1, b2, r1, r2)
            a_swapped = TRIAD(v1=r2 / np.linalg.norm(r2), v2=r1 / np.linalg.norm(r1)).estimate(b2, b1)
            worst = max(worst, np.abs(attitude_matrix(q_est1) - a_swapped).max())
    finally:
        u0.close()
        u1.close()
    print(f"FMI {fmi} TRIAD: max |A - A_ahrs| = {worst:.2e}, max quaternion distance {worst_q:.2e}, "
          f"exact observations {worst_exact:.2e}")
    assert worst < TOL and worst_q < TOL and worst_exact < TOL


@pytest.mark.parametrize("fmi", [2, 3])
def test_quest_matches_ahrs_quest_and_davenport_and_the_closed_form_loss(fmi):
    rng = np.random.default_rng(3702)
    worst_quest = worst_dav = worst_loss = worst_exact = 0.0
    for case in range(N_CASES):
        w = rng.uniform(0.1, 2.0, size=2)
        unit = Unit("Quest", fmi, {"weight_sun": w[0], "weight_b": w[1]})
        try:
            q = random_quaternion(rng)
            a = attitude_matrix(q)
            dip = rng.uniform(-80.0, 80.0)
            g_ref = np.array([0.0, 0.0, 1.0])
            m_ref = np.array([np.cos(np.radians(dip)), 0.0, np.sin(np.radians(dip))])
            # exact observations
            q_est = unit.estimate(a @ g_ref, a @ m_ref * 5e-5, g_ref, m_ref * 5e-5)
            worst_exact = max(worst_exact, qdist(q_est, q))
            assert unit.get("loss") < 1e-20
            # inconsistent observations: ahrs' QUEST and Davenport with the same weights and references
            b1 = noisy(rng, a @ g_ref, 0.03)
            b2 = noisy(rng, a @ m_ref, 0.05)
            q_est = unit.estimate(b1, b2, g_ref, m_ref)
            u1, u2 = b1 / np.linalg.norm(b1), b2 / np.linalg.norm(b2)
            q_quest = QUEST(weights=w.copy(), magnetic_dip=dip).estimate(u1, u2)
            q_dav = np.real(Davenport(weights=w.copy(), magnetic_dip=dip, gravity=1.0).estimate(u1, u2))
            worst_quest = max(worst_quest, qdist(q_est, q_quest))
            worst_dav = max(worst_dav, qdist(q_est, q_dav / np.linalg.norm(q_dav)))
            # the loss output is Wahba's loss at the estimate, 1/2 sum a |b - A r|^2 (closed form)
            ae = attitude_matrix(q_est)
            loss = 0.5 * (w[0] * np.sum((u1 - ae @ g_ref) ** 2) + w[1] * np.sum((u2 - ae @ m_ref) ** 2))
            worst_loss = max(worst_loss, abs(unit.get("loss") - loss))
            assert loss > 1e-12, f"case {case}: observations should be inconsistent"
        finally:
            unit.close()
    print(f"FMI {fmi} QUEST: max distance to ahrs QUEST {worst_quest:.2e}, to ahrs Davenport {worst_dav:.2e}, "
          f"loss {worst_loss:.2e}, exact observations {worst_exact:.2e}")
    assert worst_quest < TOL and worst_dav < TOL and worst_loss < TOL and worst_exact < TOL


@pytest.mark.parametrize("fmi", [2, 3])
def test_quest_with_four_observations_is_wahbas_optimum(fmi):
    """Four weighted observations: the estimate minimises Wahba's loss (no random perturbation of it is
    lower), and zero-weight slots are ignored."""
    rng = np.random.default_rng(3703)
    w = [1.0, 0.5, 2.0, 0.25]
    unit = Unit("Quest", fmi, {"weight_sun": w[0], "weight_b": w[1], "weight_v3": w[2], "weight_v4": w[3]})
    try:
        q = random_quaternion(rng)
        a = attitude_matrix(q)
        refs = [rng.normal(size=3) for _ in range(4)]
        meas = [noisy(rng, a @ r, 0.05) for r in refs]
        q_est = unit.estimate(meas[0], meas[1], refs[0], refs[1],
                              {"v3_meas": meas[2], "v4_meas": meas[3], "v3_ref": refs[2], "v4_ref": refs[3]})

        def loss(qq):
            aa = attitude_matrix(qq / np.linalg.norm(qq))
            return 0.5 * sum(wi * np.sum((m / np.linalg.norm(m) - aa @ (r / np.linalg.norm(r))) ** 2)
                             for wi, m, r in zip(w, meas, refs))

        best = loss(q_est)
        assert abs(unit.get("loss") - best) < 1e-12
        for _ in range(200):
            assert loss(q_est + 1e-4 * rng.normal(size=4)) > best
    finally:
        unit.close()


@pytest.mark.parametrize("model", ["Triad", "Quest"])
@pytest.mark.parametrize("fmi", [2, 3])
def test_bad_geometry_gives_the_error_status_and_a_reason(model, fmi):
    """Each bad input on a fresh instance (after an error an FMI 3.0 instance may only be terminated or
    reset): the call returns the error status and the log names the reason."""
    s = np.array([0.3, 0.4, 0.5])
    cases = [((s, -2e-5 * s, [1, 0, 0], [0, 1, 0]), "(anti)parallel"),  # measured directions antiparallel
             ((s, [0, 0, 1], [1, 2, 3], [0, 0, 0]), "no direction")]  # a zero reference vector
    for args, reason in cases:
        unit = Unit(model, fmi)
        try:
            with pytest.raises(FMICallException) as e:
                unit.estimate(*args)
            log = " | ".join(unit.f.last_errors())
            assert "status 3 (error)" in str(e.value) and reason in log, (str(e.value), log)
        finally:
            unit.close()
    # a Quest with a single positive weight is refused at initialization
    if model == "Quest":
        with pytest.raises(FMICallException) as e:
            Fmu("Quest", {"weight_b": 0.0}, path=fmu_file("Quest", fmi))
        assert "at least two must be > 0" in str(e.value), str(e.value)
