//! The blocks of the multiplicative extended Kalman filter of attitude (MEKF): the rotation-vector
//! exponential and logarithm of unit quaternions, the discrete state transition and process noise of
//! the attitude-error / gyro-bias state driven by a gyro with angle and rate random walk, and the
//! Joseph-form measurement update.
//!
//! Conventions (README, "Conventions"): scalar-first Hamilton quaternions of B relative to R with
//! q̇ = ½ q ⊗ (0, ω). The attitude error is a body-frame rotation vector δθ: q = q̂ ⊗ exp(δθ/2),
//! so that A(q) ≈ (I − [δθ×]) A(q̂) and δθ̇ = −[ω̂×] δθ − δb − η_v.

use nalgebra::{Matrix3, Quaternion, SMatrix, SVector, Vector3};

use super::attitude::skew;

pub type Matrix6 = SMatrix<f64, 6, 6>;

/// exp(θ/2) = (cos |θ|/2, sin(|θ|/2) θ/|θ|): the unit quaternion of a rotation vector θ (rad); exact
/// to round-off for any |θ| (the series of sin(x)/x below |θ| = 1e-4).
pub fn quat_exp(theta: &Vector3<f64>) -> Quaternion<f64> {
    let a = theta.norm();
    let half = 0.5 * a;
    // sin(a/2)/a = ½ (1 − a²/24 + a⁴/1920 …)
    let s = if a < 1e-4 {
        0.5 * (1.0 - a * a / 24.0)
    } else {
        half.sin() / a
    };
    Quaternion::from_parts(half.cos(), theta * s)
}

/// The rotation vector θ (|θ| ≤ π) of a unit quaternion: q = ±exp(θ/2) (the shorter rotation).
pub fn quat_log(q: &Quaternion<f64>) -> Vector3<f64> {
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.vector().into_owned())
    } else {
        (q.w, q.vector().into_owned())
    };
    let s = v.norm();
    if s < 1e-300 {
        return Vector3::zeros();
    }
    // angle = 2 atan2(|v|, w), robust for every angle
    v * (2.0 * s.atan2(w) / s)
}

/// Discrete state transition Φ of the error state x = (δθ, δb) over Δt with the estimated rate ω̂
/// held constant: Φ = [[Φ₁₁, Φ₁₂], [0, I]],
/// Φ₁₁ = exp(−[ω̂×] Δt) = I − [ω̂×] sin(ωΔt)/ω + [ω̂×]² (1 − cos ωΔt)/ω²,
/// Φ₁₂ = −∫₀^Δt exp(−[ω̂×] s) ds = [ω̂×] (1 − cos ωΔt)/ω² − I Δt − [ω̂×]² (ωΔt − sin ωΔt)/ω³.
pub fn error_transition(w: &Vector3<f64>, dt: f64) -> Matrix6 {
    let x = skew(w);
    let x2 = x * x;
    let a = w.norm();
    let th = a * dt;
    // coefficients with their series for small ω Δt (relative error < 1e-16 below th = 1e-3)
    let (c1, c2, c3) = if th < 1e-3 {
        let t2 = dt * dt;
        (
            dt * (1.0 - th * th / 6.0),
            t2 * (0.5 - th * th / 24.0),
            t2 * dt * (1.0 / 6.0 - th * th / 120.0),
        )
    } else {
        (th.sin() / a, (1.0 - th.cos()) / (a * a), (th - th.sin()) / (a * a * a))
    };
    let phi11 = Matrix3::identity() - x * c1 + x2 * c2;
    let phi12 = x * c2 - Matrix3::identity() * dt - x2 * c3;
    let mut phi = Matrix6::identity();
    phi.fixed_view_mut::<3, 3>(0, 0).copy_from(&phi11);
    phi.fixed_view_mut::<3, 3>(0, 3).copy_from(&phi12);
    phi
}

/// Discrete process noise over Δt of a gyro with angle random walk PSD σ_v² (rad²/s) and rate random
/// walk PSD σ_u² (rad²/s³) per axis:
/// Q = [[(σ_v² Δt + σ_u² Δt³/3) I, −σ_u² Δt²/2 I], [−σ_u² Δt²/2 I, σ_u² Δt I]].
pub fn gyro_process_noise(arw_psd: &Vector3<f64>, rrw_psd: &Vector3<f64>, dt: f64) -> Matrix6 {
    let mut q = Matrix6::zeros();
    for i in 0..3 {
        let (v, u) = (arw_psd[i], rrw_psd[i]);
        q[(i, i)] = v * dt + u * dt * dt * dt / 3.0;
        q[(i, i + 3)] = -u * dt * dt / 2.0;
        q[(i + 3, i)] = q[(i, i + 3)];
        q[(i + 3, i + 3)] = u * dt;
    }
    q
}

/// Joseph-form update of (x = 0, P) with a measurement of dimension M: innovation ν, sensitivity H,
/// noise R. Returns (δx, P⁺, ν ᵀ S⁻¹ ν) with S = H P Hᵀ + R, K = P Hᵀ S⁻¹,
/// P⁺ = (I − K H) P (I − K H)ᵀ + K R Kᵀ (symmetrised), or `None` when S is not positive definite.
pub fn joseph_update<const M: usize>(
    p: &Matrix6,
    h: &SMatrix<f64, M, 6>,
    r: &SMatrix<f64, M, M>,
    nu: &SVector<f64, M>,
) -> Option<(SVector<f64, 6>, Matrix6, f64)> {
    joseph_update_with_gain(p, h, r, nu).map(|(dx, pp, nis, _)| (dx, pp, nis))
}

/// [`joseph_update`] that also returns the gain K (6 × M): the error-state transition of the update is
/// I − K H (used to carry a delayed correction across the updates after the measurement's instant).
pub fn joseph_update_with_gain<const M: usize>(
    p: &Matrix6,
    h: &SMatrix<f64, M, 6>,
    r: &SMatrix<f64, M, M>,
    nu: &SVector<f64, M>,
) -> Option<(SVector<f64, 6>, Matrix6, f64, SMatrix<f64, 6, M>)> {
    let s = h * p * h.transpose() + r;
    let s = (s + s.transpose()) * 0.5;
    let chol = s.cholesky()?;
    let k = chol.solve(&(h * p)).transpose(); // K = P Hᵀ S⁻¹ (S, P symmetric)
    let nis = nu.dot(&chol.solve(nu));
    let ikh = Matrix6::identity() - k * h;
    let pp = ikh * p * ikh.transpose() + k * r * k.transpose();
    Some((k * nu, (pp + pp.transpose()) * 0.5, nis, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_derivative;

    fn rk4_quat(q0: Quaternion<f64>, w: Vector3<f64>, dt: f64, n: usize) -> Quaternion<f64> {
        let h = dt / n as f64;
        let mut q = q0;
        for _ in 0..n {
            let k1 = quat_derivative(&q, &w);
            let k2 = quat_derivative(&(q + k1 * (h / 2.0)), &w);
            let k3 = quat_derivative(&(q + k2 * (h / 2.0)), &w);
            let k4 = quat_derivative(&(q + k3 * h), &w);
            q += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        q
    }

    #[test]
    fn exponential_and_logarithm_are_inverse_and_match_the_kinematics() {
        for th in [
            Vector3::new(0.3, -1.2, 2.0),
            Vector3::new(1e-9, 2e-9, -1e-9),
            Vector3::new(5e-5, 0.0, 1e-5),
            Vector3::new(0.0, 0.0, 3.1),
        ] {
            let q = quat_exp(&th);
            assert!((q.norm() - 1.0).abs() < 1e-15);
            assert!((quat_log(&q) - th).norm() < 1e-15 * (1.0 + th.norm()), "{th}");
            assert!((quat_log(&-q) - th).norm() < 1e-15 * (1.0 + th.norm()));
        }
        // closed form: exp of 90 deg about z
        let q = quat_exp(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        let h = std::f64::consts::FRAC_PI_4;
        assert!((q.w - h.cos()).abs() < 1e-16 && (q.k - h.sin()).abs() < 1e-16);
        // a constant body rate for t: q(t) = q0 ⊗ exp(ω t / 2) against RK4 of q̇ = ½ q ⊗ ω
        let q0 = quat_exp(&Vector3::new(0.2, 0.1, -0.4));
        let w = Vector3::new(0.05, -0.3, 0.2);
        let num = rk4_quat(q0, w, 2.0, 2000);
        assert!((q0 * quat_exp(&(w * 2.0)) - num).norm() < 1e-12);
    }

    /// Φ against the closed-form matrix exponential of the continuous error dynamics
    /// F = [[−[ω×], −I], [0, 0]] computed by a long Taylor series.
    #[test]
    fn transition_matches_the_matrix_exponential() {
        for (w, dt) in [
            (Vector3::new(0.1, -0.2, 0.3), 0.5),
            (Vector3::new(1e-6, 0.0, 2e-6), 0.01),
            (Vector3::zeros(), 0.1),
        ] {
            let mut f = Matrix6::zeros();
            f.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-skew(&w)));
            f.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-Matrix3::identity()));
            let (mut term, mut sum) = (Matrix6::identity(), Matrix6::identity());
            for n in 1..40 {
                term = term * f * dt / n as f64;
                sum += term;
            }
            let phi = error_transition(&w, dt);
            assert!((phi - sum).abs().max() < 1e-15, "{w} {dt}: {}", (phi - sum).abs().max());
        }
    }

    /// Q against the integral ∫₀^Δt Φ(s) G Qc Gᵀ Φ(s)ᵀ ds at ω = 0 (closed form) and its structure.
    #[test]
    fn process_noise_is_the_integral_of_the_continuous_noise() {
        let (v, u, dt) = (Vector3::new(1e-6, 2e-6, 3e-6), Vector3::new(1e-9, 0.0, 4e-9), 0.7);
        // numerical integral, midpoint rule, of Φ(s) diag(σ_v², σ_u²) Φ(s)ᵀ with G = diag(−I, I)
        let n = 20_000;
        let mut qn = Matrix6::zeros();
        let mut qc = Matrix6::zeros();
        for i in 0..3 {
            qc[(i, i)] = v[i];
            qc[(i + 3, i + 3)] = u[i];
        }
        let g = Matrix6::from_diagonal(&SVector::<f64, 6>::from_column_slice(&[
            -1.0, -1.0, -1.0, 1.0, 1.0, 1.0,
        ]));
        for k in 0..n {
            let s = (k as f64 + 0.5) * dt / n as f64;
            let phi = error_transition(&Vector3::zeros(), s);
            qn += phi * g * qc * g.transpose() * phi.transpose() * (dt / n as f64);
        }
        let q = gyro_process_noise(&v, &u, dt);
        assert!(
            ((q - qn).abs().max()) < 1e-9 * q.abs().max(),
            "{}",
            (q - qn).abs().max()
        );
        assert_eq!(q, q.transpose());
    }

    /// Joseph form against the scalar closed form, and the standard form K = P Hᵀ S⁻¹, P⁺ = (I − K H) P.
    #[test]
    fn joseph_update_matches_the_closed_form() {
        let mut p = Matrix6::from_diagonal_element(4.0);
        p[(0, 3)] = 1.0;
        p[(3, 0)] = 1.0;
        let h = SMatrix::<f64, 1, 6>::from_row_slice(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let r = SMatrix::<f64, 1, 1>::new(1.0);
        let nu = SVector::<f64, 1>::new(2.0);
        let (dx, pp, nis) = joseph_update(&p, &h, &r, &nu).unwrap();
        // S = 5, K = (4, 0, 0, 1, 0, 0)/5, δx = 2 K, NIS = 4/5, P⁺₀₀ = 4 − 16/5, P⁺₃₃ = 4 − 1/5
        assert!((dx[0] - 1.6).abs() < 1e-15 && (dx[3] - 0.4).abs() < 1e-15 && (nis - 0.8).abs() < 1e-15);
        assert!(
            (pp[(0, 0)] - 0.8).abs() < 1e-15 && (pp[(3, 3)] - 3.8).abs() < 1e-15 && (pp[(0, 3)] - 0.2).abs() < 1e-15
        );
        assert!(joseph_update(&p, &h, &SMatrix::<f64, 1, 1>::new(-10.0), &nu).is_none());
    }
}
