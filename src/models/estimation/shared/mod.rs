//! What the static determination units share (not FMUs): the two sensor observations with their
//! reference directions, the estimated quaternion output and the separation limit, with the same names
//! and value references in `Triad` and `Quest`.

use nalgebra::Vector3;

use crate::declare_variables;

declare_variables! {
    /// Sun sensor and magnetometer observations (body axes, named as the sensors' outputs so that they
    /// are fed by name) and their reference-frame directions; the estimated attitude.
    pub struct TwoObservations {
        0 => sun_meas: Vec3 = [1.0, 0.0, 0.0], Input, "", "Measured sun direction, body axes (the SunSensor's output; normalised here)";
        3 => b_meas: Vec3 = [0.0, 1.0, 0.0], Input, "T", "Measured geomagnetic field, body axes (the Magnetometer's output; only its direction is used)";
        12 => sun_ref: Vec3 = [1.0, 0.0, 0.0], Input, "", "Sun direction in the reference frame R (ephemeris; normalised here)";
        15 => b_ref: Vec3 = [0.0, 1.0, 0.0], Input, "T", "Geomagnetic field in the reference frame R (field model; only its direction is used)";
        40 => q_est: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Estimated attitude quaternion of B relative to R (scalar first, q_est_w >= 0; the plant's q convention)";
        100 => min_separation: Real = 1e-3, Parameter, "rad", "Smallest accepted angle between two observation directions (or from antiparallel); below it the attitude about their common line is undetermined and the unit returns an error", Range(1e-9, 1.5);
    }
}

/// Every input vector is finite (the FMI layer refuses non-finite values when they are set; a unit
/// reached by an unconnected port still sees its start values).
pub fn check_finite(name: &str, v: &Vector3<f64>) -> Result<(), String> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("input {name} = [{}, {}, {}] is not finite", v.x, v.y, v.z))
    }
}
