//! Model Exchange units inside the compiled loop: an embedded explicit Runge–Kutta solver, the
//! Dormand–Prince 5(4) pair with local extrapolation, adaptive step size and its fourth-order
//! continuous extension (the method of SciPy's `RK45`, written here from the published coefficients).
//!
//! Or, chosen per instance, the classic fourth-order Runge–Kutta method with a fixed step (the
//! communication step, or `max_step` when smaller): four derivative evaluations per step, like a
//! Co-Simulation unit's own RK4 (state events located by bisection on re-integrated partial steps).
//!
//! One communication step of an ME unit from t to t + h, its inputs held (as a co-simulation step):
//! integrate the continuous states, stopping at the unit's next time event; after every accepted
//! solver step call `completedIntegratorStep` and look for a sign change of an event indicator (a state
//! event), located by bisection on the continuous extension to 1e-12 relative time; at a time event,
//! a state event, or when the unit asks for it, enter event mode and run the event iteration
//! (`newDiscreteStates` / `updateDiscreteStates` until no update is needed; a new next-event time is
//! taken over), re-read the states (the unit may have changed them) and continue in continuous-time mode.

mod dopri;
mod rk4;

use std::ffi::c_void;
use std::mem::transmute;

use crate::{Fail, Fmu, PHASE_SOLVER, PHASE_STEP, PHASE_TERMINATE};
use crate::{
    F_COMPLETED_STEP, F_ENTER_CONT_MODE, F_ENTER_EVENT_MODE, F_GET_DERIVATIVES, F_GET_INDICATORS, F_GET_STATES,
    F_SET_STATES, F_SET_TIME, F_UPDATE_DISCRETE,
};

type SetTime = unsafe extern "C" fn(*mut c_void, f64) -> i32;
type Vector = unsafe extern "C" fn(*mut c_void, *mut f64, usize) -> i32;
type Plain = unsafe extern "C" fn(*mut c_void) -> i32;
type Completed2 = unsafe extern "C" fn(*mut c_void, i32, *mut i32, *mut i32) -> i32;
type Completed3 = unsafe extern "C" fn(*mut c_void, bool, *mut bool, *mut bool) -> i32;
type Update3 =
    unsafe extern "C" fn(*mut c_void, *mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64) -> i32;

/// `fmi2EventInfo`.
#[repr(C)]
#[derive(Default)]
struct EventInfo2 {
    new_discrete_states_needed: i32,
    terminate_simulation: i32,
    nominals_changed: i32,
    values_changed: i32,
    next_event_time_defined: i32,
    next_event_time: f64,
}

const MAX_STEPS_PER_INTERVAL: usize = 1_000_000;

/// The solver state of one Model Exchange unit.
pub struct Solver {
    nx: usize,
    nz: usize,
    rtol: f64,
    atol: f64,
    next_event: Option<f64>,
    h: f64, // last accepted step size (0: choose one)
    x: Vec<f64>,
    k: [Vec<f64>; 7],
    y: Vec<f64>,
    x_new: Vec<f64>,
    z: Vec<f64>,
    z_new: Vec<f64>,
    xi: Vec<f64>,
    zi: Vec<f64>,
    pub accepted: usize,
    pub rejected: usize,
    pub events: usize,
    rk4: bool,
    max_step: f64,
    /// Some(t) when the unit is known to be at (t, self.x): its time and states need not be set again
    at: Option<f64>,
}

fn ok(st: i32) -> Result<i32, Fail> {
    if st > 1 {
        Err((st, PHASE_STEP))
    } else {
        Ok(st)
    }
}

impl Solver {
    pub fn new(nx: usize, nz: usize, rtol: f64, atol: f64, next_event: Option<f64>) -> Solver {
        let v = |n: usize| vec![0.0; n];
        Solver {
            nx,
            nz,
            rtol,
            atol,
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
            rk4: false,
            max_step: 0.0,
            at: None,
        }
    }

    /// dx = f(t, x) where the unit already is at (t, x): only the derivatives are read.
    unsafe fn derivatives_here(&self, f: &Fmu, dx: &mut [f64]) -> Result<i32, Fail> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(transmute::<*const c_void, Vector>(f.fns[F_GET_DERIVATIVES])(
            f.comp,
            dx.as_mut_ptr(),
            self.nx,
        ))
    }

    /// Classic Runge–Kutta 4 with a fixed step of at most `max_step` (0: the communication step).
    pub fn fixed_rk4(&mut self, max_step: f64) {
        self.rk4 = true;
        self.max_step = max_step;
    }

    /// The continuous states only (the unit's time is already the right one).
    unsafe fn set_states_only(&self, f: &Fmu, x: &[f64]) -> Result<i32, Fail> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(transmute::<*const c_void, Vector>(f.fns[F_SET_STATES])(
            f.comp,
            x.as_ptr() as *mut f64,
            self.nx,
        ))
    }

    unsafe fn set(&self, f: &Fmu, t: f64, x: &[f64]) -> Result<i32, Fail> {
        let mut w = ok(transmute::<*const c_void, SetTime>(f.fns[F_SET_TIME])(f.comp, t))?;
        if self.nx > 0 {
            w = w.max(ok(transmute::<*const c_void, Vector>(f.fns[F_SET_STATES])(
                f.comp,
                x.as_ptr() as *mut f64,
                self.nx,
            ))?);
        }
        Ok(w)
    }

    /// dx = f(t, x) (leaves the unit at (t, x)).
    unsafe fn rhs(&self, f: &Fmu, t: f64, x: &[f64], dx: &mut [f64]) -> Result<i32, Fail> {
        let w = self.set(f, t, x)?;
        if self.nx == 0 {
            return Ok(w);
        }
        Ok(w.max(ok(transmute::<*const c_void, Vector>(f.fns[F_GET_DERIVATIVES])(
            f.comp,
            dx.as_mut_ptr(),
            self.nx,
        ))?))
    }

    unsafe fn indicators(&self, f: &Fmu, z: &mut [f64]) -> Result<i32, Fail> {
        if self.nz == 0 {
            return Ok(0);
        }
        ok(transmute::<*const c_void, Vector>(f.fns[F_GET_INDICATORS])(
            f.comp,
            z.as_mut_ptr(),
            self.nz,
        ))
    }

    unsafe fn read_states(&mut self, f: &Fmu) -> Result<i32, Fail> {
        if self.nx == 0 {
            return Ok(0);
        }
        ok(transmute::<*const c_void, Vector>(f.fns[F_GET_STATES])(
            f.comp,
            self.x.as_mut_ptr(),
            self.nx,
        ))
    }

    /// (enterEventMode, status) after an accepted step.
    unsafe fn completed(&self, f: &Fmu) -> Result<(bool, i32), Fail> {
        let p = f.fns[F_COMPLETED_STEP];
        let (enter, term, st) = if f.v3 {
            let (mut e, mut t) = (false, false);
            let st = transmute::<*const c_void, Completed3>(p)(f.comp, true, &mut e, &mut t);
            (e, t, st)
        } else {
            let (mut e, mut t) = (0i32, 0i32);
            let st = transmute::<*const c_void, Completed2>(p)(f.comp, 1, &mut e, &mut t);
            (e != 0, t != 0, st)
        };
        let st = ok(st)?;
        if term {
            return Err((3, PHASE_TERMINATE));
        }
        Ok((enter, st))
    }

    /// Event mode, the event iteration, continuous-time mode; the states are read again.
    unsafe fn event(&mut self, f: &Fmu) -> Result<i32, Fail> {
        self.events += 1;
        let mut w = ok(transmute::<*const c_void, Plain>(f.fns[F_ENTER_EVENT_MODE])(f.comp))?;
        let upd = f.fns[F_UPDATE_DISCRETE];
        for _ in 0..1000 {
            let (needed, term, defined, next) = if f.v3 {
                let (mut n, mut t, mut nc, mut vc, mut d, mut nt) = (false, false, false, false, false, 0.0f64);
                w = w.max(ok(transmute::<*const c_void, Update3>(upd)(
                    f.comp, &mut n, &mut t, &mut nc, &mut vc, &mut d, &mut nt,
                ))?);
                (n, t, d, nt)
            } else {
                let mut ei = EventInfo2::default();
                w = w.max(ok(transmute::<
                    *const c_void,
                    unsafe extern "C" fn(*mut c_void, *mut EventInfo2) -> i32,
                >(upd)(f.comp, &mut ei))?);
                (
                    ei.new_discrete_states_needed != 0,
                    ei.terminate_simulation != 0,
                    ei.next_event_time_defined != 0,
                    ei.next_event_time,
                )
            };
            if term {
                return Err((3, PHASE_TERMINATE));
            }
            if !needed {
                self.next_event = if defined { Some(next) } else { None };
                w = w.max(ok(transmute::<*const c_void, Plain>(f.fns[F_ENTER_CONT_MODE])(f.comp))?);
                w = w.max(self.read_states(f)?);
                return Ok(w);
            }
        }
        Err((3, PHASE_SOLVER)) // an event iteration that never settles
    }

    /// Start of an event-free piece at t: k1 = f(t, x) into `k[0]` (only the derivatives where the unit already
    /// is at (t, x)); the adaptive method's first step size when it has none.
    unsafe fn piece_start(&mut self, f: &Fmu, t: f64, t_stop: f64) -> Result<i32, Fail> {
        let mut k0 = std::mem::take(&mut self.k[0]);
        let r = if self.at == Some(t) {
            self.derivatives_here(f, &mut k0)
        } else {
            self.rhs(f, t, &self.x, &mut k0)
        };
        self.k[0] = k0;
        let w = r?;
        self.at = Some(t);
        if self.h <= 0.0 && self.nx > 0 && !self.rk4 {
            self.h = self.initial_step(f, t, t_stop - t)?;
            self.at = None;
        }
        Ok(w)
    }

    /// An event at t (time event, state event or the unit's request): the event iteration, then the
    /// indicators at the (possibly changed) states.
    unsafe fn event_at(&mut self, f: &Fmu, t: f64) -> Result<i32, Fail> {
        let mut w = self.event(f)?;
        self.at = None; // the event iteration may have changed the states (read again)
        if self.nz > 0 {
            w = w.max(self.set(f, t, &self.x)?);
            self.at = Some(t);
            let mut z = std::mem::take(&mut self.z);
            w = w.max(self.indicators(f, &mut z)?);
            self.z = z;
        }
        Ok(w)
    }

    /// One communication step of the unit from `t` to `t_end` (module docstring). The loop gives the next
    /// communication point t_(k+1) = t0 + (k+1)·dt itself, not t_k + dt (which can differ from it in the last
    /// bit): the unit then ends exactly where the next step starts, and nothing is read or set again there.
    ///
    /// # Safety
    /// `f` must be a Model Exchange instance in continuous-time mode with the function table of its version.
    pub unsafe fn step(&mut self, f: &mut Fmu, t: f64, t_end: f64) -> Result<i32, Fail> {
        let dt = t_end - t;
        let eps = 1e-12 * t_end.abs().max(1.0);
        let mut t = t;
        let here = self.at == Some(t); // left at (t, x) by the previous step: nothing to read or set
        let mut w = if here { 0 } else { self.read_states(f)? };
        if self.nz > 0 {
            if !here {
                w = w.max(self.set(f, t, &self.x)?);
                self.at = Some(t);
            }
            let mut z = std::mem::take(&mut self.z);
            w = w.max(self.indicators(f, &mut z)?);
            self.z = z;
        }
        let mut rounds = 0usize;
        while t < t_end - eps {
            rounds += 1;
            if rounds > MAX_STEPS_PER_INTERVAL {
                return Err((3, PHASE_SOLVER)); // events that never let the time advance
            }
            let t_stop = match self.next_event {
                Some(te) if te < t_end - eps && te > t - eps => te.max(t),
                _ => t_end,
            };
            // ----- integrate from t to t_stop, or to the first state event / event request
            let mut steps = 0usize;
            let mut stop_event = false;
            w = w.max(self.piece_start(f, t, t_stop)?);
            while t < t_stop - eps {
                if self.nx == 0 {
                    t = t_stop;
                    w = w.max(self.set(f, t, &[])?);
                    self.at = Some(t);
                    let (enter, st) = self.completed(f)?;
                    w = w.max(st);
                    stop_event = enter;
                    break;
                }
                steps += 1;
                if steps > MAX_STEPS_PER_INTERVAL {
                    return Err((3, PHASE_SOLVER));
                }
                let (t_new, st, stop) = if self.rk4 {
                    self.rk4_advance(f, t, t_stop, dt, eps, steps == 1)?
                } else {
                    self.dp_advance(f, t, t_stop, eps)?
                };
                t = t_new;
                w = w.max(st);
                if stop {
                    stop_event = true;
                    break;
                }
            }
            let at_time_event = self.next_event.is_some_and(|te| (t - te).abs() <= eps);
            if stop_event || at_time_event {
                w = w.max(self.event_at(f, t)?);
            }
        }
        // leave the unit exactly at (t_end, x(t_end)) for the outputs read at the next communication point
        if self.at != Some(t_end) {
            w = w.max(self.set(f, t_end, &self.x)?);
            self.at = Some(t_end);
        }
        Ok(w)
    }
}
