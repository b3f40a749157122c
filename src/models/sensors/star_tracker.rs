//! `StarTracker`: attitude quaternion with noise about the cross-boresight and boresight axes, an
//! update rate, a latency and an availability flag (sun in the exclusion cone).

use nalgebra::{Matrix3, Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::shared::{sample_index, check_unit, max_queue, quat_of_rotation, rotation, DelayLine, SunParams, TrueAttitude};
use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::math::environment::sun_ref;
use crate::math::random::normal;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct StarTrackerVars {
        truth: TrueAttitude;
        sun: SunParams;
        20 => q_meas: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Measured attitude quaternion of B relative to R (the last valid one while valid = 0)";
        24 => valid: Real = 0.0, Output, "", "1 = q_meas is the measurement delivered now, 0 = none delivered yet or sun in the exclusion cone (q_meas held)";
        25 => st_valid: Real = 0.0, Output, "", "The same flag as valid, under the name of the Mekf's input (so that the two connect by name beside a SunSensor, whose valid is another flag)";
        30 => sun_angle: Real = 0.0, Output, "rad", "Diagnostic: angle between the boresight and the sun at the current true attitude";
        100 => sample_period: Real = 0.2, Parameter, "s", "Update period T of the star tracker", Range(1e-6, 1e4);
        103 => noise_cross: Real = 2.5e-5, Parameter, "rad", "1-sigma error about each cross-boresight axis (sensor x, y; default 5 arcsec)", NonNegative;
        104 => noise_about: Real = 2.0e-4, Parameter, "rad", "1-sigma error about the boresight (sensor z; default 41 arcsec)", NonNegative;
        105 => latency: Real = 0.1, Parameter, "s", "Latency d: the sample of t_k is delivered at t_k + d", Range(0.0, 1e4);
        106 => mount: Vec3 = [0.0; 3], Parameter, "rad", "Mounting: rotation vector of the sensor axes relative to the body axes (boresight = sensor z)", Range(-4.0, 4.0);
        109 => sun_exclusion: Real = 0.5235987755982988, Parameter, "rad", "Sun exclusion half-angle about the boresight (0 = none; default 30 deg)", Range(0.0, std::f64::consts::PI);
        140 => seed: Integer = 1, Parameter, "", "Seed of the counter-based noise generator";
    }
}

/// One star-tracker sample: the measured quaternion and whether it is usable.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StSample {
    q: [f64; 4],
    valid: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    latency: f64,
    k0: i64,
    seed: i64,
    /// R(mount): sensor axes in body components (columns).
    mount: Matrix3<f64>,
    sigma: Vector3<f64>,
    cos_exclusion: f64,
    sun_lambda0: f64,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct StarTracker {
    d: Derived,
    line: DelayLine<StSample>,
}

impl StarTracker {
    fn boresight_sun_cos(&self, q: &Quaternion<f64>, t: f64) -> f64 {
        let b_body = self.d.mount.column(2).into_owned();
        (attitude_matrix(q) * sun_ref(self.d.sun_lambda0, t)).dot(&b_body)
    }

    /// Sample k of the true attitude q: q_meas = q ⊗ exp(δθ_B / 2), δθ_B = R(mount) (σ_c n0, σ_c n1, σ_a n2).
    fn sample(&self, k: i64, q: &Quaternion<f64>) -> StSample {
        let d = &self.d;
        let n = Vector3::from_fn(|i, _| d.sigma[i] * normal(d.seed, k, i as u64));
        let qm = q * quat_of_rotation(&(d.mount * n));
        let valid = d.cos_exclusion >= 1.0 || self.boresight_sun_cos(q, k as f64 * d.period) < d.cos_exclusion;
        StSample { q: [qm.w, qm.i, qm.j, qm.k], valid }
    }
}

impl Model for StarTracker {
    type Vars = StarTrackerVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: the true attitude is measured at each tick",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &[],
        },
        ClockDecl {
            name: "delivery_clock",
            description: "Delivery clock: at each tick (sample instant + latency) the delivered quaternion and its flags are output and held",
            interval: "sample_period",
            shift: "latency",
            steps: false,
            outputs: &["q_meas", "valid", "st_valid"],
        },
    ];
    fn time_grid(v: &StarTrackerVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["line"];
    const INFO: ModelInfo = ModelInfo {
        name: "StarTracker",
        description: "Star tracker: attitude quaternion with cross- and about-boresight noise, update rate, latency and sun-exclusion availability flag, seeded",
        source: "measurement model of [Markley-Crassidis-2014] Sec. 5.4 (error rotation with a larger about-boresight error); sun exclusion cone and the sun on the ecliptic: project choice",
        equations_html: concat!("<pre>samples at t_k = k T, delivered at t_k + d (latency), held until the next delivery:\n\
dtheta_S = (sigma_c n_k,0, sigma_c n_k,1, sigma_a n_k,2)          sensor axes (z = boresight)\n\
q_meas,k = q(t_k) (x) exp(R(mount) dtheta_S / 2)                 error rotation in body axes\n\
valid_k  = angle(boresight, sun) >= sun_exclusion,  boresight_B = R(mount) e_z,\n\
           sun_B = A(q(t_k)) s_R(t_k),  s_R = [cos l, sin l cos eps, sin l sin eps],  l = l_0 + n_sun t\n\
output at t: sample k_d = floor((t - d)/T); if k_d < 0 or sample k_d is not valid: the last valid delivered\n\
             sample (the identity before any) with valid = 0\n\
n_k,i: standard normal numbers N(seed, k, i) of math::random</pre>\n\
<p>The error statistics per sensor axis are those declared (sigma_c, sigma_c, sigma_a); the error is the \
rotation from the true to the measured body frame. A sample strictly inside a communication step sees the \
attitude held at the step's start.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut StarTrackerVars, exp: &Experiment) -> Result<Self, String> {
        if v.latency / v.sample_period > 1e6 {
            return Err(format!("parameters latency = {} and sample_period = {}: the latency is more than 1e6 sample periods", v.latency, v.sample_period));
        }
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let d = Derived {
            period: v.sample_period,
            latency: v.latency,
            k0,
            seed: v.seed as i64,
            mount: rotation(&v.mount),
            sigma: Vector3::new(v.noise_cross, v.noise_cross, v.noise_about),
            cos_exclusion: if v.sun_exclusion > 0.0 { v.sun_exclusion.cos() } else { 2.0 },
            sun_lambda0: v.sun.sun_ecliptic_longitude,
        };
        Ok(StarTracker { d, line: DelayLine::new(StSample { q: [1.0, 0.0, 0.0, 0.0], valid: false }, k0) })
    }

    fn outputs(&self, v: &mut StarTrackerVars, t: f64) -> ModelResult {
        check_unit("q", &v.truth.q)?;
        let q = v.truth.q;
        let (s, ok) = self.line.at(t, self.d.period, self.d.latency, |k| self.sample(k, &q), |s| s.valid)?;
        v.q_meas = Quaternion::new(s.q[0], s.q[1], s.q[2], s.q[3]);
        v.valid = if ok { 1.0 } else { 0.0 };
        v.st_valid = v.valid;
        v.sun_angle = self.boresight_sun_cos(&q, t).clamp(-1.0, 1.0).acos();
        Ok(())
    }

    fn step(&mut self, v: &StarTrackerVars, t: f64, h: f64) -> ModelResult {
        check_unit("q", &v.truth.q)?;
        let q = v.truth.q;
        let mut line = self.line.clone();
        line.advance(t, h, self.d.period, self.d.latency, |k| self.sample(k, &q), |s| s.valid)?;
        self.line = line;
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        self.line.check(max_queue(self.d.period, self.d.latency), self.d.k0)?;
        let unit = |q: &[f64; 4]| (q.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs() < 1e-6;
        if !unit(&self.line.held.q) || !self.line.queue.iter().all(|(_, s)| unit(&s.q)) {
            return Err("restored state: a latched star-tracker quaternion is not of unit norm".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;
    use crate::model::Fmu;

    /// Error rotation vectors in sensor axes of n samples at a slowly rotating attitude.
    fn errors(st: &mut Fmu<StarTracker>, n: usize) -> Vec<Vector3<f64>> {
        st.initialize(&Experiment::default()).unwrap();
        let t_s = st.v.sample_period;
        let r = rotation(&st.v.mount);
        let mut out = vec![];
        for i in 0..n {
            let t = i as f64 * t_s;
            let q = quat_from_euler321(0.3 + 1e-4 * i as f64, -0.2, 0.1);
            st.v.truth.q = q;
            st.outputs(t).unwrap();
            assert_eq!(st.v.valid, 1.0);
            // δq = q* ⊗ q_meas, δθ_B = 2 δq_v (small angles), δθ_S = R(mount)ᵀ δθ_B
            let dq = q.conjugate() * st.v.q_meas;
            let th = dq.vector() * (2.0 * dq.w.signum());
            out.push(r.transpose() * th);
            st.step(t, t_s).unwrap();
        }
        out
    }

    #[test]
    fn error_statistics_per_sensor_axis_match_the_declared_noise() {
        let mut st = Fmu::<StarTracker>::default();
        (st.v.latency, st.v.sun_exclusion) = (0.0, 0.0);
        st.v.mount = Vector3::new(0.4, -0.3, 1.0);
        let n = 40_000;
        let e = errors(&mut st, n);
        let want = [st.v.noise_cross, st.v.noise_cross, st.v.noise_about];
        for (i, w) in want.iter().enumerate() {
            let m = e.iter().map(|v| v[i]).sum::<f64>() / n as f64;
            let sd = (e.iter().map(|v| (v[i] - m).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
            // mean within 4 sigma/sqrt(n); std within 4 standard errors (sqrt(1/(2n)) relative)
            assert!(m.abs() < 4.0 * w / (n as f64).sqrt(), "axis {i}: mean {m}");
            assert!((sd / w - 1.0).abs() < 4.0 / (2.0 * n as f64).sqrt(), "axis {i}: std {sd} vs {w}");
        }
        // cross-axis correlation ~ 0
        let c01 = e.iter().map(|v| v[0] * v[2]).sum::<f64>() / n as f64 / (want[0] * want[2]);
        assert!(c01.abs() < 4.0 / (n as f64).sqrt(), "{c01}");
    }

    #[test]
    fn update_rate_and_latency_shift_the_measurements() {
        // noise-free: the output at t is the true attitude of sample floor((t - d)/T) T
        let mut st = Fmu::<StarTracker>::default();
        (st.v.noise_cross, st.v.noise_about, st.v.sun_exclusion) = (0.0, 0.0, 0.0);
        (st.v.sample_period, st.v.latency) = (0.2, 0.3);
        st.initialize(&Experiment::default()).unwrap();
        let h = 0.05;
        let truth = |t: f64| quat_from_euler321(0.1 * t, 0.0, 0.0);
        for i in 0..80 {
            let t = i as f64 * h;
            st.v.truth.q = truth(t);
            st.outputs(t).unwrap();
            assert_eq!(st.v.st_valid, st.v.valid, "t = {t}"); // the Mekf's name for the same flag
            let kd = ((t - 0.3) / 0.2 + 1e-9).floor();
            if kd < 0.0 {
                assert_eq!((st.v.q_meas, st.v.valid), (Quaternion::new(1.0, 0.0, 0.0, 0.0), 0.0), "t = {t}");
            } else {
                assert!((st.v.q_meas - truth(kd * 0.2)).norm() < 1e-15, "t = {t}");
                assert_eq!(st.v.valid, 1.0);
            }
            st.step(t, h).unwrap();
        }
    }

    #[test]
    fn sun_in_the_exclusion_cone_holds_the_last_valid_measurement() {
        // sun at λ0 = 0: R's x axis; boresight = body z. Pitch 90° points the boresight at the sun,
        // the identity puts the sun 90° away
        let mut st = Fmu::<StarTracker>::default();
        (st.v.latency, st.v.noise_cross, st.v.noise_about) = (0.0, 0.0, 0.0);
        st.initialize(&Experiment::default()).unwrap();
        let toward = quat_from_euler321(0.0, std::f64::consts::FRAC_PI_2, 0.0);
        let away = Quaternion::new(1.0, 0.0, 0.0, 0.0);
        let h = st.v.sample_period;
        let mut log = vec![];
        for i in 0..6 {
            let t = i as f64 * h;
            st.v.truth.q = if (2..4).contains(&i) { toward } else { away };
            st.outputs(t).unwrap();
            log.push((st.v.valid, st.v.q_meas, st.v.sun_angle));
            st.step(t, h).unwrap();
        }
        assert_eq!(log.iter().map(|l| l.0).collect::<Vec<_>>(), [1.0, 1.0, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(log[2].1, away);
        assert_eq!(log[3].1, away);
        // the sun moves 1.99e-7 rad/s along the ecliptic: angles 0 and 90 deg within 1e-6 rad
        assert!(log[2].2 < 1e-6 && (log[5].2 - std::f64::consts::FRAC_PI_2).abs() < 1e-6, "{log:?}");
    }

    #[test]
    fn bad_parameters_and_inputs_are_named() {
        let mut st = Fmu::<StarTracker>::default();
        st.v.noise_about = -1.0;
        assert!(st.initialize(&Experiment::default()).unwrap_err().contains("noise_about"));
        st.v.noise_about = 0.0;
        (st.v.sample_period, st.v.latency) = (1e-6, 10.0);
        assert!(st.initialize(&Experiment::default()).unwrap_err().contains("latency"));
        st.v.latency = 0.0;
        st.initialize(&Experiment::default()).unwrap();
        st.v.truth.q = Quaternion::new(0.0, 0.0, 0.0, 0.0);
        assert!(st.outputs(0.0).unwrap_err().contains("input quaternion q"));
    }
}
