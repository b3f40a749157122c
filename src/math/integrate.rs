//! Fixed-step integrators over nalgebra vectors, the adaptive Dormand–Prince 5(4) integrator, the
//! splitting of a communication step into pieces at events, and the `Stepper` every plant uses.

use nalgebra::SVector;

// Dormand & Prince (1980) RK5(4)7M coefficients: the one tableau of every integrator of the project
use super::dopri_tableau::{A as DP_A, C as DP_C, E as DP_E};
use crate::model::{Experiment, ParamEnum};

/// Most internal integration steps one call may take (one `fmi2DoStep` of a plant, one adaptive
/// integration): a step that would need more is refused before any work is done, so every call
/// returns in bounded time.
pub const MAX_INTERNAL_STEPS: usize = 1_000_000;

/// Refuses a fixed-step integration of `span` seconds in steps of at most `max_step` when it would
/// take more than [`MAX_INTERNAL_STEPS`] steps.
pub fn check_step_count(span: f64, max_step: f64) -> Result<(), String> {
    let n = span / max_step;
    if !(n <= MAX_INTERNAL_STEPS as f64) {
        return Err(format!(
            "a step of {span} s needs {n:.3e} internal steps of at most {max_step} s, more than the limit of {MAX_INTERNAL_STEPS} per call \
             (use shorter communication steps or a larger internal step)"
        ));
    }
    Ok(())
}

/// One classical Runge–Kutta 4 step of ẋ = f(t, x).
pub fn rk4<const N: usize>(
    f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N> {
    let k1 = f(t, x);
    let k2 = f(t + 0.5 * h, &(x + k1 * (0.5 * h)));
    let k3 = f(t + 0.5 * h, &(x + k2 * (0.5 * h)));
    let k4 = f(t + h, &(x + k3 * h));
    x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

/// One explicit Euler step.
pub fn euler<const N: usize>(
    f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N> {
    x + f(t, x) * h
}

/// Result of an adaptive integration over one interval.
#[derive(Clone, Copy, Debug)]
pub struct AdaptiveOutcome<const N: usize> {
    pub x: SVector<f64, N>,
    /// Step size to try first on the next interval (the controller's last proposal).
    pub h_next: f64,
    pub accepted: usize,
    pub rejected: usize,
}

/// The step's error estimate as the RMS over components of e_i / (atol + rtol · max(|x_i|, |x_new,i|)),
/// with e = step · Σ_j E_j k_j.
fn error_norm<const N: usize>(
    k: &[SVector<f64, N>; 7],
    step: f64,
    x: &SVector<f64, N>,
    xs: &SVector<f64, N>,
    rtol: f64,
    atol: f64,
) -> f64 {
    let mut errv = SVector::<f64, N>::zeros();
    for (j, kj) in k.iter().enumerate() {
        if DP_E[j] != 0.0 {
            errv += kj * (DP_E[j] * step);
        }
    }
    let mut sum = 0.0;
    for i in 0..N {
        let sc = atol + rtol * x[i].abs().max(xs[i].abs());
        let r = errv[i] / sc;
        sum += r * r;
    }
    (sum / N as f64).sqrt()
}

/// Adaptive Dormand–Prince 5(4) (local extrapolation, FSAL) from t0 to exactly t1.
/// Error norm: RMS over components of e_i / (atol + rtol · max(|x_i|, |x_new,i|)); a step is
/// accepted when the norm is ≤ 1; the next step is h · clamp(0.9 · norm^(−1/5), 0.2, 5).
/// `h0` is the first trial step (≤ 0: h = 0.01·(t1 − t0)); steps never exceed `h_max`.
pub fn dopri5<const N: usize>(
    f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t0: f64,
    x0: &SVector<f64, N>,
    t1: f64,
    rtol: f64,
    atol: f64,
    h0: f64,
    h_max: f64,
) -> Result<AdaptiveOutcome<N>, String> {
    let span = t1 - t0;
    let mut out = AdaptiveOutcome {
        x: *x0,
        h_next: h0,
        accepted: 0,
        rejected: 0,
    };
    if span <= 0.0 {
        return Ok(out);
    }
    let h_max = if h_max > 0.0 { h_max.min(span) } else { span };
    let mut h = if h0 > 0.0 { h0.min(h_max) } else { 0.01 * span };
    let mut t = t0;
    let mut x = *x0;
    let mut k1 = f(t, &x);
    let mut h_prop = h;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * span.max(t1.abs());
        let step = if last { t1 - t } else { h };
        let mut k = [SVector::<f64, N>::zeros(); 7];
        k[0] = k1;
        for s in 1..7 {
            let mut xs = x;
            for (j, kj) in k.iter().enumerate().take(s) {
                let a = DP_A[s][j];
                if a != 0.0 {
                    xs += kj * (a * step);
                }
            }
            if s == 6 {
                // the 7th stage is evaluated at the 5th-order solution (FSAL)
                k[6] = f(t + step, &xs);
                let norm = error_norm(&k, step, &x, &xs, rtol, atol);
                if !norm.is_finite() {
                    return Err(format!("adaptive integrator: non-finite error estimate at t = {t}"));
                }
                let fac = if norm == 0.0 {
                    5.0
                } else {
                    (0.9 * norm.powf(-0.2)).clamp(0.2, 5.0)
                };
                if norm <= 1.0 {
                    t = if last { t1 } else { t + step };
                    x = xs;
                    k1 = k[6];
                    out.accepted += 1;
                    // a short final step does not shrink the proposal for the next interval
                    h_prop = if last && step < h { h } else { (step * fac).min(h_max) };
                    h = (step * fac).min(h_max);
                } else {
                    out.rejected += 1;
                    h = step * fac.min(1.0);
                    if h < 1e-14 * t.abs().max(1.0) {
                        return Err(format!("adaptive integrator: step size underflow at t = {t}"));
                    }
                }
                if out.accepted + out.rejected >= MAX_INTERNAL_STEPS {
                    return Err(format!("adaptive integrator: more than {MAX_INTERNAL_STEPS} steps in one call at t = {t} (tolerance too tight for this step?)"));
                }
            } else {
                k[s] = f(t + DP_C[s] * step, &xs);
            }
        }
    }
    out.x = x;
    out.h_next = h_prop;
    Ok(out)
}

crate::param_enum! {
    /// Integrator option shared by the plants (`integrator` parameter).
    #[derive(Default)]
    pub enum Method {
        /// 0: classical RK4 with ⌈h / max_step⌉ equal internal steps.
        #[default]
        Rk4 = 0,
        /// 1: explicit Euler with ⌈h / max_step⌉ equal internal steps.
        Euler = 1,
        /// 2: adaptive Dormand–Prince 5(4).
        DormandPrince = 2,
    }
}

/// Pieces of [t0, t0 + h] between the breakpoints strictly inside it (events such as a fault onset
/// must fall on a piece boundary, not inside an integration step). Returns (start, length) pairs.
pub fn pieces(t0: f64, h: f64, breakpoints: &[f64]) -> Vec<(f64, f64)> {
    let t1 = t0 + h;
    let mut edges = vec![t0];
    edges.extend(
        breakpoints
            .iter()
            .copied()
            .filter(|b| *b > t0 + 1e-12 * h && *b < t1 - 1e-12 * h),
    );
    edges[1..].sort_by(f64::total_cmp);
    edges.push(t1);
    edges.windows(2).map(|p| (p[0], p[1] - p[0])).collect()
}

/// A plant's integrator: method, fixed internal step, adaptive tolerance and the adaptive step
/// proposal carried from one communication step to the next (part of the FMU state).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Stepper {
    pub method: Method,
    /// Largest internal step of the fixed-step methods.
    pub max_step: f64,
    /// rtol = atol of Dormand–Prince.
    pub tol: f64,
    /// Dormand–Prince's proposal for its next step (0 = none yet).
    pub h_adapt: f64,
}

impl Stepper {
    pub fn new(method: Method, max_step: f64, tol: f64) -> Self {
        Stepper {
            method,
            max_step,
            tol,
            h_adapt: 0.0,
        }
    }

    /// Checks a restored stepper against `fresh`, the one the parameters give: same method, step and
    /// tolerance, and a usable adaptive step proposal.
    pub fn check_against(&self, fresh: &Stepper) -> Result<(), String> {
        if (self.method, self.max_step, self.tol) != (fresh.method, fresh.max_step, fresh.tol) {
            return Err(format!(
                "integrator state ({:?}, step {}, tolerance {}) does not match the parameters ({:?}, step {}, tolerance {})",
                self.method, self.max_step, self.tol, fresh.method, fresh.max_step, fresh.tol
            ));
        }
        if !(self.h_adapt.is_finite() && self.h_adapt >= 0.0) {
            return Err(format!(
                "adaptive step proposal {} is not a finite non-negative number",
                self.h_adapt
            ));
        }
        Ok(())
    }

    /// The stepper a plant's `integrator` and `max_internal_step` parameters select; the adaptive
    /// tolerance comes from `fmi2SetupExperiment` (default 1e-8).
    pub fn for_plant(integrator: i32, max_internal_step: f64, exp: &Experiment) -> Result<Self, String> {
        Ok(Stepper::new(
            Method::from_param("integrator", integrator)?,
            max_internal_step,
            exp.tolerance_or_default(),
        ))
    }

    /// Advances a plant's state over one communication step [t, t + h] with the inputs held. The step
    /// is cut into pieces at the `breakpoints` inside it (events such as a fault onset); `rhs(start,
    /// len)` gives the right-hand side valid on a piece; after every internal step the state must be
    /// finite and `after_step(x, t)` may project it (e.g. renormalise a quaternion).
    pub fn advance<const N: usize, F>(
        &mut self,
        t: f64,
        h: f64,
        breakpoints: &[f64],
        x: &mut SVector<f64, N>,
        mut rhs: impl FnMut(f64, f64) -> F,
        mut after_step: impl FnMut(&mut SVector<f64, N>, f64) -> Result<(), String>,
    ) -> Result<(), String>
    where
        F: FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
    {
        if self.method != Method::DormandPrince {
            check_step_count(h, self.max_step)?;
        }
        for (ts, len) in pieces(t, h, breakpoints) {
            let mut f = rhs(ts, len);
            self.piece(&mut f, ts, len, x, |xx, tt| {
                if !xx.iter().all(|c| c.is_finite()) {
                    return Err(format!("state became non-finite at t = {tt}"));
                }
                after_step(xx, tt)
            })?;
        }
        Ok(())
    }

    /// Integrates ẋ = f(t, x) over one piece [ts, ts + len] that contains no event. Fixed-step
    /// methods take ⌈len / max_step⌉ equal steps and call `after_step(x, t)` after each (e.g. to
    /// renormalise a quaternion); Dormand–Prince adapts its steps and calls it once at the end.
    pub fn piece<const N: usize>(
        &mut self,
        f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
        ts: f64,
        len: f64,
        x: &mut SVector<f64, N>,
        mut after_step: impl FnMut(&mut SVector<f64, N>, f64) -> Result<(), String>,
    ) -> Result<(), String> {
        match self.method {
            Method::DormandPrince => {
                let r = dopri5(f, ts, x, ts + len, self.tol, self.tol, self.h_adapt, 0.0)?;
                *x = r.x;
                self.h_adapt = r.h_next;
                after_step(x, ts + len)
            }
            fixed => {
                let n = (len / self.max_step - 1e-9).ceil().max(1.0) as usize;
                let dt = len / n as f64;
                for k in 0..n {
                    let tk = ts + k as f64 * dt;
                    *x = if fixed == Method::Euler {
                        euler(f, tk, x, dt)
                    } else {
                        rk4(f, tk, x, dt)
                    };
                    after_step(x, tk + dt)?;
                }
                Ok(())
            }
        }
    }
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
        let (coarse, fine) = (err(0.1), err(0.05));
        let ratio = coarse / fine;
        assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn euler_is_first_order_exact_on_linear_growth() {
        let mut f = |_t: f64, _x: &SVector<f64, 1>| SVector::<f64, 1>::new(2.0);
        let x = euler(&mut f, 0.0, &SVector::<f64, 1>::new(1.0), 0.5);
        assert_eq!(x[0], 2.0);
    }

    #[test]
    fn pieces_split_at_breakpoints_and_stepper_takes_equal_steps() {
        assert_eq!(pieces(0.0, 0.1, &[]), vec![(0.0, 0.1)]);
        let p = pieces(0.0, 0.1, &[0.07, 0.05, 0.2]);
        assert_eq!(p.len(), 3);
        assert!((p[1].0 - 0.05).abs() < 1e-15 && (p[2].0 - 0.07).abs() < 1e-15);
        let total: f64 = p.iter().map(|x| x.1).sum();
        assert!((total - 0.1).abs() < 1e-15);
        // breakpoints on the edges do not add pieces
        assert_eq!(pieces(1.0, 0.01, &[1.0, 1.01]).len(), 1);
        // [0, 0.05] with max step 0.04 → 2 equal Euler steps of 0.025
        let mut times = vec![];
        let mut f = |_t: f64, _x: &SVector<f64, 1>| SVector::<f64, 1>::new(1.0);
        let mut x = SVector::<f64, 1>::new(0.0);
        Stepper::new(Method::Euler, 0.04, 0.0)
            .piece(&mut f, 0.0, 0.05, &mut x, |_, t| {
                times.push(t);
                Ok(())
            })
            .unwrap();
        assert_eq!(times, vec![0.025, 0.05]);
        assert!((x[0] - 0.05).abs() < 1e-15);
    }

    #[test]
    fn dopri5_meets_tolerance_on_oscillator() {
        // ẍ = −x over 20 s: the global error follows the tolerance
        let mut f = |_t: f64, x: &Vector2<f64>| Vector2::new(x[1], -x[0]);
        for &tol in &[1e-6, 1e-9, 1e-12] {
            let r = dopri5(&mut f, 0.0, &Vector2::new(1.0, 0.0), 20.0, tol, tol, 0.0, 0.0).unwrap();
            let err = (r.x[0] - 20f64.cos()).abs().max((r.x[1] + 20f64.sin()).abs());
            println!(
                "dopri5 tol {tol:e}: error {err:.2e}, {} accepted, {} rejected",
                r.accepted, r.rejected
            );
            assert!(err < 200.0 * tol, "tol {tol}: error {err}");
        }
    }

    #[test]
    fn dopri5_is_fifth_order_and_hits_the_end_exactly() {
        // With a fixed step forced through h_max and a loose tolerance, halving h divides the
        // error by ~32 (5th order with local extrapolation).
        let f = |t: f64, x: &SVector<f64, 1>| SVector::<f64, 1>::new(x[0] * t.cos());
        let exact = 2f64.sin().exp();
        let err = |h: f64| {
            let mut f2 = |t: f64, x: &SVector<f64, 1>| f(t, x);
            let r = dopri5(&mut f2, 0.0, &SVector::<f64, 1>::new(1.0), 2.0, 1.0, 1.0, h, h).unwrap();
            (r.x[0] - exact).abs()
        };
        let ratio = err(0.2) / err(0.1);
        assert!((25.0..40.0).contains(&ratio), "ratio {ratio}");
        // stiff-ish decay with a rejected first step still ends at t1
        let mut g = |_t: f64, x: &SVector<f64, 1>| SVector::<f64, 1>::new(-50.0 * x[0]);
        let r = dopri5(&mut g, 1.0, &SVector::<f64, 1>::new(1.0), 1.3, 1e-10, 1e-12, 1.0, 0.0).unwrap();
        assert!(r.rejected > 0);
        assert!((r.x[0] - (-15f64).exp()).abs() < 1e-10);
    }
}
