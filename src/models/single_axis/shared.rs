//! What the single-axis PID and PI^λD^μ controllers share: the law parameters from their declared
//! variables, the sample-time rule, and what each call does with the law.

use crate::math::fractional::{FopidLaw, FopidParams, PidLaw};

/// Law parameters from the declared variables (the bounds were checked by the FMI layer).
#[allow(clippy::too_many_arguments)]
pub fn law_params(kp: f64, ki: f64, kd: f64, lambda: f64, mu: f64, step: f64, gl_memory: i32, history_before_start: i32) -> FopidParams {
    FopidParams { kp, ki, kd, lambda, mu, h: step, memory: gl_memory.max(0) as usize, history_before_start: history_before_start == 1 }
}

/// The GL history is sampled at `step`: any other communication step is an error.
pub fn check_step(h: f64, step: f64) -> Result<(), String> {
    if (h - step).abs() > 1e-9 * step {
        return Err(format!("communication step {h} s differs from the sample time parameter step = {step} s (the error history is sampled at step)"));
    }
    Ok(())
}

/// The two laws as the FMUs use them: the output for the current error, and the error of t_n appended
/// at the end of the step.
pub trait SampledLaw {
    fn output(&self, e: f64) -> f64;
    fn push(&mut self, e: f64);
}

impl SampledLaw for PidLaw {
    fn output(&self, e: f64) -> f64 {
        PidLaw::output(self, e)
    }
    fn push(&mut self, e: f64) {
        PidLaw::push(self, e)
    }
}

impl SampledLaw for FopidLaw {
    fn output(&self, e: f64) -> f64 {
        FopidLaw::output(self, e)
    }
    fn push(&mut self, e: f64) {
        FopidLaw::push(self, e)
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

/// One sample: the step must equal the sample time, then the error of t_n joins the history.
pub fn sampled_step(law: &mut impl SampledLaw, h: f64, step: f64, theta_ref: f64, theta: f64) -> Result<(), String> {
    check_step(h, step)?;
    law.push(theta_ref - theta);
    Ok(())
}
