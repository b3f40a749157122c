//! `SunSensor`: body-frame sun direction with noise and a fixed bias rotation, a field of view and the
//! Earth's shadow, sampled at its own rate, seeded: the uniformly moving sun and the cylindrical shadow of
//! the plant's circular orbit, or (environment_inputs = 1) the true sun `sun_eci` and the visible
//! fraction `eclipse` of the solar disk from `Environment`.
//!
//! The shadow switch is the parameter `shadow` (value reference 141, as before); it was named `eclipse`
//! until the input `eclipse` (Environment's output of that name, so that the two connect by name) took
//! the name: one unit cannot hold two variables of one name.

use nalgebra::{Matrix3, Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::shared::{check_unit, eclipse_input, rotation, sample_index, sun_input, DelayLine, OrbitParams, SunInputs, SunParams, TrueAttitude};
use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::math::environment::{in_eclipse, sun_ref, CircularOrbit};
use crate::math::random::normal;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct SunSensorVars {
        truth: TrueAttitude;
        orbit: OrbitParams;
        sun: SunParams;
        world: SunInputs;
        20 => sun_meas: Vec3 = [0.0, 0.0, 1.0], Output, "", "Measured unit sun direction, body axes (the last valid one while valid = 0)";
        23 => valid: Real = 0.0, Output, "", "1 = sun in the field of view and not in the Earth's shadow; 0 = sun_meas held";
        24 => sun_valid: Real = 0.0, Output, "", "The same flag as valid, under the name of the Mekf's input (so that the two connect by name beside a StarTracker, whose valid is another flag)";
        100 => sample_period: Real = 0.1, Parameter, "s", "Sample period T", Range(1e-6, 1e4);
        103 => noise: Real = 1.745e-3, Parameter, "rad", "1-sigma angular noise about each axis perpendicular to the sun line (default 0.1 deg)", NonNegative;
        110 => bias: Vec3 = [0.0; 3], Parameter, "rad", "Bias: fixed rotation vector applied to the measured direction, body axes", Range(-0.5, 0.5);
        106 => mount: Vec3 = [0.0; 3], Parameter, "rad", "Mounting: rotation vector of the sensor axes relative to the body axes (boresight = sensor z)", Range(-4.0, 4.0);
        113 => fov: Real = 1.0471975511965976, Parameter, "rad", "Field-of-view half-angle about the boresight (pi = whole sky; default 60 deg)", Range(0.0, std::f64::consts::PI);
        114 => sun_fraction_min: Real = 0.5, Parameter, "", "environment_inputs = 1 and shadow = 1: least visible fraction of the solar disk (input eclipse) with a measurement; at 0.5 the sun's centre is on the Earth's limb, the boundary of the cylindrical shadow (project choice)", Range(0.0, 1.0);
        140 => seed: Integer = 1, Parameter, "", "Seed of the counter-based noise generator";
        141 => shadow: Integer = 1, Parameter, "", "1 = no measurement in the Earth's shadow (the cylindrical shadow of the circular orbit, or with environment_inputs = 1 the input eclipse below sun_fraction_min), 0 = shadow ignored (named eclipse before the input eclipse existed)", Choice(SWITCH);
        191 => environment_inputs: Integer = 0, Parameter, "", "0 = the sun on its circular apparent orbit (sun_ecliptic_longitude) and the cylindrical shadow of the circular orbit; 1 = the inputs sun_eci and eclipse (Environment's true sun and shadow; the attitude q is then relative to the inertial axes, as the plant's with its environment_inputs = 1)", Choice(SWITCH);
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunSample {
    s: [f64; 3],
    valid: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    k0: i64,
    seed: i64,
    orbit: CircularOrbit,
    sun_lambda0: f64,
    boresight: Vector3<f64>,
    cos_fov: f64,
    bias: Vector3<f64>,
    noise: f64,
    shadow: bool,
    fraction_min: f64,
    /// environment_inputs = 1: sun and shadow are the inputs sun_eci and eclipse.
    world: bool,
}

/// The environment inputs a sample reads (environment_inputs = 1): the unit sun direction in R and the
/// visible fraction of the solar disk.
#[derive(Clone, Copy)]
struct SunWorld {
    sun: Vector3<f64>,
    eclipse: f64,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct SunSensor {
    d: Derived,
    line: DelayLine<SunSample>,
}

impl SunSensor {
    /// Sample k: s_B = A(q) ŝ(t_k), measured R(bias + σ n_k) s_B; valid if in the field of view and lit.
    /// ŝ and the shadow are the circular orbit's at t_k, or the inputs held at t_k (`world`).
    fn sample(&self, k: i64, q: &Quaternion<f64>, world: Option<SunWorld>) -> SunSample {
        let d = &self.d;
        let t = k as f64 * d.period;
        let s_ref = match world {
            Some(w) => w.sun,
            None => sun_ref(d.sun_lambda0, t),
        };
        let s_b = attitude_matrix(q) * s_ref;
        let n = Vector3::from_fn(|i, _| d.noise * normal(d.seed, k, i as u64));
        let m: Matrix3<f64> = rotation(&(d.bias + n));
        let meas = (m * s_b).normalize();
        let lit = !d.shadow
            || match world {
                Some(w) => w.eclipse > 0.0 && w.eclipse >= d.fraction_min,
                None => !in_eclipse(&d.orbit.r_hat(t), d.orbit.radius, &s_ref),
            };
        SunSample { s: [meas.x, meas.y, meas.z], valid: lit && s_b.dot(&d.boresight) >= d.cos_fov }
    }

    /// The inputs a sample reads, checked: q, and with the environment inputs sun_eci (normalised) and eclipse.
    fn inputs(&self, v: &SunSensorVars) -> Result<(Quaternion<f64>, Option<SunWorld>), String> {
        check_unit("q", &v.truth.q)?;
        if !self.d.world {
            return Ok((v.truth.q, None));
        }
        let w = SunWorld { sun: sun_input(&v.world.sun_eci)?, eclipse: eclipse_input(v.world.eclipse)? };
        Ok((v.truth.q, Some(w)))
    }
}

impl Model for SunSensor {
    type Vars = SunSensorVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: at each tick the sun direction and its flags are computed and held",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["sun_meas", "valid", "sun_valid"],
        },
    ];
    fn time_grid(v: &SunSensorVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["line"];
    const INFO: ModelInfo = ModelInfo {
        name: "SunSensor",
        description: "Sun sensor: body-frame sun direction with angular noise and bias, field of view and Earth shadow (the circular orbit's, or the true sun and shadow of Environment), sampled at its own rate, seeded",
        source: "sun-sensor measurement model of [Markley-Crassidis-2014] Sec. 4.4 (unit-vector measurement with small-angle noise); sun on the ecliptic and cylindrical shadow, the threshold on the visible fraction: project choice",
        equations_html: concat!("<pre>samples at t_k = k T, held until the next sample:\n\
s_R(t)   = [cos l, sin l cos eps, sin l sin eps],  l = l_0 + n_sun t,  eps = 23.439 deg,  n_sun = 2 pi / 365.256 d\n\
s_B      = A(q(t_k)) s_R(t_k)\n\
s_meas,k = R(b + sigma n_k) s_B,   n_k,i = N(seed, k, i) of math::random, R(.) the rotation of a rotation vector\n\
valid_k  = s_B . boresight_B >= cos(fov)  and not in shadow (shadow = 1): r_hat . s_R < 0 and r |r_hat x s_R| < R_E\n\
           r_hat(t) = the plant's circular orbit (same parameters, value references 160-164)\n\
environment_inputs = 1: s_R = sun_eci / |sun_eci| held at t_k, and in shadow (shadow = 1) when\n\
           eclipse(t_k) = 0 or eclipse(t_k) &lt; sun_fraction_min\n\
while not valid: the last valid sample, valid = 0 (before any: (0, 0, 1))</pre>\n\
<p>The angular error about each axis perpendicular to the sun line has standard deviation sigma (the component \
of the noise along the sun line does not move the direction), so the angle between measured and true direction \
is Rayleigh-distributed with mean square 2 sigma^2.</p>\n\
<p>With environment_inputs = 1, wire sun_eci and eclipse from an <code>Environment</code> unit (the names match); \
an unwired (zero) or non-finite sun_eci and an eclipse outside [0, 1] are refused with an error naming the input. \
The direction is Earth to sun: the parallax of the spacecraft's position, |r| / 1 au (0.003 deg in low orbit), \
is neglected. In the penumbra the measured direction stays the sun's centre (the centroid of the visible crescent \
moves by up to the solar radius, 0.27 deg, not modelled); sun_fraction_min = 0.5 (the default) ends the \
measurements where the sun's centre meets the Earth's limb, which is the boundary of the cylindrical shadow \
of environment_inputs = 0, so the two modes lose the sun at the same place up to the cone of the penumbra. \
With 0 (the default) the inputs are not read and the sensor is the circular-orbit sensor above, bit for bit. \
The shadow switch shadow (value reference 141) was named eclipse before the input eclipse existed.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SunSensorVars, exp: &Experiment) -> Result<Self, String> {
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let d = Derived {
            period: v.sample_period,
            k0,
            seed: v.seed as i64,
            orbit: v.orbit.orbit(),
            sun_lambda0: v.sun.sun_ecliptic_longitude,
            boresight: rotation(&v.mount).column(2).into_owned(),
            cos_fov: v.fov.cos(),
            bias: v.bias,
            noise: v.noise,
            shadow: v.shadow == 1,
            fraction_min: v.sun_fraction_min,
            world: v.environment_inputs == 1,
        };
        Ok(SunSensor { d, line: DelayLine::new(SunSample { s: [0.0, 0.0, 1.0], valid: false }, k0) })
    }

    fn outputs(&self, v: &mut SunSensorVars, t: f64) -> ModelResult {
        let (q, world) = self.inputs(v)?;
        let (s, ok) = self.line.at(t, self.d.period, 0.0, |k| self.sample(k, &q, world), |s| s.valid)?;
        v.sun_meas = Vector3::from(s.s);
        v.valid = if ok { 1.0 } else { 0.0 };
        v.sun_valid = v.valid;
        Ok(())
    }

    fn step(&mut self, v: &SunSensorVars, t: f64, h: f64) -> ModelResult {
        let (q, world) = self.inputs(v)?;
        let mut line = self.line.clone();
        line.advance(t, h, self.d.period, 0.0, |k| self.sample(k, &q, world), |s| s.valid)?;
        self.line = line;
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        self.line.check(super::shared::max_queue(self.d.period, 0.0), self.d.k0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;
    use crate::model::Fmu;

    #[test]
    fn direction_noise_bias_and_shadow() {
        // noise-free with a bias of 0.01 rad about body x: the measured direction is R(b) A(q) s_R
        let mut s = Fmu::<SunSensor>::default();
        (s.v.noise, s.v.fov, s.v.shadow) = (0.0, std::f64::consts::PI, 0);
        s.v.bias = Vector3::new(0.01, 0.0, 0.0);
        s.initialize(&Experiment::default()).unwrap();
        let q = quat_from_euler321(0.2, 0.5, -1.0);
        s.v.truth.q = q;
        s.outputs(0.0).unwrap();
        // independent: rotate s_R = x (λ0 = 0) by hand: A(q) = R1(0.2) R2(0.5) R3(-1.0) for the 321 sequence
        let r1 = |a: f64| Matrix3::new(1.0, 0.0, 0.0, 0.0, a.cos(), a.sin(), 0.0, -a.sin(), a.cos());
        let r2 = |a: f64| Matrix3::new(a.cos(), 0.0, -a.sin(), 0.0, 1.0, 0.0, a.sin(), 0.0, a.cos());
        let r3 = |a: f64| Matrix3::new(a.cos(), a.sin(), 0.0, -a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0);
        let sb = r1(0.2) * r2(0.5) * r3(-1.0) * Vector3::x();
        // active rotation by +0.01 about x: (x, y c - z s, y s + z c)
        let (sn, c) = 0.01f64.sin_cos();
        let want = Vector3::new(sb.x, sb.y * c - sb.z * sn, sb.y * sn + sb.z * c);
        assert!((s.v.sun_meas - want).norm() < 1e-14, "{} vs {want}", s.v.sun_meas);
        assert_eq!((s.v.valid, s.v.sun_valid), (1.0, 1.0));

        // noise: mean square angle 2 σ² (Rayleigh), over 20 000 samples
        let mut s = Fmu::<SunSensor>::default();
        (s.v.noise, s.v.fov, s.v.shadow) = (1e-3, std::f64::consts::PI, 0);
        s.initialize(&Experiment::default()).unwrap();
        s.v.truth.q = q;
        let (n, h) = (20_000, s.v.sample_period);
        let mut ms = 0.0;
        for i in 0..n {
            let t = i as f64 * h;
            s.outputs(t).unwrap();
            let truth = attitude_matrix(&q) * sun_ref(0.0, t);
            ms += s.v.sun_meas.angle(&truth).powi(2);
            s.step(t, h).unwrap();
        }
        let ms = ms / n as f64;
        // the squared angle is exponential with mean 2σ²: relative standard error 1/sqrt(n)
        assert!((ms / 2e-6 - 1.0).abs() < 4.0 / (n as f64).sqrt(), "{ms}");

        // shadow: argument of latitude 180° with the sun at λ0 = 0 and the equatorial... orbit inclination 0
        let mut s = Fmu::<SunSensor>::default();
        s.v.orbit.orbit_inclination = 0.0;
        s.v.orbit.orbit_arg_lat0 = std::f64::consts::PI;
        s.v.fov = std::f64::consts::PI;
        s.initialize(&Experiment::default()).unwrap();
        s.outputs(0.0).unwrap();
        assert_eq!((s.v.valid, s.v.sun_valid, s.v.sun_meas), (0.0, 0.0, Vector3::new(0.0, 0.0, 1.0)));
        // field of view: the boresight body z at identity is 90° from the sun: outside a 60° cone
        s.v.orbit.orbit_arg_lat0 = 0.0;
        s.v.fov = 1.0;
        s.initialize(&Experiment::default()).unwrap();
        s.outputs(0.0).unwrap();
        assert_eq!(s.v.valid, 0.0);
    }

    fn world(shadow: i32, fraction_min: f64, sun: Vector3<f64>, eclipse: f64) -> Fmu<SunSensor> {
        let mut s = Fmu::<SunSensor>::default();
        (s.v.noise, s.v.fov, s.v.environment_inputs) = (0.0, std::f64::consts::PI, 1);
        (s.v.shadow, s.v.sun_fraction_min) = (shadow, fraction_min);
        s.initialize(&Experiment::default()).unwrap();
        (s.v.world.sun_eci, s.v.world.eclipse) = (sun, eclipse);
        s
    }

    #[test]
    fn sun_and_shadow_from_the_environment_inputs() {
        // a sun vector of norm 5 (normalised), attitude 90 deg about z: A = R3(90 deg), body = (s_y, -s_x, s_z)
        let mut s = world(1, 0.5, Vector3::new(3.0, 4.0, 0.0), 1.0);
        s.v.truth.q = quat_from_euler321(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        s.outputs(0.0).unwrap();
        assert!((s.v.sun_meas - Vector3::new(0.8, -0.6, 0.0)).norm() < 1e-15, "{}", s.v.sun_meas);
        assert_eq!(s.v.valid, 1.0);
        // validity against the visible fraction and the threshold (shadow = 1), or none (shadow = 0)
        for (shadow, min, ecl, valid) in [
            (1, 0.5, 0.6, 1.0),
            (1, 0.5, 0.5, 1.0),
            (1, 0.5, 0.4, 0.0),
            (1, 0.0, 0.01, 1.0),
            (1, 0.0, 0.0, 0.0),
            (1, 1.0, 0.999, 0.0),
            (0, 0.5, 0.0, 1.0),
        ] {
            let mut s = world(shadow, min, Vector3::x(), ecl);
            s.outputs(0.0).unwrap();
            assert_eq!((s.v.valid, s.v.sun_valid), (valid, valid), "shadow {shadow}, min {min}, eclipse {ecl}");
        }
        // refused by name: an unwired (zero) or non-finite sun, an eclipse outside [0, 1]
        let mut s = world(1, 0.5, Vector3::zeros(), 1.0);
        assert!(s.outputs(0.0).unwrap_err().contains("input sun_eci"));
        let mut s = world(1, 0.5, Vector3::new(f64::NAN, 0.0, 1.0), 1.0);
        assert!(s.step(0.0, 0.1).unwrap_err().contains("input sun_eci"));
        let mut s = world(1, 0.5, Vector3::x(), 1.2);
        assert!(s.outputs(0.0).unwrap_err().contains("input eclipse"));
    }
}
