//! What the single-axis PID and PI^λD^μ controllers share: the laws (`laws`), the law parameters
//! from their declared variables, the sample-time rule, and what each call does with the law.

pub mod laws;

use laws::{FopidLaw, FopidParams, PidLaw};

pub use crate::math::sample_grid::SampleCounter;

/// The one FMI 3.0 clock of the discrete PID and PI^lambda D^mu laws (their sample time `step`).
pub const LAW_CLOCKS: &[crate::model::ClockDecl] = &[crate::model::ClockDecl {
    name: "sample_clock",
    description: "Sample clock of the law: at each tick u is computed from the inputs and held; the error is appended to the history",
    interval: "step",
    shift: "",
    steps: true,
    outputs: &["u"],
}];

/// Law parameters from the declared variables (the bounds were checked by the FMI layer).
#[allow(clippy::too_many_arguments)]
pub fn law_params(
    kp: f64,
    ki: f64,
    kd: f64,
    lambda: f64,
    mu: f64,
    step: f64,
    gl_memory: i32,
    history_before_start: i32,
) -> FopidParams {
    FopidParams {
        kp,
        ki,
        kd,
        lambda,
        mu,
        h: step,
        memory: gl_memory.max(0) as usize,
        history_before_start: history_before_start == 1,
    }
}

/// Most samples one communication step may take (as the plants' internal steps): bounds the work
/// and the history growth of one fmi2DoStep.
pub const MAX_SAMPLES_PER_STEP: u64 = 1_000_000;

/// The GL history is sampled at `step` on an integer sample counter (`math::sample_grid`): a
/// communication step must be a whole multiple k >= 0 of it and start at the counter's instant
/// start + n step (both to the grid tolerance, which absorbs a master's summed or clipped time), and
/// then takes k samples; any other step is an error.
pub fn samples_in_step(clock: &SampleCounter, n: usize, t: f64, h: f64) -> Result<usize, String> {
    let k = clock.step(n as u64, t, h, "the error history is sampled at step")?;
    if k > MAX_SAMPLES_PER_STEP {
        return Err(format!("communication step {h} s would take {k} samples of step = {} s (at most {MAX_SAMPLES_PER_STEP} per doStep)", clock.period));
    }
    Ok(k as usize)
}

/// The two laws as the FMUs use them: the output for the current error, and the error of t_n appended
/// at the end of the step.
pub trait SampledLaw {
    fn output(&self, e: f64) -> f64;
    fn push(&mut self, e: f64);
    /// Samples taken so far (the sample counter).
    fn samples(&self) -> usize;
}

impl SampledLaw for PidLaw {
    fn output(&self, e: f64) -> f64 {
        PidLaw::output(self, e)
    }
    fn push(&mut self, e: f64) {
        PidLaw::push(self, e)
    }
    fn samples(&self) -> usize {
        self.len()
    }
}

impl SampledLaw for FopidLaw {
    fn output(&self, e: f64) -> f64 {
        FopidLaw::output(self, e)
    }
    fn push(&mut self, e: f64) {
        FopidLaw::push(self, e)
    }
    fn samples(&self) -> usize {
        self.len()
    }
}

/// (u, e) for the inputs held: e = theta_ref − theta; a non-finite u is an error, never an output.
pub fn sampled_output(law: &impl SampledLaw, theta_ref: f64, theta: f64) -> Result<(f64, f64), String> {
    let e = theta_ref - theta;
    let u = law.output(e);
    if !u.is_finite() {
        return Err(format!("u = {u} is not finite (error e = {e})"));
    }
    Ok((u, e))
}

/// One communication step doStep(t, h) of k samples (see [`samples_in_step`]): the inputs are held
/// over the step, so the error of t_n joins the history k times (the law is sampled at t_n, t_n + step, …).
pub fn sampled_step(
    law: &mut impl SampledLaw,
    clock: &SampleCounter,
    t: f64,
    h: f64,
    theta_ref: f64,
    theta: f64,
) -> Result<(), String> {
    let k = samples_in_step(clock, law.samples(), t, h)?;
    let e = theta_ref - theta;
    for _ in 0..k {
        law.push(e);
    }
    Ok(())
}
