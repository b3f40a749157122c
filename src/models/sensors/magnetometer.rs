//! `Magnetometer`: the dipole field of the plant's orbit in body axes with bias and noise, sampled at
//! its own rate, seeded.

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::shared::{sample_index, check_unit, max_queue, DelayLine, OrbitParams, TrueAttitude};
use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::math::environment::CircularOrbit;
use crate::math::random::normal;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct MagnetometerVars {
        truth: TrueAttitude;
        orbit: OrbitParams;
        20 => b_meas: Vec3 = [0.0; 3], Output, "T", "Measured geomagnetic field, body axes, held between samples";
        100 => sample_period: Real = 0.1, Parameter, "s", "Sample period T", Range(1e-6, 1e4);
        103 => noise: Vec3 = [1e-7; 3], Parameter, "T", "1-sigma white noise per axis (default 100 nT)", NonNegative;
        110 => bias: Vec3 = [0.0; 3], Parameter, "T", "Constant bias per axis";
        140 => seed: Integer = 1, Parameter, "", "Seed of the counter-based noise generator";
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
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Magnetometer {
    d: Derived,
    line: DelayLine<[f64; 3]>,
}

impl Magnetometer {
    fn sample(&self, k: i64, q: &Quaternion<f64>) -> [f64; 3] {
        let d = &self.d;
        let b = attitude_matrix(q) * d.orbit.field_ref(k as f64 * d.period) + d.bias
            + Vector3::from_fn(|i, _| d.noise[i] * normal(d.seed, k, i as u64));
        [b.x, b.y, b.z]
    }
}

impl Model for Magnetometer {
    type Vars = MagnetometerVars;
    fn time_grid(v: &MagnetometerVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["line"];
    const INFO: ModelInfo = ModelInfo {
        name: "Magnetometer",
        description: "Three-axis magnetometer: the plant's dipole field in body axes with bias and white noise, sampled at its own rate, seeded",
        source: "magnetometer model of [Markley-Crassidis-2014] Sec. 4.5 (field + bias + white noise); the non-tilted dipole of the plant's orbit environment ([T2FSMC-LEO] set-up, project choice)",
        equations_html: concat!("<pre>samples at t_k = k T, held until the next sample:\n\
b_meas,k = A(q(t_k)) B_R(t_k) + b + sigma (.) n_k,   n_k,i = N(seed, k, i) of math::random\n\
B_R(t)   = (M_E / r^3) [z - 3 (z . r_hat) r_hat],   r_hat(t) = [cos u, sin u cos i, sin u sin i],  u = u_0 + n t\n\
(the plant's field: same orbit parameters and value references 160-164)</pre>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut MagnetometerVars, exp: &Experiment) -> Result<Self, String> {
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let d = Derived { period: v.sample_period, k0, seed: v.seed as i64, orbit: v.orbit.orbit(), noise: v.noise, bias: v.bias };
        Ok(Magnetometer { d, line: DelayLine::new([0.0; 3], k0) })
    }

    fn outputs(&self, v: &mut MagnetometerVars, t: f64) -> ModelResult {
        check_unit("q", &v.truth.q)?;
        let q = v.truth.q;
        let (b, _) = self.line.at(t, self.d.period, 0.0, |k| self.sample(k, &q), |_| true)?;
        v.b_meas = Vector3::from(b);
        Ok(())
    }

    fn step(&mut self, v: &MagnetometerVars, t: f64, h: f64) -> ModelResult {
        check_unit("q", &v.truth.q)?;
        let q = v.truth.q;
        let mut line = self.line.clone();
        line.advance(t, h, self.d.period, 0.0, |k| self.sample(k, &q), |_| true)?;
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
}
