//! The integration of one communication step of a Model Exchange unit (see the crate documentation).

// index loops over the stages and the state vector read like the method's formulas
#![allow(clippy::needless_range_loop)]

use crate::{Config, Unit, ERROR, WARNING};

// Dormand–Prince 5(4): nodes, stages, 5th-order weights, and 5th minus 4th order weights (error); the one
// tableau of the project (this crate does not depend on it, so the file of constants is included).
#[allow(dead_code)]
#[path = "../../../../src/math/dopri_tableau.rs"]
mod dopri_tableau;
use dopri_tableau::{A, C, E};
const MAX_EVENT_ITERATIONS: usize = 1000;
const MAX_STEPS_PER_CALL: usize = 1_000_000;

/// A failing step: the status to return and whether the unit asked to terminate.
pub type Fail = (i32, bool);

pub struct Solver {
    pub cfg: Config,
    pub t: f64,
    pub x: Vec<f64>,
    z: Vec<f64>,
    z1: Vec<f64>,
    x0: Vec<f64>,
    x1: Vec<f64>,
    k: Vec<Vec<f64>>,
    err: Vec<f64>,
    h: f64, // the adaptive method's last step size (0: none yet)
    pub next_event: Option<f64>,
}

fn check(st: i32) -> Result<i32, Fail> {
    if st > WARNING {
        Err((st, false))
    } else {
        Ok(st)
    }
}

impl Solver {
    pub fn new(cfg: Config) -> Solver {
        let (nx, nz) = (cfg.states, cfg.event_indicators);
        Solver {
            cfg,
            t: 0.0,
            x: vec![0.0; nx],
            z: vec![0.0; nz],
            z1: vec![0.0; nz],
            x0: vec![0.0; nx],
            x1: vec![0.0; nx],
            k: vec![vec![0.0; nx]; 7],
            err: vec![0.0; nx],
            h: 0.0,
            next_event: None,
        }
    }

    /// The event iteration (in event mode already when `in_event_mode`), then continuous-time mode with the
    /// states and event indicators re-read. Ok(true) when the unit asked to terminate.
    pub fn event_iteration(&mut self, u: &mut dyn Unit, in_event_mode: bool) -> Result<bool, Fail> {
        if !in_event_mode {
            check(u.enter_event_mode())?;
        }
        let mut n = 0;
        loop {
            let (st, more, term, next) = u.update();
            check(st)?;
            if term {
                return Ok(true);
            }
            self.next_event = next;
            n += 1;
            if !more {
                break;
            }
            if n >= MAX_EVENT_ITERATIONS {
                return Err((ERROR, false));
            }
        }
        check(u.enter_continuous_mode())?;
        check(u.get_states(&mut self.x))?;
        check(u.indicators(&mut self.z))?;
        self.h = 0.0;
        Ok(false)
    }

    fn f(&mut self, u: &mut dyn Unit, t: f64, x: &[f64], stage: usize) -> Result<(), Fail> {
        check(u.set_time(t))?;
        check(u.set_states(x))?;
        let mut k = std::mem::take(&mut self.k[stage]);
        let st = u.derivatives(&mut k);
        self.k[stage] = k;
        check(st).map(|_| ())
    }

    /// One step of size h from (t, x0) into x1 (k[0] must hold f(t, x0)); returns the error norm (0 for RK4).
    fn one_step(&mut self, u: &mut dyn Unit, t: f64, h: f64) -> Result<f64, Fail> {
        let n = self.x0.len();
        let mut y = vec![0.0; n];
        if self.cfg.rk4 {
            for (s, (c, w)) in [(1usize, (0.5, 0.5)), (2, (0.5, 0.5)), (3, (1.0, 1.0))] {
                for i in 0..n {
                    y[i] = self.x0[i] + w * h * self.k[s - 1][i];
                }
                self.f(u, t + c * h, &y, s)?;
            }
            for i in 0..n {
                let k = &self.k;
                self.x1[i] = self.x0[i] + h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
            }
            return Ok(0.0);
        }
        for s in 1..7 {
            for i in 0..n {
                y[i] = self.x0[i] + h * (0..s).map(|j| A[s][j] * self.k[j][i]).sum::<f64>();
            }
            self.f(u, t + C[s] * h, &y, s)?;
        }
        self.x1.copy_from_slice(&y); // stage 7 is evaluated at the 5th-order solution (FSAL)
        let mut sum = 0.0;
        for i in 0..n {
            self.err[i] = h * (0..7).map(|j| E[j] * self.k[j][i]).sum::<f64>();
            let sc = self.cfg.atol + self.cfg.rtol * self.x0[i].abs().max(self.x1[i].abs());
            sum += (self.err[i] / sc).powi(2);
        }
        Ok(if n == 0 { 0.0 } else { (sum / n as f64).sqrt() })
    }

    fn crossed(&self) -> bool {
        self.z.iter().zip(&self.z1).any(|(a, b)| (*a > 0.0) != (*b > 0.0))
    }

    /// A state event in the step (t0, t0 + h] (k0 = f(t0, x0), x0 in `self.x0`): located by bisection on the
    /// step size, re-integrating from (t0, x0), to 1e-12 relative in time; the unit is moved to the event's
    /// time and state, its step completed and the event iteration run. Ok(true): the unit asked to terminate.
    fn state_event(&mut self, u: &mut dyn Unit, t0: f64, h: f64, k0: &[f64]) -> Result<bool, Fail> {
        let (mut lo, mut hi) = (0.0, h);
        let tol = 1e-12 * (t0 + h).abs().max(1.0);
        let z0 = self.z.clone();
        while hi - lo > tol {
            let mid = 0.5 * (lo + hi);
            self.k[0].copy_from_slice(k0);
            self.one_step(u, t0, mid)?;
            check(u.set_time(t0 + mid))?;
            let xm = self.x1.clone();
            check(u.set_states(&xm))?;
            let mut zm = std::mem::take(&mut self.z1);
            let st = u.indicators(&mut zm);
            let cross = z0.iter().zip(&zm).any(|(a, b)| (*a > 0.0) != (*b > 0.0));
            self.z1 = zm;
            check(st)?;
            if cross {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        self.k[0].copy_from_slice(k0);
        self.one_step(u, t0, hi)?;
        self.t = t0 + hi;
        check(u.set_time(self.t))?;
        let xe = self.x1.clone();
        check(u.set_states(&xe))?;
        let (st, _, term) = u.completed();
        check(st)?;
        Ok(term || self.event_iteration(u, false)?)
    }

    /// Integrates from `self.t` to `t_end` (see the crate documentation). Ok(true): the unit asked to terminate.
    pub fn advance(&mut self, u: &mut dyn Unit, t_end: f64) -> Result<bool, Fail> {
        let eps = 1e-12 * t_end.abs().max(1.0);
        let mut steps = 0usize;
        loop {
            if let Some(te) = self.next_event {
                if te <= self.t + eps {
                    self.next_event = None;
                    check(u.set_time(te.max(self.t)))?;
                    if self.event_iteration(u, false)? {
                        return Ok(true);
                    }
                    continue;
                }
            }
            if self.t >= t_end - eps {
                break;
            }
            steps += 1;
            if steps > MAX_STEPS_PER_CALL {
                return Err((ERROR, false));
            }
            let target = self.next_event.map_or(t_end, |te| te.min(t_end));
            let mut h = if self.cfg.max_step > 0.0 {
                self.cfg.max_step
            } else {
                target - self.t
            };
            if !self.cfg.rk4 && self.h > 0.0 {
                h = h.min(self.h);
            }
            if self.t + h >= target - eps {
                h = target - self.t;
            }
            self.x0.copy_from_slice(&self.x);
            let (t0, x0) = (self.t, self.x0.clone());
            self.f(u, t0, &x0, 0)?;
            let k0 = self.k[0].clone();
            let e = self.one_step(u, t0, h)?;
            if e > 1.0 {
                self.h = h * (0.9 * e.powf(-0.2)).max(0.2);
                if self.h < 1e-14 * t0.abs().max(1.0) {
                    return Err((ERROR, false));
                }
                continue;
            }
            if !self.cfg.rk4 {
                self.h = h * if e == 0.0 {
                    5.0
                } else {
                    (0.9 * e.powf(-0.2)).clamp(0.2, 5.0)
                };
            }
            let t1 = if h == target - t0 { target } else { t0 + h };
            check(u.set_time(t1))?;
            let x1 = self.x1.clone();
            check(u.set_states(&x1))?;
            let mut z1 = std::mem::take(&mut self.z1);
            let st = u.indicators(&mut z1);
            self.z1 = z1;
            check(st)?;
            if self.crossed() {
                if self.state_event(u, t0, h, &k0)? {
                    return Ok(true);
                }
                continue;
            }
            self.t = t1;
            self.x.copy_from_slice(&self.x1);
            std::mem::swap(&mut self.z, &mut self.z1);
            let (st, enter, term) = u.completed();
            check(st)?;
            if term {
                return Ok(true);
            }
            if enter && self.event_iteration(u, false)? {
                return Ok(true);
            }
        }
        Ok(false)
    }
}
