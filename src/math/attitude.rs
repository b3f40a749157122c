//! Attitude conventions of the project (README, "Conventions"): scalar-first Hamilton quaternions of the
//! body frame B relative to the reference frame R; A(q) maps R-components into B-components.

use nalgebra::{Matrix3, Quaternion, Vector3};
use std::f64::consts::PI;

/// Deviation of |q| from 1 (or of ‖AᵀA − I‖ from 0) that is only the round-off of a normalisation
/// (8 ulp of 1): a projection event leaves such a state alone, so repeating it changes nothing.
pub const NORM_ROUNDOFF: f64 = 8.0 * f64::EPSILON;

/// Model Exchange: the drift of |q| (‖AᵀA − I‖) after a solver step that asks for a projection event:
/// the importer's relative tolerance (fmi2SetupExperiment, capped at 1e-3) when it is looser than
/// `floor`, else `floor`. A threshold tighter than the solver's own accuracy asks for an event after
/// nearly every step.
pub fn projection_threshold(tolerance: Option<f64>, floor: f64) -> f64 {
    tolerance
        .filter(|t| t.is_finite() && *t > 0.0)
        .map_or(floor, |t| t.min(1e-3).max(floor))
}

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
    if r == -PI {
        PI
    } else {
        r
    }
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

/// 321 angles (roll, pitch, yaw) from the attitude matrix A321 (README): φ = atan2(A23, A33),
/// θ = −asin(A13) (argument clamped), ψ = atan2(A12, A11).
pub fn euler321_from_dcm(a: &Matrix3<f64>) -> [f64; 3] {
    let roll = a[(1, 2)].atan2(a[(2, 2)]);
    let pitch = (-a[(0, 2)]).clamp(-1.0, 1.0).asin();
    let yaw = a[(0, 1)].atan2(a[(0, 0)]);
    [roll, pitch, yaw]
}

/// Quaternion of an attitude matrix by Shepperd's method (Shepperd 1978): of the four candidates
/// 4q_w² = 1 + tr A, 4q_i² = 1 + 2A_ii − tr A the largest is taken as pivot, so the division is
/// always by a number ≥ 1/2. Inverse of [`attitude_matrix`] (v_B = A v_R) up to the sign of q;
/// the result has a non-negative pivot component. A need not be exactly orthogonal.
pub fn quat_from_dcm(a: &Matrix3<f64>) -> Quaternion<f64> {
    let tr = a.trace();
    // Off-diagonal combinations for A(q) = (q_w² − |q_v|²) I + 2 q_v q_vᵀ − 2 q_w [q_v×]:
    // A23 − A32 = 4 q_w q_x, A31 − A13 = 4 q_w q_y, A12 − A21 = 4 q_w q_z,
    // A12 + A21 = 4 q_x q_y, A13 + A31 = 4 q_x q_z, A23 + A32 = 4 q_y q_z.
    let cand = [
        1.0 + tr,
        1.0 + 2.0 * a[(0, 0)] - tr,
        1.0 + 2.0 * a[(1, 1)] - tr,
        1.0 + 2.0 * a[(2, 2)] - tr,
    ];
    let mut k = 0;
    for i in 1..4 {
        if cand[i] > cand[k] {
            k = i;
        }
    }
    let s = 2.0 * cand[k].max(0.0).sqrt(); // = 4 |pivot component|
    let (w, x, y, z) = match k {
        0 => (
            0.25 * s,
            (a[(1, 2)] - a[(2, 1)]) / s,
            (a[(2, 0)] - a[(0, 2)]) / s,
            (a[(0, 1)] - a[(1, 0)]) / s,
        ),
        1 => (
            (a[(1, 2)] - a[(2, 1)]) / s,
            0.25 * s,
            (a[(0, 1)] + a[(1, 0)]) / s,
            (a[(0, 2)] + a[(2, 0)]) / s,
        ),
        2 => (
            (a[(2, 0)] - a[(0, 2)]) / s,
            (a[(0, 1)] + a[(1, 0)]) / s,
            0.25 * s,
            (a[(1, 2)] + a[(2, 1)]) / s,
        ),
        _ => (
            (a[(0, 1)] - a[(1, 0)]) / s,
            (a[(0, 2)] + a[(2, 0)]) / s,
            (a[(1, 2)] + a[(2, 1)]) / s,
            0.25 * s,
        ),
    };
    Quaternion::new(w, x, y, z)
}

/// q or −q, whichever is closer to `prev` (q·prev ≥ 0): keeps a quaternion output sign-continuous.
pub fn align_sign(q: Quaternion<f64>, prev: &Quaternion<f64>) -> Quaternion<f64> {
    if q.coords.dot(&prev.coords) < 0.0 {
        -q
    } else {
        q
    }
}

/// Elementary rotation matrices of the README (frame rotations): R1(a) = A(q_x(a)) etc.
pub fn rot1(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c)
}
/// R2(a) = A(q_y(a)).
pub fn rot2(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}
/// R3(a) = A(q_z(a)).
pub fn rot3(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

/// A213(φ, θ, ψ) = R3(ψ) R1(φ) R2(θ) (README; only needed to understand paper 000's Eq. 8).
pub fn dcm_from_euler213(roll: f64, pitch: f64, yaw: f64) -> Matrix3<f64> {
    rot3(yaw) * rot1(roll) * rot2(pitch)
}

/// Paper 000 Eq. 8 with the corrected sign (kinematics mode 2 of AttitudePlant): the angle rates
/// (φ̇, θ̇, ψ̇) of the 213 sequence for body rates ω. Singular at cos φ = 0 (returns non-finite values).
///   φ̇ = ω_x cos ψ − ω_y sin ψ,  θ̇ = (ω_x sin ψ + ω_y cos ψ) / cos φ,  ψ̇ = (ω_x sin ψ + ω_y cos ψ) tan φ + ω_z
pub fn euler213_rates(roll: f64, yaw: f64, w: &Vector3<f64>) -> Vector3<f64> {
    let (sy, cy) = yaw.sin_cos();
    let (sr, cr) = roll.sin_cos();
    let m = w.x * sy + w.y * cy;
    Vector3::new(w.x * cy - w.y * sy, m / cr, m * sr / cr + w.z)
}

/// Nearest orthogonal matrix (polar factor U Vᵀ of the SVD); used to re-orthonormalise an
/// integrated DCM. Returns the input unchanged if the SVD fails.
pub fn orthonormalize(a: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = a.svd(true, true);
    match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => u * vt,
        _ => *a,
    }
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
        for &(r, p, y) in &[
            (0.3, -0.2, 1.1),
            (40f64.to_radians(), -40f64.to_radians(), -60f64.to_radians()),
            (-2.0, 1.2, 3.0),
        ] {
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
            assert!(
                close(e[0], r, 1e-12) && close(e[1], p, 1e-12) && close(e[2], y, 1e-12),
                "{e:?}"
            );
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
        assert!(
            close(euler_axis_angle(&q, &-r), 0.7, 1e-15),
            "sign of q_ref must not matter"
        );
    }
    fn sample_quats() -> Vec<Quaternion<f64>> {
        let mut v = vec![
            quat(1.0, 0.0, 0.0, 0.0),
            quat(0.0, 1.0, 0.0, 0.0),
            quat(0.0, 0.0, 1.0, 0.0),
            quat(0.0, 0.0, 0.0, 1.0),
            quat(1e-9, 0.6, -0.8, 0.0),
            quat(-0.5, 0.5, -0.5, 0.5),
        ];
        // deterministic pseudo-random quaternions
        let mut s = 0.123_f64;
        for _ in 0..200 {
            let mut c = [0.0; 4];
            for ci in c.iter_mut() {
                s = (s * 997.0 + 0.311).fract();
                *ci = 2.0 * s - 1.0;
            }
            v.push(quat(c[0], c[1], c[2], c[3]));
        }
        v.into_iter().map(|q| q.normalize()).collect()
    }

    #[test]
    fn shepperd_inverts_attitude_matrix() {
        for q in sample_quats() {
            let p = quat_from_dcm(&attitude_matrix(&q));
            let d = (p.coords - q.coords).abs().max().min((p.coords + q.coords).abs().max());
            assert!(d < 1e-14, "q = {q:?}, shepperd = {p:?}");
            assert!((p.norm() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn sign_alignment() {
        let q = quat(0.1, -0.7, 0.7, 0.1).normalize();
        assert_eq!(align_sign(-q, &q), q);
        assert_eq!(align_sign(q, &q), q);
    }

    #[test]
    fn euler321_from_dcm_matches_readme() {
        for &(r, p, y) in &[(0.3, -0.2, 1.1), (-3.0, 1.5, -3.1), (0.0, 0.0, 0.0), (2.0, -0.4, -1.0)] {
            let e = euler321_from_dcm(&a321(r, p, y));
            assert!(
                close(e[0], r, 1e-12) && close(e[1], p, 1e-12) && close(e[2], y, 1e-12),
                "{e:?}"
            );
        }
        // elementary rotations are the README's frame rotations
        assert!((rot1(0.3) * rot2(-0.2) * rot3(1.1) - a321(0.3, -0.2, 1.1)).abs().max() < 1e-15);
    }

    #[test]
    fn a213_is_a_of_q213() {
        // q213 = q_y(θ) ⊗ q_x(φ) ⊗ q_z(ψ), README
        let (r, p, y): (f64, f64, f64) = (0.4, -0.9, 2.2);
        let qx = quat((0.5 * r).cos(), (0.5 * r).sin(), 0.0, 0.0);
        let qy = quat((0.5 * p).cos(), 0.0, (0.5 * p).sin(), 0.0);
        let qz = quat((0.5 * y).cos(), 0.0, 0.0, (0.5 * y).sin());
        let d = attitude_matrix(&(qy * qx * qz)) - dcm_from_euler213(r, p, y);
        assert!(d.abs().max() < 1e-15, "{d}");
    }

    #[test]
    fn euler213_rates_are_the_213_kinematics() {
        // With (φ̇, θ̇, ψ̇) from euler213_rates, d/dt A213(φ, θ, ψ) = −[ω×] A213 (central difference).
        for &(r, p, y) in &[(0.4, -0.9, 2.2), (-1.2, 0.3, -0.5), (0.0, 0.0, 0.0)] {
            let w = Vector3::new(0.3, -0.7, 0.2);
            let rates = euler213_rates(r, y, &w);
            let h = 1e-6;
            let ap = dcm_from_euler213(r + h * rates.x, p + h * rates.y, y + h * rates.z);
            let am = dcm_from_euler213(r - h * rates.x, p - h * rates.y, y - h * rates.z);
            let adot = (ap - am) / (2.0 * h);
            let err = (adot + skew(&w) * dcm_from_euler213(r, p, y)).abs().max();
            assert!(err < 1e-8, "err {err}");
        }
    }

    #[test]
    fn orthonormalize_restores_rotation() {
        let a = attitude_matrix(&quat(0.8, 0.2, -0.1, 0.5).normalize());
        let perturbed = a + Matrix3::new(1e-3, -2e-3, 0.0, 5e-4, 0.0, 1e-3, 0.0, 0.0, -1e-3);
        let o = orthonormalize(&perturbed);
        assert!((o.transpose() * o - Matrix3::identity()).abs().max() < 1e-14);
        assert!((o.determinant() - 1.0).abs() < 1e-14);
        assert!((o - a).abs().max() < 3e-3);
    }
}
