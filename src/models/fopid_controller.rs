//! `FopidController` (paper 002): fractional PI^λD^μ law u = K_P e + K_I D^{-λ} e + K_D D^μ e on the
//! error e = θ_ref − θ, with Grünwald–Letnikov operators over the sampled error history
//! (`crate::math::fractional`).

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::fractional::{FopidLaw, FopidParams};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct FopidControllerVars {
        0 => theta: Real = 0.0, Input, Continuous, "rad", "Measured angle theta";
        1 => theta_ref: Real = 0.0, Input, Continuous, "rad", "Commanded angle theta_ref";
        10 => u: Real = 0.0, Output, Continuous, "", "Wheel command u = K_P e + K_I D^-lambda e + K_D D^mu e";
        11 => error: Real = 0.0, Output, Continuous, "rad", "Error e = theta_ref - theta";
        100 => kp: Real = 2.0, Parameter, Fixed, "", "Proportional gain K_P (per rad; project default)";
        101 => ki: Real = 0.1, Parameter, Fixed, "", "Integral gain K_I (per rad s^lambda; project default)";
        102 => kd: Real = 8.0, Parameter, Fixed, "", "Derivative gain K_D (per rad s^-mu; project default)";
        103 => lambda: Real = 1.0, Parameter, Fixed, "", "Integral order lambda in [0, 2]";
        104 => mu: Real = 1.0, Parameter, Fixed, "", "Derivative order mu in [0, 2]";
        105 => step: Real = 0.001, Parameter, Fixed, "s", "Sample time h; every communication step must equal it";
        120 => gl_memory: Integer = 0, Parameter, Fixed, "", "Grunwald-Letnikov memory in samples (0 = full memory; L > 0 keeps the last L samples)";
        121 => history_before_start: Integer = 0, Parameter, Fixed, "", "0: e_k = 0 for k < 0 (derivative kick at t = 0); 1: the derivative sees e_k = e_0 for k < 0";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct FopidController {
    v: FopidControllerVars,
    law: Option<FopidLaw>,
}

impl Model for FopidController {
    type Vars = FopidControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "FopidController",
        description: "Fractional-order PI^lambda D^mu controller with Grunwald-Letnikov operators (paper 002)",
        source: "paper 002 Eqs. 16-17; Grunwald-Letnikov discretisation",
        equations_html: "<pre>e_n = theta_ref(t_n) - theta(t_n)\n\
u_n = K_P e_n + K_I D^(-lambda) e_n + K_D D^(mu) e_n\n\
D^alpha e(t_n) = h^(-alpha) sum_{j=0}^{min(n, L-1)} w_j e_(n-j),  w_0 = 1,  w_j = (1 - (alpha + 1)/j) w_(j-1)\n\
alpha = -lambda (integral), alpha = mu (derivative); e_k = 0 for k &lt; 0; L = gl_memory (0 = full memory)</pre>\n\
<p>The error of t_n is appended to the history in doStep(t_n, h); the output read at t_n uses the inputs just set, so \
u depends directly on theta and theta_ref. Every communication step must equal the parameter step (h); any other \
step is an error. With history_before_start = 1 the derivative term sees a constant past e_k = e_0 (no derivative \
kick at t = 0); the integral always starts at t = 0. lambda = mu = 1 is the integer PID (PidController). \
The sums are evaluated exactly (to round-off) in O(log^2 n) amortised time per step: the 64 newest samples \
directly, older ones in FFT blocks. The FMU state holds the whole history.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 20.0,
        default_step: 0.001,
        variable_step: false,
    };

    fn vars(&self) -> &FopidControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut FopidControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let memory = check::non_negative("gl_memory", v.gl_memory as f64)? as usize;
        let hbs = check::choice("history_before_start", v.history_before_start, &[0, 1])? == 1;
        let h = check::positive("step", v.step)?;
        let p = FopidParams { kp: v.kp, ki: v.ki, kd: v.kd, lambda: v.lambda, mu: v.mu, h, memory, history_before_start: hbs };
        self.law = Some(FopidLaw::new(p)?);
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
            return Err(format!("communication step {h} s differs from the sample time step = {step} s (the fractional history is sampled at step)"));
        }
        let e = self.v.theta_ref - self.v.theta;
        if !e.is_finite() {
            return Err(format!("error e = {e} is not finite"));
        }
        self.law.as_mut().ok_or("controller was not initialized")?.push(e);
        Ok(())
    }
}
