//! The Dormand–Prince 5(4) pair (crate documentation): adaptive steps with local extrapolation,
//! first-same-as-last stage, the fourth-order continuous extension as the state between the step's ends
//! for the event location (the method of SciPy's `RK45`, written here from the published coefficients).

use crate::stepper::Stepper;
use crate::tableau::{A, B, C, E, P};
use crate::unit::{Stop, Unit};

const SAFETY: f64 = 0.9;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

impl Stepper {
    /// Starting step size (Hairer, Nørsett & Wanner's heuristic, as in SciPy).
    pub(crate) fn initial_step<U: Unit>(&mut self, u: &mut U, t: f64, span: f64) -> Result<f64, Stop> {
        let n = self.nx;
        let scale: Vec<f64> = self
            .x
            .iter()
            .map(|v| self.settings.atol + v.abs() * self.settings.rtol)
            .collect();
        let rms = |v: &[f64]| (v.iter().zip(&scale).map(|(a, s)| (a / s) * (a / s)).sum::<f64>() / n as f64).sqrt();
        let d0 = rms(&self.x);
        let d1 = rms(&self.k[0]);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        let h0 = h0.min(span);
        for i in 0..n {
            self.y[i] = self.x[i] + h0 * self.k[0][i];
        }
        let mut f1 = vec![0.0; n];
        let y = self.y.clone();
        self.rhs(u, t + h0, &y, &mut f1)?;
        let diff: Vec<f64> = f1.iter().zip(&self.k[0]).map(|(a, b)| a - b).collect();
        let d2 = rms(&diff) / h0;
        let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 5.0)
        };
        Ok(self.capped((100.0 * h0).min(h1).min(span)))
    }

    /// `h` at most the settings' `max_step` (when one is set).
    fn capped(&self, h: f64) -> f64 {
        if self.settings.max_step > 0.0 {
            h.min(self.settings.max_step)
        } else {
            h
        }
    }

    /// The continuous extension at t0 + θ·h into `xi`.
    fn dense(&mut self, h: f64, theta: f64) {
        let pw = [theta, theta * theta, theta.powi(3), theta.powi(4)];
        for i in 0..self.nx {
            let mut s = 0.0;
            for (j, kj) in self.k.iter().enumerate() {
                let q = P[j][0] * pw[0] + P[j][1] * pw[1] + P[j][2] * pw[2] + P[j][3] * pw[3];
                s += kj[i] * q;
            }
            self.xi[i] = self.x[i] + h * s;
        }
    }

    /// One accepted Dormand–Prince 5(4) step from (t, x) (k1 = f(t, x) in `k[0]`) towards `t_stop`; a state
    /// event found in it ends the step there. (new time, status, enter event mode).
    pub(crate) fn dp_advance<U: Unit>(
        &mut self,
        u: &mut U,
        t: f64,
        t_stop: f64,
        eps: f64,
    ) -> Result<(f64, i32, bool), Stop> {
        self.at = None;
        let (h, mut w) = self.dp_attempts(u, t, t_stop, eps)?;
        self.accepted += 1;
        // ----- state events: a sign change of an indicator over [t, t + h]
        let mut t_new = if (t + h - t_stop).abs() <= eps { t_stop } else { t + h };
        // the unit is at (t + h, x_new) after the last stage
        let (crossed, wz) = self.crossed(u)?;
        w = w.max(wz);
        if crossed {
            let (hi, st) = self.locate(u, t, h, eps, Self::dp_state_at)?;
            w = w.max(st);
            self.dense(h, hi);
            std::mem::swap(&mut self.x_new, &mut self.xi);
            t_new = t + hi * h;
            w = w.max(self.set(u, t_new, &self.x_new)?);
        }
        std::mem::swap(&mut self.x, &mut self.x_new);
        if !crossed && t_new == t + h {
            self.at = Some(t_new); // the last stage left the unit at (t + h, x_new): nothing to set again
        }
        if !crossed {
            self.k.swap(0, 6); // FSAL: k[6] is f(t, x) at the new point
            if self.nz > 0 {
                std::mem::swap(&mut self.z, &mut self.z_new);
            }
        }
        self.t = t_new;
        let (enter, st) = self.completed(u)?;
        Ok((t_new, w.max(st), crossed || enter))
    }

    /// Dormand–Prince 5(4) attempts from (t, x) until one meets the tolerance: the stages in `k`, the new
    /// point in `x_new`, the next step size proposal in `self.h`. (accepted step size, status).
    fn dp_attempts<U: Unit>(&mut self, u: &mut U, t: f64, t_stop: f64, eps: f64) -> Result<(f64, i32), Stop> {
        let mut w = 0;
        let mut h = self.capped(self.h).min(t_stop - t);
        if t + h > t_stop - eps {
            h = t_stop - t;
        }
        let truncated = h < self.h;
        let h_min = 10.0 * f64::EPSILON * t.abs().max(1.0);
        let mut rejected_now = false;
        // stages 2..6 and the new point (FSAL: stage 7 = f(t + h, x_new))
        loop {
            if h < h_min.min(t_stop - t) {
                return Err(Stop::Solver);
            }
            w = w.max(self.dp_stages(u, t, h)?);
            // the error estimate h·Σ_j E_j k_j (E[1] = 0: that term would add a zero)
            let [k0, _, k2, k3, k4, k5, k6] = &self.k;
            combine(
                &mut self.y,
                None,
                [E[0], E[2], E[3], E[4], E[5], E[6]],
                [k0, k2, k3, k4, k5, k6],
            );
            self.y.iter_mut().for_each(|yi| *yi *= h);
            let en = self.norm(&self.y, &self.x, &self.x_new);
            if en <= 1.0 {
                let mut fac = if en == 0.0 {
                    MAX_FACTOR
                } else {
                    (SAFETY * en.powf(-0.2)).min(MAX_FACTOR)
                };
                if rejected_now {
                    fac = fac.min(1.0);
                }
                self.h = if truncated && !rejected_now {
                    self.h.max(h * fac)
                } else {
                    h * fac
                };
                return Ok((h, w));
            }
            self.rejected += 1;
            rejected_now = true;
            h *= (SAFETY * en.powf(-0.2)).max(MIN_FACTOR);
        }
    }

    /// Stages 2..7 of a Dormand–Prince step of size h from (t, x): `k[1..7]`, the 5th-order point `x_new`.
    fn dp_stages<U: Unit>(&mut self, u: &mut U, t: f64, h: f64) -> Result<i32, Stop> {
        let mut w = 0;
        for s in 1..6 {
            let c: [f64; 6] = std::array::from_fn(|j| h * A[s][j]);
            let [k0, k1, k2, k3, k4, ..] = &self.k;
            match s {
                1 => combine(&mut self.y, Some(&self.x), [c[0]], [k0]),
                2 => combine(&mut self.y, Some(&self.x), [c[0], c[1]], [k0, k1]),
                3 => combine(&mut self.y, Some(&self.x), [c[0], c[1], c[2]], [k0, k1, k2]),
                4 => combine(&mut self.y, Some(&self.x), [c[0], c[1], c[2], c[3]], [k0, k1, k2, k3]),
                _ => combine(
                    &mut self.y,
                    Some(&self.x),
                    [c[0], c[1], c[2], c[3], c[4]],
                    [k0, k1, k2, k3, k4],
                ),
            }
            let y = std::mem::take(&mut self.y);
            let mut ks = std::mem::take(&mut self.k[s]);
            let r = self.rhs(u, t + C[s] * h, &y, &mut ks);
            self.y = y;
            self.k[s] = ks;
            w = w.max(r?);
        }
        // the 5th-order point (B[1] = 0: that term would add a zero)
        let [k0, _, k2, k3, k4, k5, _] = &self.k;
        combine(
            &mut self.x_new,
            Some(&self.x),
            [h * B[0], h * B[2], h * B[3], h * B[4], h * B[5]],
            [k0, k2, k3, k4, k5],
        );
        // FSAL stage f(t + h, x_new): the unit's time is already t + h (stage 6, C[5] = 1)
        let mut k6 = std::mem::take(&mut self.k[6]);
        let r = self
            .set_states_only(u, &self.x_new)
            .and_then(|a| self.derivatives_here(u, &mut k6).map(|b| a.max(b)));
        self.k[6] = k6;
        Ok(w.max(r?))
    }

    /// The continuous extension at t + θ·h into `xi` (the state the event location bisects on).
    fn dp_state_at<U: Unit>(&mut self, _u: &mut U, _t: f64, h: f64, theta: f64) -> Result<i32, Stop> {
        self.dense(h, theta);
        Ok(0)
    }

    fn norm(&self, err: &[f64], a: &[f64], b: &[f64]) -> f64 {
        if self.nx == 0 {
            return 0.0;
        }
        let mut s = 0.0;
        for ((e, a), b) in err.iter().zip(a).zip(b) {
            let e = e / (self.settings.atol + self.settings.rtol * a.abs().max(b.abs()));
            s += e * e;
        }
        (s / self.nx as f64).sqrt()
    }
}

/// out = x + Σ_j c_j·k_j (x = 0 when None), component by component with the terms added in the order of
/// j: the formula of a stage written per component, as one loop over the components that the compiler
/// vectorises (the number of terms is a constant; no bounds check per element).
#[inline]
fn combine<const S: usize>(out: &mut [f64], x: Option<&[f64]>, c: [f64; S], k: [&[f64]; S]) {
    let n = out.len();
    assert!(x.is_none_or(|x| x.len() == n) && k.iter().all(|kj| kj.len() == n));
    for i in 0..n {
        // SAFETY: i < n, and every slice has length n (asserted above)
        unsafe {
            let mut acc = match x {
                Some(x) => *x.get_unchecked(i),
                None => 0.0,
            };
            for j in 0..S {
                acc += c[j] * *k[j].get_unchecked(i);
            }
            *out.get_unchecked_mut(i) = acc;
        }
    }
}
