//! The single-axis controllers' laws: the fractional PI^λD^μ law on Grünwald–Letnikov sums
//! (`crate::math::fractional`) and the integer PID written with a running sum ([Khatoonabadi-FO]
//! Eqs. 16–17).
//!
//! Both store the error history once and nothing else that evolves: what the GL sums keep besides it
//! (weights, pending block products, partial sums of weights, the PID's running sum) is rebuilt from
//! the history when a state is decoded, with the same arithmetic in the same order as the online
//! pushes, so a restored law continues bit-identically. The serialized form is the parameters and
//! the history (8 bytes per sample).

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::math::fractional::GlKernel;

/// Longest GL memory in samples (80 MB of history): bounds what a parameter or a decoded state can
/// make the law allocate.
pub const MAX_MEMORY: usize = 10_000_000;

/// Parameters of the PI^λD^μ law u_n = K_P e_n + K_I D^{-λ} e_n + K_D D^μ e_n ([Khatoonabadi-FO] Eqs. 16–17).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FopidParams {
    pub kp: f64,
    pub ki: f64,
    pub kd: f64,
    pub lambda: f64,
    pub mu: f64,
    /// Sample time h (s).
    pub h: f64,
    /// GL memory in samples (0 = full memory).
    pub memory: usize,
    /// true: the derivative sees e_k = e_0 for k < 0 (no derivative kick); false: e_k = 0.
    pub history_before_start: bool,
}

impl FopidParams {
    /// Checks the values; the message names the offending parameter.
    pub fn validate(&self) -> Result<(), String> {
        for (n, v) in [("kp", self.kp), ("ki", self.ki), ("kd", self.kd)] {
            if !v.is_finite() {
                return Err(format!("parameter {n} = {v} is not finite"));
            }
        }
        for (n, v) in [("lambda", self.lambda), ("mu", self.mu)] {
            if !(v.is_finite() && (0.0..=2.0).contains(&v)) {
                return Err(format!("parameter {n} = {v} must lie in [0, 2]"));
            }
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(format!("parameter step = {} must be > 0", self.h));
        }
        if self.memory > MAX_MEMORY {
            return Err(format!(
                "parameter gl_memory = {} must lie in [0, {MAX_MEMORY}]",
                self.memory
            ));
        }
        Ok(())
    }
}

/// What a law's state is on the wire: its parameters and the error history.
#[derive(Serialize)]
struct StoredRef<'a> {
    p: &'a FopidParams,
    fast: bool,
    history: &'a [f64],
}

#[derive(Deserialize)]
struct Stored {
    p: FopidParams,
    fast: bool,
    history: Vec<f64>,
}

impl Stored {
    /// Whether a number of the stored law is NaN or infinite. Such a law is decoded as stored and not
    /// built (no kernels from it): the restored-state check of every model (`leaves::check_all_finite`)
    /// then refuses it naming the field, which a decoder error could not (postcard drops its text).
    fn non_finite(&self) -> bool {
        let p = &self.p;
        ![p.kp, p.ki, p.kd, p.lambda, p.mu, p.h]
            .iter()
            .chain(&self.history)
            .all(|x| x.is_finite())
    }
}

/// Fractional PI^λD^μ law on the GL sums; the error history is the whole state.
#[derive(Clone)]
pub struct FopidLaw {
    p: FopidParams,
    fast: bool,
    /// e_0 … e_{n-1}
    history: Vec<f64>,
    // derived from p and the history (never serialized)
    integral: GlKernel,
    derivative: GlKernel,
    /// partial sums S_n = Σ_{j≤n} w_j of the derivative weights (history_before_start only)
    wsum: Vec<f64>,
    /// h^{λ}, h^{-μ}
    scale_i: f64,
    scale_d: f64,
}

impl Serialize for FopidLaw {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        StoredRef {
            p: &self.p,
            fast: self.fast,
            history: &self.history,
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for FopidLaw {
    /// Checks the parameters (so that nothing is allocated from absurd ones), then rebuilds the
    /// derived buffers from the history.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = Stored::deserialize(d)?;
        if s.non_finite() {
            let kernel = || GlKernel::new(0.0, 0, s.fast);
            return Ok(FopidLaw {
                integral: kernel(),
                derivative: kernel(),
                wsum: Vec::new(),
                scale_i: f64::NAN,
                scale_d: f64::NAN,
                p: s.p,
                fast: s.fast,
                history: s.history,
            });
        }
        FopidLaw::from_history(s.p, s.fast, s.history).map_err(serde::de::Error::custom)
    }
}

impl FopidLaw {
    pub fn new(p: FopidParams) -> Result<Self, String> {
        Self::with_evaluation(p, true)
    }

    /// `fast` = false evaluates every GL sum directly (reference and benchmark).
    pub fn with_evaluation(p: FopidParams, fast: bool) -> Result<Self, String> {
        Self::from_history(p, fast, Vec::new())
    }

    /// The law after the samples `history` were pushed one by one (bit-identical to the online pushes).
    pub fn from_history(p: FopidParams, fast: bool, history: Vec<f64>) -> Result<Self, String> {
        p.validate()?;
        let integral = if p.ki != 0.0 {
            GlKernel::rebuild(-p.lambda, p.memory, fast, &history)
        } else {
            GlKernel::new(-p.lambda, p.memory, fast)
        };
        let derivative = GlKernel::rebuild(p.mu, p.memory, fast, &history);
        let mut law = FopidLaw {
            p,
            fast,
            history,
            integral,
            derivative,
            wsum: Vec::new(),
            scale_i: p.h.powf(p.lambda),
            scale_d: p.h.powf(-p.mu),
        };
        if p.history_before_start {
            law.extend_wsum(if p.memory > 0 { p.memory } else { 1 });
            law.extend_wsum(law.history.len() + 1);
        }
        Ok(law)
    }

    pub fn params(&self) -> &FopidParams {
        &self.p
    }
    /// Number of samples in the history.
    pub fn len(&self) -> usize {
        self.history.len()
    }
    pub fn is_empty(&self) -> bool {
        self.history.is_empty()
    }
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// D^{-λ} e_n and D^μ e_n for the current error e_n (state unchanged).
    pub fn terms(&self, e: f64) -> (f64, f64) {
        let i = if self.p.ki != 0.0 {
            self.scale_i * self.integral.eval(&self.history, e)
        } else {
            0.0
        };
        let mut d = self.derivative.eval(&self.history, e);
        if self.p.history_before_start {
            // e_k = e_0 for k < 0 adds e_0 Σ_{j=n+1}^{L-1} w_j (full memory: Σ_{j>n} w_j = S_∞ - S_n,
            // with S_∞ = 0 for μ > 0 and 1 for μ = 0)
            let e0 = self.history.first().copied().unwrap_or(e);
            d += e0 * self.tail_weight();
        }
        (i, self.scale_d * d)
    }

    /// Σ_{j=n+1}^{L-1} w_j for the derivative (full memory: S_∞ - S_n with S_∞ = 0 for μ > 0, 1 for μ = 0).
    fn tail_weight(&self) -> f64 {
        let n = self.history.len();
        let s = &self.wsum;
        let mem = self.p.memory;
        if mem > 0 {
            if n + 1 >= mem {
                0.0
            } else {
                s[mem - 1] - s[n]
            }
        } else {
            let s_inf = if self.p.mu == 0.0 { 1.0 } else { 0.0 };
            s_inf - s[n]
        }
    }

    fn extend_wsum(&mut self, len: usize) {
        while self.wsum.len() < len {
            let j = self.wsum.len();
            let w = self.derivative.weight(j);
            self.wsum.push(self.wsum.last().copied().unwrap_or(0.0) + w);
        }
    }

    /// Control output u_n for the current error e_n (state unchanged).
    pub fn output(&self, e: f64) -> f64 {
        let (i, d) = self.terms(e);
        self.p.kp * e + self.p.ki * i + self.p.kd * d
    }

    /// Appends e_n to the history (called once per sample with the error of t_n).
    pub fn push(&mut self, e: f64) {
        self.history.push(e);
        if self.p.ki != 0.0 {
            self.integral.push(&self.history);
        }
        self.derivative.push(&self.history);
        if self.p.history_before_start {
            let n = self.history.len();
            self.extend_wsum(n + 1);
        }
    }
}

/// Integer PID u_n = K_P e_n + K_I h Σ_{j} e_{n-j} + K_D (e_n - e_{n-1})/h: the λ = μ = 1 case of
/// [`FopidLaw`] written with a running sum and a backward difference (O(1) per step). With a memory
/// L > 0 the sum covers the last L samples (short-memory principle).
#[derive(Clone)]
pub struct PidLaw {
    p: FopidParams,
    /// whole error history (the integral window and the state to save)
    history: Vec<f64>,
    /// Σ of the samples inside the memory window (derived from the history, never serialized)
    sum: f64,
}

impl Serialize for PidLaw {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        StoredRef {
            p: &self.p,
            fast: true,
            history: &self.history,
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for PidLaw {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = Stored::deserialize(d)?;
        if s.non_finite() {
            return Ok(PidLaw {
                p: s.p,
                history: s.history,
                sum: f64::NAN,
            });
        }
        // the PID is the λ = μ = 1 law with the exact running sum: anything else is not its state
        if !s.fast || s.p.lambda != 1.0 || s.p.mu != 1.0 {
            return Err(serde::de::Error::custom(
                "PID law state with orders other than 1 or without fast = true",
            ));
        }
        PidLaw::from_history(s.p, s.history).map_err(serde::de::Error::custom)
    }
}

impl PidLaw {
    pub fn new(p: FopidParams) -> Result<Self, String> {
        Self::from_history(p, Vec::new())
    }

    /// The law after the samples `history` were pushed one by one (bit-identical running sum).
    pub fn from_history(mut p: FopidParams, history: Vec<f64>) -> Result<Self, String> {
        p.lambda = 1.0;
        p.mu = 1.0;
        p.validate()?;
        let mut law = PidLaw {
            p,
            history: Vec::with_capacity(history.len()),
            sum: 0.0,
        };
        for e in history {
            law.push(e);
        }
        Ok(law)
    }

    pub fn len(&self) -> usize {
        self.history.len()
    }
    pub fn is_empty(&self) -> bool {
        self.history.is_empty()
    }
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    pub fn output(&self, e: f64) -> f64 {
        let n = self.history.len();
        let mem = self.p.memory;
        // window Σ_{j=0}^{min(n, L-1)} e_{n-j}
        let dropped = if mem > 0 && n + 1 > mem {
            self.history[n - mem]
        } else {
            0.0
        };
        let window = self.sum + e - dropped;
        let prev = match self.history.last() {
            Some(&x) => x,
            None if self.p.history_before_start => e,
            None => 0.0,
        };
        // short memory with L = 1 drops e_{n-1} from the derivative too
        let prev = if mem == 1 { 0.0 } else { prev };
        self.p.kp * e + self.p.ki * (self.p.h * window) + self.p.kd * ((e - prev) / self.p.h)
    }

    pub fn push(&mut self, e: f64) {
        let n = self.history.len();
        let mem = self.p.memory;
        self.sum += e;
        if mem > 0 && n + 1 > mem {
            self.sum -= self.history[n - mem];
        }
        self.history.push(e);
    }
}

#[cfg(test)]
#[path = "laws_tests.rs"]
mod tests;
