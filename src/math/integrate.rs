//! Fixed-step integrators over nalgebra vectors, and the splitting of a communication step into
//! internal steps (equal steps between breakpoints such as a fault onset).

use nalgebra::SVector;

/// One classical Runge–Kutta 4 step of ẋ = f(t, x).
pub fn rk4<const N: usize>(f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>, t: f64, x: &SVector<f64, N>, h: f64) -> SVector<f64, N> {
    let k1 = f(t, x);
    let k2 = f(t + 0.5 * h, &(x + k1 * (0.5 * h)));
    let k3 = f(t + 0.5 * h, &(x + k2 * (0.5 * h)));
    let k4 = f(t + h, &(x + k3 * h));
    x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

/// One explicit Euler step.
pub fn euler<const N: usize>(f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>, t: f64, x: &SVector<f64, N>, h: f64) -> SVector<f64, N> {
    x + f(t, x) * h
}

/// Fixed-step methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FixedMethod {
    Rk4,
    Euler,
}

/// Internal steps covering [t0, t0 + h]: the interval is cut at every breakpoint strictly inside it,
/// and each piece is divided into ⌈length / max_step⌉ equal steps. Returns (start, length) pairs.
pub fn internal_steps(t0: f64, h: f64, max_step: f64, breakpoints: &[f64]) -> Vec<(f64, f64)> {
    let t1 = t0 + h;
    let mut cuts: Vec<f64> = breakpoints.iter().copied().filter(|b| *b > t0 + 1e-12 * h && *b < t1 - 1e-12 * h).collect();
    cuts.sort_by(f64::total_cmp);
    let mut edges = vec![t0];
    edges.extend(cuts);
    edges.push(t1);
    let mut steps = Vec::new();
    for pair in edges.windows(2) {
        let len = pair[1] - pair[0];
        let n = (len / max_step - 1e-9).ceil().max(1.0) as usize;
        let dt = len / n as f64;
        for k in 0..n {
            steps.push((pair[0] + k as f64 * dt, dt));
        }
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn rk4_harmonic_oscillator_is_fourth_order() {
        // ẍ = −x, x(0) = 1: x(t) = cos t. Halving h divides the error by about 16.
        let mut f = |_t: f64, x: &Vector2<f64>| Vector2::new(x[1], -x[0]);
        let mut err = |h: f64| {
            let n = (1.0 / h).round() as usize;
            let mut x = Vector2::new(1.0, 0.0);
            for k in 0..n {
                x = rk4(&mut f, k as f64 * h, &x, h);
            }
            (x[0] - 1f64.cos()).abs()
        };
        let ratio = err(0.1) / err(0.05);
        assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn euler_is_first_order_exact_on_linear_growth() {
        let mut f = |_t: f64, _x: &SVector<f64, 1>| SVector::<f64, 1>::new(2.0);
        let x = euler(&mut f, 0.0, &SVector::<f64, 1>::new(1.0), 0.5);
        assert_eq!(x[0], 2.0);
    }

    #[test]
    fn internal_steps_split_at_breakpoints() {
        let s = internal_steps(0.0, 0.1, 0.01, &[]);
        assert_eq!(s.len(), 10);
        let s = internal_steps(0.0, 0.1, 0.04, &[0.05]);
        // [0, 0.05] in 2 steps, [0.05, 0.1] in 2 steps
        assert_eq!(s.len(), 4);
        assert!((s[2].0 - 0.05).abs() < 1e-15);
        let total: f64 = s.iter().map(|x| x.1).sum();
        assert!((total - 0.1).abs() < 1e-15);
        // breakpoints on the edges do not add steps
        assert_eq!(internal_steps(1.0, 0.01, 0.01, &[1.0, 1.01]).len(), 1);
    }
}
