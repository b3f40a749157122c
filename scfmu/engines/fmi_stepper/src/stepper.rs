//! The stepper's state and one communication step (see the crate documentation): the pieces between
//! events, the event iteration, and the one event-location method.

use crate::unit::{Method, Settings, Stop, Unit, OK, WARNING};

const MAX_STEPS_PER_INTERVAL: usize = 1_000_000;
const MAX_EVENT_ITERATIONS: usize = 1000;
/// Bisection halvings of a step at most (2^-200 of a step is far below any time resolution).
const MAX_BISECTIONS: usize = 200;

/// A status above fmi2Warning / fmi3Warning stops the step.
pub(crate) fn ok(st: i32) -> Result<i32, Stop> {
    if st > WARNING {
        Err(Stop::Failed(st))
    } else {
        Ok(st)
    }
}

/// The stepper of one Model Exchange unit: its settings, its continuous states and event indicators as
/// last seen, the next time event, and the work vectors of the integrators.
pub struct Stepper {
    pub settings: Settings,
    pub(crate) nx: usize,
    pub(crate) nz: usize,
    /// The time reached: after [`Stepper::step`] its end, or where the unit asked to terminate.
    pub t: f64,
    /// The unit's next time event (from the last event iteration), if any.
    pub next_event: Option<f64>,
    pub(crate) h: f64, // the adaptive method's next step size (0: choose one)
    pub(crate) x: Vec<f64>,
    pub(crate) k: [Vec<f64>; 7],
    pub(crate) y: Vec<f64>,
    pub(crate) x_new: Vec<f64>,
    pub(crate) z: Vec<f64>,
    pub(crate) z_new: Vec<f64>,
    pub(crate) xi: Vec<f64>,
    pub(crate) zi: Vec<f64>,
    pub accepted: usize,
    pub rejected: usize,
    pub events: usize,
    /// Some(t) when the unit is known to be at (t, self.x): its time and states need not be set again
    pub(crate) at: Option<f64>,
}

impl Stepper {
    /// A stepper for `nx` states and `nz` event indicators; `next_event`: the unit's next time event
    /// after its initialization, when the caller ran the initial event iteration itself.
    pub fn new(nx: usize, nz: usize, settings: Settings, next_event: Option<f64>) -> Stepper {
        let v = |n: usize| vec![0.0; n];
        Stepper {
            settings,
            nx,
            nz,
            t: 0.0,
            next_event,
            h: 0.0,
            x: v(nx),
            k: [v(nx), v(nx), v(nx), v(nx), v(nx), v(nx), v(nx)],
            y: v(nx),
            x_new: v(nx),
            z: v(nz),
            z_new: v(nz),
            xi: v(nx),
            zi: v(nz),
            accepted: 0,
            rejected: 0,
            events: 0,
            at: None,
        }
    }

    /// The continuous states as last seen by the stepper.
    pub fn states(&self) -> &[f64] {
        &self.x
    }

    /// dx = f(t, x) where the unit already is at (t, x): only the derivatives are read.
    pub(crate) fn derivatives_here(&self, u: &mut impl Unit, dx: &mut [f64]) -> Result<i32, Stop> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(u.derivatives(dx))
    }

    /// The continuous states only (the unit's time is already the right one).
    pub(crate) fn set_states_only(&self, u: &mut impl Unit, x: &[f64]) -> Result<i32, Stop> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(u.set_states(x))
    }

    pub(crate) fn set(&self, u: &mut impl Unit, t: f64, x: &[f64]) -> Result<i32, Stop> {
        let w = ok(u.set_time(t))?;
        Ok(w.max(self.set_states_only(u, x)?))
    }

    /// dx = f(t, x) (leaves the unit at (t, x)).
    pub(crate) fn rhs(&self, u: &mut impl Unit, t: f64, x: &[f64], dx: &mut [f64]) -> Result<i32, Stop> {
        let w = self.set(u, t, x)?;
        Ok(w.max(self.derivatives_here(u, dx)?))
    }

    pub(crate) fn indicators(&self, u: &mut impl Unit, z: &mut [f64]) -> Result<i32, Stop> {
        if self.nz == 0 {
            return Ok(0);
        }
        ok(u.indicators(z))
    }

    fn read_states(&mut self, u: &mut impl Unit) -> Result<i32, Stop> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(u.get_states(&mut self.x))
    }

    fn read_indicators(&mut self, u: &mut impl Unit) -> Result<i32, Stop> {
        let mut z = std::mem::take(&mut self.z);
        let r = self.indicators(u, &mut z);
        self.z = z;
        r
    }

    /// `completedIntegratorStep` after an accepted step at `self.t`: (enter event mode, status).
    pub(crate) fn completed(&self, u: &mut impl Unit) -> Result<(bool, i32), Stop> {
        let (st, enter, term) = u.completed();
        let st = ok(st)?;
        if term {
            return Err(Stop::Terminate);
        }
        Ok((enter, st))
    }

    /// The event iteration (`enterEventMode` first unless `in_event_mode`; `newDiscreteStates` /
    /// `updateDiscreteStates` until no update is needed; the next time event taken over), continuous-time
    /// mode, and the states read again (the unit may have changed them). The initialization's event
    /// iteration is `event_iteration(u, true)` after `exitInitializationMode`.
    pub fn event_iteration(&mut self, u: &mut impl Unit, in_event_mode: bool) -> Result<i32, Stop> {
        self.events += 1;
        self.at = None;
        let mut w = if in_event_mode { 0 } else { ok(u.enter_event_mode())? };
        for _ in 0..MAX_EVENT_ITERATIONS {
            let (st, needed, term, next) = u.update();
            w = w.max(ok(st)?);
            if term {
                return Err(Stop::Terminate);
            }
            if !needed {
                self.next_event = next;
                w = w.max(ok(u.enter_continuous_mode())?);
                w = w.max(self.read_states(u)?);
                return Ok(w);
            }
        }
        Err(Stop::Solver) // an event iteration that never settles
    }

    /// k1 = f(t, x) into `k[0]`: only the derivatives when the unit already is at (t, x).
    pub(crate) fn k1(&mut self, u: &mut impl Unit, t: f64) -> Result<i32, Stop> {
        let mut k0 = std::mem::take(&mut self.k[0]);
        let r = if self.at == Some(t) {
            self.derivatives_here(u, &mut k0)
        } else {
            self.rhs(u, t, &self.x, &mut k0)
        };
        self.k[0] = k0;
        r
    }

    /// The event indicators where the unit is now, into `z_new`, and whether one changed sign since `z`
    /// (with the worst status of the call).
    pub(crate) fn crossed(&mut self, u: &mut impl Unit) -> Result<(bool, i32), Stop> {
        if self.nz == 0 {
            return Ok((false, OK));
        }
        let mut zn = std::mem::take(&mut self.z_new);
        let w = self.indicators(u, &mut zn)?;
        self.z_new = zn;
        Ok((self.z.iter().zip(&self.z_new).any(|(a, b)| (*a > 0.0) != (*b > 0.0)), w))
    }

    /// Start of an event-free piece at t: k1 = f(t, x) into `k[0]` (only the derivatives where the unit already
    /// is at (t, x)); the adaptive method's first step size when it has none.
    fn piece_start(&mut self, u: &mut impl Unit, t: f64, t_stop: f64) -> Result<i32, Stop> {
        let w = self.k1(u, t)?;
        self.at = Some(t);
        if self.h <= 0.0 && self.nx > 0 && self.settings.method == Method::DormandPrince {
            self.h = self.initial_step(u, t, t_stop - t)?;
            self.at = None;
        }
        Ok(w)
    }

    /// An event at t (time event, state event or the unit's request): the event iteration, then the
    /// indicators at the (possibly changed) states.
    fn event_at(&mut self, u: &mut impl Unit, t: f64) -> Result<i32, Stop> {
        let mut w = self.event_iteration(u, false)?;
        if self.nz > 0 {
            w = w.max(self.set(u, t, &self.x)?);
            self.at = Some(t);
            w = w.max(self.read_indicators(u)?);
        }
        Ok(w)
    }

    /// One communication step of the unit from `t` to `t_end`, its inputs held (crate documentation); the
    /// worst status seen. A caller that steps on a fixed grid gives t_(k+1) = t0 + (k+1)·dt itself, not
    /// t_k + dt (which can differ from it in the last bit): the unit then ends exactly where the next step
    /// starts, and nothing is read or set again there. The unit must be in continuous-time mode.
    pub fn step(&mut self, u: &mut impl Unit, t: f64, t_end: f64) -> Result<i32, Stop> {
        let dt = t_end - t;
        let eps = 1e-12 * t_end.abs().max(1.0);
        let mut t = t;
        self.t = t;
        let here = self.at == Some(t); // left at (t, x) by the previous step: nothing to read or set
        let mut w = if here { 0 } else { self.read_states(u)? };
        if self.nz > 0 {
            if !here {
                w = w.max(self.set(u, t, &self.x)?);
                self.at = Some(t);
            }
            w = w.max(self.read_indicators(u)?);
        }
        let mut rounds = 0usize;
        while t < t_end - eps {
            rounds += 1;
            if rounds > MAX_STEPS_PER_INTERVAL {
                return Err(Stop::Solver); // events that never let the time advance
            }
            // a time event before t_end (one already due, or overdue when a caller skipped it: at once)
            let t_stop = match self.next_event {
                Some(te) if te < t_end - eps => te.max(t),
                _ => t_end,
            };
            // ----- integrate from t to t_stop, or to the first state event / event request
            let mut steps = 0usize;
            let mut stop_event = false;
            w = w.max(self.piece_start(u, t, t_stop)?);
            while t < t_stop - eps {
                if self.nx == 0 {
                    t = t_stop;
                    self.t = t;
                    w = w.max(self.set(u, t, &[])?);
                    self.at = Some(t);
                    let (enter, st) = self.completed(u)?;
                    w = w.max(st);
                    stop_event = enter;
                    break;
                }
                steps += 1;
                if steps > MAX_STEPS_PER_INTERVAL {
                    return Err(Stop::Solver);
                }
                let (t_new, st, stop) = match self.settings.method {
                    Method::Rk4 => self.rk4_advance(u, t, t_stop, dt, eps, steps == 1)?,
                    Method::DormandPrince => self.dp_advance(u, t, t_stop, eps)?,
                };
                t = t_new;
                w = w.max(st);
                if stop {
                    stop_event = true;
                    break;
                }
            }
            let at_time_event = self.next_event.is_some_and(|te| te <= t + eps);
            if stop_event || at_time_event {
                w = w.max(self.event_at(u, t)?);
            }
        }
        // leave the unit exactly at (t_end, x(t_end)) for the outputs read at the next communication point
        if self.at != Some(t_end) {
            w = w.max(self.set(u, t_end, &self.x)?);
            self.at = Some(t_end);
        }
        self.t = t_end;
        Ok(w)
    }

    /// THE event-location method of both integrators: a sign change of an event indicator over the
    /// accepted step [t, t + h] (indicators `z` at t), located by bisection on the fraction θ of the step
    /// to `eps` in time; the state at t + θh is the integrator's own (`state_at` writes it into `xi`: the
    /// continuous extension of Dormand–Prince, a re-integrated partial step of RK4). Leaves the state just
    /// past the crossing in `xi`. (θ just past the crossing, status).
    pub(crate) fn locate<U: Unit>(
        &mut self,
        u: &mut U,
        t: f64,
        h: f64,
        eps: f64,
        state_at: fn(&mut Stepper, &mut U, f64, f64, f64) -> Result<i32, Stop>,
    ) -> Result<(f64, i32), Stop> {
        let mut w = 0;
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let mut x_hi = self.x_new.clone();
        for _ in 0..MAX_BISECTIONS {
            if (hi - lo) * h <= eps {
                break;
            }
            let mid = 0.5 * (lo + hi);
            w = w.max(state_at(self, u, t, h, mid)?);
            let xi = std::mem::take(&mut self.xi);
            w = w.max(self.set(u, t + mid * h, &xi)?);
            let mut zi = std::mem::take(&mut self.zi);
            w = w.max(self.indicators(u, &mut zi)?);
            self.zi = zi;
            if self.z.iter().zip(&self.zi).any(|(a, b)| (*a > 0.0) != (*b > 0.0)) {
                hi = mid;
                x_hi.copy_from_slice(&xi);
            } else {
                lo = mid;
            }
            self.xi = xi;
        }
        self.xi = x_hi;
        Ok((hi, w))
    }
}
