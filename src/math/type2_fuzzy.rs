//! Interval type-2 fuzzy inference with Karnik–Mendel type reduction.
//!
//! An interval type-2 set has a footprint of uncertainty between a lower and an upper membership
//! function; here Gaussians with a common centre and an uncertain width σ ∈ [σ_lo, σ_up]:
//! upper μ̄(x) = exp(−(x − c)²/(2σ_up²)), lower μ(x) = exp(−(x − c)²/(2σ_lo²)), so μ ≤ μ̄.
//! A rule's firing strength is an interval [f, f̄] (product t-norm of the lower and of the upper
//! memberships). With crisp consequents y_r the type-reduced set is the interval [y_l, y_r] of all
//! weighted averages Σ f_r y_r / Σ f_r with every f_r in its firing interval; Karnik and Mendel
//! showed that the extremes are reached with one switch point:
//!
//! ```text
//! rules sorted by y (ascending, stable)
//! y_l = min over L = 0..n of [Σ_{r≤L} f̄_r y_r + Σ_{r>L} f_r y_r] / [Σ_{r≤L} f̄_r + Σ_{r>L} f_r]
//! y_r = max over R = 0..n of [Σ_{r≤R} f_r y_r + Σ_{r>R} f̄_r y_r] / [Σ_{r≤R} f_r + Σ_{r>R} f̄_r]
//! y   = (y_l + y_r)/2
//! ```
//!
//! [`km_exhaustive`] evaluates every switch point (n + 1 of them, O(n) each with running sums); it
//! is the reference implementation and the one the controllers use (9 rules: trivially cheap). The
//! iterative (E)KM algorithms are not used.

use serde::{Deserialize, Serialize};

use super::fuzzy::gaussian;

/// Interval Gaussian membership: centre c, widths σ_lo ≤ σ_up. Returns (lower, upper).
pub fn interval_gaussian(x: f64, center: f64, sigma_lo: f64, sigma_up: f64) -> (f64, f64) {
    (gaussian(x, center, sigma_lo), gaussian(x, center, sigma_up))
}

/// Karnik–Mendel type reduction by exhaustive switch-point search.
///
/// `y` are the crisp rule consequents, `f_lo` ≤ `f_up` the firing intervals (same length). The rules
/// need not be sorted: they are sorted by `y` here (stable). Returns (y_l, y_r), or `None` when a
/// weighted average is undefined (all firing strengths zero, or the inputs have different lengths /
/// non-finite values).
pub fn km_exhaustive(y: &[f64], f_lo: &[f64], f_up: &[f64]) -> Option<(f64, f64)> {
    let n = y.len();
    if f_lo.len() != n || f_up.len() != n || n == 0 {
        return None;
    }
    if y.iter().chain(f_lo).chain(f_up).any(|v| !v.is_finite()) {
        return None;
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| y[a].total_cmp(&y[b])); // stable
    let ys: Vec<f64> = idx.iter().map(|&i| y[i]).collect();
    let lo: Vec<f64> = idx.iter().map(|&i| f_lo[i]).collect();
    let up: Vec<f64> = idx.iter().map(|&i| f_up[i]).collect();
    Some((
        switch_extreme(&ys, &up, &lo, false)?,
        switch_extreme(&ys, &lo, &up, true)?,
    ))
}

/// min (or max) over the switch point k = 0..n of
/// [Σ_{r<k} first_r y_r + Σ_{r≥k} second_r y_r] / [Σ_{r<k} first_r + Σ_{r≥k} second_r]
/// (k counts the rules that take `first`; 0-based r). Running sums: O(n).
fn switch_extreme(ys: &[f64], first: &[f64], second: &[f64], maximise: bool) -> Option<f64> {
    let n = ys.len();
    // start with k = 0: all rules take `second`
    let mut num: f64 = (0..n).map(|r| second[r] * ys[r]).sum();
    let mut den: f64 = second.iter().sum();
    let mut best: Option<f64> = None;
    for k in 0..=n {
        if k > 0 {
            let r = k - 1;
            num += (first[r] - second[r]) * ys[r];
            den += first[r] - second[r];
        }
        if den > 0.0 {
            let v = num / den;
            best = Some(match best {
                None => v,
                Some(b) if maximise => b.max(v),
                Some(b) => b.min(v),
            });
        }
    }
    best
}

/// Output term of the sliding-mode gain table: the change of the switching gain.
pub const N: f64 = -1.0;
pub const Z: f64 = 0.0;
pub const P: f64 = 1.0;

/// Rule table of the type-2 fuzzy sliding-mode gain schedule ("change of K"): rows e = N, Z, P,
/// columns ė = N, Z, P. Symmetric under (e, ė) → (−e, −ė).
pub const SMC_GAIN_TABLE: [[f64; 3]; 3] = [[P, P, Z], [Z, N, Z], [Z, P, P]];

/// The per-axis interval type-2 system of the fuzzy sliding-mode controller: inputs ē, ē' ∈ [−1, 1],
/// three interval Gaussian sets N, Z, P (centres −1, 0, 1) on each, nine product rules with crisp
/// consequents from the table, Karnik–Mendel type reduction, output the midpoint of [y_l, y_r].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SmcGainFuzzy {
    pub sigma_lo: f64,
    pub sigma_up: f64,
    /// table[i][j]: consequent of the rule (e is set i, ė is set j).
    pub table: [[f64; 3]; 3],
}

/// Result of one inference: the type-reduced interval and its midpoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Type2Output {
    pub y_l: f64,
    pub y_r: f64,
    pub y: f64,
}

impl SmcGainFuzzy {
    /// `transpose` = true reads the table with rows ė and columns e.
    pub fn new(sigma_lo: f64, sigma_up: f64, transpose: bool) -> Result<Self, String> {
        if !(sigma_lo > 0.0 && sigma_lo.is_finite()) {
            return Err(format!("sigma_lo = {sigma_lo} must be > 0"));
        }
        if !(sigma_up >= sigma_lo && sigma_up.is_finite()) {
            return Err(format!("sigma_up = {sigma_up} must be >= sigma_lo = {sigma_lo}"));
        }
        let mut table = SMC_GAIN_TABLE;
        if transpose {
            for i in 0..3 {
                for j in 0..3 {
                    table[i][j] = SMC_GAIN_TABLE[j][i];
                }
            }
        }
        Ok(SmcGainFuzzy {
            sigma_lo,
            sigma_up,
            table,
        })
    }

    /// Firing intervals and consequents of the nine rules, in row-major order (e set, ė set).
    pub fn rules(&self, e_bar: f64, edot_bar: f64) -> ([f64; 9], [f64; 9], [f64; 9]) {
        const C: [f64; 3] = [-1.0, 0.0, 1.0];
        let me: Vec<(f64, f64)> = C
            .iter()
            .map(|&c| interval_gaussian(e_bar, c, self.sigma_lo, self.sigma_up))
            .collect();
        let md: Vec<(f64, f64)> = C
            .iter()
            .map(|&c| interval_gaussian(edot_bar, c, self.sigma_lo, self.sigma_up))
            .collect();
        let (mut y, mut lo, mut up) = ([0.0; 9], [0.0; 9], [0.0; 9]);
        for (i, (row, e)) in self.table.iter().zip(&me).enumerate() {
            for (j, (&cell, d)) in row.iter().zip(&md).enumerate() {
                let r = 3 * i + j;
                y[r] = cell;
                lo[r] = e.0 * d.0;
                up[r] = e.1 * d.1;
            }
        }
        (y, lo, up)
    }

    /// Inference for normalised inputs (expected in [−1, 1]). `None` if no rule fires (only possible
    /// for extreme inputs with tiny widths, where every Gaussian underflows).
    pub fn infer(&self, e_bar: f64, edot_bar: f64) -> Option<Type2Output> {
        let (y, lo, up) = self.rules(e_bar, edot_bar);
        let (y_l, y_r) = km_exhaustive(&y, &lo, &up)?;
        Some(Type2Output {
            y_l,
            y_r,
            y: 0.5 * (y_l + y_r),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small deterministic generator for test data (xorshift64*).
    struct Gen(u64);
    impl Gen {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Weighted average Σ f y / Σ f.
    fn wavg(y: &[f64], f: &[f64]) -> f64 {
        y.iter().zip(f).map(|(a, b)| a * b).sum::<f64>() / f.iter().sum::<f64>()
    }

    /// Brute force: min and max of the weighted average over all 2^n vertices of the firing box
    /// (a linear-fractional function attains its extremes over a box at vertices).
    fn brute_force(y: &[f64], lo: &[f64], up: &[f64]) -> (f64, f64) {
        let n = y.len();
        let (mut mn, mut mx) = (f64::INFINITY, f64::NEG_INFINITY);
        for mask in 0u32..(1 << n) {
            let f: Vec<f64> = (0..n).map(|r| if mask >> r & 1 == 1 { up[r] } else { lo[r] }).collect();
            if f.iter().sum::<f64>() > 0.0 {
                let v = wavg(y, &f);
                mn = mn.min(v);
                mx = mx.max(v);
            }
        }
        (mn, mx)
    }

    /// Every switch point evaluated directly from the formula (no running sums), rules sorted by y.
    fn switch_points_direct(y: &[f64], lo: &[f64], up: &[f64]) -> (f64, f64) {
        let n = y.len();
        let mut idx: Vec<usize> = (0..n).collect();
        idx.sort_by(|&a, &b| y[a].total_cmp(&y[b]));
        let (mut yl, mut yr) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..=n {
            let fl: Vec<f64> = (0..n).map(|p| if p < k { up[idx[p]] } else { lo[idx[p]] }).collect();
            let fr: Vec<f64> = (0..n).map(|p| if p < k { lo[idx[p]] } else { up[idx[p]] }).collect();
            let ys: Vec<f64> = idx.iter().map(|&i| y[i]).collect();
            yl = yl.min(wavg(&ys, &fl));
            yr = yr.max(wavg(&ys, &fr));
        }
        (yl, yr)
    }

    #[test]
    fn km_equals_brute_force_over_all_vertices_and_switch_points() {
        let mut g = Gen(0x9E3779B97F4A7C15);
        for case in 0..400 {
            let n = 1 + case % 9;
            let y: Vec<f64> = (0..n)
                .map(|_| {
                    if case % 2 == 0 {
                        (g.next() * 3.0).floor() - 1.0
                    } else {
                        g.next() * 4.0 - 2.0
                    }
                })
                .collect();
            let lo: Vec<f64> = (0..n).map(|_| g.next() * 0.5 + 1e-3).collect();
            let up: Vec<f64> = lo.iter().map(|l| l + g.next() * 0.8).collect();
            let (yl, yr) = km_exhaustive(&y, &lo, &up).unwrap();
            let (bl, br) = brute_force(&y, &lo, &up);
            let (dl, dr) = switch_points_direct(&y, &lo, &up);
            assert!(
                (yl - bl).abs() <= 1e-12 && (yr - br).abs() <= 1e-12,
                "case {case}: KM ({yl}, {yr}) vs vertices ({bl}, {br})"
            );
            assert!(
                (yl - dl).abs() <= 1e-12 && (yr - dr).abs() <= 1e-12,
                "case {case}: running sums vs direct"
            );
            // every weighted average with interior firing strengths lies in [y_l, y_r]
            for _ in 0..20 {
                let f: Vec<f64> = lo.iter().zip(&up).map(|(l, u)| l + (u - l) * g.next()).collect();
                let v = wavg(&y, &f);
                assert!(
                    v >= yl - 1e-12 && v <= yr + 1e-12,
                    "case {case}: {v} outside [{yl}, {yr}]"
                );
            }
        }
    }

    #[test]
    fn degenerate_inputs_give_none() {
        assert_eq!(km_exhaustive(&[1.0, 2.0], &[0.0, 0.0], &[0.0, 0.0]), None);
        assert_eq!(km_exhaustive(&[1.0], &[0.5, 0.1], &[0.6]), None);
        assert_eq!(km_exhaustive(&[f64::NAN], &[0.5], &[0.6]), None);
        // zero lower firing but positive upper: the all-lower switch point is skipped, the rest defined
        assert_eq!(km_exhaustive(&[-1.0, 1.0], &[0.0, 0.0], &[1.0, 1.0]), Some((-1.0, 1.0)));
    }

    #[test]
    fn equal_widths_give_the_type1_weighted_average() {
        let f = SmcGainFuzzy::new(0.4, 0.4, false).unwrap();
        let c = [-1.0, 0.0, 1.0];
        for a in -10..=10 {
            for b in -10..=10 {
                let (e, d) = (a as f64 / 10.0, b as f64 / 10.0);
                // type-1 system written out: product firing of Gaussians, weighted average of the table
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..3 {
                    for j in 0..3 {
                        let w = (-(e - c[i]).powi(2) / (2.0 * 0.16)).exp() * (-(d - c[j]).powi(2) / (2.0 * 0.16)).exp();
                        num += w * SMC_GAIN_TABLE[i][j];
                        den += w;
                    }
                }
                let o = f.infer(e, d).unwrap();
                assert!(
                    (o.y_l - num / den).abs() < 1e-13 && (o.y_r - num / den).abs() < 1e-13,
                    "({e}, {d}): {o:?} vs {}",
                    num / den
                );
            }
        }
    }

    #[test]
    fn output_lies_in_the_interval_and_respects_the_table_symmetry() {
        let f = SmcGainFuzzy::new(0.3, 0.5, false).unwrap();
        let ft = SmcGainFuzzy::new(0.3, 0.5, true).unwrap();
        for a in -20..=20 {
            for b in -20..=20 {
                let (e, d) = (a as f64 / 20.0, b as f64 / 20.0);
                let o = f.infer(e, d).unwrap();
                assert!(o.y_l <= o.y && o.y <= o.y_r && o.y_l >= -1.0 && o.y_r <= 1.0, "{o:?}");
                assert!(o.y_r - o.y_l > 0.0, "widths differ: the interval is not a point");
                // (e, ė) → (−e, −ė) leaves the table unchanged
                let m = f.infer(-e, -d).unwrap();
                assert!((m.y - o.y).abs() < 1e-12);
                // transposed reading = swapped inputs
                let t = ft.infer(e, d).unwrap();
                let s = f.infer(d, e).unwrap();
                assert!((t.y - s.y).abs() < 1e-12);
            }
        }
        // at the rule centres the dominant rule's consequent pulls the output its way
        assert!(f.infer(0.0, 0.0).unwrap().y < -0.5);
        assert!(f.infer(1.0, 1.0).unwrap().y > 0.5);
        assert!(f.infer(-1.0, 0.0).unwrap().y > 0.3);
    }

    #[test]
    fn bad_widths_are_refused() {
        assert!(SmcGainFuzzy::new(0.0, 0.5, false).unwrap_err().contains("sigma_lo"));
        assert!(SmcGainFuzzy::new(0.6, 0.5, false).unwrap_err().contains("sigma_up"));
    }
}
