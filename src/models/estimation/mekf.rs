//! `Mekf`: the multiplicative extended Kalman filter of spacecraft attitude — error state of three
//! small-angle attitude errors and three gyro biases, a unit reference quaternion kept unit by the
//! multiplicative reset, propagation with the gyro, Joseph-form updates from star-tracker quaternions
//! and from body-frame unit vectors (sun sensor, magnetometer) with their reference directions; a star
//! tracker's latency (`st_latency`) is compensated by a delayed update (`mekf_delay.rs`); a coarse attitude
//! re-initialises the filter on request (`init_request`, `mekf_coarse.rs`). The equations of the FMU's
//! documentation are in `mekf_equations.html`.

use std::collections::VecDeque;
use nalgebra::{Matrix3, Quaternion, Rotation3, SMatrix, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{attitude_matrix, skew};
use crate::math::attitude_kalman::{error_transition, gyro_process_noise, joseph_update_with_gain, quat_exp, quat_log, Matrix6};
use crate::math::sample_grid;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

#[path = "mekf_delay.rs"]
mod delay;
#[path = "mekf_coarse.rs"]
mod coarse;

/// At most this many filter samples per doStep (bounded work: a longer step is refused before any work).
pub const MAX_SAMPLES_PER_CALL: i64 = 1_000_000;

const SWITCH: &[i32] = &[0, 1];

declare_variables! {
    pub struct MekfVars {
        0 => w_meas: Vec3 = [0.0; 3], Input, "rad/s", "Measured body rate (the Gyro's w_meas)";
        3 => q_meas: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Measured attitude quaternion of B relative to R (the StarTracker's q_meas)";
        7 => st_valid: Real = 1.0, Input, "", "Star-tracker validity (the StarTracker's st_valid, equal to its valid): >= 0.5 = q_meas usable";
        8 => sun_meas: Vec3 = [0.0, 0.0, 1.0], Input, "", "Measured sun direction, body axes (the SunSensor's sun_meas; normalised by the filter)";
        11 => sun_ref: Vec3 = [1.0, 0.0, 0.0], Input, "", "Sun direction in the reference frame R (ephemeris; normalised by the filter)";
        14 => sun_valid: Real = 1.0, Input, "", "Sun-sensor validity (the SunSensor's sun_valid, equal to its valid): >= 0.5 = sun_meas usable";
        15 => b_meas: Vec3 = [0.0, 0.0, 1.0], Input, "T", "Measured geomagnetic field, body axes (the Magnetometer's b_meas; only its direction is used)";
        18 => b_ref: Vec3 = [1.0, 0.0, 0.0], Input, "T", "Geomagnetic field in R (the Ephemeris' b_ref or another field model; only its direction is used)";
        21 => q_coarse: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Coarse attitude quaternion of B relative to R (e.g. the Triad's or Quest's q_est; normalised by the filter), read only when init_request >= 0.5";
        25 => init_request: Real = 0.0, Input, "", "Re-initialisation request: >= 0.5 at a filter sample = the attitude estimate becomes q_coarse with covariance sigma_att_coarse^2 I, uncorrelated with the bias (bias estimate and covariance kept), before that sample's updates";
        40 => q_est: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Estimated attitude quaternion of B relative to R (the plant's q convention), held between samples";
        44 => w_est: Vec3 = [0.0; 3], Output, "rad/s", "Estimated body rate: gyro rate minus estimated bias";
        47 => bias_est: Vec3 = [0.0; 3], Output, "rad/s", "Estimated gyro bias";
        50 => p_att: Vec3 = [0.0; 3], Output, "rad2", "Covariance diagonal of the attitude error (body axes)";
        53 => p_bias: Vec3 = [0.0; 3], Output, "rad2/s2", "Covariance diagonal of the bias error";
        56 => innovation: Vec3 = [0.0; 3], Output, "rad", "Star-tracker innovation of the current sample: rotation vector from the predicted attitude (with st_latency > 0: the estimate of the measurement's sample) to the measured one (0 without a star-tracker update)";
        59 => nis: Real = 0.0, Output, "", "Normalized innovation squared of the current sample's updates, summed over them (0 without updates)";
        60 => nis_dim: Integer = 0, Output, "", "Innovation dimension of the current sample: 3 per star-tracker update + 2 per vector update (0 = no update)";
        61 => nis_sum: Real = 0.0, Output, "", "Running sum of nis over every sample since the start (a consumer sampled at its own times, or behind a coupling delay, takes the increments and misses no update)";
        62 => nis_dim_sum: Real = 0.0, Output, "", "Running sum of nis_dim over every sample since the start (a whole number)";
        100 => sample_period: Real = 0.01, Parameter, "s", "Sample period T of the filter (equal to the gyro's, so that each gyro sample is used once)", Range(1e-6, 1e4);
        101 => q_init: Quat = [1.0, 0.0, 0.0, 0.0], Parameter, "", "Initial attitude estimate (normalised; replaced by the first star-tracker measurement if init_from_star_tracker = 1)";
        105 => bias_init: Vec3 = [0.0; 3], Parameter, "rad/s", "Initial bias estimate", Range(-1.0, 1.0);
        108 => sigma_att_init: Real = 0.1, Parameter, "rad", "Initial 1-sigma attitude error per axis", Range(1e-12, 3.2);
        109 => sigma_bias_init: Real = 1e-4, Parameter, "rad/s", "Initial 1-sigma bias error per axis", Range(1e-15, 1.0);
        110 => arw_psd: Vec3 = [1.9e-9; 3], Parameter, "rad2/s", "Angle random walk N^2 assumed by the filter (as the Gyro's arw_psd)", Positive;
        113 => rrw_psd: Vec3 = [1.8e-13; 3], Parameter, "rad2/s3", "Rate random walk K^2 assumed by the filter (as the Gyro's rrw_psd; default ~ the Gyro's default bias instability as a random walk)", NonNegative;
        116 => st_noise_cross: Real = 2.5e-5, Parameter, "rad", "Star-tracker 1-sigma error about each cross-boresight axis (as the StarTracker's noise_cross)", Positive;
        117 => st_noise_about: Real = 2.0e-4, Parameter, "rad", "Star-tracker 1-sigma error about the boresight (as the StarTracker's noise_about)", Positive;
        118 => st_mount: Vec3 = [0.0; 3], Parameter, "rad", "Star-tracker mounting rotation vector (as the StarTracker's mount; boresight = sensor z)", Range(-4.0, 4.0);
        121 => sun_noise: Real = 1.745e-3, Parameter, "rad", "Sun-sensor 1-sigma angular error about each axis perpendicular to the sun line (as the SunSensor's noise)", Positive;
        122 => mag_noise: Real = 0.01, Parameter, "rad", "Magnetometer 1-sigma angular error of the field direction (noise / |B|; 100 nT of 30 uT = 3.3e-3 rad)", Positive;
        123 => init_from_star_tracker: Integer = 1, Parameter, "", "1 = the first usable star-tracker measurement initialises the attitude (covariance = its noise), 0 = it is an update of q_init", Choice(SWITCH);
        124 => use_star_tracker: Integer = 1, Parameter, "", "1 = update with q_meas when st_valid >= 0.5 and q_meas is new", Choice(SWITCH);
        125 => use_sun: Integer = 0, Parameter, "", "1 = update with sun_meas when sun_valid >= 0.5 and sun_meas is new", Choice(SWITCH);
        126 => use_mag: Integer = 0, Parameter, "", "1 = update with b_meas whenever it is new", Choice(SWITCH);
        127 => st_latency: Real = 0.0, Parameter, "s", "Star-tracker latency compensated by the filter (as the StarTracker's latency): a quaternion arriving at sample k was measured at sample k - st_latency/sample_period (a whole number, at most 1000)", Range(0.0, 10.0);
        128 => sigma_att_coarse: Real = 0.05, Parameter, "rad", "1-sigma attitude error per axis of q_coarse, the covariance of a re-initialisation (init_request >= 0.5)", Range(1e-12, 3.2);
    }
}

/// Constants of the filter (derived from the parameters).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    /// Index of the first sample: the interval of the experiment's start time.
    k0: i64,
    q0: Quaternion<f64>,
    b0: Vector3<f64>,
    p0: Matrix6,
    /// Q over one sample period.
    q_proc: Matrix6,
    /// Star-tracker noise covariance in body axes, M diag(σ_c², σ_c², σ_a²) Mᵀ.
    r_st: Matrix3<f64>,
    sun_var: f64,
    mag_var: f64,
    init_from_st: bool,
    use_st: bool,
    use_sun: bool,
    use_mag: bool,
    /// Star-tracker latency in samples (0: no compensation, the history stays empty).
    delay: usize,
    /// Attitude variance of a coarse re-initialisation, sigma_att_coarse².
    coarse_var: f64,
}

/// The filter after sample k: estimate, covariance, the gyro rate to propagate with, the last used
/// measurements (a measurement is used once) and the diagnostics of sample k.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Est {
    k: i64,
    q: Quaternion<f64>,
    b: Vector3<f64>,
    p: Matrix6,
    w: Vector3<f64>,
    last_q: [f64; 4],
    last_sun: [f64; 3],
    last_mag: [f64; 3],
    initialized: bool,
    innovation: Vector3<f64>,
    nis: f64,
    nis_dim: i32,
    /// Running sums of nis and nis_dim over the samples since the start.
    nis_sum: f64,
    nis_dim_sum: f64,
    /// With a star-tracker latency: the filter after each of the last `delay` + 1 samples (the newest is
    /// this one), for the delayed update (`mekf_delay`).
    hist: VecDeque<delay::Entry>,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Mekf {
    d: Derived,
    s: Est,
}

fn finite(name: &str, x: &[f64]) -> ModelResult {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(format!("input {name} is not finite: {x:?}"))
    }
}

/// A direction input normalised (a zero or non-finite vector is refused).
fn unit(name: &str, x: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    finite(name, x.as_slice())?;
    let n = x.norm();
    if n < 1e-300 || !n.is_finite() {
        return Err(format!("input {name} has norm {n}, expected a direction (is it connected?)"));
    }
    Ok(x / n)
}

/// Multiplicative reset of an estimate (q̂, b̂) by an error-state correction: q̂ ← q̂ ⊗ exp(δθ/2)
/// (renormalised), b̂ ← b̂ + δb (also the delayed update's, `mekf_delay`).
fn apply_correction(q: &mut Quaternion<f64>, b: &mut Vector3<f64>, dx: &SVector<f64, 6>) {
    *q = (*q * quat_exp(&dx.fixed_rows::<3>(0).into_owned())).normalize();
    *b += dx.fixed_rows::<3>(3);
}

/// A star-tracker quaternion update's innovation against the prediction q̂ (rotation vector from q̂ to
/// q_meas) and its H = [I 0]: the attitude error is observed directly, the bias not.
fn star_innovation(q: &Quaternion<f64>, q_m: &Quaternion<f64>) -> (Vector3<f64>, SMatrix<f64, 3, 6>) {
    let mut h = SMatrix::<f64, 3, 6>::zeros();
    h.fixed_view_mut::<3, 3>(0, 0).fill_with_identity();
    (quat_log(&(q.conjugate() * q_m)), h)
}

/// Initialisation from a first star-tracker quaternion: the measurement on the estimate's hemisphere
/// (the same rotation) and the covariance whose attitude block is the star tracker's noise, uncorrelated
/// with the bias.
fn star_initialization(q: &Quaternion<f64>, p: &Matrix6, q_m: &Quaternion<f64>, r_st: &Matrix3<f64>) -> (Quaternion<f64>, Matrix6) {
    let mut p = *p;
    p.fixed_view_mut::<3, 6>(0, 0).fill(0.0);
    p.fixed_view_mut::<6, 3>(0, 0).fill(0.0);
    p.fixed_view_mut::<3, 3>(0, 0).copy_from(r_st);
    (if q_m.dot(q) < 0.0 { -q_m } else { *q_m }, p)
}

impl Mekf {
    /// Multiplicative reset of the current estimate, δx ← 0.
    fn reset(s: &mut Est, dx: &SVector<f64, 6>) {
        apply_correction(&mut s.q, &mut s.b, dx);
    }

    /// Joseph-form update of the current sample; returns its error-state transition I − K H.
    fn update<const M: usize>(s: &mut Est, h: &SMatrix<f64, M, 6>, r: &SMatrix<f64, M, M>, nu: &SVector<f64, M>, what: &str) -> Result<Matrix6, String> {
        let (dx, p, nis, k) = joseph_update_with_gain(&s.p, h, r, nu).ok_or_else(|| format!("{what} update: innovation covariance is not positive definite"))?;
        s.p = p;
        Self::reset(s, &dx);
        s.nis += nis;
        s.nis_dim += M as i32;
        Ok(Matrix6::identity() - k * h)
    }

    /// Update with a measured body direction `meas` of the reference direction `refd`: the innovation is
    /// the measured unit vector's components on two unit vectors E = [e₁ e₂] perpendicular to the
    /// predicted b̂ = A(q̂) r, H = [Eᵀ [b̂×], 0], R = σ² I₂.
    /// `port`: the inputs' stem (`sun`, `b`), `what`: the sensor named in a message.
    fn vector_update(s: &mut Est, meas: &Vector3<f64>, refd: &Vector3<f64>, var: f64, port: &str, what: &str) -> Result<Matrix6, String> {
        let bm = unit(&format!("{port}_meas"), meas)?;
        let r = unit(&format!("{port}_ref"), refd)?;
        let bh = attitude_matrix(&s.q) * r;
        // the coordinate axis least aligned with b̂ gives e₁ ⟂ b̂
        let i = bh.iamin();
        let e1 = bh.cross(&Vector3::ith(i, 1.0)).normalize();
        let e2 = bh.cross(&e1);
        let et = SMatrix::<f64, 2, 3>::from_rows(&[e1.transpose(), e2.transpose()]);
        let mut h = SMatrix::<f64, 2, 6>::zeros();
        h.fixed_view_mut::<2, 3>(0, 0).copy_from(&(et * skew(&bh)));
        let nu = et * bm;
        Self::update(s, &h, &(SMatrix::<f64, 2, 2>::identity() * var), &nu, what)
    }

    /// The zero-latency star-tracker update of sample k (a new usable q_meas, normalised): the first one
    /// initialises the attitude with init_from_star_tracker = 1, the others update it.
    fn star_update(&self, s: &mut Est, q_m: &Quaternion<f64>) -> ModelResult {
        if self.d.init_from_st && !s.initialized {
            // first measurement: the estimate is the measurement, its error covariance the noise's
            (s.q, s.p) = star_initialization(&s.q, &s.p, q_m, &self.d.r_st);
        } else {
            let (nu, h) = star_innovation(&s.q, q_m);
            Self::update(s, &h, &self.d.r_st, &nu, "star-tracker")?;
            s.innovation = nu;
        }
        Ok(())
    }

    /// The delayed star-tracker update of sample k (`st_latency` > 0): the current sample is recorded in
    /// the history with its transition `t`, a new measurement `q_m` (if any) updates the history's oldest
    /// sample and the correction is carried to the current one (`mekf_delay`).
    fn delayed_star_update(&self, s: &mut Est, t: Matrix6, q_m: Option<Quaternion<f64>>) -> ModelResult {
        let d = &self.d;
        let e = delay::Entry { k: s.k, q: s.q, b: s.b, p: s.p, t };
        delay::record(&mut s.hist, d.delay, e);
        if let Some(q_m) = q_m {
            if d.init_from_st && !s.initialized {
                s.initialized = delay::initialize(&mut s.hist, d.delay, &q_m, &d.r_st);
            } else if let Some((nu, nis)) = delay::update(&mut s.hist, d.delay, &q_m, &d.r_st)? {
                (s.innovation, s.nis, s.nis_dim) = (nu, s.nis + nis, s.nis_dim + 3);
            }
            let now = s.hist.back().expect("the current sample is recorded");
            (s.q, s.b, s.p) = (now.q, now.b, now.p);
        }
        Ok(())
    }

    /// The filter after sample k given the filter after sample k − 1 (first sample k0: the initial estimate).
    fn next(&self, mut s: Est, k: i64, v: &MekfVars) -> Result<Est, String> {
        let d = &self.d;
        finite("w_meas", v.w_meas.as_slice())?;
        s.k = k;
        let mut t = Matrix6::identity();
        if k == d.k0 {
            (s.q, s.b, s.p) = (d.q0, d.b0, d.p0);
        } else {
            // propagation over T with the mean of the previous and the current gyro sample (trapezoidal
            // rule: exact for a rate linear over the step, as the plant's under a held torque)
            let w = (s.w + v.w_meas) * 0.5 - s.b;
            s.q = (s.q * quat_exp(&(w * d.period))).normalize();
            t = error_transition(&w, d.period);
            let p = t * s.p * t.transpose() + d.q_proc;
            s.p = (p + p.transpose()) * 0.5;
        }
        coarse::reinitialize(&mut s, v, d.coarse_var)?;
        (s.innovation, s.nis, s.nis_dim) = (Vector3::zeros(), 0.0, 0);
        let qm = [v.q_meas.w, v.q_meas.i, v.q_meas.j, v.q_meas.k];
        if !v.st_valid.is_finite() || !v.sun_valid.is_finite() {
            return Err(format!("validity inputs are not finite: st_valid = {}, sun_valid = {}", v.st_valid, v.sun_valid));
        }
        if d.use_st && v.st_valid >= 0.5 {
            finite("q_meas", &qm)?;
            let n = v.q_meas.norm();
            if (n - 1.0).abs() > 1e-3 {
                return Err(format!("input quaternion q_meas has norm {n}, expected 1 (is it connected?)"));
            }
        }
        // a new usable star-tracker measurement is used once: now (no latency) or after the vector
        // updates, as an update of the sample it was measured at
        let q_new = (d.use_st && v.st_valid >= 0.5 && qm != s.last_q).then(|| v.q_meas / v.q_meas.norm());
        if let (Some(q_m), 0) = (q_new, d.delay) {
            self.star_update(&mut s, &q_m)?;
            s.initialized = true;
        }
        if q_new.is_some() {
            s.last_q = qm;
        }
        let sm = [v.sun_meas.x, v.sun_meas.y, v.sun_meas.z];
        if d.use_sun && v.sun_valid >= 0.5 {
            unit("sun_meas", &v.sun_meas)?;
            unit("sun_ref", &v.sun_ref)?;
        }
        if d.use_sun && v.sun_valid >= 0.5 && sm != s.last_sun {
            t = Self::vector_update(&mut s, &v.sun_meas, &v.sun_ref, d.sun_var, "sun", "sun-sensor")? * t;
            s.last_sun = sm;
        }
        let mm = [v.b_meas.x, v.b_meas.y, v.b_meas.z];
        if d.use_mag {
            unit("b_meas", &v.b_meas)?;
            unit("b_ref", &v.b_ref)?;
        }
        if d.use_mag && mm != s.last_mag {
            t = Self::vector_update(&mut s, &v.b_meas, &v.b_ref, d.mag_var, "b", "magnetometer")? * t;
            s.last_mag = mm;
        }
        if d.delay > 0 {
            self.delayed_star_update(&mut s, t, q_new)?;
        }
        s.w = v.w_meas;
        (s.nis_sum, s.nis_dim_sum) = (s.nis_sum + s.nis, s.nis_dim_sum + f64::from(s.nis_dim));
        if !(s.q.coords.iter().all(|x| x.is_finite()) && s.p.iter().all(|x| x.is_finite())) {
            return Err(format!("the estimate became non-finite at sample {k}"));
        }
        Ok(s)
    }

    /// Runs the filter through the samples up to k with the inputs v.
    fn propagate(&self, s: &Est, k: i64, v: &MekfVars) -> Result<Est, String> {
        let n = k.checked_sub(s.k).ok_or("sample count overflows")?;
        if n > MAX_SAMPLES_PER_CALL {
            return Err(format!("the filter would take {n} samples of period {} s in one call (at most {MAX_SAMPLES_PER_CALL})", self.d.period));
        }
        let mut s = s.clone();
        for j in s.k + 1..=k {
            s = self.next(s, j, v)?;
        }
        Ok(s)
    }
}

impl Model for Mekf {
    type Vars = MekfVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock of the filter: at each tick the estimate of the sample is output and held, then the filter propagates",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["q_est", "w_est", "bias_est", "p_att", "p_bias", "innovation", "nis", "nis_dim", "nis_sum", "nis_dim_sum"],
        },
    ];
    fn time_grid(v: &MekfVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["s"];
    const INFO: ModelInfo = ModelInfo {
        name: "Mekf",
        description: "Multiplicative extended Kalman filter of attitude and gyro bias: gyro propagation, star-tracker (with latency compensation) and sun/magnetometer vector updates (Joseph form), covariance, innovation and NIS outputs",
        source: "multiplicative EKF of [Lefferts-Markley-Shuster-1982] in the discrete form of [Markley-Crassidis-2014] Ch. 6 (state transition and process noise of a gyro with angle and rate random walk); vector measurement on the tangent plane of the predicted direction and measurement-once rule: project choice",
        equations_html: concat!(include_str!("mekf_equations.html"), crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut MekfVars, exp: &Experiment) -> Result<Self, String> {
        let t = v.sample_period;
        let nq = v.q_init.norm();
        if !(nq > 1e-6 && nq.is_finite()) {
            return Err(format!("parameter q_init has norm {nq}, expected a non-zero quaternion"));
        }
        let k0 = sample_grid::index_at(exp.start_time, t, exp.start_time)?;
        let mut p0 = Matrix6::zeros();
        for i in 0..3 {
            p0[(i, i)] = v.sigma_att_init.powi(2);
            p0[(i + 3, i + 3)] = v.sigma_bias_init.powi(2);
        }
        let m = Rotation3::new(v.st_mount).into_inner();
        let r_st = m * Matrix3::from_diagonal(&Vector3::new(v.st_noise_cross, v.st_noise_cross, v.st_noise_about).map(|x| x * x)) * m.transpose();
        let d = Derived {
            period: t,
            k0,
            q0: v.q_init / nq,
            b0: v.bias_init,
            p0,
            q_proc: gyro_process_noise(&v.arw_psd, &v.rrw_psd, t),
            r_st: (r_st + r_st.transpose()) * 0.5,
            sun_var: v.sun_noise.powi(2),
            mag_var: v.mag_noise.powi(2),
            init_from_st: v.init_from_star_tracker == 1,
            use_st: v.use_star_tracker == 1,
            use_sun: v.use_sun == 1,
            use_mag: v.use_mag == 1,
            delay: delay::delay_samples(v.st_latency, t)?,
            coarse_var: v.sigma_att_coarse * v.sigma_att_coarse,
        };
        let s = Est {
            k: k0 - 1,
            q: d.q0,
            b: d.b0,
            p: d.p0,
            w: Vector3::zeros(),
            last_q: [0.0; 4],
            last_sun: [0.0; 3],
            last_mag: [0.0; 3],
            initialized: false,
            innovation: Vector3::zeros(),
            nis: 0.0,
            nis_dim: 0,
            nis_sum: 0.0,
            nis_dim_sum: 0.0,
            hist: VecDeque::new(),
        };
        Ok(Mekf { d, s })
    }

    fn outputs(&self, v: &mut MekfVars, t: f64) -> ModelResult {
        let k = sample_grid::index_at(t, self.d.period, t)?;
        let s = if k > self.s.k { self.propagate(&self.s, k, v)? } else { self.s.clone() };
        if s.k < self.d.k0 {
            return Err(format!("the filter has no sample before the start time (t = {t})"));
        }
        v.q_est = s.q;
        v.bias_est = s.b;
        v.w_est = s.w - s.b;
        v.p_att = Vector3::new(s.p[(0, 0)], s.p[(1, 1)], s.p[(2, 2)]);
        v.p_bias = Vector3::new(s.p[(3, 3)], s.p[(4, 4)], s.p[(5, 5)]);
        v.innovation = s.innovation;
        v.nis = s.nis;
        v.nis_dim = s.nis_dim;
        (v.nis_sum, v.nis_dim_sum) = (s.nis_sum, s.nis_dim_sum);
        Ok(())
    }

    fn step(&mut self, v: &MekfVars, t: f64, h: f64) -> ModelResult {
        let k_end = sample_grid::last_before(t + h, self.d.period, t + h)?;
        if k_end > self.s.k {
            self.s = self.propagate(&self.s, k_end, v)?;
        }
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        let s = &self.s;
        if s.k < self.d.k0 - 1 {
            return Err(format!("restored state: sample index {} before the first sample {}", s.k, self.d.k0));
        }
        if (s.q.norm() - 1.0).abs() > 1e-9 {
            return Err(format!("restored state: estimated quaternion has norm {}", s.q.norm()));
        }
        if (s.p - s.p.transpose()).abs().max() > 0.0 || s.p.cholesky().is_none() {
            return Err("restored state: covariance is not symmetric positive definite".into());
        }
        delay::check(&s.hist, self.d.delay, s.k)
    }
}

#[cfg(test)]
#[path = "mekf_tests.rs"]
mod tests;
