//! `Gyro`: a three-axis rate gyro sampled at its own rate — scale factor and misalignment, constant
//! bias, bias instability (first-order Gauss–Markov), rate random walk and angle random walk, every
//! draw from the seeded counter-based generator of `math::random`.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::shared::{sample_index, last_sample_before, rotation, MAX_SAMPLES_PER_CALL};
use crate::declare_variables;
use crate::math::random::normal;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

/// √(2 ln 2 / π): the Allan deviation of flicker rate noise of coefficient B is this × B ([IEEE-952]).
pub const FLICKER_FLOOR: f64 = 0.664_282_470_267_960_1;
/// Maximum over τ of the Allan deviation of a first-order Gauss–Markov process, per unit stationary
/// standard deviation (reached at τ = 1.8926 τ_c): max_x sqrt((2/x)(1 − (3 − 4e^−x + e^−2x)/(2x))).
pub const GM_ADEV_PEAK: f64 = 0.617_364_283_144_441_4;

declare_variables! {
    pub struct GyroVars {
        4 => w: Vec3 = [0.0; 3], Input, "rad/s", "True body rate (the plant's w)";
        20 => w_meas: Vec3 = [0.0; 3], Output, "rad/s", "Measured body rate, sensor axes, held between samples";
        30 => bias_total: Vec3 = [0.0; 3], Output, "rad/s", "Diagnostic: total bias of the current sample (constant + Gauss-Markov + rate random walk)";
        100 => sample_period: Real = 0.01, Parameter, "s", "Sample period T of the gyro (output held between samples)", Range(1e-6, 1e4);
        103 => arw_psd: Vec3 = [1.9e-9; 3], Parameter, "rad2/s", "Angle random walk N^2: PSD of the white rate noise (N in rad/sqrt(s); default N = 4.36e-5 rad/sqrt(s) = 0.15 deg/sqrt(h))", NonNegative;
        106 => bias_const: Vec3 = [0.0; 3], Parameter, "rad/s", "Constant (turn-on) bias b_0";
        109 => bias_instability: Vec3 = [4.85e-6; 3], Parameter, "rad/s", "Bias instability B (the IEEE coefficient: the Allan deviation's flat floor is 0.664 B; default 1 deg/h)", NonNegative;
        112 => bias_corr_time: Real = 300.0, Parameter, "s", "Correlation time tau_c of the Gauss-Markov bias that realises the bias instability (floor around tau = 1.9 tau_c)", Range(1e-6, 1e9);
        113 => rrw_psd: Vec3 = [0.0; 3], Parameter, "rad2/s3", "Rate random walk K^2: PSD of the bias's white derivative (K in rad/s/sqrt(s))", NonNegative;
        116 => scale_factor: Vec3 = [0.0; 3], Parameter, "", "Scale-factor error s (measured = (1 + s) x true)", Range(-0.5, 0.5);
        119 => misalignment: Vec3 = [0.0; 3], Parameter, "rad", "Misalignment: rotation vector theta of the sensor axes relative to the body axes", Range(-0.5, 0.5);
        140 => seed: Integer = 1, Parameter, "", "Seed of the counter-based noise generator";
        200 => gm_std: Vec3 = [0.0; 3], CalculatedParameter, "rad/s", "Stationary standard deviation of the Gauss-Markov bias, sigma_b = 0.664 B / 0.6174";
        203 => rate_noise_std: Vec3 = [0.0; 3], CalculatedParameter, "rad/s", "Standard deviation of the white rate noise of one sample, N / sqrt(T)";
    }
}

/// Constants of the sample recursion (derived from the parameters).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    /// Index of the first sample: the interval of the experiment's start time.
    k0: i64,
    seed: i64,
    /// (I + diag(s)) R(θ)ᵀ
    c: Matrix3<f64>,
    bias_const: Vector3<f64>,
    /// φ = exp(−T/τ_c), σ_b, σ_b sqrt(1 − φ²)
    phi: f64,
    gm_std: Vector3<f64>,
    gm_drive: Vector3<f64>,
    /// K sqrt(T), N / sqrt(T)
    rw_step: Vector3<f64>,
    white: Vector3<f64>,
}

/// The gyro's evolving state: index of the last latched sample and its bias states and measurement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Sample {
    k: i64,
    gm: Vector3<f64>,
    rw: Vector3<f64>,
    meas: Vector3<f64>,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Gyro {
    d: Derived,
    s: Sample,
}

impl Gyro {
    fn draws(&self, k: i64, first: u64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| normal(self.d.seed, k, first + i as u64))
    }

    /// The state after sample k given the state after sample k − 1 (first sample k0: stationary start).
    fn next(&self, s: &Sample, k: i64, w: &Vector3<f64>) -> Sample {
        let d = &self.d;
        let (gm, rw) = if k == d.k0 {
            (d.gm_std.component_mul(&self.draws(k, 3)), Vector3::zeros())
        } else {
            (s.gm * d.phi + d.gm_drive.component_mul(&self.draws(k, 3)), s.rw + d.rw_step.component_mul(&self.draws(k, 6)))
        };
        let meas = d.c * w + d.bias_const + gm + rw + d.white.component_mul(&self.draws(k, 0));
        Sample { k, gm, rw, meas }
    }

    /// Propagates `s` through the samples up to k with the input w.
    fn propagate(&self, s: &Sample, k: i64, w: &Vector3<f64>) -> Result<Sample, String> {
        let n = k.checked_sub(s.k).ok_or("sample count overflows")?;
        if n > MAX_SAMPLES_PER_CALL {
            return Err(format!("the gyro would take {n} samples of period {} s in one call (at most {MAX_SAMPLES_PER_CALL})", self.d.period));
        }
        let mut s = s.clone();
        for j in s.k + 1..=k {
            s = self.next(&s, j, w);
        }
        Ok(s)
    }
}

impl Model for Gyro {
    type Vars = GyroVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: at each tick the measured rate and the bias are computed and held",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["w_meas", "bias_total"],
        },
    ];
    fn time_grid(v: &GyroVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["s"];
    const INFO: ModelInfo = ModelInfo {
        name: "Gyro",
        description: "Three-axis rate gyro: scale factor, misalignment, constant bias, bias instability, rate and angle random walk, sampled at its own rate, seeded",
        source: "error model of [Markley-Crassidis-2014] Sec. 4.7.1 (angle and rate random walk) and [IEEE-952] Annex C (Allan variance: N, B, K); bias instability realised as a Gauss-Markov bias (project choice)",
        equations_html: concat!("<pre>samples at t_k = k T (k = 0, 1, ...), output held until the next sample:\n\
w_meas,k = (I + diag(s)) R(theta)^T w(t_k) + b_0 + b_GM,k + b_RW,k + (N/sqrt(T)) n_k\n\
b_GM,0 = sigma_b n'_0,   b_GM,k = phi b_GM,k-1 + sigma_b sqrt(1 - phi^2) n'_k,   phi = exp(-T/tau_c)\n\
b_RW,0 = 0,             b_RW,k = b_RW,k-1 + K sqrt(T) n''_k\n\
sigma_b = 0.664 B / 0.6174   (the Gauss-Markov Allan deviation peaks at 0.6174 sigma_b for tau = 1.89 tau_c;\n\
                              0.664 B = sqrt(2 ln 2 / pi) B is the flicker floor of [IEEE-952])\n\
n_k, n'_k, n''_k: standard normal numbers N(seed, k, i) of math::random (channels 0-2, 3-5, 6-8)\n\
Allan deviation of the rate: sigma(tau) = N / sqrt(tau) (slope -1/2), ~0.664 B near tau = 1.9 tau_c (flat),\n\
K sqrt(tau/3) (slope +1/2)</pre>\n\
<p>Parameters are given as power spectral densities (N^2, K^2) because FMI units have integer exponents. \
R(theta) is the rotation matrix of the misalignment rotation vector. A sample strictly inside a communication \
step sees the input held at the step's start. The draws depend only on (seed, k, channel), so the output does \
not depend on the communication step, and an FMU state restores the bias states exactly.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut GyroVars, exp: &Experiment) -> Result<Self, String> {
        let t = v.sample_period;
        let k0 = sample_index(exp.start_time, t)?;
        let phi = (-t / v.bias_corr_time).exp();
        v.gm_std = v.bias_instability * (FLICKER_FLOOR / GM_ADEV_PEAK);
        v.rate_noise_std = v.arw_psd.map(|p| (p / t).sqrt());
        let c = Matrix3::from_diagonal(&v.scale_factor.add_scalar(1.0)) * rotation(&v.misalignment).transpose();
        let d = Derived {
            period: t,
            k0,
            seed: v.seed as i64,
            c,
            bias_const: v.bias_const,
            phi,
            gm_std: v.gm_std,
            gm_drive: v.gm_std * (1.0 - phi * phi).sqrt(),
            rw_step: v.rrw_psd.map(|p| (p * t).sqrt()),
            white: v.rate_noise_std,
        };
        Ok(Gyro { d, s: Sample { k: k0 - 1, gm: Vector3::zeros(), rw: Vector3::zeros(), meas: Vector3::zeros() } })
    }

    fn outputs(&self, v: &mut GyroVars, t: f64) -> ModelResult {
        let k = sample_index(t, self.d.period)?;
        let s = if k > self.s.k { self.propagate(&self.s, k, &v.w)? } else { self.s.clone() };
        if s.k < self.d.k0 {
            return Err(format!("the gyro has no sample before the start time (t = {t})"));
        }
        v.w_meas = s.meas;
        v.bias_total = self.d.bias_const + s.gm + s.rw;
        if !v.w_meas.iter().all(|x| x.is_finite()) {
            return Err(format!("measured rate is not finite (input w = {:?})", v.w.as_slice()));
        }
        Ok(())
    }

    fn step(&mut self, v: &GyroVars, t: f64, h: f64) -> ModelResult {
        let k_end = last_sample_before(t + h, self.d.period)?;
        if k_end > self.s.k {
            self.s = self.propagate(&self.s, k_end, &v.w)?;
        }
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        if self.s.k < self.d.k0 - 1 {
            return Err(format!("restored state: sample index {} before the first sample {}", self.s.k, self.d.k0));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn quiet() -> Fmu<Gyro> {
        let mut g = Fmu::<Gyro>::default();
        g.v.arw_psd = Vector3::zeros();
        g.v.bias_instability = Vector3::zeros();
        g
    }

    /// Runs `n` steps of h with input w(t); returns the outputs at the communication points.
    fn run(g: &mut Fmu<Gyro>, h: f64, n: usize, w: impl Fn(f64) -> Vector3<f64>) -> Vec<Vector3<f64>> {
        g.initialize(&Experiment::default()).unwrap();
        let mut out = vec![];
        for i in 0..n {
            let t = i as f64 * h;
            g.v.w = w(t);
            g.outputs(t).unwrap();
            out.push(g.v.w_meas);
            g.step(t, h).unwrap();
        }
        out
    }

    #[test]
    fn scale_factor_misalignment_and_constant_bias_closed_form() {
        let mut g = quiet();
        g.v.scale_factor = Vector3::new(0.01, -0.02, 0.03);
        g.v.misalignment = Vector3::new(0.0, 0.0, 0.01); // 0.01 rad about z
        g.v.bias_const = Vector3::new(1e-4, 2e-4, -3e-4);
        let w = Vector3::new(0.1, -0.05, 0.02);
        let out = run(&mut g, 0.01, 3, |_| w);
        // sensor axes rotated by 0.01 rad about z: w_S = (w_x cos + w_y sin, -w_x sin + w_y cos, w_z)
        let (s, c) = 0.01f64.sin_cos();
        let ws = Vector3::new(w.x * c + w.y * s, -w.x * s + w.y * c, w.z);
        let want = Vector3::new(1.01 * ws.x, 0.98 * ws.y, 1.03 * ws.z) + g.v.bias_const;
        assert!((out[2] - want).norm() < 1e-17, "{} vs {want}", out[2]);
    }

    #[test]
    fn sampled_at_its_own_rate_and_independent_of_the_communication_step() {
        let w = |t: f64| Vector3::new((0.7 * t).sin(), 0.1, -0.2 * t);
        let mut a = Fmu::<Gyro>::default();
        a.v.sample_period = 0.1;
        a.v.rrw_psd = Vector3::repeat(1e-10);
        let fine = run(&mut a, 0.025, 400, w);
        let mut b = Fmu::<Gyro>::default();
        b.v.sample_period = 0.1;
        b.v.rrw_psd = Vector3::repeat(1e-10);
        let coarse = run(&mut b, 0.1, 100, w);
        for (i, c) in coarse.iter().enumerate() {
            // the output at every communication point of the fine run equals the sample of its interval
            for j in 0..4 {
                assert_eq!(fine[4 * i + j], *c, "sample {i}, sub-step {j}");
            }
        }
        // a different seed changes the noise, the same seed reproduces it bit for bit
        let mut c2 = Fmu::<Gyro>::default();
        c2.v.sample_period = 0.1;
        c2.v.rrw_psd = Vector3::repeat(1e-10);
        c2.v.seed = 2;
        let other = run(&mut c2, 0.1, 100, w);
        assert!(other.iter().zip(&coarse).all(|(x, y)| x != y));
    }

    #[test]
    fn white_noise_and_gauss_markov_bias_statistics() {
        // N / sqrt(T) per sample; Gauss-Markov lag-1 correlation phi and stationary std sigma_b
        let mut g = Fmu::<Gyro>::default();
        g.v.sample_period = 1.0;
        g.v.arw_psd = Vector3::new(4e-8, 0.0, 0.0);
        g.v.bias_instability = Vector3::new(0.0, 1e-4, 0.0);
        g.v.bias_corr_time = 5.0;
        let n = 100_000;
        let out = run(&mut g, 1.0, n, |_| Vector3::zeros());
        let x: Vec<f64> = out.iter().map(|v| v.x).collect();
        let y: Vec<f64> = out.iter().map(|v| v.y).collect();
        let var = |a: &[f64]| a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64;
        // white: variance N^2/T = 4e-8 within 4 sigma of a chi-square with n dof (sqrt(2/n) = 0.45 %)
        assert!((var(&x) / 4e-8 - 1.0).abs() < 4.0 * (2.0 / n as f64).sqrt(), "{}", var(&x));
        // Gauss-Markov: variance sigma_b^2 and lag-1 correlation exp(-T/tau_c) (effective sample size n (1-phi)/(1+phi))
        let sb = 1e-4 * FLICKER_FLOOR / GM_ADEV_PEAK;
        let phi = (-1.0f64 / 5.0).exp();
        let n_eff = n as f64 * (1.0 - phi) / (1.0 + phi);
        assert!((var(&y) / (sb * sb) - 1.0).abs() < 4.0 * (2.0 / n_eff).sqrt(), "{} vs {}", var(&y), sb * sb);
        let r1 = y.windows(2).map(|p| p[0] * p[1]).sum::<f64>() / (n - 1) as f64 / var(&y);
        assert!((r1 - phi).abs() < 0.02, "{r1} vs {phi}");
        assert!((g.v.gm_std.y / sb - 1.0).abs() < 1e-15);
    }

    #[test]
    fn gm_allan_peak_constant_is_the_closed_form_maximum() {
        // dense search of the closed-form Allan deviation of a Gauss-Markov process
        let f = |x: f64| ((2.0 / x) * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x))).sqrt();
        let (mut best, mut at) = (0.0, 0.0);
        for i in 1..200_000 {
            let x = i as f64 * 5e-5;
            if f(x) > best {
                (best, at) = (f(x), x);
            }
        }
        assert!((best - GM_ADEV_PEAK).abs() < 1e-9 && (at - 1.8926).abs() < 1e-3, "{best} at {at}");
        assert!((FLICKER_FLOOR - (2.0 * 2f64.ln() / std::f64::consts::PI).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_step_of_too_many_samples_is_refused() {
        let mut g = Fmu::<Gyro>::default();
        g.v.sample_period = 1e-6;
        g.initialize(&Experiment::default()).unwrap();
        g.outputs(0.0).unwrap();
        let e = g.step(0.0, 10.0).unwrap_err();
        assert!(e.contains("samples of period"), "{e}");
        g.v.sample_period = 0.0;
        assert!(g.initialize(&Experiment::default()).unwrap_err().contains("sample_period"));
    }
}
