//! `FopidController` (paper 002): fractional PI^λD^μ law u = K_P e + K_I D^{-λ} e + K_D D^μ e on the
//! error e = θ_ref − θ, with Grünwald–Letnikov operators over the sampled error history
//! (`crate::math::fractional`, law in `shared::laws`).

use serde::{Deserialize, Serialize};

use super::shared::{LAW_CLOCKS, law_params, sampled_output, sampled_step, SampleCounter};
use crate::declare_variables;
use super::shared::laws::FopidLaw;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct FopidControllerVars {
        0 => theta: Real = 0.0, Input, "rad", "Measured angle theta";
        1 => theta_ref: Real = 0.0, Input, "rad", "Commanded angle theta_ref";
        10 => u: Real = 0.0, Output, "", "Wheel command u = K_P e + K_I D^-lambda e + K_D D^mu e";
        30 => error: Real = 0.0, Output, "rad", "Error e = theta_ref - theta";
        100 => kp: Real = 2.0, Parameter, "", "Proportional gain K_P (per rad; project default)";
        101 => ki: Real = 0.1, Parameter, "", "Integral gain K_I (per rad s^lambda; project default)";
        102 => kd: Real = 8.0, Parameter, "", "Derivative gain K_D (per rad s^-mu; project default)";
        103 => lambda: Real = 1.0, Parameter, "", "Integral order lambda", Range(0.0, 2.0);
        104 => mu: Real = 1.0, Parameter, "", "Derivative order mu", Range(0.0, 2.0);
        105 => step: Real = 0.001, Parameter, "s", "Sample time h; every communication step must be an integer multiple of it (to 1e-10 of the time, at most 1e-3 h)", Positive;
        120 => gl_memory: Integer = 0, Parameter, "", "Grunwald-Letnikov memory in samples (0 = full memory; L > 0 keeps the last L samples)", Range(0.0, 1e7);
        121 => history_before_start: Integer = 0, Parameter, "", "0: e_k = 0 for k < 0 (derivative kick at t = 0); 1: the derivative sees e_k = e_0 for k < 0", Choice(SWITCH);
    }
}

/// The law holds the whole error history (the FMU state).
#[derive(Clone, Serialize, Deserialize)]
pub struct FopidController {
    law: FopidLaw,
    /// The sample grid t_start + n h (n = samples in the history).
    clock: SampleCounter,
}

impl Model for FopidController {
    type Vars = FopidControllerVars;
    const CLOCKS: &'static [ClockDecl] = LAW_CLOCKS;
    fn time_grid(v: &FopidControllerVars) -> Option<f64> {
        Some(v.step)
    }
    const EVOLVING: &'static [&'static str] = &["law.history"];
    const INFO: ModelInfo = ModelInfo {
        name: "FopidController",
        description: "Fractional-order PI^lambda D^mu controller with Grunwald-Letnikov operators ([Khatoonabadi-FO])",
        source: "[Khatoonabadi-FO], Eqs. 16-17; Grunwald-Letnikov discretisation",
        equations_html: "<pre>e_n = theta_ref(t_n) - theta(t_n)\n\
u_n = K_P e_n + K_I D^(-lambda) e_n + K_D D^(mu) e_n\n\
D^alpha e(t_n) = h^(-alpha) sum_{j=0}^{min(n, L-1)} w_j e_(n-j),  w_0 = 1,  w_j = (1 - (alpha + 1)/j) w_(j-1)\n\
alpha = -lambda (integral), alpha = mu (derivative); e_k = 0 for k &lt; 0; L = gl_memory (0 = full memory)</pre>\n\
<p>The error of t_n is appended to the history in doStep(t_n, h); the output read at t_n uses the inputs just set, so \
u depends directly on theta and theta_ref. A communication step must be an integer multiple k of the parameter step (h) starting at the next sample instant \
t_start + n h (n = samples taken: the schedule is an integer counter, never a sum of times); the inputs are \
held over it and the law takes k samples of the same error; any other step is an error. A master's rounding is \
tolerated: a step or communication point within 1e-10 of the time (at most 1e-3 h) of a multiple or instant is \
taken as it, which covers masters that sum t += h (1e5 steps drift by about 2e-12 of the time) and clip the \
last step to the stop time; a step of rounding size (k = 0) takes no sample. With history_before_start = 1 the derivative term sees a constant past e_k = e_0 (no derivative \
kick at t = 0); the integral always starts at t = 0. lambda = mu = 1 is the integer PID (PidController). \
The sums are evaluated exactly (to round-off) in O(log^2 n) amortised time per step: the 64 newest samples \
directly, older ones in FFT blocks. The FMU state holds the whole history.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 20.0,
        default_step: 0.001,
        variable_step: false, // a constant step, any integer multiple of `step`
    };

    fn initialize(v: &mut FopidControllerVars, exp: &Experiment) -> Result<Self, String> {
        let p = law_params(v.kp, v.ki, v.kd, v.lambda, v.mu, v.step, v.gl_memory, v.history_before_start);
        Ok(FopidController { law: FopidLaw::new(p)?, clock: SampleCounter { start: exp.start_time, period: v.step } })
    }

    fn outputs(&self, v: &mut FopidControllerVars, _t: f64) -> ModelResult {
        (v.u, v.error) = sampled_output(&self.law, v.theta_ref, v.theta)?;
        Ok(())
    }

    fn step(&mut self, v: &FopidControllerVars, t: f64, h: f64) -> ModelResult {
        sampled_step(&mut self.law, &self.clock, t, h, v.theta_ref, v.theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn ctrl(setup: impl FnOnce(&mut FopidControllerVars)) -> Result<Fmu<FopidController>, String> {
        let mut c = Fmu::<FopidController>::default();
        setup(&mut c.v);
        c.initialize(&Experiment::default())?;
        Ok(c)
    }

    #[test]
    fn bad_parameters_name_the_parameter() {
        for (name, e) in [
            ("lambda", ctrl(|v| v.lambda = 2.5).err().unwrap()),
            ("mu", ctrl(|v| v.mu = -0.1).err().unwrap()),
            ("gl_memory", ctrl(|v| v.gl_memory = -1).err().unwrap()),
            ("step", ctrl(|v| v.step = 0.0).err().unwrap()),
            ("history_before_start", ctrl(|v| v.history_before_start = 2).err().unwrap()),
        ] {
            assert!(e.contains(name), "{name}: {e}");
        }
    }

    #[test]
    fn other_step_is_refused_and_outputs_are_pure() {
        let mut c = ctrl(|v| (v.theta_ref, v.lambda, v.mu) = (0.5, 0.6, 1.4)).unwrap();
        c.outputs(0.0).unwrap();
        let u0 = c.v.u;
        c.outputs(0.0).unwrap();
        assert_eq!(u0.to_bits(), c.v.u.to_bits());
        c.step(0.0, 0.001).unwrap();
        let e = c.step(0.001, 0.0015).unwrap_err();
        assert!(e.contains("integer multiple") && e.contains("step = 0.001"), "{e}");
        assert!(c.step(0.001, 1e4).unwrap_err().contains("at most"));
        // a step of k sample times takes k samples of the held error: the same as k single steps
        let mut d = ctrl(|v| (v.theta_ref, v.lambda, v.mu) = (0.5, 0.6, 1.4)).unwrap();
        d.step(0.0, 0.001).unwrap();
        for k in 0..3 {
            d.step(0.001 + k as f64 * 0.001, 0.001).unwrap();
        }
        c.step(0.001, 0.003).unwrap();
        assert_eq!(c.model().law.history(), d.model().law.history());
        c.outputs(0.004).unwrap();
        d.outputs(0.004).unwrap();
        assert_eq!(c.v.u.to_bits(), d.v.u.to_bits());
        // u_0 = K_P e + K_I h^λ e + K_D h^-μ e with e = 0.5
        let expect = 0.5 * (2.0 + 0.1 * 0.001f64.powf(0.6) + 8.0 * 0.001f64.powf(-1.4));
        assert!((u0 - expect).abs() < 1e-12 * expect, "{u0} vs {expect}");
    }
}
