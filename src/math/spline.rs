//! Cubic interpolating spline with not-a-knot end conditions (the default of MATLAB's `spline` and
//! of `scipy.interpolate.CubicSpline(..., bc_type="not-a-knot")`).
//!
//! Through n nodes (t_0 < … < t_{n−1}, values y_i) the spline is one cubic per interval, twice
//! continuously differentiable. Not-a-knot: the third derivative is also continuous at t_1 and at
//! t_{n−2}, so the first two and the last two intervals are each one cubic. Consequences used by the
//! tests: any cubic polynomial is reproduced exactly; with 3 nodes the spline is the parabola through
//! them, with 2 nodes the straight line.
//!
//! Construction by the second-derivative ("moment") form: with h_i = t_{i+1} − t_i,
//! d_i = (y_{i+1} − y_i)/h_i and M_i = s''(t_i),
//! ```text
//! h_{i−1} M_{i−1} + 2 (h_{i−1} + h_i) M_i + h_i M_{i+1} = 6 (d_i − d_{i−1}),   i = 1 … n−2
//! h_1 M_0 − (h_0 + h_1) M_1 + h_0 M_2 = 0                                         (s''' continuous at t_1)
//! h_{n−2} M_{n−3} − (h_{n−3} + h_{n−2}) M_{n−2} + h_{n−3} M_{n−1} = 0               (at t_{n−2})
//! ```
//! The n × n system is solved once by LU with partial pivoting. Evaluation outside [t_0, t_{n−1}]
//! extends the end cubics (like SciPy's `extrapolate=True`); callers that want something else
//! (e.g. zero torque after the last node) decide that themselves.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// A not-a-knot cubic spline; value, first and second derivative at any t.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NotAKnotSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the nodes.
    m: Vec<f64>,
}

impl NotAKnotSpline {
    /// Builds the spline through (t_i, y_i). Needs at least 2 nodes, strictly increasing finite
    /// times and finite values; otherwise an error message naming the problem.
    pub fn new(t: &[f64], y: &[f64]) -> Result<Self, String> {
        let n = t.len();
        if n != y.len() {
            return Err(format!("spline: {} node times but {} node values", n, y.len()));
        }
        if n < 2 {
            return Err(format!("spline: needs at least 2 nodes, got {n}"));
        }
        if let Some(i) = t.iter().chain(y.iter()).position(|v| !v.is_finite()) {
            return Err(format!("spline: node {} is not finite", i % n));
        }
        if let Some(i) = (1..n).find(|&i| t[i] <= t[i - 1]) {
            return Err(format!(
                "spline: node times must increase strictly (t[{}] = {} ≤ t[{}] = {})",
                i,
                t[i],
                i - 1,
                t[i - 1]
            ));
        }
        let m = match n {
            2 => vec![0.0, 0.0],
            // not-a-knot with 3 nodes: the parabola through them (constant second derivative)
            3 => {
                let (h0, h1) = (t[1] - t[0], t[2] - t[1]);
                let c = 2.0 * ((y[2] - y[1]) / h1 - (y[1] - y[0]) / h0) / (h0 + h1);
                vec![c; 3]
            }
            _ => Self::moments(t, y)?,
        };
        Ok(NotAKnotSpline {
            t: t.to_vec(),
            y: y.to_vec(),
            m,
        })
    }

    fn moments(t: &[f64], y: &[f64]) -> Result<Vec<f64>, String> {
        let n = t.len();
        let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let d: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut b = DVector::<f64>::zeros(n);
        (a[(0, 0)], a[(0, 1)], a[(0, 2)]) = (h[1], -(h[0] + h[1]), h[0]);
        for i in 1..n - 1 {
            (a[(i, i - 1)], a[(i, i)], a[(i, i + 1)]) = (h[i - 1], 2.0 * (h[i - 1] + h[i]), h[i]);
            b[i] = 6.0 * (d[i] - d[i - 1]);
        }
        let k = n - 1;
        (a[(k, k - 2)], a[(k, k - 1)], a[(k, k)]) = (h[k - 1], -(h[k - 2] + h[k - 1]), h[k - 2]);
        let m = a.lu().solve(&b).ok_or("spline: singular not-a-knot system")?;
        Ok(m.iter().copied().collect())
    }

    /// Node times.
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// Index of the interval used for t (end intervals extended beyond the nodes).
    fn interval(&self, t: f64) -> usize {
        let n = self.t.len();
        // first node index with t_i > t, minus one, clamped to 0 … n−2
        let p = self.t.partition_point(|&ti| ti <= t);
        p.saturating_sub(1).min(n - 2)
    }

    /// (s(t), s'(t), s''(t)).
    pub fn eval_all(&self, t: f64) -> (f64, f64, f64) {
        let i = self.interval(t);
        let h = self.t[i + 1] - self.t[i];
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let (y0, y1) = (self.y[i], self.y[i + 1]);
        let a = t - self.t[i]; // distance from the left node
        let b = self.t[i + 1] - t; // distance to the right node
                                   // s = M0 b³/(6h) + M1 a³/(6h) + (y0/h − M0 h/6) b + (y1/h − M1 h/6) a
        let c0 = y0 / h - m0 * h / 6.0;
        let c1 = y1 / h - m1 * h / 6.0;
        let s = (m0 * b * b * b + m1 * a * a * a) / (6.0 * h) + c0 * b + c1 * a;
        let ds = (-m0 * b * b + m1 * a * a) / (2.0 * h) - c0 + c1;
        let dds = (m0 * b + m1 * a) / h;
        (s, ds, dds)
    }

    /// s(t).
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_all(t).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    #[test]
    fn reproduces_any_cubic_exactly_on_uneven_nodes() {
        let p = |t: f64| 0.7 - 1.3 * t + 0.25 * t * t - 0.04 * t * t * t;
        let dp = |t: f64| -1.3 + 0.5 * t - 0.12 * t * t;
        let ddp = |t: f64| 0.5 - 0.24 * t;
        let t = [0.0, 0.5, 2.0, 2.7, 4.0, 6.5, 7.0];
        let y: Vec<f64> = t.iter().map(|&x| p(x)).collect();
        let s = NotAKnotSpline::new(&t, &y).unwrap();
        for k in 0..=140 {
            let x = -0.5 + k as f64 * 0.0575; // includes extrapolation on both sides
            let (v, d, dd) = s.eval_all(x);
            assert!(close(v, p(x), 1e-12), "s({x}) = {v} vs {}", p(x));
            assert!(close(d, dp(x), 1e-11), "s'({x}) = {d} vs {}", dp(x));
            assert!(close(dd, ddp(x), 1e-10), "s''({x}) = {dd} vs {}", ddp(x));
        }
    }

    #[test]
    fn three_nodes_give_the_parabola_and_two_the_line() {
        let s = NotAKnotSpline::new(&[1.0, 2.0, 4.0], &[1.0, 4.0, 16.0]).unwrap(); // y = t²
        for x in [0.0, 1.5, 3.0, 5.0] {
            assert!(close(s.eval(x), x * x, 1e-13));
        }
        let l = NotAKnotSpline::new(&[0.0, 2.0], &[1.0, 5.0]).unwrap();
        assert!(close(l.eval(0.5), 2.0, 1e-15) && close(l.eval_all(3.0).1, 2.0, 1e-15));
    }

    /// Reference values from scipy 1.17 `CubicSpline(t, y, bc_type="not-a-knot")` (computed once
    /// outside this crate and pasted here): nodes of the paper-004 layout, 6 nodes on [0, 20] s.
    #[test]
    fn matches_scipy_not_a_knot_on_six_equally_spaced_nodes() {
        let t = [0.0, 4.0, 8.0, 12.0, 16.0, 20.0];
        let y = [0.3, -0.5, 1.0, 0.2, -0.7, 0.0];
        let s = NotAKnotSpline::new(&t, &y).unwrap();
        for (x, v, d, dd) in SCIPY_REF {
            let (sv, sd, sdd) = s.eval_all(x);
            assert!(close(sv, v, 1e-13), "s({x}) = {sv} vs scipy {v}");
            assert!(close(sd, d, 1e-13), "s'({x}) = {sd} vs scipy {d}");
            assert!(close(sdd, dd, 1e-12), "s''({x}) = {sdd} vs scipy {dd}");
        }
        // the third derivative is continuous at t_1 and t_4 (not-a-knot)
        let jump = |k: f64| {
            let e = 1e-3;
            let l = (s.eval_all(k - e).2 - s.eval_all(k - 2.0 * e).2) / e;
            let r = (s.eval_all(k + 2.0 * e).2 - s.eval_all(k + e).2) / e;
            (l - r).abs()
        };
        assert!(jump(4.0) < 1e-9 && jump(16.0) < 1e-9);
        assert!(jump(8.0) > 1e-3, "an ordinary knot keeps its third-derivative jump");
    }

    #[test]
    fn rejects_bad_nodes() {
        assert!(NotAKnotSpline::new(&[0.0], &[1.0]).unwrap_err().contains("at least 2"));
        assert!(NotAKnotSpline::new(&[0.0, 1.0, 1.0], &[1.0, 2.0, 3.0])
            .unwrap_err()
            .contains("increase"));
        assert!(NotAKnotSpline::new(&[0.0, 1.0], &[1.0, f64::NAN])
            .unwrap_err()
            .contains("not finite"));
        assert!(NotAKnotSpline::new(&[0.0, 1.0], &[1.0]).unwrap_err().contains("values"));
    }

    // (t, s, s', s'') — filled from scipy, see the test above.
    const SCIPY_REF: [(f64, f64, f64, f64); 13] = [
        (-1.0, 1.6148437499999997, -1.621753472222222, 0.6473958333333333),
        (0.0, 0.3, -1.024722222222222, 0.5466666666666666),
        (1.3, -0.6070892187499999, -0.39917170138888874, 0.41571875),
        (4.0, -0.5, 0.3561111111111111, 0.14375000000000002),
        (5.5, 0.1392252604166667, 0.4584157986111111, -0.00734375000000001),
        (8.0, 1.0, 0.12527777777777774, -0.2591666666666667),
        (10.1, 0.8033638020833335, -0.2593394097222223, -0.10713541666666668),
        (12.0, 0.2, -0.33222222222222214, 0.030416666666666647),
        (14.9, -0.5648311979166666, -0.17086440972222222, 0.0808645833333333),
        (16.0, -0.7, -0.07138888888888893, 0.09999999999999998),
        (19.2, -0.3214400000000003, 0.3376777777777777, 0.15566666666666673),
        (20.0, 0.0, 0.4677777777777779, 0.16958333333333345),
        (21.0, 0.5554687500000002, 0.646059027777778, 0.1869791666666668),
    ];
}
