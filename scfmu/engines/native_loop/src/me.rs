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

// Dormand–Prince 5(4): nodes, stage coefficients, 5th-order weights, error weights, dense output.
const C: [f64; 6] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0];
const A: [[f64; 5]; 6] = [
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ],
];
const B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
const E: [f64; 7] = [
    -71.0 / 57600.0,
    0.0,
    71.0 / 16695.0,
    -71.0 / 1920.0,
    17253.0 / 339200.0,
    -22.0 / 525.0,
    1.0 / 40.0,
];
const P: [[f64; 4]; 7] = [
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
const SAFETY: f64 = 0.9;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;
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
                ok(transmute::<*const c_void, Vector>(f.fns[F_SET_STATES])(
                    f.comp,
                    y.as_ptr() as *mut f64,
                    n,
                ))
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

    fn norm(&self, err: &[f64], a: &[f64], b: &[f64]) -> f64 {
        if self.nx == 0 {
            return 0.0;
        }
        let mut s = 0.0;
        for i in 0..self.nx {
            let sc = self.atol + self.rtol * a[i].abs().max(b[i].abs());
            let e = err[i] / sc;
            s += e * e;
        }
        (s / self.nx as f64).sqrt()
    }

    /// Starting step size (Hairer, Nørsett & Wanner's heuristic, as in SciPy).
    unsafe fn initial_step(&mut self, f: &Fmu, t: f64, span: f64) -> Result<f64, Fail> {
        let n = self.nx;
        let scale: Vec<f64> = self.x.iter().map(|v| self.atol + v.abs() * self.rtol).collect();
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
        self.rhs(f, t + h0, &y, &mut f1)?;
        let diff: Vec<f64> = f1.iter().zip(&self.k[0]).map(|(a, b)| a - b).collect();
        let d2 = rms(&diff) / h0;
        let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 5.0)
        };
        Ok((100.0 * h0).min(h1).min(span))
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
            let mut k0 = std::mem::take(&mut self.k[0]);
            let r = if self.at == Some(t) {
                self.derivatives_here(f, &mut k0)
            } else {
                self.rhs(f, t, &self.x, &mut k0)
            };
            self.k[0] = k0;
            w = w.max(r?);
            self.at = Some(t);
            if self.h <= 0.0 && self.nx > 0 && !self.rk4 {
                self.h = self.initial_step(f, t, t_stop - t)?;
                self.at = None;
            }
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
                if self.rk4 {
                    let h_fix = if self.max_step > 0.0 { self.max_step.min(dt) } else { dt };
                    let mut h = h_fix.min(t_stop - t);
                    if t + h > t_stop - eps {
                        h = t_stop - t;
                    }
                    if steps > 1 {
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
                        // bisection on the step size: x(t + θh) by one RK4 step of θh from (t, x)
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
                        t_new = t + hi * h;
                        self.x_new = x_hi;
                        let xn = self.x_new.clone();
                        w = w.max(self.set(f, t_new, &xn)?);
                    } else if self.nz > 0 {
                        std::mem::swap(&mut self.z, &mut self.z_new);
                    }
                    std::mem::swap(&mut self.x, &mut self.x_new);
                    t = t_new;
                    self.at = Some(t); // set just above (x_new, now x)
                    let (enter, st) = self.completed(f)?;
                    w = w.max(st);
                    if crossed || enter {
                        stop_event = true;
                        break;
                    }
                    continue;
                }
                self.at = None;
                let mut h = self.h.min(t_stop - t);
                if t + h > t_stop - eps {
                    h = t_stop - t;
                }
                let truncated = h < self.h;
                let h_min = 10.0 * f64::EPSILON * t.abs().max(1.0);
                let mut rejected_now = false;
                // stages 2..6 and the new point (FSAL: stage 7 = f(t + h, x_new))
                loop {
                    if h < h_min.min(t_stop - t) {
                        return Err((3, PHASE_SOLVER));
                    }
                    for s in 1..6 {
                        for i in 0..self.nx {
                            let mut acc = self.x[i];
                            for j in 0..s {
                                acc += h * A[s][j] * self.k[j][i];
                            }
                            self.y[i] = acc;
                        }
                        let y = std::mem::take(&mut self.y);
                        let mut ks = std::mem::take(&mut self.k[s]);
                        let r = self.rhs(f, t + C[s] * h, &y, &mut ks);
                        self.y = y;
                        self.k[s] = ks;
                        w = w.max(r?);
                    }
                    for i in 0..self.nx {
                        let mut acc = self.x[i];
                        for j in 0..6 {
                            acc += h * B[j] * self.k[j][i];
                        }
                        self.x_new[i] = acc;
                    }
                    // FSAL stage f(t + h, x_new): the unit's time is already t + h (stage 6, C[5] = 1)
                    let mut k6 = std::mem::take(&mut self.k[6]);
                    let r = self
                        .set_states_only(f, &self.x_new)
                        .and_then(|a| self.derivatives_here(f, &mut k6).map(|b| a.max(b)));
                    self.k[6] = k6;
                    w = w.max(r?);
                    for i in 0..self.nx {
                        let mut acc = 0.0;
                        for j in 0..7 {
                            acc += E[j] * self.k[j][i];
                        }
                        self.y[i] = h * acc; // the error estimate
                    }
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
                        break;
                    }
                    self.rejected += 1;
                    rejected_now = true;
                    h *= (SAFETY * en.powf(-0.2)).max(MIN_FACTOR);
                }
                self.accepted += 1;
                // ----- state events: a sign change of an indicator over [t, t + h]
                let mut t_new = if (t + h - t_stop).abs() <= eps { t_stop } else { t + h };
                let mut crossed = false;
                if self.nz > 0 {
                    // the unit is at (t + h, x_new) after the last stage
                    let mut zn = std::mem::take(&mut self.z_new);
                    w = w.max(self.indicators(f, &mut zn)?);
                    self.z_new = zn;
                    crossed = self.z.iter().zip(&self.z_new).any(|(a, b)| (*a > 0.0) != (*b > 0.0));
                }
                if crossed {
                    let (mut lo, mut hi) = (0.0f64, 1.0f64);
                    for _ in 0..200 {
                        if (hi - lo) * h <= eps {
                            break;
                        }
                        let mid = 0.5 * (lo + hi);
                        self.dense(h, mid);
                        let xi = std::mem::take(&mut self.xi);
                        w = w.max(self.set(f, t + mid * h, &xi)?);
                        self.xi = xi;
                        let mut zi = std::mem::take(&mut self.zi);
                        w = w.max(self.indicators(f, &mut zi)?);
                        self.zi = zi;
                        if self.z.iter().zip(&self.zi).any(|(a, b)| (*a > 0.0) != (*b > 0.0)) {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    self.dense(h, hi);
                    std::mem::swap(&mut self.x_new, &mut self.xi);
                    t_new = t + hi * h;
                    let xn = self.x_new.clone();
                    w = w.max(self.set(f, t_new, &xn)?);
                }
                std::mem::swap(&mut self.x, &mut self.x_new);
                if !crossed && t_new == t + h {
                    self.at = Some(t_new); // the last stage left the unit at (t + h, x_new): nothing to set again
                }
                t = t_new;
                if !crossed {
                    self.k.swap(0, 6); // FSAL: k[6] is f(t, x) at the new point
                    if self.nz > 0 {
                        std::mem::swap(&mut self.z, &mut self.z_new);
                    }
                }
                let (enter, st) = self.completed(f)?;
                w = w.max(st);
                if crossed || enter {
                    stop_event = true;
                    break;
                }
            }
            let at_time_event = self.next_event.is_some_and(|te| (t - te).abs() <= eps);
            if stop_event || at_time_event {
                w = w.max(self.event(f)?);
                self.at = None; // the event iteration may have changed the states (read again)
                if self.nz > 0 {
                    w = w.max(self.set(f, t, &self.x)?);
                    self.at = Some(t);
                    let mut z = std::mem::take(&mut self.z);
                    w = w.max(self.indicators(f, &mut z)?);
                    self.z = z;
                }
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
