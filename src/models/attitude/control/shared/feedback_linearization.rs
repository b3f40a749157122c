//! Feedback-linearising quaternion attitude law of paper 004 and the open-loop model its reference
//! corrector integrates. Plain functions and one plain struct, no FMI: the FMUs
//! `FeedbackLinearizingController` and `ReferenceCorrector` are thin wrappers around this module.
//!
//! Body with diagonal inertia I, scalar-first quaternion q = (q_w, q_v), body rate ω, torque u,
//! u' = u ⊘ I (componentwise):
//! ```text
//! q̇_v  = ½ (q_w ω + q_v × ω) = ½ M(q) ω,          M(q) = q_w I3 + [q_v×],   det M = q_w |q|²
//! ω̇    = u' + g,   g = (G1 ω_y ω_z, G2 ω_x ω_z, G3 ω_x ω_y),
//!        G1 = (I_y − I_z)/I_x, G2 = (I_z − I_x)/I_y, G3 = (I_x − I_y)/I_z
//! q̈_v  = χ + ½ M(q) u',   χ = −¼ q_v |ω|² + ½ M(q) g
//! ```
//! The law imposes q̈_v = u'' with u'' = q̈_ref − k_q̇ ⊙ (q̇_v − q̇_ref) − k_q ⊙ (q_v − q_ref), so the
//! error e = q_v − q_ref,v obeys ë + k_q̇ ė + k_q e = 0 on each axis while no torque saturates:
//! ```text
//! u' = 2 M(q)⁻¹ (u'' − χ),     torque = I ⊙ u'
//! ```
//! M is singular at q_w = 0 (a 180° attitude): [`control_torque`] returns an error there instead of
//! a huge or non-finite torque.
//!
//! The reference corrector solves the same relation for q̈_ref given an open-loop torque u_ol acting
//! on a copy of the plant: q̈_ref = k_q̇ ⊙ ė + k_q ⊙ e + χ + ½ M(q) u'_ol with (q, ω) the copy's state
//! ([`reference_accel`]). [`OpenLoopCopy`] is that copy: the same rigid-body equations, RK4 steps and
//! quaternion renormalisation as `AttitudePlant` (actuator mode 0, quaternion kinematics), so that a
//! run of the corrector and a run of the plant with the same held torques agree to the last bits.

use nalgebra::{Matrix3, Quaternion, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::math::attitude::{quat_derivative, skew};
use crate::math::integrate::rk4;

/// |q_w| below which the law is refused (det M(q) = q_w for a unit quaternion).
pub const SINGULAR_QW: f64 = 1e-6;

/// Per-axis gains k_q (1/s²) and k_q̇ (1/s) of the error dynamics ë + k_q̇ ė + k_q e = 0.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Gains {
    pub k_q: Vector3<f64>,
    pub k_qdot: Vector3<f64>,
}

/// Vector part of the reference and its first two derivatives.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Reference {
    pub q_v: Vector3<f64>,
    pub q_v_dot: Vector3<f64>,
    pub q_v_ddot: Vector3<f64>,
}

/// M(q) = q_w I3 + [q_v×].
pub fn m_matrix(q: &Quaternion<f64>) -> Matrix3<f64> {
    Matrix3::identity() * q.w + skew(&q.vector().into_owned())
}

/// q̇_v = ½ (q_w ω + q_v × ω), computed from q and ω.
pub fn quat_vec_rate(q: &Quaternion<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    let v = q.vector().into_owned();
    (w * q.w + v.cross(w)) * 0.5
}

/// Gyroscopic coupling per unit inertia, g = (G1 ω_y ω_z, G2 ω_x ω_z, G3 ω_x ω_y).
pub fn gyro(w: &Vector3<f64>, inertia: &Vector3<f64>) -> Vector3<f64> {
    let (ix, iy, iz) = (inertia.x, inertia.y, inertia.z);
    Vector3::new(
        (iy - iz) / ix * w.y * w.z,
        (iz - ix) / iy * w.x * w.z,
        (ix - iy) / iz * w.x * w.y,
    )
}

/// χ = −¼ q_v |ω|² + ½ M(q) g: the part of q̈_v that does not depend on the torque.
pub fn chi(q: &Quaternion<f64>, w: &Vector3<f64>, inertia: &Vector3<f64>) -> Vector3<f64> {
    let v = q.vector().into_owned();
    v * (-0.25 * w.norm_squared()) + m_matrix(q) * gyro(w, inertia) * 0.5
}

/// Solves M(q) x = b in closed form, M⁻¹ = (q_w² I + q_v q_vᵀ − q_w [q_v×]) / (q_w (q_w² + |q_v|²)).
/// Refuses |q_w| < [`SINGULAR_QW`] with a message.
pub fn solve_m(q: &Quaternion<f64>, b: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    if q.w.is_nan() || q.w.abs() < SINGULAR_QW {
        return Err(format!(
            "feedback linearisation is singular: |q_w| = {:e} < {SINGULAR_QW:e} (attitude near 180 degrees, det M(q) = q_w)",
            q.w.abs()
        ));
    }
    let v = q.vector().into_owned();
    let num = b * (q.w * q.w) + v * v.dot(b) - v.cross(b) * q.w;
    Ok(num / (q.w * (q.w * q.w + v.norm_squared())))
}

/// u'' = q̈_ref − k_q̇ ⊙ (q̇_v − q̇_ref) − k_q ⊙ (q_v − q_ref)   (paper 004 Eq. 3).
pub fn outer_loop(q: &Quaternion<f64>, w: &Vector3<f64>, r: &Reference, k: &Gains) -> Vector3<f64> {
    let e = q.vector().into_owned() - r.q_v;
    let e_dot = quat_vec_rate(q, w) - r.q_v_dot;
    r.q_v_ddot - k.k_qdot.component_mul(&e_dot) - k.k_q.component_mul(&e)
}

/// Torque command of the feedback-linearising law: I ⊙ 2 M(q)⁻¹ (u'' − χ)   (paper 004 Eqs. 1–3).
pub fn control_torque(
    q: &Quaternion<f64>,
    w: &Vector3<f64>,
    r: &Reference,
    inertia: &Vector3<f64>,
    k: &Gains,
) -> Result<Vector3<f64>, String> {
    let rhs = (outer_loop(q, w, r, k) - chi(q, w, inertia)) * 2.0;
    let u_prime = solve_m(q, &rhs)?;
    let torque = inertia.component_mul(&u_prime);
    if torque.iter().all(|x| x.is_finite()) {
        Ok(torque)
    } else {
        Err(format!(
            "feedback linearisation produced a non-finite torque {:?}",
            torque.as_slice()
        ))
    }
}

/// q̈_ref of the reference corrector (paper 004 Eq. 17): k_q̇ ⊙ (q̇_v − q̇_ref) + k_q ⊙ (q_v − q_ref)
/// + χ + ½ M(q) u'_ol, with (q, ω) the open-loop state and u'_ol = sat(u_ol) ⊘ I.
pub fn reference_accel(
    q: &Quaternion<f64>,
    w: &Vector3<f64>,
    q_ref_v: &Vector3<f64>,
    q_ref_v_dot: &Vector3<f64>,
    u_prime: &Vector3<f64>,
    inertia: &Vector3<f64>,
    k: &Gains,
) -> Vector3<f64> {
    let e = q.vector().into_owned() - q_ref_v;
    let e_dot = quat_vec_rate(q, w) - q_ref_v_dot;
    k.k_qdot.component_mul(&e_dot) + k.k_q.component_mul(&e) + chi(q, w, inertia) + m_matrix(q) * u_prime * 0.5
}

/// State of [`OpenLoopCopy`]: quaternion (w, x, y, z), body rate, reference error e = q_v − q_ref,v
/// and its rate ė.
pub type CopyState = SVector<f64, 13>;

/// The reference corrector's internal open-loop plant plus its reference error.
///
/// The open-loop part repeats `AttitudePlant` in actuator mode 0 with quaternion kinematics and no
/// disturbance: I ω̇ = sat(u) − ω × I ω, q̇ = ½ q ⊗ (0, ω), classical RK4 with ⌈Δ/h_max⌉ equal
/// internal steps per communication step, the torque held over the communication step, q
/// renormalised after every internal step, I⁻¹ from a Cholesky factorisation — the same arithmetic as
/// the plant, so the two agree to round-off for the same torque sequence.
///
/// Instead of q_ref itself the copy integrates e = q_v − q_ref,v: by Eq. 17 ë = −k_q̇ ⊙ ė − k_q ⊙ e
/// exactly (the open-loop motion obeys q̈_v = χ + ½ M u'), so q_ref,v = q_v − e solves Eq. 17 and stays
/// equal to the open-loop q_v bit for bit when e(0) = ė(0) = 0.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct OpenLoopCopy {
    pub x: CopyState,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// Torque limits a_i u_max,i.
    pub limit: Vector3<f64>,
    pub gains: Gains,
    /// Largest internal RK4 step.
    pub max_step: f64,
}

impl OpenLoopCopy {
    #[allow(clippy::too_many_arguments)]
    /// Starts at state (q0, ω0) with reference error (e0, ė0). `inertia` is the
    /// diagonal (must be positive), `limit` the torque limits (≥ 0).
    pub fn new(
        inertia: &Vector3<f64>,
        limit: &Vector3<f64>,
        gains: Gains,
        max_step: f64,
        q0: &Quaternion<f64>,
        w0: &Vector3<f64>,
        e0: &Vector3<f64>,
        e0_dot: &Vector3<f64>,
    ) -> Result<Self, String> {
        let i = Matrix3::from_diagonal(inertia);
        let chol = nalgebra::Cholesky::new(i)
            .ok_or_else(|| format!("inertia {:?} is not positive definite", inertia.as_slice()))?;
        if max_step.is_nan() || max_step <= 0.0 {
            return Err(format!("max_internal_step = {max_step} must be positive"));
        }
        let mut x = CopyState::zeros();
        x.as_mut_slice()[0..4].copy_from_slice(&[q0.w, q0.i, q0.j, q0.k]);
        x.as_mut_slice()[4..7].copy_from_slice(w0.as_slice());
        x.as_mut_slice()[7..10].copy_from_slice(e0.as_slice());
        x.as_mut_slice()[10..13].copy_from_slice(e0_dot.as_slice());
        Ok(OpenLoopCopy {
            x,
            inertia: i,
            inertia_inv: chol.inverse(),
            limit: *limit,
            gains,
            max_step,
        })
    }

    pub fn q(&self) -> Quaternion<f64> {
        Quaternion::new(self.x[0], self.x[1], self.x[2], self.x[3])
    }
    pub fn w(&self) -> Vector3<f64> {
        Vector3::new(self.x[4], self.x[5], self.x[6])
    }
    pub fn e(&self) -> Vector3<f64> {
        Vector3::new(self.x[7], self.x[8], self.x[9])
    }
    pub fn e_dot(&self) -> Vector3<f64> {
        Vector3::new(self.x[10], self.x[11], self.x[12])
    }
    pub fn inertia_diag(&self) -> Vector3<f64> {
        self.inertia.diagonal()
    }

    /// sat(u): componentwise clamp into ±limit (the plant's actuator mode 0).
    pub fn saturate(&self, u: &Vector3<f64>) -> Vector3<f64> {
        let l = self.limit;
        Vector3::new(u.x.clamp(-l.x, l.x), u.y.clamp(-l.y, l.y), u.z.clamp(-l.z, l.z))
    }

    fn derivative(&self, x: &CopyState, tau: &Vector3<f64>) -> CopyState {
        let q = Quaternion::new(x[0], x[1], x[2], x[3]);
        let w = Vector3::new(x[4], x[5], x[6]);
        let qdot = quat_derivative(&q, &w);
        // the plant's expression with h_w = 0: I⁻¹ (τ − ω × (I ω + 0))
        let wdot = self.inertia_inv * (tau - w.cross(&(self.inertia * w + Vector3::zeros())));
        let e = Vector3::new(x[7], x[8], x[9]);
        let ed = Vector3::new(x[10], x[11], x[12]);
        let edd = -self.gains.k_qdot.component_mul(&ed) - self.gains.k_q.component_mul(&e);
        let mut d = CopyState::zeros();
        (d[0], d[1], d[2], d[3]) = (qdot.w, qdot.i, qdot.j, qdot.k);
        d.fixed_rows_mut::<3>(4).copy_from(&wdot);
        d.fixed_rows_mut::<3>(7).copy_from(&ed);
        d.fixed_rows_mut::<3>(10).copy_from(&edd);
        d
    }

    /// ẋ of the current state for the torque command u (saturated inside): the Model Exchange
    /// right-hand side.
    pub fn rate(&self, u: &Vector3<f64>) -> CopyState {
        self.derivative(&self.x, &self.saturate(u))
    }

    /// Advances by one communication step h with the torque command u held (saturated inside).
    pub fn step(&mut self, t: f64, h: f64, u: &Vector3<f64>) -> Result<(), String> {
        let tau = self.saturate(u);
        let n = (h / self.max_step - 1e-9).ceil().max(1.0) as usize;
        let dt = h / n as f64;
        let mut x = self.x;
        for k in 0..n {
            let tk = t + k as f64 * dt;
            let mut f = |_t: f64, xx: &CopyState| self.derivative(xx, &tau);
            x = rk4(&mut f, tk, &x, dt);
            if !x.iter().all(|c| c.is_finite()) {
                return Err(format!(
                    "reference corrector: open-loop state became non-finite at t = {}",
                    tk + dt
                ));
            }
            let nq = x.fixed_rows::<4>(0).norm();
            if nq <= 0.0 {
                return Err(format!(
                    "reference corrector: quaternion norm became zero at t = {}",
                    tk + dt
                ));
            }
            x.fixed_rows_mut::<4>(0).unscale_mut(nq);
        }
        self.x = x;
        Ok(())
    }

    /// Reference (q_ref,v, q̇_ref,v, q̈_ref,v) for the current state and the open-loop torque command
    /// u_ol applied now: q_ref,v = q_v − e, q̇_ref,v = q̇_v − ė, q̈_ref,v by Eq. 17.
    pub fn reference(&self, u_ol: &Vector3<f64>) -> Reference {
        let (q, w) = (self.q(), self.w());
        let i = self.inertia_diag();
        let u_prime = self.saturate(u_ol).component_div(&i);
        let q_v = q.vector().into_owned() - self.e();
        let q_v_dot = quat_vec_rate(&q, &w) - self.e_dot();
        let q_v_ddot = reference_accel(&q, &w, &q_v, &q_v_dot, &u_prime, &i, &self.gains);
        Reference { q_v, q_v_dot, q_v_ddot }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;

    fn gains() -> Gains {
        Gains {
            k_q: Vector3::repeat(0.5),
            k_qdot: Vector3::repeat(2.0),
        }
    }
    const I4: [f64; 3] = [449.5, 264.5, 312.5];

    fn inertia() -> Vector3<f64> {
        Vector3::from(I4)
    }

    /// q̈_v of the rigid body for a given torque, by central differences of q̇_v(q(t), ω(t)) along
    /// the true dynamics (an independent route to the quantity the law linearises).
    fn qv_ddot_numeric(q: &Quaternion<f64>, w: &Vector3<f64>, u: &Vector3<f64>) -> Vector3<f64> {
        let i = inertia();
        let f = |q: &Quaternion<f64>, w: &Vector3<f64>| {
            let qd = quat_derivative(q, w);
            let iw = i.component_mul(w);
            let wd = (u - w.cross(&iw)).component_div(&i);
            (qd, wd)
        };
        let h = 1e-5;
        let shift = |s: f64| {
            let (qd, wd) = f(q, w);
            let q1 = q + qd * s;
            let w1 = w + wd * s;
            quat_vec_rate(&q1, &w1)
        };
        (shift(h) - shift(-h)) / (2.0 * h)
    }

    #[test]
    fn chi_plus_half_m_u_is_the_second_derivative_of_q_v() {
        let q = quat_from_euler321(0.4, -0.3, 1.1);
        let w = Vector3::new(0.05, -0.12, 0.08);
        let u = Vector3::new(3.0, -1.0, 2.0);
        let model = chi(&q, &w, &inertia()) + m_matrix(&q) * u.component_div(&inertia()) * 0.5;
        let num = qv_ddot_numeric(&q, &w, &u);
        assert!((model - num).norm() < 1e-9, "{model:?} vs {num:?}");
    }

    #[test]
    fn law_imposes_the_commanded_second_derivative() {
        let q = quat_from_euler321(-0.7, 0.2, 0.5);
        let w = Vector3::new(-0.03, 0.02, 0.06);
        let r = Reference {
            q_v: Vector3::new(0.01, -0.02, 0.03),
            q_v_dot: Vector3::new(0.001, 0.0, -0.002),
            q_v_ddot: Vector3::new(1e-4, -2e-4, 3e-4),
        };
        let u = control_torque(&q, &w, &r, &inertia(), &gains()).unwrap();
        let achieved = qv_ddot_numeric(&q, &w, &u);
        let wanted = outer_loop(&q, &w, &r, &gains());
        assert!((achieved - wanted).norm() < 1e-9, "{achieved:?} vs {wanted:?}");
    }

    #[test]
    fn m_inverse_closed_form_matches_lu() {
        let q = Quaternion::new(0.3, -0.5, 0.7, 0.2).normalize();
        let b = Vector3::new(0.3, -2.0, 1.5);
        let x = solve_m(&q, &b).unwrap();
        let lu = m_matrix(&q).lu().solve(&b).unwrap();
        assert!((x - lu).norm() < 1e-13);
        assert!((m_matrix(&q).determinant() - q.w).abs() < 1e-14);
    }

    #[test]
    fn singular_attitude_is_an_error_not_a_nan() {
        // 180° about an axis: q_w = 0
        let q = Quaternion::new(0.0, 0.6, 0.0, 0.8);
        let err = control_torque(&q, &Vector3::zeros(), &Reference::default(), &inertia(), &gains()).unwrap_err();
        assert!(err.contains("singular") && err.contains("q_w"), "{err}");
        let q = Quaternion::new(5e-7, (1.0f64 - 2.5e-13).sqrt(), 0.0, 0.0);
        assert!(control_torque(&q, &Vector3::zeros(), &Reference::default(), &inertia(), &gains()).is_err());
        let q = Quaternion::new(2e-6, (1.0f64 - 4e-12).sqrt(), 0.0, 0.0);
        let t = control_torque(&q, &Vector3::zeros(), &Reference::default(), &inertia(), &gains()).unwrap();
        assert!(t.iter().all(|x| x.is_finite()));
    }

    #[test]
    fn zero_error_at_rest_gives_zero_torque() {
        let q = quat_from_euler321(0.1, 0.2, 0.3);
        let r = Reference {
            q_v: q.vector().into_owned(),
            ..Default::default()
        };
        let t = control_torque(&q, &Vector3::zeros(), &r, &inertia(), &gains()).unwrap();
        assert!(t.norm() < 1e-12);
    }

    #[test]
    fn reference_on_the_open_loop_trajectory_commands_the_open_loop_torque() {
        // With q_ref = q_ol, q̇_ref = q̇_ol and q̈_ref from Eq. 17, the law returns sat(u_ol).
        let g = gains();
        let lim = Vector3::repeat(1.0);
        let q0 = quat_from_euler321(0.14, -0.07, 0.1);
        let mut copy = OpenLoopCopy::new(
            &inertia(),
            &lim,
            g,
            0.01,
            &q0,
            &Vector3::new(0.01, 0.0, -0.02),
            &Vector3::zeros(),
            &Vector3::zeros(),
        )
        .unwrap();
        for k in 0..50 {
            let u = Vector3::new(0.8 * (0.1 * k as f64).sin(), -1.7, 0.3);
            let r = copy.reference(&u);
            assert!((r.q_v - copy.q().vector()).norm() == 0.0);
            let torque = control_torque(&copy.q(), &copy.w(), &r, &inertia(), &g).unwrap();
            assert!((torque - copy.saturate(&u)).norm() < 1e-12, "{torque:?}");
            copy.step(0.01 * k as f64, 0.01, &u).unwrap();
        }
    }

    #[test]
    fn reference_error_decays_with_the_design_poles() {
        // ë + 2 ė + 0.5 e = 0 → e(t) = c1 e^{p1 t} + c2 e^{p2 t}, p = −1 ± √2/2
        let g = gains();
        let e0 = Vector3::new(0.01, -0.02, 0.005);
        let mut copy = OpenLoopCopy::new(
            &inertia(),
            &Vector3::repeat(1.0),
            g,
            0.01,
            &Quaternion::identity(),
            &Vector3::zeros(),
            &e0,
            &Vector3::zeros(),
        )
        .unwrap();
        let (p1, p2) = (-1.0 + 0.5f64.sqrt(), -1.0 - 0.5f64.sqrt());
        // e(0) = e0, ė(0) = 0: c1 = −p2 e0/(p1 − p2), c2 = p1 e0/(p1 − p2)
        let t_end = 5.0;
        for k in 0..500 {
            copy.step(0.01 * k as f64, 0.01, &Vector3::zeros()).unwrap();
        }
        let exact = e0 * ((-p2 * (p1 * t_end).exp() + p1 * (p2 * t_end).exp()) / (p1 - p2));
        assert!((copy.e() - exact).norm() < 1e-11, "{:?} vs {exact:?}", copy.e());
    }
}
