//! Continuous algebraic Riccati equation (CARE) and the LQR gain, for any state dimension n:
//!
//! ```text
//! Aᵀ P + P A + Q − P B R⁻¹ Bᵀ P = 0,      K = R⁻¹ Bᵀ P
//! ```
//!
//! Method: the stabilising solution spans the stable invariant subspace Im [I; P] of the Hamiltonian
//! H = [A, −B R⁻¹ Bᵀ; −Q, −Aᵀ]. That subspace is found with the matrix sign function of H (scaled
//! Newton iteration Z ← ½ (c Z + (c Z)⁻¹), Roberts 1971 / Byers 1987): (sign H + I) [I; P] = 0 is solved
//! for P in the least-squares sense. The result is then refined by Newton–Kleinman iterations
//! (Kleinman 1968), each solving the Lyapunov equation (A − BK)ᵀ X + X (A − BK) = −(Q + Kᵀ R K) through
//! its Kronecker form, which converge quadratically from this stabilising start. The solution is
//! accepted only if the closed loop A − BK is Hurwitz and the relative residual is below 1e-10.

use nalgebra::DMatrix;

/// Relative residual ‖AᵀP + PA + Q − PSP‖ / (‖AᵀP‖ + ‖PA‖ + ‖Q‖ + ‖PSP‖) (Frobenius norms).
pub fn care_residual(a: &DMatrix<f64>, s: &DMatrix<f64>, q: &DMatrix<f64>, p: &DMatrix<f64>) -> f64 {
    let atp = a.transpose() * p;
    let pa = p * a;
    let psp = p * s * p;
    let res = &atp + &pa + q - &psp;
    let scale = atp.norm() + pa.norm() + q.norm() + psp.norm();
    if scale == 0.0 {
        res.norm()
    } else {
        res.norm() / scale
    }
}

/// Solves Aᵀ X + X A = −M for X (M symmetric) through (I ⊗ Aᵀ + Aᵀ ⊗ I) vec X = −vec M.
pub fn lyapunov(a: &DMatrix<f64>, m: &DMatrix<f64>) -> Result<DMatrix<f64>, String> {
    let n = a.nrows();
    let at = a.transpose();
    let eye = DMatrix::<f64>::identity(n, n);
    let big = eye.kronecker(&at) + at.kronecker(&eye);
    let rhs = DMatrix::from_column_slice(n * n, 1, (-m).as_slice());
    let sol = big
        .lu()
        .solve(&rhs)
        .ok_or("Lyapunov equation is singular (A has eigenvalues λi + λj = 0)")?;
    let x = DMatrix::from_column_slice(n, n, sol.as_slice());
    Ok((&x + x.transpose()) * 0.5)
}

/// Largest real part of the eigenvalues of a square matrix.
pub fn spectral_abscissa(a: &DMatrix<f64>) -> f64 {
    a.clone()
        .complex_eigenvalues()
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max)
}

fn check_dims(a: &DMatrix<f64>, b: &DMatrix<f64>, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<(), String> {
    let n = a.nrows();
    let m = b.ncols();
    if n == 0 || a.ncols() != n {
        return Err(format!(
            "A must be square and non-empty, got {}x{}",
            a.nrows(),
            a.ncols()
        ));
    }
    if b.nrows() != n || m == 0 {
        return Err(format!("B must be {n}xm with m >= 1, got {}x{}", b.nrows(), b.ncols()));
    }
    if q.shape() != (n, n) || r.shape() != (m, m) {
        return Err(format!(
            "Q must be {n}x{n} and R {m}x{m}, got {:?} and {:?}",
            q.shape(),
            r.shape()
        ));
    }
    let all = a.iter().chain(b.iter()).chain(q.iter()).chain(r.iter());
    if all.into_iter().any(|v| !v.is_finite()) {
        return Err("A, B, Q and R must be finite".into());
    }
    let qs = (q - q.transpose()).norm();
    if qs > 1e-12 * q.norm().max(1e-300) {
        return Err("Q must be symmetric".into());
    }
    if (r - r.transpose()).norm() > 1e-12 * r.norm().max(1e-300) {
        return Err("R must be symmetric".into());
    }
    Ok(())
}

/// Matrix sign function by the scaled Newton iteration.
fn matrix_sign(h: &DMatrix<f64>) -> Result<DMatrix<f64>, String> {
    let n2 = h.nrows();
    let mut z = h.clone();
    let mut scale = true;
    for _ in 0..200 {
        let lu = z.clone().lu();
        let det = lu.determinant();
        let zinv = lu.try_inverse().ok_or("Hamiltonian matrix has eigenvalues on the imaginary axis: no stabilising Riccati solution (check stabilisability/detectability)")?;
        let c = if scale && det.is_finite() && det != 0.0 {
            det.abs().powf(-1.0 / n2 as f64)
        } else {
            1.0
        };
        let znew = (&z * c + zinv / c) * 0.5;
        if !znew.iter().all(|v| v.is_finite()) {
            return Err("matrix sign iteration diverged".into());
        }
        let diff = (&znew - &z).norm();
        let size = znew.norm();
        z = znew;
        if diff <= 1e-3 * size {
            scale = false; // close to convergence: plain Newton keeps its quadratic rate
        }
        if diff <= 1e-14 * size {
            return Ok(z);
        }
    }
    // Round-off may keep the last change around 1e-14; accept if sign(H)² ≈ I.
    let eye = DMatrix::<f64>::identity(n2, n2);
    if (&z * &z - &eye).norm() < 1e-8 * (n2 as f64) {
        Ok(z)
    } else {
        Err("matrix sign iteration did not converge".into())
    }
}

/// Stabilising solution P of the CARE. `r` must be symmetric positive definite, `q` symmetric
/// positive semi-definite, (A, B) stabilisable and (Q, A) detectable (else `Err`).
pub fn solve_care(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<DMatrix<f64>, String> {
    check_dims(a, b, q, r)?;
    let n = a.nrows();
    let chol = r.clone().cholesky().ok_or("R must be positive definite")?;
    let s = b * chol.solve(&b.transpose()); // B R⁻¹ Bᵀ
    let s = (&s + s.transpose()) * 0.5;

    // Hamiltonian and its sign
    let mut h = DMatrix::<f64>::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(a);
    h.view_mut((0, n), (n, n)).copy_from(&(-&s));
    h.view_mut((n, 0), (n, n)).copy_from(&(-q));
    h.view_mut((n, n), (n, n)).copy_from(&(-a.transpose()));
    let w = matrix_sign(&h)?;

    // (W + I) [I; P] = 0  →  [W12; W22 + I] P = −[W11 + I; W21]
    let eye = DMatrix::<f64>::identity(n, n);
    let mut lhs = DMatrix::<f64>::zeros(2 * n, n);
    lhs.view_mut((0, 0), (n, n)).copy_from(&w.view((0, n), (n, n)));
    lhs.view_mut((n, 0), (n, n)).copy_from(&(w.view((n, n), (n, n)) + &eye));
    let mut rhs = DMatrix::<f64>::zeros(2 * n, n);
    rhs.view_mut((0, 0), (n, n))
        .copy_from(&(-(w.view((0, 0), (n, n)) + &eye)));
    rhs.view_mut((n, 0), (n, n)).copy_from(&(-w.view((n, 0), (n, n))));
    let p0 = lhs
        .svd(true, true)
        .solve(&rhs, 1e-14)
        .map_err(|e| format!("stable subspace extraction failed: {e}"))?;
    let mut p = (&p0 + p0.transpose()) * 0.5;

    // Newton–Kleinman refinement
    let mut res = care_residual(a, &s, q, &p);
    for _ in 0..20 {
        let k = chol.solve(&(b.transpose() * &p));
        let acl = a - b * &k;
        if spectral_abscissa(&acl) >= 0.0 {
            break; // not stabilising: keep the sign-function result (checked below)
        }
        let m = q + k.transpose() * r * &k;
        let pn = lyapunov(&acl, &m)?;
        let rn = care_residual(a, &s, q, &pn);
        if !(rn < res) {
            break;
        }
        let change = (&pn - &p).norm() / pn.norm().max(1e-300);
        p = pn;
        res = rn;
        if change < 1e-15 {
            break;
        }
    }

    if !(res <= 1e-10) {
        return Err(format!("Riccati solution inaccurate: relative residual {res:e}"));
    }
    let acl = a - &s * &p;
    let abscissa = spectral_abscissa(&acl);
    if !(abscissa < 0.0) {
        return Err(format!(
            "Riccati solution is not stabilising (closed-loop spectral abscissa {abscissa:e})"
        ));
    }
    Ok(p)
}

/// LQR gain K = R⁻¹ Bᵀ P and the Riccati solution P (u = −K x minimises ∫ xᵀQx + uᵀRu dt).
pub fn lqr(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), String> {
    let p = solve_care(a, b, q, r)?;
    let chol = r.clone().cholesky().ok_or("R must be positive definite")?;
    let k = chol.solve(&(b.transpose() * &p));
    Ok((k, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small deterministic generator for test matrices (xorshift64*).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let v = self.0.wrapping_mul(0x2545F4914F6CDD1D);
            (v >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        fn mat(&mut self, r: usize, c: usize) -> DMatrix<f64> {
            DMatrix::from_fn(r, c, |_, _| self.next())
        }
        fn spd(&mut self, n: usize) -> DMatrix<f64> {
            let m = self.mat(n, n);
            &m * m.transpose() + DMatrix::identity(n, n) * 0.1
        }
    }

    #[test]
    fn double_integrator_closed_form() {
        // A = [0 1; 0 0], B = [0; b], Q = diag(q1, q2), R = r: p12 = sqrt(q1 r)/b,
        // p22 = sqrt(r (q2 + 2 p12))/b, p11 = b² p12 p22 / r.
        for &(q1, q2, r, inertia) in &[
            (1.0, 2.0, 1.0 / 1e6, 1000.0),
            (3.0, 0.5, 2.0, 7.0),
            (0.2, 5.0, 1e-3, 250.0),
        ] {
            let b = 1.0 / inertia;
            let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
            let bm = DMatrix::from_row_slice(2, 1, &[0.0, b]);
            let q = DMatrix::from_row_slice(2, 2, &[q1, 0.0, 0.0, q2]);
            let rm = DMatrix::from_element(1, 1, r);
            let (k, p) = lqr(&a, &bm, &q, &rm).unwrap();
            let p12 = (q1 * r).sqrt() / b;
            let p22 = (r * (q2 + 2.0 * p12)).sqrt() / b;
            let p11 = b * b * p12 * p22 / r;
            for (got, want) in [
                (p[(0, 0)], p11),
                (p[(0, 1)], p12),
                (p[(1, 1)], p22),
                (k[(0, 0)], b * p12 / r),
                (k[(0, 1)], b * p22 / r),
            ] {
                assert!((got - want).abs() <= 1e-12 * want.abs(), "{got} vs {want}");
            }
        }
        // paper 000 defaults: K = [I, 2I]
        let i = 1000.0;
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let bm = DMatrix::from_row_slice(2, 1, &[0.0, 1.0 / i]);
        let q = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 2.0]);
        let (k, _) = lqr(&a, &bm, &q, &DMatrix::from_element(1, 1, 1.0 / (i * i))).unwrap();
        assert!(
            (k[(0, 0)] - i).abs() < 1e-12 * i && (k[(0, 1)] - 2.0 * i).abs() < 1e-12 * i,
            "{k}"
        );
    }

    #[test]
    fn random_systems_satisfy_care_and_stabilise() {
        let mut rng = Rng(0x9E3779B97F4A7C15);
        let mut worst: f64 = 0.0;
        for n in 1..=6 {
            for m in 1..=n.min(3) {
                for _ in 0..5 {
                    let a = rng.mat(n, n) * 2.0;
                    let b = rng.mat(n, m);
                    let q = rng.spd(n);
                    let r = rng.spd(m);
                    let (k, p) = lqr(&a, &b, &q, &r).unwrap();
                    let s = &b * r.clone().try_inverse().unwrap() * b.transpose();
                    let res = care_residual(&a, &s, &q, &p);
                    worst = worst.max(res);
                    assert!(res < 1e-10, "n={n} m={m}: residual {res:e}");
                    assert!(spectral_abscissa(&(&a - &b * &k)) < 0.0);
                    assert!((&p - p.transpose()).norm() < 1e-12 * p.norm());
                    // P positive definite (Q > 0)
                    assert!(p.clone().cholesky().is_some());
                }
            }
        }
        println!("worst relative CARE residual {worst:e}");
    }

    #[test]
    fn scalar_case() {
        // a p + p a + q − p² b²/r = 0 → p = r (a + sqrt(a² + q b²/r)) / b²
        for &(a, b, q, r) in &[(1.0, 1.0, 1.0, 1.0), (-2.0, 0.5, 3.0, 0.1), (5.0, 2.0, 0.0, 1.0)] {
            let p = solve_care(
                &DMatrix::from_element(1, 1, a),
                &DMatrix::from_element(1, 1, b),
                &DMatrix::from_element(1, 1, q),
                &DMatrix::from_element(1, 1, r),
            )
            .unwrap();
            let want = r * (a + (a * a + q * b * b / r).sqrt()) / (b * b);
            assert!(
                (p[(0, 0)] - want).abs() < 1e-13 * want.abs().max(1.0),
                "{} vs {want}",
                p[(0, 0)]
            );
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let q = DMatrix::identity(2, 2);
        assert!(
            solve_care(&a, &b, &q, &DMatrix::from_element(1, 1, 0.0)).is_err(),
            "R = 0"
        );
        assert!(
            solve_care(&a, &b, &q, &DMatrix::from_element(1, 1, -1.0)).is_err(),
            "R < 0"
        );
        // uncontrollable unstable mode: A = diag(1, 1), B = [1; 0]
        let a2 = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let b2 = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        assert!(
            solve_care(&a2, &b2, &q, &DMatrix::from_element(1, 1, 1.0)).is_err(),
            "not stabilisable"
        );
        assert!(
            solve_care(&a, &b, &DMatrix::identity(3, 3), &DMatrix::from_element(1, 1, 1.0)).is_err(),
            "dims"
        );
    }

    #[test]
    fn lyapunov_solution() {
        let a = DMatrix::from_row_slice(3, 3, &[-1.0, 2.0, 0.0, 0.0, -3.0, 1.0, 0.5, 0.0, -2.0]);
        let m = DMatrix::from_row_slice(3, 3, &[2.0, 0.1, 0.0, 0.1, 1.0, 0.3, 0.0, 0.3, 4.0]);
        let x = lyapunov(&a, &m).unwrap();
        assert!((a.transpose() * &x + &x * &a + &m).norm() < 1e-13);
    }
}
