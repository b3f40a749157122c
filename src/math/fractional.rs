//! Grünwald–Letnikov (GL) fractional derivatives and integrals of a sampled signal: weights, direct
//! sums and an exact online evaluation. The control laws built on them live with the single-axis
//! controllers (`crate::models::single_axis::shared::laws`).
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
    (0..e.len())
        .map(|n| scale * gl_sum_direct(&w, &e[..=n], memory))
        .collect()
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

/// Online GL sum s_n = Σ_{j=0}^{min(n, L-1)} w_j e_{n-j} of a signal that arrives one sample per step,
/// without the samples themselves: the caller owns the history e_0 … e_{n-1} and passes it to every
/// call, so a law with several sums over one signal stores the signal once. What the kernel holds
/// (weights, pending block products, FFT plans) is derived from the order, the memory and the history;
/// [`rebuild`](Self::rebuild) recomputes it from a history alone, bit-identically.
#[derive(Clone)]
pub struct GlKernel {
    alpha: f64,
    memory: usize,
    fast: bool,
    /// w_0 … (never longer than `memory` when memory > 0)
    weights: Vec<f64>,
    /// far[n] = block products Σ_{j ≥ NEAR} w_j e_{n-j} accumulated so far (fast mode)
    far: Vec<f64>,
    cache: FftCache,
}

impl GlKernel {
    /// Order `alpha`, memory `memory` samples (0 = full), `fast` = block-FFT evaluation.
    pub fn new(alpha: f64, memory: usize, fast: bool) -> Self {
        let mut c = GlKernel {
            alpha,
            memory,
            fast,
            weights: Vec::new(),
            far: Vec::new(),
            cache: FftCache::default(),
        };
        c.ensure_weights(NEAR.max(2));
        c
    }

    /// The kernel after the samples `history` were pushed one by one (the same arithmetic in the same
    /// order as the online pushes, so the result is bit-identical).
    pub fn rebuild(alpha: f64, memory: usize, fast: bool, history: &[f64]) -> Self {
        let mut c = Self::new(alpha, memory, fast);
        for n1 in 1..=history.len() {
            c.push(&history[..n1]);
        }
        c
    }

    pub fn alpha(&self) -> f64 {
        self.alpha
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

    /// s_n with e_n = `e_now` after the samples `history` = e_0 … e_{n-1}. Does not change the state.
    pub fn eval(&self, history: &[f64], e_now: f64) -> f64 {
        let n = history.len();
        let m = if self.memory == 0 {
            n + 1
        } else {
            (n + 1).min(self.memory)
        };
        if !self.fast {
            // direct: e_now * w_0 + Σ_{j=1}^{m-1} w_j e_{n-j}
            return e_now + gl_sum_direct(&self.weights[1..m], &history[n + 1 - m..], 0);
        }
        let near = m.min(NEAR);
        let mut s = e_now;
        for j in 1..near {
            s += self.weights[j] * history[n - j];
        }
        s + self.far.get(n).copied().unwrap_or(0.0)
    }

    /// Accounts for the sample just appended: `history` ends with e_n.
    pub fn push(&mut self, history: &[f64]) {
        let n1 = history.len();
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
            self.add_block_product(history, k, l, n1);
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
                let w = if i < l && (self.memory == 0 || j < self.memory) {
                    self.weights[j]
                } else {
                    0.0
                };
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
    fn add_block_product(&mut self, history: &[f64], k: usize, l: usize, n1: usize) {
        let lv = self.level(k, l);
        let Some(w_hat) = &lv.w_hat else { return };
        let mut buf: Vec<Complex<f64>> = (0..2 * l)
            .map(|i| Complex::new(if i < l { history[n1 - l + i] } else { 0.0 }, 0.0))
            .collect();
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

/// [`GlKernel`] with its own history: the GL sum of one signal, for tests and single-sum uses.
#[derive(Clone)]
pub struct GlConvolution {
    kernel: GlKernel,
    history: Vec<f64>,
}

impl GlConvolution {
    pub fn new(alpha: f64, memory: usize, fast: bool) -> Self {
        GlConvolution {
            kernel: GlKernel::new(alpha, memory, fast),
            history: Vec::new(),
        }
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
    /// s_n with e_n = `e_now`, n = number of samples pushed so far. Does not change the state.
    pub fn eval(&self, e_now: f64) -> f64 {
        self.kernel.eval(&self.history, e_now)
    }
    /// Appends e_n (the sample of the step just taken).
    pub fn push(&mut self, e: f64) {
        self.history.push(e);
        self.kernel.push(&self.history);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn signal(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| (0.013 * k as f64).sin() + 0.3 * (0.0071 * k as f64 * k as f64 % 7.0).cos() - 0.2)
            .collect()
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
                assert!(
                    (wj - expect).abs() <= 1e-14 * expect.abs().max(1e-300) + 1e-300,
                    "α={a} j={j}: {wj} vs {expect}"
                );
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
            (0.5, 1.0, 1.0 / (sp / 2.0)),         // Γ(2)/Γ(1.5)
            (0.5, 2.0, 2.0 / (3.0 * sp / 4.0)),   // Γ(3)/Γ(2.5)
            (1.5, 2.0, 2.0 / (sp / 2.0)),         // Γ(3)/Γ(1.5)
            (-0.5, 1.0, 1.0 / (3.0 * sp / 4.0)),  // Γ(2)/Γ(2.5)
            (-1.5, 1.0, 1.0 / (15.0 * sp / 8.0)), // Γ(2)/Γ(3.5)
            (-1.0, 2.0, 1.0 / 3.0),               // Γ(3)/Γ(4): ∫ t² = t³/3
        ];
        for (alpha, p, exact) in cases {
            let (h1, h2) = (1e-3, 5e-4);
            let (e1, e2) = (
                (gl_at_one(alpha, p, h1) - exact).abs(),
                (gl_at_one(alpha, p, h2) - exact).abs(),
            );
            let order = (e1 / e2).ln() / (h1 / h2).ln();
            println!(
                "D^{alpha} t^{p} at t = 1: error {e1:.3e} (h = 1e-3), {e2:.3e} (h = 5e-4), fitted order {order:.4}"
            );
            assert!(e1 < 5.0 * h1, "α={alpha} p={p}: error {e1}");
            assert!(
                (order - 1.0).abs() < 0.05,
                "α={alpha} p={p}: fitted order {order} ({e1}, {e2})"
            );
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
                    assert!(
                        (a - b).abs() <= 1e-13 * mag.max(1e-300),
                        "α={alpha} L={mem} n={n}: {a} vs {b}"
                    );
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
}
