//! `AttitudeCommand`: the attitude reference of the three-axis loop: a constant 321 attitude applied as a
//! step (the papers' slews), the local-vertical local-horizontal frame (nadir pointing along an orbit) or
//! sun pointing or pointing at a fixed inertial target.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{euler321_from_quat, quat_from_euler321};
use crate::math::orbit;
use crate::math::wahba::{self, quat_nonneg, triad};
use crate::model::{check_derived, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};
use crate::param_enum;

param_enum! {
    /// What the command points.
    pub enum Reference { Euler321Step = 0, Nadir = 1, Sun = 2, Target = 3 }
}

declare_variables! {
    pub struct AttitudeCommandVars {
        0 => r: Vec3 = [0.0; 3], Input, "m", "Spacecraft position, inertial axes (reference = 1; e.g. the Orbit unit's r)";
        3 => v: Vec3 = [0.0; 3], Input, "m/s", "Spacecraft velocity, inertial axes (reference = 1)";
        6 => sun_eci: Vec3 = [0.0; 3], Input, "", "Direction Earth to sun, inertial axes (reference = 2; e.g. the Environment unit's sun_eci; normalised here)";
        10 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Commanded attitude quaternion (of the commanded body axes relative to the reference frame; scalar part >= 0)";
        14 => w_ref: Vec3 = [0.0; 3], Output, "rad/s", "Commanded body rate, in the commanded body axes (0 for reference 0, 2 and 3)";
        17 => roll_ref: Real = 0.0, Output, "rad", "Commanded roll (321)";
        18 => pitch_ref: Real = 0.0, Output, "rad", "Commanded pitch (321)";
        19 => yaw_ref: Real = 0.0, Output, "rad", "Commanded yaw (321)";
        20 => w_ref_dot: Vec3 = [0.0; 3], Output, "rad/s2", "Commanded angular acceleration dw_ref/dt, in the commanded body axes (0 for reference 0, 2 and 3; nadir: the LVLH rate's change on an eccentric orbit)";
        100 => ref_euler321_roll: Real = 0.0, Parameter, "rad", "Commanded roll of the 321 sequence after step_time (reference 0)";
        101 => ref_euler321_pitch: Real = 0.0, Parameter, "rad", "Commanded pitch of the 321 sequence after step_time (reference 0)";
        102 => ref_euler321_yaw: Real = 0.0, Parameter, "rad", "Commanded yaw of the 321 sequence after step_time (reference 0)";
        103 => step_time: Real = 0.0, Parameter, "s", "Time of the step; identity before it (reference 0)";
        104 => reference: Integer = 0, Parameter, "", "0 = constant 321 command applied at step_time (the papers'); 1 = nadir: the body axes on the LVLH axes of r, v (z to the Earth's centre, x along-track, y against the orbit normal); 2 = sun: body axis sun_axis to the sun, body axis secondary_axis as close as possible to the inertial z axis; 3 = inertial target: body axis sun_axis on the fixed direction target_eci, secondary_axis as in 2", Choice(Reference::CODES);
        105 => sun_axis: Vec3 = [0.0, 0.0, -1.0], Parameter, "", "References 2, 3: the pointing axis, the body axis pointed at the sun (e.g. the solar array normal) or at the target (e.g. an instrument boresight; normalised)";
        108 => secondary_axis: Vec3 = [1.0, 0.0, 0.0], Parameter, "", "References 2, 3: the body axis turned toward the inertial z axis (not parallel to sun_axis; normalised)";
        111 => target_eci: Vec3 = [1.0, 0.0, 0.0], Parameter, "", "Reference 3: the fixed inertial direction the pointing axis sun_axis is turned to (not zero, not along the inertial z axis; normalised)";
    }
}

/// The nadir reference: attitude matrix of the LVLH frame, its rate and its angular acceleration.
type Nadir = (Matrix3<f64>, Vector3<f64>, Vector3<f64>);

/// No state: the outputs are a function of time, the inputs and the parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct AttitudeCommand {
    reference: Reference,
}

/// The unit vector of an input; the message names it and asks whether it is wired.
fn unit(name: &str, x: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    wahba::unit(&format!("input {name}"), x).map_err(|e| format!("{e} (is it connected?)"))
}

impl AttitudeCommand {
    /// Nadir: rows of A = the LVLH axes in inertial components; the frame turns at (r x v)/|r|^2 about the
    /// orbit normal, i.e. at -|h|/|r|^2 about its own y axis (h = r x v). Two-body motion keeps h constant, so
    /// the rate changes only through |r|: d/dt (-|h| |r|^-2) = 2 |h| |r|^-3 d|r|/dt = 2 |h| (r.v) / |r|^4, about the
    /// same fixed axis (the frame's y, so the derivative is the same in inertial and in LVLH axes).
    fn nadir(v: &AttitudeCommandVars) -> Result<Nadir, String> {
        unit("r", &v.r)?;
        let [x, y, z] = orbit::lvlh_axes(&v.r, &v.v).map_err(|e| format!("inputs r, v: {e}"))?;
        let (h, r2) = (v.r.cross(&v.v).norm(), v.r.norm_squared());
        let a = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
        Ok((a, Vector3::new(0.0, -h / r2, 0.0), Vector3::new(0.0, 2.0 * h * v.r.dot(&v.v) / (r2 * r2), 0.0)))
    }

    /// Reference 2 or 3: sun_axis exactly on the unit direction `u`, secondary_axis turned toward the inertial z axis.
    fn two_axis(v: &AttitudeCommandVars, name: &str, u: &Vector3<f64>) -> Result<Matrix3<f64>, String> {
        let z = Vector3::z();
        if u.cross(&z).norm() < 1e-6 {
            return Err(format!("{name} is along the inertial z axis: the pointing attitude about it is undefined"));
        }
        // TRIAD: sun_axis matched to u exactly, secondary_axis turned toward z (both pairs are checked apart
        // already: at initialisation and just above)
        triad(&v.sun_axis, &v.secondary_axis, u, &z, 0.0)
    }
}

impl Model for AttitudeCommand {
    type Vars = AttitudeCommandVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudeCommand",
        description: "Attitude reference: a constant 321 Euler-angle command applied as a step, nadir (LVLH), sun or inertial-target pointing, with the reference's rate and angular acceleration",
        source: "command of the large- and small-angle slews ([Navabi-2019], [T2FSMC-LEO]); LVLH frame and two-vector attitude ([Markley-Crassidis-2014])",
        equations_html: "<pre>reference 0:  t &lt; step_time:  q_ref = (1, 0, 0, 0), angles 0\n\
              t &gt;= step_time: q_ref = q321(roll, pitch, yaw) = q_z(yaw) (x) q_y(pitch) (x) q_x(roll),  w_ref = 0\n\
reference 1:  z = -r/|r|,  y = -(r x v)/|r x v|,  x = y x z,   A(q_ref) = [x y z]^T\n\
              w_ref = (0, -|r x v| / |r|^2, 0)      (the LVLH frame's rate, in its own axes)\n\
              w_ref_dot = (0, 2 |r x v| (r.v) / |r|^4, 0)   (two-body: r x v constant, d|r|/dt = r.v/|r|)\n\
reference 2:  A(q_ref) a_k = u_k with a_1 = sun_axis, a_2 = a_1 x secondary_axis, u_1 = sun_eci, u_2 = u_1 x z_R\n\
              (a_3 = a_1 x a_2, u_3 = u_1 x u_2),  w_ref = 0 (the sun moves about 1 deg per day)\n\
reference 3:  as 2 with u_1 = target_eci/|target_eci| (a fixed inertial direction),  w_ref = 0\n\
w_ref_dot = 0 for references 0, 2 and 3\n\
q_ref from A by Shepperd's method, sign with q_w &gt;= 0; roll/pitch/yaw_ref = euler321(q_ref)</pre>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut AttitudeCommandVars, _exp: &Experiment) -> Result<Self, String> {
        let reference = Reference::from_param("reference", v.reference)?;
        if reference == Reference::Target {
            let t = wahba::unit("target_eci", &v.target_eci).map_err(|e| format!("parameter {e}"))?;
            if t.cross(&Vector3::z()).norm() < 1e-6 {
                return Err(format!(
                    "target_eci ({}, {}, {}) is along the inertial z axis: the pointing attitude about it is undefined",
                    v.target_eci.x, v.target_eci.y, v.target_eci.z
                ));
            }
        }
        if matches!(reference, Reference::Sun | Reference::Target) {
            let (a, b) = (v.sun_axis, v.secondary_axis);
            let (na, nb) = (a.norm(), b.norm());
            if !(na > 0.0 && nb > 0.0) || a.cross(&b).norm() < 1e-3 * na * nb {
                return Err(format!(
                    "sun_axis ({}, {}, {}) and secondary_axis ({}, {}, {}) must be non-zero and not parallel",
                    a.x, a.y, a.z, b.x, b.y, b.z
                ));
            }
        }
        Ok(AttitudeCommand { reference })
    }

    fn outputs(&self, v: &mut AttitudeCommandVars, t: f64) -> ModelResult {
        let zero = Vector3::zeros();
        let (q, w, w_dot) = match self.reference {
            Reference::Euler321Step => {
                let (r, p, y) = if t >= v.step_time { (v.ref_euler321_roll, v.ref_euler321_pitch, v.ref_euler321_yaw) } else { (0.0, 0.0, 0.0) };
                v.q_ref = quat_from_euler321(r, p, y);
                (v.roll_ref, v.pitch_ref, v.yaw_ref) = (r, p, y);
                (v.w_ref, v.w_ref_dot) = (zero, zero);
                return Ok(());
            }
            Reference::Nadir => {
                let (a, w, w_dot) = Self::nadir(v)?;
                (quat_nonneg(&a), w, w_dot)
            }
            Reference::Sun => {
                let s = unit("sun_eci", &v.sun_eci)?;
                (quat_nonneg(&Self::two_axis(v, "sun_eci", &s)?), zero, zero)
            }
            Reference::Target => {
                let u = v.target_eci.normalize(); // not zero: checked at initialisation
                (quat_nonneg(&Self::two_axis(v, "target_eci", &u)?), zero, zero)
            }
        };
        v.q_ref = q;
        [v.roll_ref, v.pitch_ref, v.yaw_ref] = euler321_from_quat(&v.q_ref);
        (v.w_ref, v.w_ref_dot) = (w, w_dot);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("reference", &self.reference, &fresh.reference)
    }

    /// Model Exchange: the step is a time event.
    fn next_time_event(&self, v: &AttitudeCommandVars, t: f64) -> Option<f64> {
        (self.reference == Reference::Euler321Step && v.step_time > t).then_some(v.step_time)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::attitude_matrix;
    use crate::model::Fmu;
    use nalgebra::Quaternion;

    #[test]
    fn nadir_puts_z_on_the_earth_and_x_along_track() {
        let mut c = Fmu::<AttitudeCommand>::default();
        c.v.reference = 1;
        c.initialize(&Experiment::default()).unwrap();
        // equatorial prograde orbit seen at r = R x: nadir -x, velocity +y, orbit normal +z
        (c.v.r, c.v.v) = (Vector3::new(7.0e6, 0.0, 0.0), Vector3::new(0.0, 7.5e3, 0.0));
        c.outputs(0.0).unwrap();
        let a = attitude_matrix(&c.v.q_ref);
        assert!((a * Vector3::new(-1.0, 0.0, 0.0) - Vector3::z()).norm() < 1e-15);
        assert!((a * Vector3::y() - Vector3::x()).norm() < 1e-15);
        assert!((a * Vector3::z() + Vector3::y()).norm() < 1e-15);
        assert!((c.v.w_ref - Vector3::new(0.0, -7.5e3 / 7.0e6, 0.0)).norm() < 1e-18);
        assert!(c.v.q_ref.w >= 0.0);
        // an unwired position is refused with its name
        c.v.r = Vector3::zeros();
        assert!(c.outputs(0.0).unwrap_err().contains("input r"));
    }

    #[test]
    fn sun_pointing_aligns_the_axis_and_turns_the_secondary_to_z() {
        let mut c = Fmu::<AttitudeCommand>::default();
        c.v.reference = 2;
        c.initialize(&Experiment::default()).unwrap();
        let s = Vector3::new(0.9, 0.3, 0.2).normalize();
        c.v.sun_eci = 3.0 * s;
        c.outputs(0.0).unwrap();
        let a = attitude_matrix(&c.v.q_ref);
        // body -z (the default sun_axis) on the sun; body x in the plane of the sun and the inertial z, on z's side
        assert!((a * s - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-14);
        let x_r = a.transpose() * Vector3::x();
        assert!(x_r.dot(&s.cross(&Vector3::z())).abs() < 1e-14 && x_r.z > 0.0, "{x_r}");
        c.v.secondary_axis = Vector3::new(0.0, 0.0, 2.0);
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("not parallel"));
    }

    #[test]
    fn target_pointing_and_the_nadir_acceleration() {
        let mut c = Fmu::<AttitudeCommand>::default();
        c.v.reference = 3;
        c.v.target_eci = Vector3::new(0.0, 0.0, 2.0);
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("target_eci"));
        c.v.target_eci = Vector3::zeros();
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("target_eci"));
        let u = Vector3::new(0.2, -0.9, 0.3).normalize();
        (c.v.target_eci, c.v.sun_axis) = (5.0 * u, Vector3::new(0.0, 1.0, 0.0));
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.0).unwrap();
        let a = attitude_matrix(&c.v.q_ref);
        assert!((a * u - Vector3::y()).norm() < 1e-14);
        let x_r = a.transpose() * Vector3::x();
        assert!(x_r.dot(&u.cross(&Vector3::z())).abs() < 1e-14 && x_r.z > 0.0, "{x_r}");
        assert_eq!((c.v.w_ref, c.v.w_ref_dot), (Vector3::zeros(), Vector3::zeros()));
        // nadir at r = 7000 km x, v = (1, 7.5, 0) km/s, by hand: |h| = 5.25e10 m2/s, r.v = 7e9 m2/s,
        // |r|^4 = 2.401e27 m4: w_ref_dot_y = 2 * 5.25e10 * 7e9 / 2.401e27 = 3.0612244897959e-7 rad/s2
        c.v.reference = 1;
        c.initialize(&Experiment::default()).unwrap();
        (c.v.r, c.v.v) = (Vector3::new(7.0e6, 0.0, 0.0), Vector3::new(1.0e3, 7.5e3, 0.0));
        c.outputs(0.0).unwrap();
        assert!((c.v.w_ref_dot - Vector3::new(0.0, 3.0612244897959183e-7, 0.0)).norm() < 1e-20, "{}", c.v.w_ref_dot);
    }

    #[test]
    fn the_step_command_is_unchanged() {
        let mut c = Fmu::<AttitudeCommand>::default();
        (c.v.ref_euler321_roll, c.v.step_time) = (0.5, 1.0);
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.5).unwrap();
        assert_eq!(c.v.q_ref, Quaternion::identity());
        c.outputs(1.0).unwrap();
        assert_eq!(c.v.q_ref, quat_from_euler321(0.5, 0.0, 0.0));
        assert_eq!(c.next_time_event(0.5), Some(1.0));
    }
}
