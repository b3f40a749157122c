//! `PidController` (paper 002): integer PID u = K_P e + K_I h Σ e_j + K_D (e_n − e_{n−1})/h on the error
//! e = θ_ref − θ, the λ = μ = 1 case of `FopidController` with a running sum and a backward difference
//! (`crate::math::fractional::PidLaw`).

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::fractional::{PidLaw, FopidParams};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct PidControllerVars {
        0 => theta: Real = 0.0, Input, Continuous, "rad", "Measured angle theta";
        1 => theta_ref: Real = 0.0, Input, Continuous, "rad", "Commanded angle theta_ref";
        10 => u: Real = 0.0, Output, Continuous, "", "Wheel command u = K_P e + K_I h sum(e) + K_D (e_n - e_n-1)/h";
        11 => error: Real = 0.0, Output, Continuous, "rad", "Error e = theta_ref - theta";
        100 => kp: Real = 2.0, Parameter, Fixed, "", "Proportional gain K_P (per rad; project default)";
        101 => ki: Real = 0.1, Parameter, Fixed, "1/s", "Integral gain K_I (per rad s; project default)";
        102 => kd: Real = 8.0, Parameter, Fixed, "s", "Derivative gain K_D (s per rad; project default)";
        105 => step: Real = 0.001, Parameter, Fixed, "s", "Sample time h; every communication step must equal it";
        120 => gl_memory: Integer = 0, Parameter, Fixed, "", "Memory in samples (0 = full; L > 0: the integral sums the last L samples)";
        121 => history_before_start: Integer = 0, Parameter, Fixed, "", "0: e_k = 0 for k < 0 (derivative kick at t = 0); 1: the derivative sees e_k = e_0 for k < 0";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct PidController {
    v: PidControllerVars,
    law: Option<PidLaw>,
}

impl Model for PidController {
    type Vars = PidControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "PidController",
        description: "Discrete PID controller, the lambda = mu = 1 case of FopidController (paper 002)",
        source: "paper 002 Eqs. 16-17 with lambda = mu = 1",
        equations_html: "<pre>e_n = theta_ref(t_n) - theta(t_n)\n\
u_n = K_P e_n + K_I h sum_{j=0}^{min(n, L-1)} e_(n-j) + K_D (e_n - e_(n-1)) / h\n\
e_k = 0 for k &lt; 0; L = gl_memory (0 = full memory)</pre>\n\
<p>The error of t_n is appended to the history in doStep(t_n, h); the output read at t_n uses the inputs just set, so \
u depends directly on theta and theta_ref. Every communication step must equal the parameter step (h); any other \
step is an error. With history_before_start = 1 the derivative uses e_(-1) = e_0 (no derivative kick at t = 0); \
the integral always starts at t = 0. The same law as FopidController with lambda = mu = 1, written with a running \
sum (O(1) per step). The FMU state holds the whole history.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 20.0,
        default_step: 0.001,
        variable_step: false,
    };

    fn vars(&self) -> &PidControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut PidControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let memory = check::non_negative("gl_memory", v.gl_memory as f64)? as usize;
        let hbs = check::choice("history_before_start", v.history_before_start, &[0, 1])? == 1;
        let h = check::positive("step", v.step)?;
        for (n, x) in [("kp", v.kp), ("ki", v.ki), ("kd", v.kd)] {
            check::finite(n, x)?;
        }
        let p = FopidParams { kp: v.kp, ki: v.ki, kd: v.kd, lambda: 1.0, mu: 1.0, h, memory, history_before_start: hbs };
        self.law = Some(PidLaw::new(p)?);
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let law = self.law.as_ref().ok_or("controller was not initialized")?;
        let e = self.v.theta_ref - self.v.theta;
        let u = law.output(e);
        if !u.is_finite() {
            return Err(format!("u = {u} is not finite (e = {e})"));
        }
        (self.v.u, self.v.error) = (u, e);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let step = self.v.step;
        if (h - step).abs() > 1e-9 * step {
            return Err(format!("communication step {h} s differs from the sample time step = {step} s (the error history is sampled at step)"));
        }
        let e = self.v.theta_ref - self.v.theta;
        if !e.is_finite() {
            return Err(format!("error e = {e} is not finite"));
        }
        self.law.as_mut().ok_or("controller was not initialized")?.push(e);
        Ok(())
    }
}
