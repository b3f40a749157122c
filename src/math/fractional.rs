//! Grünwald–Letnikov (GL) fractional derivatives and integrals of a sampled signal, and the PID /
//! fractional PI^λD^μ control laws built on them (paper 002).
//!
//! For a signal sampled at t_k = k h (e_k = 0 for k < 0) the GL approximation of order α is
//! ```text
//!   D^α e(t_n) ≈ h^{-α} Σ_{j=0}^{min(n, L-1)} w_j e_{n-j},   w_0 = 1,   w_j = (1 - (α + 1)/j) w_{j-1}
//! ```
//! with w_j = (-1)^j binom(α, j); α > 0 is a derivative, α < 0 an integral (α = -1 is the rectangle
//! rule h Σ e_j), and L the memory length in samples (0 = full memory; L > 0 is the short-memory
//! principle, which drops samples older than L - 1 steps).
//!
//! [`GlConvolution`] evaluates the sum online, one new sample per step. A direct evaluation costs O(n)
//! per step, so a full-memory run of N steps costs O(N²). The fast mode computes exactly the same sum
//! with a different association of the terms: the weights w_j with j < [`NEAR`] are applied directly,
//! and the older part of the history is convolved in blocks with FFTs (a "semi-relaxed" online
//! convolution: weight block [L, 2L) times each completed history chunk of length L, for
//! L = NEAR, 2 NEAR, 4 NEAR, …), whose products are added to a buffer of future outputs before those
//! outputs are needed. The amortised cost is O(log² n) per step and the result equals the direct sum to
//! floating-point round-off.

use std::sync::Arc;

use rustfft::{num_complex::Complex, Fft, FftPlanner};
use serde::{Deserialize, Serialize};

/// Number of most recent weights applied directly in the fast mode (a power of two).
pub const NEAR: usize = 64;

/// GL weights w_0 … w_{n-1} of order α by the recursion w_j = (1 - (α + 1)/j) w_{j-1}.
pub fn gl_weights(alpha: f64, n: usize) -> Vec<f64> {
    let mut w = Vec::with_capacity(n);
    extend_weights(alpha, &mut w, n);
    w
}

fn extend_weights(alpha: f64, w: &mut Vec<f64>, n: usize) {
    if w.is_empty() && n > 0 {
        w.push(1.0);
    }
    while w.len() < n {
        let j = w.len();
        let prev = w[j - 1];
        w.push((1.0 - (alpha + 1.0) / j as f64) * prev);
    }
}

/// Direct GL sum Σ_{j=0}^{min(n, L-1)} w_j e_{n-j} at the last sample n = e.len() - 1 (no h factor).
/// `weights` must hold at least min(n + 1, L) entries; `memory` = L (0 = full memory).
pub fn gl_sum_direct(weights: &[f64], e: &[f64], memory: usize) -> f64 {
    let n1 = e.len();
    let m = if memory == 0 { n1 } else { n1.min(memory) };
    // four partial sums: the same terms, summed in a vectorisable order
    let w = &weights[..m];
    let x = &e[n1 - m..];
    let mut acc = [0.0f64; 4];
    let chunks = m / 4;
    for c in 0..chunks {
        for (k, a) in acc.iter_mut().enumerate() {
            let j = 4 * c + k;
            *a += w[j] * x[m - 1 - j];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for j in 4 * chunks..m {
        s += w[j] * x[m - 1 - j];
    }
    s
}

/// GL fractional derivative (α > 0) or integral (α < 0) of the samples `e` (e_k = 0 for k < 0) at every
/// sample, by the direct sum: returns h^{-α} Σ_{j=0}^{min(n, L-1)} w_j e_{n-j} for n = 0 … e.len()-1.
pub fn gl_series(alpha: f64, h: f64, e: &[f64], memory: usize) -> Vec<f64> {
    let w = gl_weights(alpha, if memory == 0 { e.len() } else { memory.min(e.len()) });
    let scale = h.powf(-alpha);
    (0..e.len()).map(|n| scale * gl_sum_direct(&w, &e[..=n], memory)).collect()
}

/// FFT plans and weight spectrum of one block level (rebuilt on demand, never serialized).
struct Level {
    fwd: Arc<dyn Fft<f64>>,
    inv: Arc<dyn Fft<f64>>,
    /// FFT (size 2L) of the weight block w_L … w_{2L-1}, scaled by 1/(2L); None if the block is all zero.
    w_hat: Option<Vec<Complex<f64>>>,
}

#[derive(Clone, Default)]
struct FftCache {
    levels: Vec<Option<Arc<Level>>>,
}

/// Online GL sum s_n = Σ_{j=0}^{min(n, L-1)} w_j e_{n-j} of a signal that arrives one sample per step.
/// [`eval`](Self::eval) gives s_n for a candidate e_n without changing the state; [`push`](Self::push)
/// appends e_n. The serialized state holds the whole history (and the pending block products), so a
/// restored copy continues bit-identically.
#[derive(Clone, Serialize, Deserialize)]
pub struct GlConvolution {
    alpha: f64,
    memory: usize,
    fast: bool,
    /// w_0 … (never longer than `memory` when memory > 0)
    weights: Vec<f64>,
    /// e_0 … e_{n-1}
    history: Vec<f64>,
    /// far[n] = block products Σ_{j ≥ NEAR} w_j e_{n-j} accumulated so far (fast mode)
    far: Vec<f64>,
    #[serde(skip)]
    cache: FftCache,
}

impl GlConvolution {
    /// Order `alpha`, memory `memory` samples (0 = full), `fast` = block-FFT evaluation.
    pub fn new(alpha: f64, memory: usize, fast: bool) -> Self {
        let mut c = GlConvolution { alpha, memory, fast, weights: Vec::new(), history: Vec::new(), far: Vec::new(), cache: FftCache::default() };
        c.ensure_weights(NEAR.max(2));
        c
    }

    pub fn alpha(&self) -> f64 {
        self.alpha
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

    fn ensure_weights(&mut self, n: usize) {
        let n = if self.memory == 0 { n } else { n.min(self.memory) };
        extend_weights(self.alpha, &mut self.weights, n);
    }

    /// Weight w_j, zero beyond the memory.
    pub fn weight(&mut self, j: usize) -> f64 {
        if self.memory > 0 && j >= self.memory {
            return 0.0;
        }
        self.ensure_weights(j + 1);
        self.weights[j]
    }

    /// Partial sum of the weights S_n = Σ_{j=0}^{min(n, L-1)} w_j.
    pub fn weight_partial_sum(&mut self, n: usize) -> f64 {
        let m = if self.memory == 0 { n + 1 } else { (n + 1).min(self.memory) };
        self.ensure_weights(m);
        self.weights[..m].iter().sum()
    }

    /// s_n with e_n = `e_now`, n = number of samples pushed so far. Does not change the state.
    pub fn eval(&self, e_now: f64) -> f64 {
        let n = self.history.len();
        let m = if self.memory == 0 { n + 1 } else { (n + 1).min(self.memory) };
        if !self.fast {
            // direct: e_now * w_0 + Σ_{j=1}^{m-1} w_j e_{n-j}
            return e_now + gl_sum_direct(&self.weights[1..m], &self.history[n + 1 - m..], 0);
        }
        let near = m.min(NEAR);
        let mut s = e_now;
        for j in 1..near {
            s += self.weights[j] * self.history[n - j];
        }
        s + self.far.get(n).copied().unwrap_or(0.0)
    }

    /// Appends e_n (the sample of the step just taken).
    pub fn push(&mut self, e: f64) {
        self.history.push(e);
        let n1 = self.history.len();
        // weights needed by the next eval (direct mode) or by the block levels completed now
        self.ensure_weights(if self.fast { (2 * n1).max(NEAR) } else { n1 + 1 });
        if !self.fast {
            return;
        }
        // level k: blocks of length L = NEAR 2^k; the history chunk [n1 - L, n1) is complete when L | n1
        let mut k = 0;
        loop {
            let l = NEAR << k;
            if !n1.is_multiple_of(l) || (self.memory > 0 && l >= self.memory) {
                break;
            }
            self.add_block_product(k, l, n1);
            k += 1;
        }
    }

    fn level(&mut self, k: usize, l: usize) -> Arc<Level> {
        if self.cache.levels.len() <= k {
            self.cache.levels.resize(k + 1, None);
        }
        if let Some(lv) = &self.cache.levels[k] {
            return lv.clone();
        }
        let mut planner = FftPlanner::<f64>::new();
        let fwd = planner.plan_fft_forward(2 * l);
        let inv = planner.plan_fft_inverse(2 * l);
        self.ensure_weights(2 * l);
        let scale = 1.0 / (2 * l) as f64;
        let mut buf: Vec<Complex<f64>> = (0..2 * l)
            .map(|i| {
                let j = l + i;
                let w = if i < l && (self.memory == 0 || j < self.memory) { self.weights[j] } else { 0.0 };
                Complex::new(w * scale, 0.0)
            })
            .collect();
        let w_hat = if buf.iter().all(|c| c.re == 0.0) {
            None
        } else {
            fwd.process(&mut buf);
            Some(buf)
        };
        let lv = Arc::new(Level { fwd, inv, w_hat });
        self.cache.levels[k] = Some(lv.clone());
        lv
    }

    /// Adds the products of weight block [L, 2L) and history chunk [n1 - L, n1) to far[n1 …].
    fn add_block_product(&mut self, k: usize, l: usize, n1: usize) {
        let lv = self.level(k, l);
        let Some(w_hat) = &lv.w_hat else { return };
        let mut buf: Vec<Complex<f64>> = (0..2 * l).map(|i| Complex::new(if i < l { self.history[n1 - l + i] } else { 0.0 }, 0.0)).collect();
        lv.fwd.process(&mut buf);
        for (b, w) in buf.iter_mut().zip(w_hat) {
            *b *= *w;
        }
        lv.inv.process(&mut buf);
        // buf[i] = Σ_{a+b=i} e_{n1-L+a} w_{L+b}: contributes to s at index n1 - L + L + i = n1 + i
        let end = n1 + 2 * l - 1;
        if self.far.len() < end {
            self.far.resize(end, 0.0);
        }
        for (i, b) in buf[..2 * l - 1].iter().enumerate() {
            self.far[n1 + i] += b.re;
        }
    }
}

/// Parameters of the PI^λD^μ law u_n = K_P e_n + K_I D^{-λ} e_n + K_D D^μ e_n (paper 002 Eqs. 16–17).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
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
        Ok(())
    }
}

/// Fractional PI^λD^μ law on the GL sums; the error history is the whole state.
#[derive(Clone, Serialize, Deserialize)]
pub struct FopidLaw {
    p: FopidParams,
    integral: GlConvolution,
    derivative: GlConvolution,
    e0: Option<f64>,
    /// partial sums S_n = Σ_{j≤n} w_j of the derivative weights (history_before_start only)
    wsum: Vec<f64>,
    /// h^{λ}, h^{-μ}
    scale_i: f64,
    scale_d: f64,
}

impl FopidLaw {
    pub fn new(p: FopidParams) -> Result<Self, String> {
        Self::with_evaluation(p, true)
    }

    /// `fast` = false evaluates every GL sum directly (reference and benchmark).
    pub fn with_evaluation(p: FopidParams, fast: bool) -> Result<Self, String> {
        p.validate()?;
        let mut law = FopidLaw {
            p,
            integral: GlConvolution::new(-p.lambda, p.memory, fast),
            derivative: GlConvolution::new(p.mu, p.memory, fast),
            e0: None,
            wsum: Vec::new(),
            scale_i: p.h.powf(p.lambda),
            scale_d: p.h.powf(-p.mu),
        };
        if p.history_before_start {
            law.extend_wsum(if p.memory > 0 { p.memory } else { 1 });
        }
        Ok(law)
    }

    pub fn params(&self) -> &FopidParams {
        &self.p
    }
    /// Number of samples in the history.
    pub fn len(&self) -> usize {
        self.integral.len()
    }
    pub fn is_empty(&self) -> bool {
        self.integral.is_empty()
    }

    /// D^{-λ} e_n and D^μ e_n for the current error e_n (state unchanged).
    pub fn terms(&self, e: f64) -> (f64, f64) {
        let i = if self.p.ki != 0.0 { self.scale_i * self.integral.eval(e) } else { 0.0 };
        let mut d = self.derivative.eval(e);
        if self.p.history_before_start {
            // e_k = e_0 for k < 0 adds e_0 Σ_{j=n+1}^{L-1} w_j (full memory: Σ_{j>n} w_j = S_∞ - S_n,
            // with S_∞ = 0 for μ > 0 and 1 for μ = 0)
            let e0 = self.e0.unwrap_or(e);
            d += e0 * self.tail_weight();
        }
        (i, self.scale_d * d)
    }

    /// Σ_{j=n+1}^{L-1} w_j for the derivative (full memory: S_∞ - S_n with S_∞ = 0 for μ > 0, 1 for μ = 0).
    fn tail_weight(&self) -> f64 {
        let n = self.derivative.len();
        let s = &self.wsum;
        let mem = self.p.memory;
        if mem > 0 {
            if n + 1 >= mem { 0.0 } else { s[mem - 1] - s[n] }
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

    /// Appends e_n to the history (called once per step with the error of t_n).
    pub fn push(&mut self, e: f64) {
        self.e0.get_or_insert(e);
        if self.p.ki != 0.0 {
            self.integral.push(e);
        } else {
            // keep the sample count without paying for an unused sum
            self.integral.history.push(e);
        }
        self.derivative.push(e);
        if self.p.history_before_start {
            let n = self.derivative.len();
            self.extend_wsum(n + 1);
        }
    }
}

/// Integer PID u_n = K_P e_n + K_I h Σ_{j} e_{n-j} + K_D (e_n - e_{n-1})/h: the λ = μ = 1 case of
/// [`FopidLaw`] written with a running sum and a backward difference (O(1) per step). With a memory
/// L > 0 the sum covers the last L samples (short-memory principle).
#[derive(Clone, Serialize, Deserialize)]
pub struct PidLaw {
    p: FopidParams,
    /// whole error history (the integral window and the state to save)
    history: Vec<f64>,
    /// Σ of the samples inside the memory window
    sum: f64,
}

impl PidLaw {
    pub fn new(mut p: FopidParams) -> Result<Self, String> {
        p.lambda = 1.0;
        p.mu = 1.0;
        p.validate()?;
        Ok(PidLaw { p, history: Vec::new(), sum: 0.0 })
    }
    pub fn len(&self) -> usize {
        self.history.len()
    }
    pub fn is_empty(&self) -> bool {
        self.history.is_empty()
    }

    pub fn output(&self, e: f64) -> f64 {
        let n = self.history.len();
        let mem = self.p.memory;
        // window Σ_{j=0}^{min(n, L-1)} e_{n-j}
        let dropped = if mem > 0 && n + 1 > mem { self.history[n - mem] } else { 0.0 };
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
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn signal(n: usize) -> Vec<f64> {
        (0..n).map(|k| (0.013 * k as f64).sin() + 0.3 * (0.0071 * k as f64 * k as f64 % 7.0).cos() - 0.2).collect()
    }

    #[test]
    fn weights_are_signed_binomials() {
        // (-1)^j binom(α, j) by the product formula Π_{i=1}^{j} (α - i + 1)/i, computed independently
        for &a in &[0.5, 1.0, -1.0, 1.7, -0.3, 2.0, 0.0] {
            let w = gl_weights(a, 40);
            for (j, wj) in w.iter().enumerate() {
                let mut num = 1.0f64;
                let mut den = 1.0f64;
                for i in 1..=j {
                    num *= a - i as f64 + 1.0;
                    den *= i as f64;
                }
                let expect = if j % 2 == 0 { num / den } else { -num / den };
                assert!((wj - expect).abs() <= 1e-14 * expect.abs().max(1e-300) + 1e-300, "α={a} j={j}: {wj} vs {expect}");
            }
        }
        assert_eq!(&gl_weights(1.0, 4), &[1.0, -1.0, 0.0, 0.0]);
        assert_eq!(&gl_weights(-1.0, 4), &[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(&gl_weights(2.0, 5), &[1.0, -2.0, 1.0, 0.0, 0.0]);
        let w = gl_weights(0.5, 4);
        assert!((w[1] + 0.5).abs() < 1e-16 && (w[2] + 0.125).abs() < 1e-16 && (w[3] + 0.0625).abs() < 1e-16);
    }

    /// GL value at t = 1 of e(t) = t^p with step h.
    fn gl_at_one(alpha: f64, p: f64, h: f64) -> f64 {
        let n = (1.0 / h).round() as usize;
        let e: Vec<f64> = (0..=n).map(|k| (k as f64 * h).powf(p)).collect();
        *gl_series(alpha, h, &e, 0).last().unwrap()
    }

    #[test]
    fn power_law_closed_form_first_order() {
        // D^α t^p = Γ(p+1)/Γ(p+1-α) t^{p-α}; at t = 1 with Γ(1/2) = √π, Γ(3/2) = √π/2, Γ(5/2) = 3√π/4
        let sp = PI.sqrt();
        let cases = [
            (0.5, 1.0, 1.0 / (sp / 2.0)),        // Γ(2)/Γ(1.5)
            (0.5, 2.0, 2.0 / (3.0 * sp / 4.0)),  // Γ(3)/Γ(2.5)
            (1.5, 2.0, 2.0 / (sp / 2.0)),        // Γ(3)/Γ(1.5)
            (-0.5, 1.0, 1.0 / (3.0 * sp / 4.0)), // Γ(2)/Γ(2.5)
            (-1.5, 1.0, 1.0 / (15.0 * sp / 8.0)), // Γ(2)/Γ(3.5)
            (-1.0, 2.0, 1.0 / 3.0),               // Γ(3)/Γ(4): ∫ t² = t³/3
        ];
        for (alpha, p, exact) in cases {
            let (h1, h2) = (1e-3, 5e-4);
            let (e1, e2) = ((gl_at_one(alpha, p, h1) - exact).abs(), (gl_at_one(alpha, p, h2) - exact).abs());
            let order = (e1 / e2).ln() / (h1 / h2).ln();
            println!("D^{alpha} t^{p} at t = 1: error {e1:.3e} (h = 1e-3), {e2:.3e} (h = 5e-4), fitted order {order:.4}");
            assert!(e1 < 5.0 * h1, "α={alpha} p={p}: error {e1}");
            assert!((order - 1.0).abs() < 0.05, "α={alpha} p={p}: fitted order {order} ({e1}, {e2})");
        }
    }

    #[test]
    fn order_minus_one_is_rectangle_rule() {
        let e = signal(3000);
        let h = 0.01;
        let y = gl_series(-1.0, h, &e, 0);
        let mut s = 0.0;
        for (n, x) in e.iter().enumerate() {
            s += h * x;
            assert!((y[n] - s).abs() < 1e-12 * (1.0 + s.abs()), "n={n}");
        }
    }

    #[test]
    fn fast_equals_direct_to_round_off() {
        let e = signal(9000);
        let mut worst = 0.0f64;
        for &alpha in &[0.3, -0.7, 1.0, -1.0, 1.6, 0.0, 2.0] {
            for &mem in &[0usize, 1, 2, 63, 64, 65, 1000, 4096, 5000] {
                let mut fast = GlConvolution::new(alpha, mem, true);
                let mut direct = GlConvolution::new(alpha, mem, false);
                let w = gl_weights(alpha, e.len());
                // bound on the round-off scale Σ |w_j e_{n-j}| ≤ max|e| Σ_{j<m} |w_j|
                let emax = e.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                let mut wabs = vec![0.0; e.len() + 1];
                for j in 0..e.len() {
                    wabs[j + 1] = wabs[j] + w[j].abs();
                }
                for (n, &x) in e.iter().enumerate() {
                    let (a, b) = (fast.eval(x), direct.eval(x));
                    let m = if mem == 0 { n + 1 } else { (n + 1).min(mem) };
                    let mag = emax * wabs[m];
                    assert!((a - b).abs() <= 1e-13 * mag.max(1e-300), "α={alpha} L={mem} n={n}: {a} vs {b}");
                    worst = worst.max((a - b).abs() / mag.max(1e-300));
                    if n % 997 == 0 {
                        // independent plain loop
                        let plain: f64 = (0..m).map(|j| w[j] * e[n - j]).sum();
                        assert!((b - plain).abs() <= 1e-13 * mag.max(1e-300));
                    }
                    fast.push(x);
                    direct.push(x);
                }
            }
        }
        println!("fast vs direct GL sum, 9000 samples: max |fast - direct| / (max|e| Σ|w_j|) = {worst:.2e}");
    }

    #[test]
    fn short_memory_drops_old_samples() {
        let e = signal(500);
        let y = gl_series(0.6, 1.0, &e, 10);
        let w = gl_weights(0.6, 10);
        let n = 321;
        let s: f64 = (0..10).map(|j| w[j] * e[n - j]).sum();
        assert!((y[n] - s).abs() < 1e-14);
    }

    fn params(kp: f64, ki: f64, kd: f64, lambda: f64, mu: f64) -> FopidParams {
        FopidParams { kp, ki, kd, lambda, mu, h: 0.001, memory: 0, history_before_start: false }
    }

    #[test]
    fn fopid_with_unit_orders_equals_pid() {
        for hbs in [false, true] {
            for mem in [0usize, 1, 2, 50, 3000] {
                let p = FopidParams { memory: mem, history_before_start: hbs, ..params(2.0, 0.1, 8.0, 1.0, 1.0) };
                let mut f = FopidLaw::new(p).unwrap();
                let mut q = PidLaw::new(p).unwrap();
                for (n, &e) in signal(20_000).iter().enumerate() {
                    let (a, b) = (f.output(e), q.output(e));
                    assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "L={mem} hbs={hbs} n={n}: {a} vs {b}");
                    f.push(e);
                    q.push(e);
                }
            }
        }
    }

    #[test]
    fn history_before_start_removes_derivative_kick() {
        let e0 = 0.5;
        for mu in [1.0, 0.7, 1.5] {
            for mem in [0usize, 30] {
                let p = FopidParams { memory: mem, history_before_start: true, ..params(0.0, 0.0, 1.0, 1.0, mu) };
                let mut f = FopidLaw::new(p).unwrap();
                // constant error that has always been there: full memory gives D^μ = 0; short memory
                // gives the truncated sum e_0 h^{-μ} Σ_{j<L} w_j from the first sample on (no kick)
                let expect = if mem == 0 { 0.0 } else { e0 * 1000f64.powf(mu) * gl_weights(mu, mem).iter().sum::<f64>() };
                for _ in 0..200 {
                    assert!((f.output(e0) - expect).abs() < 1e-9 * expect.abs().max(1.0), "μ={mu} L={mem}: {} vs {expect}", f.output(e0));
                    f.push(e0);
                }
                let p0 = FopidParams { history_before_start: false, ..p };
                let f0 = FopidLaw::new(p0).unwrap();
                assert!((f0.output(e0) - e0 * 1000f64.powf(mu)).abs() < 1e-9);
            }
        }
        // μ = 0: D^0 e = e whatever the option
        let f = FopidLaw::new(FopidParams { history_before_start: true, ..params(0.0, 0.0, 1.0, 1.0, 0.0) }).unwrap();
        assert!((f.output(0.3) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn bad_parameters_are_named() {
        let e = FopidLaw::new(params(1.0, 1.0, 1.0, 2.5, 1.0)).err().unwrap();
        assert!(e.contains("lambda"), "{e}");
        let e = FopidLaw::new(params(1.0, 1.0, 1.0, 1.0, -0.1)).err().unwrap();
        assert!(e.contains("mu"), "{e}");
        let e = FopidLaw::new(params(f64::NAN, 1.0, 1.0, 1.0, 1.0)).err().unwrap();
        assert!(e.contains("kp"), "{e}");
    }

    #[test]
    fn serialized_state_continues_bit_identically() {
        let p = FopidParams { ..params(2.0, 0.3, 5.0, 0.8, 1.3) };
        let mut a = FopidLaw::new(p).unwrap();
        let e = signal(6000);
        for &x in &e[..2500] {
            a.push(x);
        }
        let bytes = postcard::to_allocvec(&a).unwrap();
        let mut b: FopidLaw = postcard::from_bytes(&bytes).unwrap();
        for &x in &e[2500..] {
            assert_eq!(a.output(x).to_bits(), b.output(x).to_bits());
            a.push(x);
            b.push(x);
        }
    }
}
