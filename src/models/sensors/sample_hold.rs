//! `SampleHold`: a flight computer's timing for a vector of signals — zero-order hold at a sample
//! period with a computation delay (whole samples or a fraction), so a continuous controller placed
//! before it becomes a sampled one.

use serde::{Deserialize, Serialize};

use super::shared::{sample_index, max_queue, DelayLine};
use crate::declare_variables;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

/// Number of channels.
pub const CHANNELS: usize = 8;

declare_variables! {
    pub struct SampleHoldVars {
        0 => u_1: Real = 0.0, Input, "", "Channel 1 in";
        1 => u_2: Real = 0.0, Input, "", "Channel 2 in";
        2 => u_3: Real = 0.0, Input, "", "Channel 3 in";
        3 => u_4: Real = 0.0, Input, "", "Channel 4 in";
        4 => u_5: Real = 0.0, Input, "", "Channel 5 in";
        5 => u_6: Real = 0.0, Input, "", "Channel 6 in";
        6 => u_7: Real = 0.0, Input, "", "Channel 7 in";
        7 => u_8: Real = 0.0, Input, "", "Channel 8 in";
        20 => y_1: Real = 0.0, Output, "", "Channel 1 out: u_1 sampled, delayed and held";
        21 => y_2: Real = 0.0, Output, "", "Channel 2 out";
        22 => y_3: Real = 0.0, Output, "", "Channel 3 out";
        23 => y_4: Real = 0.0, Output, "", "Channel 4 out";
        24 => y_5: Real = 0.0, Output, "", "Channel 5 out";
        25 => y_6: Real = 0.0, Output, "", "Channel 6 out";
        26 => y_7: Real = 0.0, Output, "", "Channel 7 out";
        27 => y_8: Real = 0.0, Output, "", "Channel 8 out";
        100 => sample_period: Real = 0.1, Parameter, "s", "Sample period T of the flight computer", Range(1e-6, 1e4);
        101 => delay: Real = 0.0, Parameter, "s", "Computation delay d (any multiple or fraction of T): the sample of t_k is output from t_k + d", Range(0.0, 1e4);
        102 => initial_output: Real = 0.0, Parameter, "", "Output of every channel before the first delivery (t < d)";
        200 => delay_samples: Real = 0.0, CalculatedParameter, "", "Delay in sample periods d / T";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct SampleHold {
    period: f64,
    delay: f64,
    k0: i64,
    line: DelayLine<[f64; CHANNELS]>,
}

fn inputs(v: &SampleHoldVars) -> [f64; CHANNELS] {
    [v.u_1, v.u_2, v.u_3, v.u_4, v.u_5, v.u_6, v.u_7, v.u_8]
}

impl Model for SampleHold {
    type Vars = SampleHoldVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: the inputs are latched at each tick",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &[],
        },
        ClockDecl {
            name: "delivery_clock",
            description: "Delivery clock: at each tick (sample instant + delay) the delivered sample is output and held",
            interval: "sample_period",
            shift: "delay",
            steps: false,
            outputs: &["y_1", "y_2", "y_3", "y_4", "y_5", "y_6", "y_7", "y_8"],
        },
    ];
    fn time_grid(v: &SampleHoldVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["line"];
    const INFO: ModelInfo = ModelInfo {
        name: "SampleHold",
        description: "Zero-order hold of 8 signals at a flight-computer period with a computation delay (whole samples or a fraction)",
        source: "sampled-data timing of a flight computer ([Franklin-Powell-Workman-1998] Ch. 4: zero-order hold, computation delay); project choice",
        equations_html: concat!("<pre>samples at t_k = k T (k = 0, 1, ...):  y(t) = u(t_k)  for  t_k + d <= t < t_k+1 + d\n\
i.e. y(t) = u(floor((t - d)/T) T), and y = initial_output for t < d\n\
d = m T (whole samples) or any fraction; delay_samples = d / T</pre>\n\
<p>Placed after a controller whose inputs are the sensors' outputs, it turns the controller into a sampled one \
whose command computed at t_k is applied from t_k + d. A sample strictly inside a communication step sees the \
input held at the step's start; with T and d multiples of the communication step the staircase is exact.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SampleHoldVars, exp: &Experiment) -> Result<Self, String> {
        if v.delay / v.sample_period > 1e6 {
            return Err(format!("parameters delay = {} and sample_period = {}: the delay is more than 1e6 sample periods", v.delay, v.sample_period));
        }
        v.delay_samples = v.delay / v.sample_period;
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        Ok(SampleHold { period: v.sample_period, delay: v.delay, k0, line: DelayLine::new([v.initial_output; CHANNELS], k0) })
    }

    fn outputs(&self, v: &mut SampleHoldVars, t: f64) -> ModelResult {
        let u = inputs(v);
        let (y, _) = self.line.at(t, self.period, self.delay, |_| u, |_| true)?;
        [v.y_1, v.y_2, v.y_3, v.y_4, v.y_5, v.y_6, v.y_7, v.y_8] = y;
        Ok(())
    }

    fn step(&mut self, v: &SampleHoldVars, t: f64, h: f64) -> ModelResult {
        let u = inputs(v);
        let mut line = self.line.clone();
        line.advance(t, h, self.period, self.delay, |_| u, |_| true)?;
        self.line = line;
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.line.check(max_queue(self.period, self.delay), self.k0)?;
        // before the first delivery the held value is the initial output
        if self.line.last < self.k0 && self.line.held != fresh.line.held {
            return Err("restored state: held value before any sample differs from initial_output".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    /// The staircase of an independent reference: u(t) = sin(3t) + t on the communication grid, sampled at
    /// k T and shifted by d: y(t) = u(floor((t - d)/T) T), computed here with integer arithmetic on the grid.
    #[test]
    fn hold_and_delay_reproduce_the_shifted_staircase_exactly() {
        let u = |t: f64| (3.0 * t).sin() + t;
        // communication step h = T / 8; delays in whole samples (0, 1, 3) and fractions (3/8, 1 + 5/8)
        let (h, per) = (0.0125, 8i64);
        let period = h * per as f64;
        for delay_steps in [0i64, 8, 24, 3, 13] {
            let mut f = Fmu::<SampleHold>::default();
            f.v.sample_period = period;
            f.v.delay = delay_steps as f64 * h;
            f.v.initial_output = -7.0;
            f.initialize(&Experiment::default()).unwrap();
            assert!((f.v.delay_samples - delay_steps as f64 / 8.0).abs() < 1e-12);
            for n in 0..400i64 {
                let t = n as f64 * h;
                f.v.u_1 = u(t);
                f.v.u_8 = -u(t);
                f.outputs(t).unwrap();
                // grid index of the delivered sample: the last multiple of `per` at or below n - delay_steps
                let m = n - delay_steps;
                let want = if m < 0 { -7.0 } else { u((m.div_euclid(per) * per) as f64 * h) };
                assert_eq!(f.v.y_1, want, "delay {delay_steps} h, n = {n}");
                assert_eq!(f.v.y_8, if m < 0 { -7.0 } else { -want });
                f.step(t, h).unwrap();
            }
        }
    }

    #[test]
    fn bad_delay_is_named() {
        let mut f = Fmu::<SampleHold>::default();
        f.v.delay = -0.1;
        assert!(f.initialize(&Experiment::default()).unwrap_err().contains("delay"));
        (f.v.delay, f.v.sample_period) = (100.0, 1e-5);
        assert!(f.initialize(&Experiment::default()).unwrap_err().contains("delay = 100"));
    }
}
