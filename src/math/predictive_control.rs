//! Nonlinear predictive control gains of paper 001 (Eqs. 22, 25): the weighting matrix H̄ of the
//! prediction over [T1, T2] for a relative-degree-2 output and the gains K1, K2 derived from it.

use nalgebra::Matrix3;

fn factorial(k: usize) -> f64 {
    (1..=k).fold(1.0, |a, i| a * i as f64)
}

/// H̄_ij = (T2^{i+j−1} − T1^{i+j−1}) / ((i−1)! (j−1)! (i+j−1)), i, j ∈ {1, 2, 3} (paper 001 Eq. 22).
pub fn hbar(t1: f64, t2: f64) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| {
        // r, c are 0-based: i = r + 1, j = c + 1, i + j − 1 = r + c + 1
        let k = (r + c + 1) as i32;
        (t2.powi(k) - t1.powi(k)) / (factorial(r) * factorial(c) * k as f64)
    })
}

/// K1 = H̄33⁻¹ H̄31, K2 = H̄33⁻¹ H̄32 (paper 001 Eq. 25), from the H̄ matrix. Requires 0 ≤ T1 < T2.
pub fn predictive_gains(t1: f64, t2: f64) -> Result<(f64, f64), String> {
    if !(t1.is_finite() && t1 >= 0.0) {
        return Err(format!("parameter T1 = {t1} must be >= 0"));
    }
    if !(t2.is_finite() && t2 > t1) {
        return Err(format!("parameter T2 = {t2} must be finite and > T1 = {t1}"));
    }
    let h = hbar(t1, t2);
    let h33 = h[(2, 2)];
    Ok((h[(2, 0)] / h33, h[(2, 1)] / h33))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gains_match_closed_form_for_t1_zero() {
        // T1 = 0: K1 = 10/(3T²), K2 = 5/(2T) ([NPPID-Formation] Eq. 25 with T1 = 0)
        for t in [0.5, 5.0, 25.0, 100.0] {
            let (k1, k2) = predictive_gains(0.0, t).unwrap();
            assert!((k1 - 10.0 / (3.0 * t * t)).abs() < 1e-14 * k1, "T {t}: K1 {k1}");
            assert!((k2 - 5.0 / (2.0 * t)).abs() < 1e-14 * k2, "T {t}: K2 {k2}");
        }
        let (k1, k2) = predictive_gains(0.0, 25.0).unwrap();
        assert!((k1 - 0.00533333).abs() < 1e-8 && (k2 - 0.1).abs() < 1e-15);
    }

    #[test]
    fn hbar_is_symmetric_with_known_entries() {
        let h = hbar(1.0, 3.0);
        assert!((h - h.transpose()).norm() == 0.0);
        assert_eq!(h[(0, 0)], 2.0); // T2 − T1
        assert_eq!(h[(0, 1)], 4.0); // (9 − 1)/2
        assert!((h[(2, 2)] - (243.0 - 1.0) / 20.0).abs() < 1e-12);
        // H̄ is a Gram matrix of (1, τ, τ²/2) on [T1, T2]: positive definite
        assert!(nalgebra::Cholesky::new(h).is_some());
    }

    #[test]
    fn t1_nonzero_solves_the_general_formula() {
        // independent: K from Gram integrals of 1, τ, τ²/2 over [T1, T2] by Simpson's rule
        let (t1, t2) = (2.0, 7.0);
        let n = 2000;
        let hstep = (t2 - t1) / n as f64;
        let mut g = [0.0f64; 3]; // ∫ τ²/2 · (1, τ, τ²/2) dτ
        for k in 0..=n {
            let tau = t1 + k as f64 * hstep;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let b = [1.0, tau, tau * tau / 2.0];
            for (gi, bi) in g.iter_mut().zip(b) {
                *gi += w * hstep / 3.0 * tau * tau / 2.0 * bi;
            }
        }
        let (k1, k2) = predictive_gains(t1, t2).unwrap();
        assert!((k1 - g[0] / g[2]).abs() < 1e-10 * k1);
        assert!((k2 - g[1] / g[2]).abs() < 1e-10 * k2);
    }

    #[test]
    fn invalid_horizons_are_rejected() {
        assert!(predictive_gains(0.0, 0.0).unwrap_err().contains("T2"));
        assert!(predictive_gains(-1.0, 5.0).unwrap_err().contains("T1"));
        assert!(predictive_gains(6.0, 5.0).unwrap_err().contains("T2"));
    }
}
