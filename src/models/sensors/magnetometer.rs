//! `Magnetometer`: the geomagnetic field in body axes with bias and noise, sampled at its own rate,
//! seeded: the dipole field of the plant's circular orbit, or (environment_inputs = 1) the true field
//! `b_eci` from `Environment`.

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::shared::{check_unit, field_input, max_queue, sample_index, DelayLine, FieldInput, OrbitParams, TrueAttitude};
use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::math::environment::CircularOrbit;
use crate::math::random::normal;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct MagnetometerVars {
        truth: TrueAttitude;
        orbit: OrbitParams;
        world: FieldInput;
        20 => b_meas: Vec3 = [0.0; 3], Output, "T", "Measured geomagnetic field, body axes, held between samples";
        100 => sample_period: Real = 0.1, Parameter, "s", "Sample period T", Range(1e-6, 1e4);
        103 => noise: Vec3 = [1e-7; 3], Parameter, "T", "1-sigma white noise per axis (default 100 nT)", NonNegative;
        110 => bias: Vec3 = [0.0; 3], Parameter, "T", "Constant bias per axis";
        140 => seed: Integer = 1, Parameter, "", "Seed of the counter-based noise generator";
        191 => environment_inputs: Integer = 0, Parameter, "", "0 = the dipole field of the circular orbit (parameters 160-164); 1 = the input b_eci (Environment's true field; the attitude q is then relative to the inertial axes, as the plant's with its environment_inputs = 1)", Choice(SWITCH);
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    k0: i64,
    seed: i64,
    orbit: CircularOrbit,
    noise: Vector3<f64>,
    bias: Vector3<f64>,
    /// environment_inputs = 1: the field is the input b_eci.
    world: bool,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Magnetometer {
    d: Derived,
    line: DelayLine<[f64; 3]>,
}

impl Magnetometer {
    /// Sample k from the inputs held at t_k: the field in R is `b_eci` (environment_inputs = 1) or the
    /// circular orbit's dipole at t_k.
    fn sample(&self, k: i64, q: &Quaternion<f64>, b_eci: Option<&Vector3<f64>>) -> [f64; 3] {
        let d = &self.d;
        let field = match b_eci {
            Some(b) => *b,
            None => d.orbit.field_ref(k as f64 * d.period),
        };
        let b = attitude_matrix(q) * field + d.bias
            + Vector3::from_fn(|i, _| d.noise[i] * normal(d.seed, k, i as u64));
        [b.x, b.y, b.z]
    }

    /// The inputs a sample reads, checked: q, and b_eci with the environment inputs.
    fn inputs(&self, v: &MagnetometerVars) -> Result<(Quaternion<f64>, Option<Vector3<f64>>), String> {
        check_unit("q", &v.truth.q)?;
        let b = if self.d.world { Some(field_input(&v.world.b_eci)?) } else { None };
        Ok((v.truth.q, b))
    }
}

impl Model for Magnetometer {
    type Vars = MagnetometerVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: at each tick the measured field is computed and held",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["b_meas"],
        },
    ];
    fn time_grid(v: &MagnetometerVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["line"];
    const INFO: ModelInfo = ModelInfo {
        name: "Magnetometer",
        description: "Three-axis magnetometer: the plant's dipole field, or the true field of Environment, in body axes with bias and white noise, sampled at its own rate, seeded",
        source: "magnetometer model of [Markley-Crassidis-2014] Sec. 4.5 (field + bias + white noise); the non-tilted dipole of the plant's orbit environment ([T2FSMC-LEO] set-up, project choice) or the IGRF-14 field of Environment",
        equations_html: concat!("<pre>samples at t_k = k T, held until the next sample:\n\
b_meas,k = A(q(t_k)) B_R(t_k) + b + sigma (.) n_k,   n_k,i = N(seed, k, i) of math::random\n\
environment_inputs = 0:\n\
B_R(t)   = (M_E / r^3) [z - 3 (z . r_hat) r_hat],   r_hat(t) = [cos u, sin u cos i, sin u sin i],  u = u_0 + n t\n\
           (the plant's field: same orbit parameters and value references 160-164)\n\
environment_inputs = 1:\n\
B_R(t_k) = b_eci(t_k), the input held at t_k (Environment's IGRF-14 field, J2000 axes; q relative to them)</pre>\n\
<p>With environment_inputs = 1, wire b_eci from an <code>Environment</code> unit (the names match); an unwired \
(zero) or non-finite b_eci is refused with an error naming it. With 0 (the default) the input is not read.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut MagnetometerVars, exp: &Experiment) -> Result<Self, String> {
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let d = Derived {
            period: v.sample_period,
            k0,
            seed: v.seed as i64,
            orbit: v.orbit.orbit(),
            noise: v.noise,
            bias: v.bias,
            world: v.environment_inputs == 1,
        };
        Ok(Magnetometer { d, line: DelayLine::new([0.0; 3], k0) })
    }

    fn outputs(&self, v: &mut MagnetometerVars, t: f64) -> ModelResult {
        let (q, b_eci) = self.inputs(v)?;
        let (b, _) = self.line.at(t, self.d.period, 0.0, |k| self.sample(k, &q, b_eci.as_ref()), |_| true)?;
        v.b_meas = Vector3::from(b);
        Ok(())
    }

    fn step(&mut self, v: &MagnetometerVars, t: f64, h: f64) -> ModelResult {
        let (q, b_eci) = self.inputs(v)?;
        let mut line = self.line.clone();
        line.advance(t, h, self.d.period, 0.0, |k| self.sample(k, &q, b_eci.as_ref()), |_| true)?;
        self.line = line;
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        self.line.check(max_queue(self.d.period, 0.0), self.d.k0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;
    use crate::model::Fmu;

    #[test]
    fn field_bias_and_noise_statistics() {
        // equator crossing (u = 0): B_R = (M_E / r^3) z; at identity the body field is that plus bias
        let mut m = Fmu::<Magnetometer>::default();
        m.v.noise = nalgebra::Vector3::zeros();
        m.v.bias = Vector3::new(1e-6, -2e-6, 3e-6);
        m.initialize(&Experiment::default()).unwrap();
        m.outputs(0.0).unwrap();
        let b0 = 7.96e15 / 7078137f64.powi(3);
        assert!((m.v.b_meas - Vector3::new(1e-6, -2e-6, b0 + 3e-6)).norm() < 1e-20, "{}", m.v.b_meas);
        // noise per axis: sample standard deviation within 4 standard errors of the declared one
        let mut m = Fmu::<Magnetometer>::default();
        m.v.noise = Vector3::new(1e-7, 2e-7, 5e-8);
        m.initialize(&Experiment::default()).unwrap();
        let q = quat_from_euler321(0.3, 0.2, 0.1);
        m.v.truth.q = q;
        let (n, h) = (20_000, 0.1);
        let mut e = vec![];
        for i in 0..n {
            let t = i as f64 * h;
            m.outputs(t).unwrap();
            e.push(m.v.b_meas - attitude_matrix(&q) * m.model().d.orbit.field_ref(t));
            m.step(t, h).unwrap();
        }
        for i in 0..3 {
            let sd = (e.iter().map(|v| v[i] * v[i]).sum::<f64>() / n as f64).sqrt();
            assert!((sd / m.v.noise[i] - 1.0).abs() < 4.0 / (2.0 * n as f64).sqrt(), "axis {i}: {sd}");
        }
    }

    #[test]
    fn field_from_the_environment_input() {
        // noise-free, environment_inputs = 1: b_meas = A(q) b_eci + bias, A(q) = R1(roll) R2(pitch) R3(yaw) by hand
        let mut m = Fmu::<Magnetometer>::default();
        (m.v.noise, m.v.environment_inputs) = (Vector3::zeros(), 1);
        m.v.bias = Vector3::new(1e-8, 0.0, -2e-8);
        m.initialize(&Experiment::default()).unwrap();
        m.v.truth.q = quat_from_euler321(-0.4, 0.7, 2.1);
        m.v.world.b_eci = Vector3::new(1.2e-5, -3.4e-5, 2.2e-5);
        m.outputs(0.0).unwrap();
        let r1 = |a: f64| nalgebra::Matrix3::new(1.0, 0.0, 0.0, 0.0, a.cos(), a.sin(), 0.0, -a.sin(), a.cos());
        let r2 = |a: f64| nalgebra::Matrix3::new(a.cos(), 0.0, -a.sin(), 0.0, 1.0, 0.0, a.sin(), 0.0, a.cos());
        let r3 = |a: f64| nalgebra::Matrix3::new(a.cos(), a.sin(), 0.0, -a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0);
        let want = r1(-0.4) * r2(0.7) * r3(2.1) * m.v.world.b_eci + m.v.bias;
        assert!((m.v.b_meas - want).norm() < 1e-12 * want.norm(), "{} vs {want}", m.v.b_meas);
        // the sample holds the input of its instant: a new field read at the next sample only
        m.step(0.0, 0.05).unwrap();
        m.v.world.b_eci *= 2.0;
        m.outputs(0.05).unwrap();
        assert!((m.v.b_meas - want).norm() < 1e-12 * want.norm());
        m.step(0.05, 0.05).unwrap();
        m.outputs(0.1).unwrap();
        let want2 = r1(-0.4) * r2(0.7) * r3(2.1) * m.v.world.b_eci + m.v.bias;
        assert!((m.v.b_meas - want2).norm() < 1e-12 * want2.norm(), "{} vs {want2}", m.v.b_meas);
        // unwired (zero) field: refused by name
        m.v.world.b_eci = Vector3::zeros();
        assert!(m.outputs(0.1).unwrap_err().contains("input b_eci"));
        assert!(m.step(0.1, 0.1).unwrap_err().contains("input b_eci"));
    }
}
