//! The classic fourth-order Runge–Kutta method with a fixed step for a Model Exchange unit (see the parent
//! module): four derivative evaluations per step, state events located by bisection on re-integrated
//! partial steps.

use super::Solver;
use crate::{Fail, Fmu};

impl Solver {
    /// One RK4 step of size h from (t, self.x) with k1 = self.k[0] into `self.x_new` (uses k[1..4], y).
    unsafe fn rk4_step(&mut self, f: &Fmu, t: f64, h: f64) -> Result<i32, Fail> {
        let mut w = 0;
        let n = self.nx;
        for (s, c) in [(1usize, 0.5f64), (2, 0.5), (3, 1.0)] {
            for i in 0..n {
                self.y[i] = self.x[i] + c * h * self.k[s - 1][i];
            }
            let y = std::mem::take(&mut self.y);
            let mut ks = std::mem::take(&mut self.k[s]);
            let r = if s == 2 {
                // the same time as stage 2: only the states are set
                self.set_states_only(f, &y)
                    .and_then(|a| self.derivatives_here(f, &mut ks).map(|b| a.max(b)))
            } else {
                self.rhs(f, t + c * h, &y, &mut ks)
            };
            self.y = y;
            self.k[s] = ks;
            w = w.max(r?);
        }
        for i in 0..n {
            self.x_new[i] =
                self.x[i] + h / 6.0 * (self.k[0][i] + 2.0 * self.k[1][i] + 2.0 * self.k[2][i] + self.k[3][i]);
        }
        Ok(w)
    }

    /// One RK4 step from (t, x) towards `t_stop` (k1 = f(t, x) in `k[0]` on the first step of a piece, else
    /// evaluated here); a state event found in it ends the step there. (new time, status, enter event mode).
    pub(super) unsafe fn rk4_advance(
        &mut self,
        f: &Fmu,
        t: f64,
        t_stop: f64,
        dt: f64,
        eps: f64,
        first: bool,
    ) -> Result<(f64, i32, bool), Fail> {
        let mut w = 0;
        let h_fix = if self.max_step > 0.0 { self.max_step.min(dt) } else { dt };
        let mut h = h_fix.min(t_stop - t);
        if t + h > t_stop - eps {
            h = t_stop - t;
        }
        if !first {
            let mut k0 = std::mem::take(&mut self.k[0]);
            let r = if self.at == Some(t) {
                self.derivatives_here(f, &mut k0)
            } else {
                self.rhs(f, t, &self.x, &mut k0)
            };
            self.k[0] = k0;
            w = w.max(r?);
        }
        self.at = None;
        w = w.max(self.rk4_step(f, t, h)?);
        self.accepted += 1;
        let mut t_new = if (t + h - t_stop).abs() <= eps { t_stop } else { t + h };
        if t_new == t + h {
            // the unit's time is already t + h (the last stage): only the states are set
            w = w.max(self.set_states_only(f, &self.x_new)?);
        } else {
            w = w.max(self.set(f, t_new, &self.x_new)?);
        }
        let mut crossed = false;
        if self.nz > 0 {
            let mut zn = std::mem::take(&mut self.z_new);
            w = w.max(self.indicators(f, &mut zn)?);
            self.z_new = zn;
            crossed = self.z.iter().zip(&self.z_new).any(|(a, b)| (*a > 0.0) != (*b > 0.0));
        }
        if crossed {
            let (hi, st) = self.rk4_locate(f, t, h, eps)?;
            w = w.max(st);
            t_new = t + hi * h;
            let xn = self.x_new.clone();
            w = w.max(self.set(f, t_new, &xn)?);
        } else if self.nz > 0 {
            std::mem::swap(&mut self.z, &mut self.z_new);
        }
        std::mem::swap(&mut self.x, &mut self.x_new);
        let t = t_new;
        self.at = Some(t); // set just above (x_new, now x)
        let (enter, st) = self.completed(f)?;
        w = w.max(st);
        Ok((t, w, crossed || enter))
    }

    /// A sign change of an indicator over the RK4 step [t, t + h]: bisection on the step size, x(t + θh) by
    /// one RK4 step of θh from (t, x); leaves the state at the crossing in `x_new`. (θ past the crossing, status).
    unsafe fn rk4_locate(&mut self, f: &Fmu, t: f64, h: f64, eps: f64) -> Result<(f64, i32), Fail> {
        let mut w = 0;
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let mut x_hi = self.x_new.clone();
        for _ in 0..200 {
            if (hi - lo) * h <= eps {
                break;
            }
            let mid = 0.5 * (lo + hi);
            w = w.max(self.rk4_step(f, t, mid * h)?);
            let xm = self.x_new.clone();
            w = w.max(self.set(f, t + mid * h, &xm)?);
            let mut zi = std::mem::take(&mut self.zi);
            w = w.max(self.indicators(f, &mut zi)?);
            self.zi = zi;
            if self.z.iter().zip(&self.zi).any(|(a, b)| (*a > 0.0) != (*b > 0.0)) {
                hi = mid;
                x_hi = xm;
            } else {
                lo = mid;
            }
        }
        self.x_new = x_hi;
        Ok((hi, w))
    }
}
