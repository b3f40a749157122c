//! What the single-axis PID and PI^λD^μ controllers share: the law parameters from their declared
//! variables and the sample-time rule.

use crate::math::fractional::FopidParams;

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
