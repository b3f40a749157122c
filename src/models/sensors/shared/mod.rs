//! What the sensors share — not FMUs themselves: the port and parameter blocks (true attitude and rate
//! from the plant, the plant's orbit parameters with the plant's value references, the sun's ecliptic
//! longitude), the sampling schedule, the delay line that holds and delays samples, and the mounting
//! rotation of a sensor frame.

pub mod delay_line;
pub mod ports;

pub use delay_line::{delivered_index, last_sample_before, max_queue, sample_index, DelayLine, MAX_SAMPLES_PER_CALL};
pub use ports::{OrbitParams, SunParams, TrueAttitude};

use nalgebra::{Matrix3, Quaternion, Rotation3, Vector3};

/// Rotation matrix R(θ) of a rotation vector θ (rad): a sensor frame S whose axes are the body axes
/// rotated by θ has components v_S = R(θ)ᵀ v_B.
pub fn rotation(theta: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::new(*theta).into_inner()
}

/// The unit quaternion exp(θ/2) = (cos |θ|/2, sin(|θ|/2) θ/|θ|) of a rotation vector.
pub fn quat_of_rotation(theta: &Vector3<f64>) -> Quaternion<f64> {
    let a = theta.norm();
    if a < 1e-300 {
        return Quaternion::new(1.0, 0.0, 0.0, 0.0);
    }
    let (s, c) = (0.5 * a).sin_cos();
    Quaternion::from_parts(c, theta * (s / a))
}

/// A quaternion input of unit norm (a measurement of a wrongly wired or unconnected port is refused).
pub fn check_unit(name: &str, q: &Quaternion<f64>) -> Result<(), String> {
    let n = q.norm();
    if (n - 1.0).abs() > 1e-3 {
        return Err(format!(
            "input quaternion {name} has norm {n}, expected 1 (is it connected?)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_vector_conventions() {
        // 90° about z: body x seen in S is -y... v_S = R^T v_B: R(z, 90°) x = y, so R^T y = x
        let r = rotation(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        let q = quat_of_rotation(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        let h = std::f64::consts::FRAC_PI_4;
        assert!((q.w - h.cos()).abs() < 1e-15 && (q.k - h.sin()).abs() < 1e-15);
        assert_eq!(quat_of_rotation(&Vector3::zeros()), Quaternion::new(1.0, 0.0, 0.0, 0.0));
        assert!(check_unit("q", &Quaternion::new(0.0, 0.0, 0.0, 0.0))
            .unwrap_err()
            .contains("q has norm 0"));
    }
}
