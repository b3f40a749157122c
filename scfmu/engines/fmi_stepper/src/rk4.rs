//! The classic fourth-order Runge–Kutta method with a fixed step (crate documentation): four derivative
//! evaluations per step; the state between the step's ends for the event location is a re-integrated
//! partial step (one RK4 step of θh from the step's start).

use crate::stepper::Stepper;
use crate::unit::{Stop, Unit};

impl Stepper {
    /// One RK4 step of size h from (t, self.x) with k1 = self.k[0] into `self.x_new` (uses k[1..4], y).
    fn rk4_step<U: Unit>(&mut self, u: &mut U, t: f64, h: f64) -> Result<i32, Stop> {
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
                self.set_states_only(u, &y)
                    .and_then(|a| self.derivatives_here(u, &mut ks).map(|b| a.max(b)))
            } else {
                self.rhs(u, t + c * h, &y, &mut ks)
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
    pub(crate) fn rk4_advance<U: Unit>(
        &mut self,
        u: &mut U,
        t: f64,
        t_stop: f64,
        dt: f64,
        eps: f64,
        first: bool,
    ) -> Result<(f64, i32, bool), Stop> {
        let mut w = 0;
        let h_fix = if self.settings.max_step > 0.0 {
            self.settings.max_step.min(dt)
        } else {
            dt
        };
        let mut h = h_fix.min(t_stop - t);
        if t + h > t_stop - eps {
            h = t_stop - t;
        }
        if !first {
            w = w.max(self.k1(u, t)?);
        }
        self.at = None;
        w = w.max(self.rk4_step(u, t, h)?);
        self.accepted += 1;
        let mut t_new = if (t + h - t_stop).abs() <= eps { t_stop } else { t + h };
        if t_new == t + h {
            // the unit's time is already t + h (the last stage): only the states are set
            w = w.max(self.set_states_only(u, &self.x_new)?);
        } else {
            w = w.max(self.set(u, t_new, &self.x_new)?);
        }
        let (crossed, wz) = self.crossed(u)?;
        w = w.max(wz);
        if crossed {
            let (hi, st) = self.locate(u, t, h, eps, Self::rk4_state_at)?;
            w = w.max(st);
            std::mem::swap(&mut self.x_new, &mut self.xi);
            t_new = t + hi * h;
            w = w.max(self.set(u, t_new, &self.x_new)?);
        } else if self.nz > 0 {
            std::mem::swap(&mut self.z, &mut self.z_new);
        }
        std::mem::swap(&mut self.x, &mut self.x_new);
        let t = t_new;
        self.at = Some(t); // set just above (x_new, now x)
        self.t = t;
        let (enter, st) = self.completed(u)?;
        w = w.max(st);
        Ok((t, w, crossed || enter))
    }

    /// One RK4 step of θ·h from (t, x) into `xi` (the state the event location bisects on; uses x_new).
    fn rk4_state_at<U: Unit>(&mut self, u: &mut U, t: f64, h: f64, theta: f64) -> Result<i32, Stop> {
        let w = self.rk4_step(u, t, theta * h)?;
        self.xi.copy_from_slice(&self.x_new);
        Ok(w)
    }
}
