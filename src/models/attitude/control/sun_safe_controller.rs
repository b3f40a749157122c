//! `SunSafeController`: the safe-mode sun-acquisition law on a sun sensor and a gyro: the quaternion
//! feedback regulator of [Wie-Weiss-Arapostathis-1989] applied to the shortest rotation that takes the
//! measured sun direction onto a body axis, with rate damping only while the sun is not seen.
//!
//! Unlike the other controllers it reads sensors, not an attitude estimate and a command, so it does not
//! embed `AttitudeControllerPorts`: its inputs carry the Gyro's and the SunSensor's output names (they
//! connect by name) on value references 60–66 (the family's table in `src/models/mod.rs`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct SunSafeControllerVars {
        20 => torque_cmd: Vec3 = [0.0; 3], Output, "N.m", "Commanded control torque, body axes";
        30 => sun_angle: Real = 0.0, Output, "rad", "Angle theta between sun_axis and the measured sun direction (the held sun_meas while sun_valid < 0.5; 0 if it has no direction)";
        31 => sun_seen: Real = 0.0, Output, "", "1 = the pointing law acts (sun_valid >= 0.5); 0 = rate damping only";
        60 => w_meas: Vec3 = [0.0; 3], Input, "rad/s", "Measured body rate (the Gyro's output)";
        63 => sun_meas: Vec3 = [0.0, 0.0, 1.0], Input, "", "Measured sun direction, body axes (the SunSensor's output; normalised here)";
        66 => sun_valid: Real = 0.0, Input, "", "Sun measurement valid: >= 0.5 = sun in view (the SunSensor's output)";
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia J", Positive;
        103 => wn: Real = 0.1, Parameter, "rad/s", "Natural frequency omega_n of the per-axis closed loop (small angles)", Positive;
        104 => zeta: Real = 0.9, Parameter, "", "Damping ratio xi of the per-axis closed loop", NonNegative;
        105 => sun_axis: Vec3 = [0.0, 0.0, 1.0], Parameter, "", "Body axis a turned onto the sun (e.g. the solar array normal; normalised; default the default SunSensor's boresight)";
        108 => spin_rate: Real = 0.0, Parameter, "rad/s", "Spin rate about sun_axis held by the law (0 = no spin; a slow spin about the sun line is a common safe-mode choice)";
        109 => torque_max: Real = 1e30, Parameter, "N.m", "Torque limit: the largest component of the torque is scaled down to it, keeping the direction (1e30 = no limit)", Limit;
        200 => k_p: Vec3 = [0.0; 3], CalculatedParameter, "N.m", "Gain on the error quaternion's vector part, K = 2 wn^2 J";
        203 => k_d: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "Rate gain, C = 2 zeta wn J";
    }
}

/// A static law: the unit pointing axis is all it derives (the gains are calculated parameters).
#[derive(Clone, Serialize, Deserialize)]
pub struct SunSafeController {
    axis: [f64; 3],
}

/// Below this |a × s| with a·s < 0 the sun is taken as opposite to the axis (the shortest rotation's axis is
/// then undefined and a fixed perpendicular is used).
const PARALLEL: f64 = 1e-9;

/// Vector part of the error quaternion of the current attitude relative to the nearest sun-pointing one:
/// the rotation by theta about e = unit(a × s) takes a onto s, so q_e,v = -sin(theta/2) e. Nearly parallel
/// directions (|a × s| < 1e-9): (s × a) / sqrt(2 (1 + a.s)) (the same, smooth through theta = 0) when a.s > 0;
/// opposite ones: e = unit(a × x) or unit(a × y), whichever cross product is longer.
pub fn error_vector(a: &Vector3<f64>, s: &Vector3<f64>) -> Vector3<f64> {
    let (c, cross) = (a.dot(s), a.cross(s));
    let n = cross.norm();
    if n >= PARALLEL {
        return -cross * ((0.5 * n.atan2(c)).sin() / n);
    }
    if c > 0.0 {
        return -cross / (2.0 * (1.0 + c)).sqrt();
    }
    let (ex, ey) = (a.cross(&Vector3::x()), a.cross(&Vector3::y()));
    let e = if ex.norm() >= ey.norm() { ex } else { ey };
    -e.normalize() * (0.5 * n.atan2(c)).sin()
}

impl Model for SunSafeController {
    type Vars = SunSafeControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "SunSafeController",
        description: "Safe-mode sun acquisition on a sun sensor and a gyro: quaternion feedback on the shortest rotation to the sun, rate damping while the sun is not seen",
        source: "quaternion feedback regulator of [Wie-Weiss-Arapostathis-1989] on the shortest rotation from the measured sun to a body axis (the classical safe mode, [Markley-Crassidis-2014] Ch. 7); gains as PdController's; spin about the sun line and torque limit project choice",
        equations_html: "<pre>a = sun_axis/|sun_axis|,  s = sun_meas/|sun_meas|,  theta = atan2(|a x s|, a.s)   (sun_angle)\n\
e     = (a x s)/|a x s|   (opposite directions, |a x s| &lt; 1e-9 and a.s &lt; 0: unit(a x x) or unit(a x y), the longer)\n\
q_e,v = -sin(theta/2) e       (vector part of the error quaternion of the attitude relative to the nearest sun-pointing one)\n\
K = 2 wn^2 J,   C = 2 zeta wn J                           (J = diag(inertia_xx, inertia_yy, inertia_zz))\n\
w_e   = w_meas - spin_rate a\n\
sun_valid &gt;= 0.5:  torque_cmd = -K q_e,v - C w_e     (sun_seen = 1)\n\
sun_valid &lt;  0.5:  torque_cmd = -C w_e               (rate damping only; sun_seen = 0)\n\
torque_cmd scaled by torque_max / max_i |torque_cmd_i| when that is below 1 (direction kept)</pre>\n\
<p>The regulator u = -K q_e - C w of [Wie-Weiss-Arapostathis-1989], with the attitude error replaced by the \
shortest rotation that takes the measured sun direction onto the body axis a: the rotation about the sun line is \
left free, so the law needs only a sun sensor and a gyro (the classical safe mode). With the gains of \
PdController (K on q_e,v = 2 wn^2 J, since q_e,v is half the angle for small angles) each axis closes to \
s^2 + 2 zeta wn s + wn^2 for small errors; the gyroscopic term w x J w is left out, as in PdController. \
The sign: a body rate w along e = unit(a x s) moves the sun, seen in body axes, at ds/dt = s x w, \
which points from s toward a, and -K q_e,v is a torque along +e (checked in closed loop by the tests). While the sun is not valid (eclipse, not yet in the field of view) the law \
damps the rate toward the spin spin_rate about a. The unit has no state: a hand-over to or from it resets \
nothing.</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SunSafeControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let n = v.sun_axis.norm();
        if !(n > 1e-12) {
            let a = v.sun_axis;
            return Err(format!("sun_axis = [{}, {}, {}] has no direction (zero)", a.x, a.y, a.z));
        }
        v.k_p = v.inertia * (2.0 * v.wn * v.wn);
        v.k_d = v.inertia * (2.0 * v.zeta * v.wn);
        let a = v.sun_axis / n;
        Ok(SunSafeController { axis: [a.x, a.y, a.z] })
    }

    fn outputs(&self, v: &mut SunSafeControllerVars, _t: f64) -> ModelResult {
        let a = Vector3::from(self.axis);
        let seen = v.sun_valid >= 0.5;
        let n = v.sun_meas.norm();
        let s = if n > 1e-12 {
            Some(v.sun_meas / n)
        } else if seen {
            let m = v.sun_meas;
            return Err(format!(
                "input sun_meas = [{}, {}, {}] has no direction while sun_valid = {} (is it connected?)",
                m.x, m.y, m.z, v.sun_valid
            ));
        } else {
            None
        };
        v.sun_angle = s.map_or(0.0, |s| a.cross(&s).norm().atan2(a.dot(&s)));
        v.sun_seen = if seen { 1.0 } else { 0.0 };
        let w_e = v.w_meas - a * v.spin_rate;
        let mut torque = -v.k_d.component_mul(&w_e);
        if let (true, Some(s)) = (seen, s) {
            torque -= v.k_p.component_mul(&error_vector(&a, &s));
        }
        let peak = torque.amax();
        if peak > v.torque_max {
            torque *= v.torque_max / peak;
        }
        v.torque_cmd = torque;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn unit_at(theta: f64) -> Vector3<f64> {
        // a = z; s in the x-z plane at angle theta from z
        Vector3::new(theta.sin(), 0.0, theta.cos())
    }

    #[test]
    fn error_vector_is_half_angle_sine_about_the_shortest_axis() {
        let a = Vector3::z();
        for deg in [0.0_f64, 1e-7, 10.0, 90.0, 120.0, 179.0] {
            let th = deg.to_radians();
            let q = error_vector(&a, &unit_at(th));
            // a x s = z x (sin, 0, cos) = (0, sin, 0): e = +y, q_e,v = -sin(theta/2) y
            let expected = Vector3::new(0.0, -(th / 2.0).sin(), 0.0);
            assert!((q - expected).norm() < 1e-15, "{deg}: {q} vs {expected}");
        }
        // opposite: z x x = y is longer than z x y = -x (equal length: x wins), q_e,v = -y
        let q = error_vector(&a, &-a);
        assert!((q - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-15, "{q}");
        let a = Vector3::x();
        let q = error_vector(&a, &-a);
        // x x x = 0, x x y = z: e = z
        assert!((q - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-15, "{q}");
    }

    #[test]
    fn torque_gains_eclipse_limit_and_refusals() {
        let mut c = Fmu::<SunSafeController>::default();
        (c.v.wn, c.v.zeta) = (0.2, 0.5);
        c.initialize(&Experiment::default()).unwrap();
        assert!((c.v.k_p - Vector3::new(80.0, 40.0, 56.0)).norm() < 1e-12, "{}", c.v.k_p);
        assert!((c.v.k_d - Vector3::new(200.0, 100.0, 140.0)).norm() < 1e-12, "{}", c.v.k_d);
        // 90 degrees: q_e,v = -sin(45 deg) y; torque = K_y sin(45 deg) y - C w
        (c.v.sun_meas, c.v.sun_valid, c.v.w_meas) = (Vector3::new(2.0, 0.0, 0.0), 1.0, Vector3::new(0.01, 0.0, 0.0));
        c.outputs(0.0).unwrap();
        let t = Vector3::new(-2.0, 40.0 * std::f64::consts::FRAC_1_SQRT_2, 0.0);
        assert!((c.v.torque_cmd - t).norm() < 1e-12, "{}", c.v.torque_cmd);
        assert!((c.v.sun_angle - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && c.v.sun_seen == 1.0);
        // eclipse: damping only, toward the spin about a
        (c.v.sun_valid, c.v.w_meas) = (0.0, Vector3::new(0.0, 0.0, 0.03));
        c.v.spin_rate = 0.01;
        c.outputs(0.0).unwrap();
        assert!((c.v.torque_cmd - Vector3::new(0.0, 0.0, -140.0 * 0.02)).norm() < 1e-12);
        assert_eq!(c.v.sun_seen, 0.0);
        // the limit scales the whole vector
        c.v.torque_max = 1.0;
        (c.v.sun_valid, c.v.spin_rate, c.v.w_meas) = (1.0, 0.0, Vector3::new(0.01, 0.0, 0.0));
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.0).unwrap();
        assert!((c.v.torque_cmd - t / t.amax()).norm() < 1e-15);
        // refusals name the parameter or the input
        c.v.sun_meas = Vector3::zeros();
        assert!(c.outputs(0.0).unwrap_err().contains("sun_meas"));
        c.v.sun_valid = 0.0;
        c.outputs(0.0).unwrap();
        assert_eq!(c.v.sun_angle, 0.0);
        c.v.sun_axis = Vector3::zeros();
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("sun_axis"));
    }
}
