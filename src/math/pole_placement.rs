//! State-feedback pole placement for single-input pairs (A, b) by Ackermann's formula:
//!
//! ```text
//! K = [0 … 0 1] C⁻¹ φ(A),    C = [b  Ab  …  Aⁿ⁻¹b],    φ(s) = sⁿ + a_{n−1} sⁿ⁻¹ + … + a_0
//! ```
//!
//! so that A − bK has the characteristic polynomial φ. Poles are given either as the monic
//! polynomial's coefficients or as a list of roots (real, or in complex-conjugate pairs).

use nalgebra::{Complex, DMatrix, DVector};

/// Monic polynomial coefficients [a_{n−1}, …, a_0] of Π (s − p_i). The roots must be real or come in
/// conjugate pairs (else `Err`).
pub fn poly_from_roots(roots: &[Complex<f64>]) -> Result<Vec<f64>, String> {
    if roots.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()) {
        return Err("poles must be finite".into());
    }
    // c[0] = 1 (leading), then the lower coefficients
    let mut c: Vec<Complex<f64>> = vec![Complex::new(1.0, 0.0)];
    for &p in roots {
        let mut next = vec![Complex::new(0.0, 0.0); c.len() + 1];
        for (i, &ci) in c.iter().enumerate() {
            next[i] += ci;
            next[i + 1] -= ci * p;
        }
        c = next;
    }
    let scale = c.iter().map(|z| z.norm()).fold(1.0, f64::max);
    if c.iter().any(|z| z.im.abs() > 1e-9 * scale) {
        return Err("complex poles must come in conjugate pairs".into());
    }
    Ok(c[1..].iter().map(|z| z.re).collect())
}

/// Coefficients [2 ξ ω_n, ω_n²] of s² + 2 ξ ω_n s + ω_n².
pub fn second_order_poly(wn: f64, zeta: f64) -> [f64; 2] {
    [2.0 * zeta * wn, wn * wn]
}

/// Roots of s² + c1 s + c0.
pub fn quadratic_roots(c1: f64, c0: f64) -> [Complex<f64>; 2] {
    let d = c1 * c1 - 4.0 * c0;
    if d >= 0.0 {
        // numerically stable form
        let sq = d.sqrt();
        let q = -0.5 * (c1 + if c1 >= 0.0 { sq } else { -sq });
        let (r1, r2) = if q != 0.0 { (q, c0 / q) } else { (0.5 * sq, -0.5 * sq) };
        [Complex::new(r1, 0.0), Complex::new(r2, 0.0)]
    } else {
        let im = 0.5 * (-d).sqrt();
        [Complex::new(-0.5 * c1, im), Complex::new(-0.5 * c1, -im)]
    }
}

/// Controllability matrix [b, Ab, …, Aⁿ⁻¹b].
pub fn controllability(a: &DMatrix<f64>, b: &DVector<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let mut c = DMatrix::<f64>::zeros(n, n);
    let mut col = b.clone();
    for j in 0..n {
        c.set_column(j, &col);
        col = a * col;
    }
    c
}

/// Ackermann gain row K (length n) with det(sI − (A − bK)) = sⁿ + coeffs[0] sⁿ⁻¹ + … + coeffs[n−1].
pub fn ackermann(a: &DMatrix<f64>, b: &DVector<f64>, coeffs: &[f64]) -> Result<DVector<f64>, String> {
    let n = a.nrows();
    if n == 0 || a.ncols() != n || b.len() != n {
        return Err(format!(
            "A must be n x n and b of length n, got {:?} and {}",
            a.shape(),
            b.len()
        ));
    }
    if coeffs.len() != n {
        return Err(format!("need {n} polynomial coefficients, got {}", coeffs.len()));
    }
    if a.iter().chain(b.iter()).chain(coeffs.iter()).any(|v| !v.is_finite()) {
        return Err("A, b and the polynomial must be finite".into());
    }
    let c = controllability(a, b);
    // φ(A) by Horner: ((A + a_{n−1} I) A + a_{n−2} I) A + …
    let eye = DMatrix::<f64>::identity(n, n);
    let mut phi = a.clone() + &eye * coeffs[0];
    for &ck in &coeffs[1..] {
        phi = &phi * a + &eye * ck;
    }
    // last row of C⁻¹: solve Cᵀ y = e_n
    let mut en = DVector::<f64>::zeros(n);
    en[n - 1] = 1.0;
    let svd = c.transpose().svd(true, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if !(smin > 1e-12 * smax) {
        return Err(format!(
            "pair (A, b) is not controllable (controllability matrix condition {:e})",
            smax / smin
        ));
    }
    let y = svd.solve(&en, 0.0).map_err(|e| e.to_string())?;
    Ok(phi.transpose() * y)
}

/// Ackermann gain for the requested closed-loop poles.
pub fn place(a: &DMatrix<f64>, b: &DVector<f64>, poles: &[Complex<f64>]) -> Result<DVector<f64>, String> {
    ackermann(a, b, &poly_from_roots(poles)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted_eigs(m: &DMatrix<f64>) -> Vec<Complex<f64>> {
        let mut e: Vec<_> = m.clone().complex_eigenvalues().iter().copied().collect();
        e.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        e
    }

    #[test]
    fn double_integrator_gains_closed_form() {
        // A = [0 1; 0 0], b = [0; 1/I]: K = [I ω_n², 2 ξ ω_n I]
        for &(wn, zeta, inertia) in &[(1.0, 1.0, 1000.0), (0.3, 0.7, 500.0), (2.0, 1.5, 7.0)] {
            let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
            let b = DVector::from_vec(vec![0.0, 1.0 / inertia]);
            let k = ackermann(&a, &b, &second_order_poly(wn, zeta)).unwrap();
            assert!((k[0] - inertia * wn * wn).abs() < 1e-12 * inertia);
            assert!((k[1] - 2.0 * zeta * wn * inertia).abs() < 1e-12 * inertia);
        }
    }

    #[test]
    fn closed_loop_poles_are_the_requested_ones() {
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0, 1.0, 0.0, 0.0, 0.3, -0.1, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, -2.0, 0.5,
            ],
        );
        let b = DVector::from_vec(vec![0.0, 0.5, 0.0, 1.0]);
        let poles = [
            Complex::new(-1.0, 0.5),
            Complex::new(-1.0, -0.5),
            Complex::new(-2.0, 0.0),
            Complex::new(-0.5, 0.0),
        ];
        let k = place(&a, &b, &poles).unwrap();
        let acl = &a - &b * k.transpose();
        let got = sorted_eigs(&acl);
        let mut want = poles.to_vec();
        want.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).norm() < 1e-8, "{g} vs {w}");
        }
    }

    #[test]
    fn polynomial_and_roots() {
        let c = poly_from_roots(&[Complex::new(-1.0, 2.0), Complex::new(-1.0, -2.0)]).unwrap();
        assert!((c[0] - 2.0).abs() < 1e-15 && (c[1] - 5.0).abs() < 1e-15);
        assert!(poly_from_roots(&[Complex::new(-1.0, 2.0), Complex::new(-1.0, 2.0)]).is_err());
        for &(c1, c0) in &[(2.0, 1.0), (3.0, 2.0), (1.0, 5.0), (-1.0, -6.0)] {
            for r in quadratic_roots(c1, c0) {
                assert!((r * r + r * c1 + c0).norm() < 1e-12, "{r}");
            }
        }
    }

    #[test]
    fn uncontrollable_pair_is_an_error() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 2.0]);
        let b = DVector::from_vec(vec![1.0, 0.0]);
        assert!(ackermann(&a, &b, &[2.0, 1.0]).is_err());
    }
}
