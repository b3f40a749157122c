//! `PidController` (paper 002): integer PID u = K_P e + K_I h Σ e_j + K_D (e_n − e_{n−1})/h on the error
//! e = θ_ref − θ: the λ = μ = 1 case of `FopidController`, written with a running sum and a backward
//! difference (`super::shared::laws::PidLaw`).

use serde::{Deserialize, Serialize};

use super::shared::{LAW_CLOCKS, law_params, sampled_output, sampled_step, SampleCounter};
use crate::declare_variables;
use super::shared::laws::PidLaw;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct PidControllerVars {
        0 => theta: Real = 0.0, Input, "rad", "Measured angle theta";
        1 => theta_ref: Real = 0.0, Input, "rad", "Commanded angle theta_ref";
        10 => u: Real = 0.0, Output, "", "Wheel command u = K_P e + K_I h sum(e) + K_D (e_n - e_n-1)/h";
        30 => error: Real = 0.0, Output, "rad", "Error e = theta_ref - theta";
        100 => kp: Real = 2.0, Parameter, "", "Proportional gain K_P (per rad; project default)";
        101 => ki: Real = 0.1, Parameter, "1/s", "Integral gain K_I (per rad s; project default)";
        102 => kd: Real = 8.0, Parameter, "s", "Derivative gain K_D (s per rad; project default)";
        105 => step: Real = 0.001, Parameter, "s", "Sample time h; every communication step must be an integer multiple of it (to 1e-10 of the time, at most 1e-3 h)", Positive;
        120 => gl_memory: Integer = 0, Parameter, "", "Memory in samples (0 = full; L > 0: the integral sums the last L samples)", Range(0.0, 1e7);
        121 => history_before_start: Integer = 0, Parameter, "", "0: e_(-1) = 0 (derivative kick at t = 0); 1: e_(-1) = e_0", Choice(SWITCH);
    }
}

/// The law holds the whole error history (the FMU state).
#[derive(Clone, Serialize, Deserialize)]
pub struct PidController {
    law: PidLaw,
    /// The sample grid t_start + n h (n = samples in the history).
    clock: SampleCounter,
}

impl Model for PidController {
    type Vars = PidControllerVars;
    const CLOCKS: &'static [ClockDecl] = LAW_CLOCKS;
    fn time_grid(v: &PidControllerVars) -> Option<f64> {
        Some(v.step)
    }
    const EVOLVING: &'static [&'static str] = &["law.history"];
    const INFO: ModelInfo = ModelInfo {
        name: "PidController",
        description: "Discrete PID controller, the lambda = mu = 1 case of FopidController ([Khatoonabadi-FO])",
        source: "[Khatoonabadi-FO], Eqs. 16-17 with lambda = mu = 1",
        equations_html: "<pre>e_n = theta_ref(t_n) - theta(t_n)\n\
u_n = K_P e_n + K_I h sum_{j=0}^{min(n, L-1)} e_(n-j) + K_D (e_n - e_(n-1)) / h\n\
e_k = 0 for k &lt; 0; L = gl_memory (0 = full memory)</pre>\n\
<p>The error of t_n is appended to the history in doStep(t_n, h); the output read at t_n uses the inputs just set, so \
u depends directly on theta and theta_ref. A communication step must be an integer multiple k of the parameter step (h) starting at the next sample instant \
t_start + n h (n = samples taken: the schedule is an integer counter, never a sum of times); the inputs are \
held over it and the law takes k samples of the same error; any other step is an error. A master's rounding is \
tolerated: a step or communication point within 1e-10 of the time (at most 1e-3 h) of a multiple or instant is \
taken as it, which covers masters that sum t += h (1e5 steps drift by about 2e-12 of the time) and clip the \
last step to the stop time; a step of rounding size (k = 0) takes no sample. With history_before_start = 1 the derivative uses e_(-1) = e_0 (no derivative kick at t = 0); \
the integral always starts at t = 0. The same law as FopidController with lambda = mu = 1, written with a running \
sum (O(1) per step). The FMU state holds the whole history.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 20.0,
        default_step: 0.001,
        variable_step: false, // a constant step, any integer multiple of `step`
    };

    fn initialize(v: &mut PidControllerVars, exp: &Experiment) -> Result<Self, String> {
        let p = law_params(v.kp, v.ki, v.kd, 1.0, 1.0, v.step, v.gl_memory, v.history_before_start);
        Ok(PidController { law: PidLaw::new(p)?, clock: SampleCounter { start: exp.start_time, period: v.step } })
    }

    fn outputs(&self, v: &mut PidControllerVars, _t: f64) -> ModelResult {
        (v.u, v.error) = sampled_output(&self.law, v.theta_ref, v.theta)?;
        Ok(())
    }

    fn step(&mut self, v: &PidControllerVars, t: f64, h: f64) -> ModelResult {
        sampled_step(&mut self.law, &self.clock, t, h, v.theta_ref, v.theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    #[test]
    fn pid_difference_equation_by_hand() {
        let mut c = Fmu::<PidController>::default();
        (c.v.kp, c.v.ki, c.v.kd) = (2.0, 0.5, 3.0);
        c.initialize(&Experiment::default()).unwrap();
        let h = 0.001;
        let (mut sum, mut prev) = (0.0, 0.0);
        for n in 0..500 {
            let th = (n as f64 * 0.01).sin();
            c.v.theta = th;
            c.outputs(n as f64 * h).unwrap();
            let e = 0.0 - th;
            sum += e;
            let u = 2.0 * e + 0.5 * h * sum + 3.0 * (e - prev) / h;
            prev = e;
            assert!((c.v.u - u).abs() < 1e-10 * (1.0 + u.abs()), "n={n}: {} vs {u}", c.v.u);
            c.step(n as f64 * h, h).unwrap();
        }
        c.v.gl_memory = -3;
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("gl_memory"));
    }
}
