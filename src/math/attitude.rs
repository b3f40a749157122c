//! Attitude conventions of the project (shared/spec README): scalar-first Hamilton quaternions of the
//! body frame B relative to the reference frame R; A(q) maps R-components into B-components.

use nalgebra::{Matrix3, Quaternion, Vector3};
use std::f64::consts::PI;

/// Cross-product matrix [a×], so that [a×] b = a × b.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// q from its scalar-first components.
pub fn quat(w: f64, x: f64, y: f64, z: f64) -> Quaternion<f64> {
    Quaternion::new(w, x, y, z)
}

/// Components (w, x, y, z) of a quaternion.
pub fn wxyz(q: &Quaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// A(q) = (q_w² − |q_v|²) I + 2 q_v q_vᵀ − 2 q_w [q_v×]   (v_B = A(q) v_R).
pub fn attitude_matrix(q: &Quaternion<f64>) -> Matrix3<f64> {
    let v = q.vector().into_owned();
    Matrix3::identity() * (q.w * q.w - v.norm_squared()) + 2.0 * v * v.transpose() - 2.0 * q.w * skew(&v)
}

/// q̇ = ½ q ⊗ (0, ω), body rates ω.
pub fn quat_derivative(q: &Quaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q * Quaternion::from_imag(*w) * 0.5
}

/// q321(φ, θ, ψ) = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ): attitude of the 321 (yaw, pitch, roll) sequence.
pub fn quat_from_euler321(roll: f64, pitch: f64, yaw: f64) -> Quaternion<f64> {
    let (sr, cr) = (0.5 * roll).sin_cos();
    let (sp, cp) = (0.5 * pitch).sin_cos();
    let (sy, cy) = (0.5 * yaw).sin_cos();
    Quaternion::new(
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )
}

/// 321 angles (roll, pitch, yaw) of a unit quaternion; the asin argument is clamped to [−1, 1].
pub fn euler321_from_quat(q: &Quaternion<f64>) -> [f64; 3] {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - x * z)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    [roll, pitch, yaw]
}

/// Wraps an angle into (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let r = (a + PI).rem_euclid(2.0 * PI) - PI;
    if r == -PI { PI } else { r }
}

/// Error quaternion q_E = q* ⊗ q_ref: the reference relative to the body (paper 000 Eq. 16).
pub fn error_quaternion(q: &Quaternion<f64>, q_ref: &Quaternion<f64>) -> Quaternion<f64> {
    q.conjugate() * q_ref
}

/// Euler-axis angle between body and reference, α = 2 atan2(|q_E,v|, |q_E,w|) ∈ [0, π].
pub fn euler_axis_angle(q: &Quaternion<f64>, q_ref: &Quaternion<f64>) -> f64 {
    let e = error_quaternion(q, q_ref);
    2.0 * e.vector().norm().atan2(e.w.abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// README's A321 written out element by element.
    fn a321(r: f64, p: f64, y: f64) -> Matrix3<f64> {
        let (sr, cr) = r.sin_cos();
        let (sp, cp) = p.sin_cos();
        let (sy, cy) = y.sin_cos();
        Matrix3::new(
            cp * cy,
            cp * sy,
            -sp,
            sr * sp * cy - cr * sy,
            sr * sp * sy + cr * cy,
            sr * cp,
            cr * sp * cy + sr * sy,
            cr * sp * sy - sr * cy,
            cr * cp,
        )
    }

    #[test]
    fn a_of_q321_equals_a321() {
        for &(r, p, y) in &[(0.3, -0.2, 1.1), (40f64.to_radians(), -40f64.to_radians(), -60f64.to_radians()), (-2.0, 1.2, 3.0)] {
            let d = attitude_matrix(&quat_from_euler321(r, p, y)) - a321(r, p, y);
            assert!(d.abs().max() < 1e-15, "{d}");
        }
    }

    #[test]
    fn attitude_matrix_is_transpose_of_nalgebra_active_rotation() {
        let q = quat(0.3, -0.5, 0.7, 0.2).normalize();
        let r = UnitQuaternion::from_quaternion(q).to_rotation_matrix().into_inner();
        assert!((attitude_matrix(&q) - r.transpose()).abs().max() < 1e-15);
    }

    #[test]
    fn composition_rule() {
        // A(p ⊗ q) = A(q) A(p)
        let p = quat(0.9, 0.1, -0.3, 0.2).normalize();
        let q = quat(0.2, 0.7, 0.1, -0.4).normalize();
        let d = attitude_matrix(&(p * q)) - attitude_matrix(&q) * attitude_matrix(&p);
        assert!(d.abs().max() < 1e-15);
    }

    #[test]
    fn euler_round_trip() {
        for &(r, p, y) in &[(0.3, -0.2, 1.1), (-3.0, 1.5, -3.1), (0.0, 0.0, 0.0)] {
            let e = euler321_from_quat(&quat_from_euler321(r, p, y));
            assert!(close(e[0], r, 1e-12) && close(e[1], p, 1e-12) && close(e[2], y, 1e-12), "{e:?}");
        }
    }

    #[test]
    fn kinematics_match_dcm_rate() {
        // Ȧ = −[ω×] A, checked with a central difference of A(q(t)).
        let q = quat(0.8, 0.2, -0.1, 0.5).normalize();
        let w = Vector3::new(0.3, -0.7, 0.2);
        let h = 1e-6;
        let qp = q + quat_derivative(&q, &w) * h;
        let qm = q - quat_derivative(&q, &w) * h;
        let adot = (attitude_matrix(&qp) - attitude_matrix(&qm)) / (2.0 * h);
        assert!((adot + skew(&w) * attitude_matrix(&q)).abs().max() < 1e-8);
    }

    #[test]
    fn wrap_range() {
        assert!(close(wrap_pi(3.0 * PI), PI, 1e-12));
        assert!(close(wrap_pi(-PI), PI, 1e-12));
        assert!(close(wrap_pi(0.5), 0.5, 0.0));
        assert!(close(wrap_pi(-7.0), -7.0 + 2.0 * PI, 1e-12));
    }

    #[test]
    fn euler_axis_angle_of_single_axis_rotation() {
        let q = quat(1.0, 0.0, 0.0, 0.0);
        let r = quat_from_euler321(0.0, 0.0, 0.7);
        assert!(close(euler_axis_angle(&q, &r), 0.7, 1e-15));
        assert!(close(euler_axis_angle(&q, &-r), 0.7, 1e-15), "sign of q_ref must not matter");
    }
}
