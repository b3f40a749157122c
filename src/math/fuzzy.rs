//! Fuzzy inference of paper 000 ([Navabi-2019] §6): membership functions (triangular,
//! Gaussian), the seven-term input partition NB … PB, product rule firing, the two 7×7 rule tables
//! (paper 000 Tables 1–2) and defuzzification by weighted average of output-set representatives:
//! c(S) = 0, c(B) = 1 (`Defuzz::Singleton`), or the centroids of the Gaussian output sets truncated to
//! [0, 1] (`Defuzz::TruncatedCentroid`), which equals product implication + sum aggregation + centroid.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Output term of the rule tables: Small or Big.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Term {
    S,
    B,
}
use Term::{B, S};

/// Names of the seven input sets, in table order.
pub const INPUT_TERMS: [&str; 7] = ["NB", "NM", "NS", "ZO", "PS", "PM", "PB"];

/// k'_p table (paper 000 Table 1): rows e, columns ė, order NB NM NS ZO PS PM PB.
pub const KP_TABLE: [[Term; 7]; 7] = [
    [B, B, B, B, B, B, B],
    [S, B, B, B, B, B, S],
    [S, S, B, B, B, S, S],
    [S, S, S, B, S, S, S],
    [S, S, B, B, B, S, S],
    [S, B, B, B, B, B, S],
    [B, B, B, B, B, B, B],
];

/// k'_d table (paper 000 Table 2): rows e, columns ė.
pub const KD_TABLE: [[Term; 7]; 7] = [
    [S, S, S, S, S, S, S],
    [B, S, S, S, S, S, B],
    [B, B, S, S, S, B, B],
    [B, B, B, S, B, B, B],
    [B, B, S, S, S, B, B],
    [B, S, S, S, S, S, B],
    [S, S, S, S, S, S, S],
];

/// Triangle with peak 1 at `center`, reaching 0 at center ± half_width.
pub fn triangle(x: f64, center: f64, half_width: f64) -> f64 {
    (1.0 - (x - center).abs() / half_width).max(0.0)
}

/// Gaussian exp(−(x − c)²/(2σ²)).
pub fn gaussian(x: f64, center: f64, sigma: f64) -> f64 {
    let d = (x - center) / sigma;
    (-0.5 * d * d).exp()
}

/// Error function, by erf(x) = 2/√π e^{−x²} Σ_{n≥0} 2ⁿ x^{2n+1} / (1·3·…·(2n+1)) (all terms positive,
/// so no cancellation); |x| ≥ 6 gives ±1 to double precision.
pub fn erf(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    let ax = x.abs();
    if ax == 0.0 {
        return x;
    }
    if ax >= 6.0 {
        return x.signum();
    }
    let x2 = ax * ax;
    let mut term = ax;
    let mut sum = ax;
    let mut n = 0.0;
    loop {
        n += 1.0;
        term *= 2.0 * x2 / (2.0 * n + 1.0);
        sum += term;
        if term <= 1e-17 * sum || n > 500.0 {
            break;
        }
    }
    let v = 2.0 / PI.sqrt() * (-x2).exp() * sum;
    v.min(1.0).copysign(x)
}

/// Centroid of the Gaussian set exp(−(x − c)²/(2σ²)) restricted to [lo, hi]:
/// c + σ (φ(α) − φ(β)) / (Φ(β) − Φ(α)) with α = (lo − c)/σ, β = (hi − c)/σ.
pub fn truncated_gaussian_centroid(center: f64, sigma: f64, lo: f64, hi: f64) -> f64 {
    let a = (lo - center) / sigma;
    let b = (hi - center) / sigma;
    let pdf = |z: f64| (-0.5 * z * z).exp() / (2.0 * PI).sqrt();
    let cdf_diff = 0.5 * (erf(b / 2f64.sqrt()) - erf(a / 2f64.sqrt()));
    center + sigma * (pdf(a) - pdf(b)) / cdf_diff
}

/// Seven triangles centred at −1, −2/3, …, 1 with a common half-width (1/3: memberships sum to 1
/// on [−1, 1]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Partition7 {
    pub half_width: f64,
}

impl Partition7 {
    pub const CENTERS: [f64; 7] = [-1.0, -2.0 / 3.0, -1.0 / 3.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];

    pub fn memberships(&self, x: f64) -> [f64; 7] {
        Self::CENTERS.map(|c| triangle(x, c, self.half_width))
    }
}

/// Product firing μ_jk = μ_j(ē) μ_k(ē') (paper 000 Eq. 45).
pub fn product_firing(mu_e: &[f64; 7], mu_de: &[f64; 7]) -> [[f64; 7]; 7] {
    let mut f = [[0.0; 7]; 7];
    for j in 0..7 {
        for k in 0..7 {
            f[j][k] = mu_e[j] * mu_de[k];
        }
    }
    f
}

/// Σ μ_jk c(table_jk) / Σ μ_jk; `None` when no rule fires.
pub fn weighted_average(firing: &[[f64; 7]; 7], table: &[[Term; 7]; 7], c_small: f64, c_big: f64) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..7 {
        for k in 0..7 {
            let c = match table[j][k] {
                S => c_small,
                B => c_big,
            };
            num += firing[j][k] * c;
            den += firing[j][k];
        }
    }
    (den > 0.0).then(|| num / den)
}

crate::param_enum! {
    /// Defuzzification of the output sets (`defuzz` parameter).
    pub enum Defuzz {
        /// 0: c(S) = 0, c(B) = 1.
        Singleton = 0,
        /// 1: centroids of the Gaussian output sets truncated to [0, 1].
        TruncatedCentroid = 1,
    }
}

/// The fuzzy gain scheduler of paper 000 §6: (ē, ē') ∈ [−1, 1]² → (k'_p, k'_d) ∈ [0, 1]².
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PdFuzzySystem {
    pub partition: Partition7,
    pub c_small: f64,
    pub c_big: f64,
}

impl PdFuzzySystem {
    /// Output sets Small = gaussian(·, 0, σ), Big = gaussian(·, 1, σ) on [0, 1].
    pub fn new(half_width: f64, sigma: f64, defuzz: Defuzz) -> Result<Self, String> {
        if !(half_width.is_finite() && half_width >= 1.0 / 3.0 - 1e-12) {
            return Err(format!(
                "membership half-width {half_width} must be >= 1/3 (else gaps with no rule firing)"
            ));
        }
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(format!("output set width sigma = {sigma} must be > 0"));
        }
        let (c_small, c_big) = match defuzz {
            Defuzz::Singleton => (0.0, 1.0),
            Defuzz::TruncatedCentroid => (
                truncated_gaussian_centroid(0.0, sigma, 0.0, 1.0),
                truncated_gaussian_centroid(1.0, sigma, 0.0, 1.0),
            ),
        };
        Ok(Self {
            partition: Partition7 { half_width },
            c_small,
            c_big,
        })
    }

    /// (k'_p, k'_d) for normalised inputs (clamped to [−1, 1] here).
    pub fn infer(&self, e_bar: f64, edot_bar: f64) -> (f64, f64) {
        let mu_e = self.partition.memberships(e_bar.clamp(-1.0, 1.0));
        let mu_de = self.partition.memberships(edot_bar.clamp(-1.0, 1.0));
        let f = product_firing(&mu_e, &mu_de);
        let kp = weighted_average(&f, &KP_TABLE, self.c_small, self.c_big).unwrap_or(0.5 * (self.c_small + self.c_big));
        let kd = weighted_average(&f, &KD_TABLE, self.c_small, self.c_big).unwrap_or(0.5 * (self.c_small + self.c_big));
        (kp, kd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_reference_values() {
        // Abramowitz & Stegun table values
        for &(x, v) in &[
            (0.0, 0.0),
            (0.5, 0.5204998778130465),
            (1.0, 0.8427007929497149),
            (2.0, 0.9953222650189527),
            (2.8284271247461903, 0.9999366575163338),
            (3.5, 0.9999992569016276),
        ] {
            assert!((erf(x) - v).abs() < 4e-15, "erf({x}) = {} vs {v}", erf(x));
            assert!((erf(-x) + v).abs() < 1e-15);
        }
    }

    #[test]
    fn memberships_sum_to_one() {
        let p = Partition7 { half_width: 1.0 / 3.0 };
        for i in 0..=200 {
            let x = -1.0 + i as f64 * 0.01;
            let s: f64 = p.memberships(x).iter().sum();
            assert!((s - 1.0).abs() < 1e-12, "x = {x}: {s}");
        }
    }

    #[test]
    fn tables_rows_are_palindromes_and_symmetric() {
        for t in [&KP_TABLE, &KD_TABLE] {
            for j in 0..7 {
                for k in 0..7 {
                    assert_eq!(t[j][k], t[j][6 - k]);
                    assert_eq!(t[j][k], t[6 - j][k]);
                }
            }
        }
        // k'_d is the complement of k'_p except on the NB/PB rows (all S in both... not B)
        assert_eq!(KP_TABLE[3][3], B);
        assert_eq!(KD_TABLE[3][3], S);
    }

    #[test]
    fn truncated_centroid_matches_spec_formula_and_quadrature() {
        let sigma: f64 = 0.25;
        let spec =
            sigma * (2.0 / PI).sqrt() * (1.0 - (-1.0 / (2.0 * sigma * sigma)).exp()) / erf(1.0 / (sigma * 2f64.sqrt()));
        let cs = truncated_gaussian_centroid(0.0, sigma, 0.0, 1.0);
        assert!((cs - spec).abs() < 1e-15, "{cs} vs {spec}");
        let cb = truncated_gaussian_centroid(1.0, sigma, 0.0, 1.0);
        assert!((cb - (1.0 - cs)).abs() < 1e-15);
        // composite Simpson quadrature of the centroid
        let n = 2000;
        let h = 1.0 / n as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..=n {
            let x = i as f64 * h;
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            num += w * x * gaussian(x, 0.0, sigma);
            den += w * gaussian(x, 0.0, sigma);
        }
        assert!((num / den - cs).abs() < 1e-12, "{} vs {cs}", num / den);
    }

    #[test]
    fn truncated_centroid_equals_product_sum_centroid_inference() {
        // Product implication, sum aggregation and centroid defuzzification over [0, 1] (quadrature)
        // equal the weighted average of the truncated centroids.
        let sigma = 0.25;
        let sys = PdFuzzySystem::new(1.0 / 3.0, sigma, Defuzz::TruncatedCentroid).unwrap();
        let n = 4000;
        let h = 1.0 / n as f64;
        for &(e, de) in &[(0.1, -0.7), (0.5, 0.2), (-0.9, 0.95), (0.0, 0.0), (0.37, -0.41)] {
            let f = product_firing(&sys.partition.memberships(e), &sys.partition.memberships(de));
            for (table, got) in [(&KP_TABLE, sys.infer(e, de).0), (&KD_TABLE, sys.infer(e, de).1)] {
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..=n {
                    let y = i as f64 * h;
                    let w = if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    let mut agg = 0.0;
                    for j in 0..7 {
                        for k in 0..7 {
                            let c = if table[j][k] == S { 0.0 } else { 1.0 };
                            agg += f[j][k] * gaussian(y, c, sigma);
                        }
                    }
                    num += w * y * agg;
                    den += w * agg;
                }
                assert!((num / den - got).abs() < 1e-12, "({e}, {de}): {} vs {got}", num / den);
            }
        }
    }

    #[test]
    fn singleton_inference_values() {
        let sys = PdFuzzySystem::new(1.0 / 3.0, 0.25, Defuzz::Singleton).unwrap();
        assert_eq!(sys.infer(0.0, 0.0), (1.0, 0.0)); // ZO/ZO: k'_p = B, k'_d = S
        assert_eq!(sys.infer(1.0, 0.0), (1.0, 0.0)); // PB row: B / S
        assert_eq!(sys.infer(1.0 / 3.0, 1.0), (0.0, 1.0)); // PS/PB: S / B
                                                           // halfway between ZO and PS on e, ZO on ė: ½ (B + B) for k'_p, ½ (S + S) for k'_d
        let (kp, kd) = sys.infer(1.0 / 6.0, 0.0);
        assert!((kp - 1.0).abs() < 1e-15 && kd.abs() < 1e-15);
        // ZO row, between ZO and PS on ė: ½ (B + S) and ½ (S + B)
        let (kp, kd) = sys.infer(0.0, 1.0 / 6.0);
        assert!((kp - 0.5).abs() < 1e-15 && (kd - 0.5).abs() < 1e-15);
        // clamping
        assert_eq!(sys.infer(5.0, -7.0), sys.infer(1.0, -1.0));
        assert!(PdFuzzySystem::new(0.2, 0.25, Defuzz::Singleton).is_err());
        assert!(PdFuzzySystem::new(1.0 / 3.0, 0.0, Defuzz::Singleton).is_err());
    }
}
