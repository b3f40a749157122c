//! The Dormand–Prince 5(4) Butcher tableau (Dormand & Prince 1980, "RK5(4)7M"), written once for the two
//! integrators that use it: the FMU runtime's adaptive plant integrator (`spacecraft_fmus`,
//! `src/math/integrate.rs`) and scfmu's Model Exchange stepper (`scfmu/engines/fmi_stepper`, used by the
//! Co-Simulation face of a Model Exchange unit and the compiled loop). A crate of its own, with no
//! dependency, so that the runtime does not link the engines' library loader and the engines do not build
//! the runtime's models.
//!
//! Seven stages in first-same-as-last form: stage 7 is evaluated at the new fifth-order point, at the
//! end of the step (`C[6] = 1`), and is stage 1 of the next step. The unit tests check the tableau
//! against the Runge–Kutta order conditions themselves, not against a second copy of the numbers.

/// Nodes c_i: stage i is evaluated at t + c_i·h.
pub const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// Stage coefficients a_ij (row i: stage i's point x + h·Σ_j a_ij k_j); row 7 holds the fifth-order
/// weights [`B`] (first same as last).
pub const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Fifth-order weights b_i (the step's result, local extrapolation); b_7 = 0.
pub const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// Fifth-order minus fourth-order weights: the local error estimate is h·Σ_i E_i k_i.
pub const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// The fourth-order continuous extension (dense output): x(t + θh) = x + h·Σ_i k_i·Σ_m P[i][m]·θ^(m+1)
/// (Shampine's interpolant, as in Hairer, Nørsett & Wanner and SciPy's `RK45`).
pub const P: [[f64; 4]; 7] = [
    [
        1.0,
        -8048581381.0 / 2820520608.0,
        8663915743.0 / 2820520608.0,
        -12715105075.0 / 11282082432.0,
    ],
    [0.0, 0.0, 0.0, 0.0],
    [
        0.0,
        131558114200.0 / 32700410799.0,
        -68118460800.0 / 10900136933.0,
        87487479700.0 / 32700410799.0,
    ],
    [
        0.0,
        -1754552775.0 / 470086768.0,
        14199869525.0 / 1410260304.0,
        -10690763975.0 / 1880347072.0,
    ],
    [
        0.0,
        127303824393.0 / 49829197408.0,
        -318862633887.0 / 49829197408.0,
        701980252875.0 / 199316789632.0,
    ],
    [
        0.0,
        -282668133.0 / 205662961.0,
        2019193451.0 / 616988883.0,
        -1453857185.0 / 822651844.0,
    ],
    [
        0.0,
        40617522.0 / 29380423.0,
        -110615467.0 / 29380423.0,
        69997945.0 / 29380423.0,
    ],
];

#[cfg(test)]
// index loops over stages and powers read like the order conditions they check
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::{A, B, C, E, P};

    type V = [f64; 7];

    fn dot(a: &V, b: &V) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }
    fn mul(a: &V, b: &V) -> V {
        std::array::from_fn(|i| a[i] * b[i])
    }
    /// (A·v)_i = Σ_j a_ij v_j
    fn av(v: &V) -> V {
        std::array::from_fn(|i| (0..6).map(|j| A[i][j] * v[j]).sum())
    }

    /// The elementary weight vectors Φ(τ) of the rooted trees τ up to order 5 with 1/γ(τ): a method
    /// with weights b has order p when b·Φ(τ) = 1/γ(τ) for every tree of order ≤ p (Butcher).
    fn trees() -> Vec<(usize, V, f64)> {
        let one = [1.0; 7];
        let c = C;
        let c2 = mul(&c, &c);
        let c3 = mul(&c2, &c);
        let ac = av(&c);
        let aac = av(&ac);
        vec![
            (1, one, 1.0),
            (2, c, 1.0 / 2.0),
            (3, c2, 1.0 / 3.0),
            (3, ac, 1.0 / 6.0),
            (4, c3, 1.0 / 4.0),
            (4, mul(&c, &ac), 1.0 / 8.0),
            (4, av(&c2), 1.0 / 12.0),
            (4, aac, 1.0 / 24.0),
            (5, mul(&c3, &c), 1.0 / 5.0),
            (5, mul(&c2, &ac), 1.0 / 10.0),
            (5, mul(&c, &av(&c2)), 1.0 / 15.0),
            (5, mul(&c, &aac), 1.0 / 30.0),
            (5, mul(&ac, &ac), 1.0 / 20.0),
            (5, av(&c3), 1.0 / 20.0),
            (5, av(&mul(&c, &ac)), 1.0 / 40.0),
            (5, av(&av(&c2)), 1.0 / 60.0),
            (5, av(&aac), 1.0 / 120.0),
        ]
    }

    #[test]
    fn rows_sum_to_the_nodes_and_last_row_is_b() {
        for i in 0..7 {
            let s: f64 = A[i].iter().sum();
            assert!((s - C[i]).abs() < 1e-15, "row {i}: Σ a = {s}, c = {}", C[i]);
            // explicit: stage i uses only the stages before it
            if i < 6 {
                assert!(A[i][i..].iter().all(|a| *a == 0.0), "row {i} is not explicit");
            }
        }
        assert_eq!(
            &A[6][..],
            &B[..6],
            "first same as last: row 7 is the fifth-order weights"
        );
        assert_eq!(B[6], 0.0);
    }

    #[test]
    fn fifth_order_weights_meet_all_17_conditions() {
        let t = trees();
        assert_eq!(t.len(), 17);
        for (k, (order, phi, g)) in t.iter().enumerate() {
            let r = dot(&B, phi);
            assert!((r - g).abs() < 2e-15, "tree {k} (order {order}): b·Φ = {r}, 1/γ = {g}");
        }
    }

    #[test]
    fn embedded_weights_have_order_four_not_five() {
        let bh: V = std::array::from_fn(|i| B[i] - E[i]);
        let mut worst5 = 0.0f64;
        for (order, phi, g) in trees() {
            let r = dot(&bh, &phi) - g;
            if order <= 4 {
                assert!(r.abs() < 2e-15, "order {order}: b̂·Φ − 1/γ = {r}");
            } else {
                worst5 = worst5.max(r.abs());
            }
        }
        // the error estimate is of the order h^5: some fifth-order condition must fail
        assert!(
            worst5 > 1e-4,
            "the embedded method meets the fifth-order conditions ({worst5})"
        );
    }

    #[test]
    fn dense_output_is_fourth_order_and_ends_at_the_step() {
        // at θ = 1 the interpolant gives the step's fifth-order point
        for i in 0..7 {
            let q1: f64 = P[i].iter().sum();
            assert!((q1 - B[i]).abs() < 1e-14, "q_{i}(1) = {q1}, b = {}", B[i]);
        }
        // Σ_i b_i(θ) Φ_i(τ) = θ^ρ(τ) / γ(τ) for every θ and tree of order ≤ 4: the coefficient of θ^m
        // (m = 1..4) is 1/γ where m = ρ(τ), else 0
        for (order, phi, g) in trees().into_iter().filter(|t| t.0 <= 4) {
            for m in 0..4 {
                let coef: f64 = (0..7).map(|i| P[i][m] * phi[i]).sum();
                let want = if m + 1 == order { g } else { 0.0 };
                assert!(
                    (coef - want).abs() < 1e-12,
                    "order {order}, θ^{}: {coef} ≠ {want}",
                    m + 1
                );
            }
        }
    }
}
