//! What the sensors share — not FMUs themselves: the port and parameter blocks (true attitude and rate
//! from the plant, the plant's orbit parameters with the plant's value references, the sun's ecliptic
//! longitude), the sampling schedule, the delay line that holds and delays samples, and the mounting
//! rotation of a sensor frame.

pub mod delay_line;
pub mod ports;

pub use delay_line::{delivered_index, last_sample_before, max_queue, sample_index, DelayLine, MAX_SAMPLES_PER_CALL};
pub use ports::{FieldInput, OrbitParams, PositionInputs, SunInputs, SunParams, TrueAttitude};

use nalgebra::{Matrix3, Quaternion, Rotation3, Vector3};

use crate::math::environment::EARTH_RADIUS;

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

/// The input `b_eci` (environment_inputs = 1): a field, refused when zero (unwired) or not finite.
pub fn field_input(b: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    if *b == Vector3::zeros() || !b.iter().all(|x| x.is_finite()) {
        return Err(format!(
            "input b_eci = {:?} T: a non-zero finite geomagnetic field is expected (is it connected to Environment's b_eci?)",
            b.as_slice()
        ));
    }
    Ok(*b)
}

/// The input `sun_eci` (environment_inputs = 1), normalised; a zero (unwired) or non-finite vector is refused.
pub fn sun_input(s: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let n = s.norm();
    if !(n.is_finite() && n > 0.0) {
        return Err(format!(
            "input sun_eci = {:?} has norm {n}: a non-zero finite sun direction is expected (is it connected to Environment's sun_eci?)",
            s.as_slice()
        ));
    }
    Ok(s / n)
}

/// The input `eclipse` (environment_inputs = 1): a visible fraction in [0, 1].
pub fn eclipse_input(e: f64) -> Result<f64, String> {
    if !(0.0..=1.0).contains(&e) {
        return Err(format!("input eclipse = {e}: a visible fraction in [0, 1] is allowed"));
    }
    Ok(e)
}

/// The input `r` (environment_inputs = 1): a position outside the Earth's equatorial radius.
pub fn position_input(r: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let n = r.norm();
    if !(n >= EARTH_RADIUS && n.is_finite()) {
        return Err(format!(
            "input r = {:?} m has norm {n} m, below the Earth's radius {EARTH_RADIUS} m (is it connected to Orbit's r?)",
            r.as_slice()
        ));
    }
    Ok(*r)
}

/// The input `jd_utc` (environment_inputs = 1): a UTC Julian date in [2.0e6, 3.0e6] (Orbit's epoch range).
pub fn date_input(jd: f64) -> Result<f64, String> {
    if !(2.0e6..=3.0e6).contains(&jd) {
        return Err(format!(
            "input jd_utc = {jd} d: a UTC Julian date in [2.0e6, 3.0e6] is expected (is it connected to Orbit's jd_utc?)"
        ));
    }
    Ok(jd)
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

    #[test]
    fn environment_inputs_refused_by_name() {
        let z = Vector3::zeros();
        assert!(field_input(&z).unwrap_err().contains("input b_eci"));
        assert!(field_input(&Vector3::new(f64::NAN, 0.0, 1e-5))
            .unwrap_err()
            .contains("input b_eci"));
        assert!(sun_input(&z).unwrap_err().contains("input sun_eci"));
        assert!(sun_input(&Vector3::new(f64::INFINITY, 0.0, 0.0))
            .unwrap_err()
            .contains("input sun_eci"));
        assert!((sun_input(&Vector3::new(3.0, 0.0, 4.0)).unwrap() - Vector3::new(0.6, 0.0, 0.8)).norm() < 1e-16);
        assert!(eclipse_input(1.5).unwrap_err().contains("input eclipse"));
        assert!(eclipse_input(f64::NAN).unwrap_err().contains("input eclipse"));
        assert!(position_input(&z).unwrap_err().contains("input r"));
        assert!(date_input(0.0).unwrap_err().contains("input jd_utc"));
        assert_eq!(date_input(2_460_000.5), Ok(2_460_000.5));
    }
}
