//! A Model Exchange toy unit in the loop: its time and state events under both solvers, and the FMI
//! calls and derivative evaluations per communication step.
use crate::*;
use std::ffi::c_void;

// ----- a Model Exchange toy (FMI 2.0 signatures): x' = -a·x + u, output y = x, one event indicator
// z = x - level (at the crossing the unit halves x: a state event with a jump), one time event at
// t_ev (a sets to a2 there); the loop holds u = 0 (no links).
struct MeToy {
    t: f64,
    x: f64,
    a: f64,
    a2: f64,
    level: f64,
    t_ev: f64,
    time_event_done: bool,
    crossings: Vec<f64>,
    time_events: Vec<f64>,
    completed: usize,
    /// FMI calls made on the unit, and the derivative evaluations among them
    calls: usize,
    evaluations: usize,
}

unsafe fn me(c: *mut c_void) -> &'static mut MeToy {
    &mut *(c as *mut MeToy)
}
unsafe extern "C" fn me_get(c: *mut c_void, _vr: *const u32, n: usize, v: *mut f64) -> i32 {
    for i in 0..n {
        *v.add(i) = me(c).x;
    }
    0
}
unsafe extern "C" fn me_set(_c: *mut c_void, _vr: *const u32, _n: usize, _v: *mut f64) -> i32 {
    0
}
unsafe extern "C" fn me_set_time(c: *mut c_void, t: f64) -> i32 {
    me(c).calls += 1;
    me(c).t = t;
    0
}
unsafe extern "C" fn me_set_states(c: *mut c_void, x: *mut f64, _n: usize) -> i32 {
    me(c).calls += 1;
    me(c).x = *x;
    0
}
unsafe extern "C" fn me_get_states(c: *mut c_void, x: *mut f64, _n: usize) -> i32 {
    me(c).calls += 1;
    *x = me(c).x;
    0
}
unsafe extern "C" fn me_der(c: *mut c_void, dx: *mut f64, _n: usize) -> i32 {
    me(c).calls += 1;
    me(c).evaluations += 1;
    *dx = -me(c).a * me(c).x;
    0
}
unsafe extern "C" fn me_ind(c: *mut c_void, z: *mut f64, _n: usize) -> i32 {
    *z = me(c).x - me(c).level;
    0
}
unsafe extern "C" fn me_completed(c: *mut c_void, _no: i32, enter: *mut i32, term: *mut i32) -> i32 {
    me(c).completed += 1;
    me(c).calls += 1;
    *enter = 0;
    *term = 0;
    0
}
unsafe extern "C" fn me_plain(_c: *mut c_void) -> i32 {
    0
}
#[repr(C)]
struct Info2 {
    needed: i32,
    term: i32,
    nom: i32,
    val: i32,
    defined: i32,
    next: f64,
}
unsafe extern "C" fn me_update(c: *mut c_void, ei: *mut Info2) -> i32 {
    let m = me(c);
    let ei = &mut *ei;
    ei.needed = 0;
    ei.term = 0;
    if !m.time_event_done && (m.t - m.t_ev).abs() < 1e-9 {
        m.time_event_done = true;
        m.a = m.a2;
        m.time_events.push(m.t);
    }
    if m.x <= m.level && m.crossings.is_empty() {
        m.crossings.push(m.t);
        m.x *= 0.5;
        ei.val = 1;
    }
    ei.defined = (!m.time_event_done) as i32;
    ei.next = m.t_ev;
    0
}

#[test]
fn model_exchange_unit_is_integrated_with_its_time_and_state_events() {
    toy_me(&[1e-10, 1e-12, 1.0, 0.0, 0.0]);
}

#[test]
fn model_exchange_unit_under_fixed_step_rk4() {
    toy_me(&[1e-10, 1e-12, 1.0, 1.0, 1e-3]);
}

#[test]
fn model_exchange_calls_per_communication_step() {
    // x' = -x, no event indicator, no time event, 100 steps of 0.1 s. RK4: 4 evaluations and 11 calls per
    // step (getDerivatives at the start point; setTime + setContinuousStates + getDerivatives at t + h/2;
    // setContinuousStates + getDerivatives at the same time; setTime + setContinuousStates +
    // getDerivatives at t + h; setContinuousStates of the result; completedIntegratorStep). DP5(4) at a
    // tolerance that takes one step per interval: 7 evaluations and 19 calls (the FSAL stage shares the
    // time of stage 6, and the unit is left where the last stage put it). A few more for the first step.
    let (n, calls, evals) = toy_calls(&[1e-10, 1e-12, f64::NAN, 1.0, 0.0]);
    eprintln!("RK4: {n} steps, {calls} calls, {evals} evaluations");
    assert_eq!(evals, 4 * n, "RK4 evaluations");
    assert_eq!(calls, 11 * n + 3, "RK4 calls");
    let (n, calls, evals) = toy_calls(&[1e-3, 1e-3, f64::NAN, 0.0, 0.0]);
    eprintln!("DP5(4): {n} steps, {calls} calls, {evals} evaluations");
    assert!(evals <= 7 * n + 2, "DP5(4) evaluations: {evals}");
    assert!(calls <= 19 * n + 6, "DP5(4) calls: {calls}");
}

/// (steps, FMI calls, derivative evaluations) of the toy with no events.
fn toy_calls(params: &[f64; 5]) -> (usize, usize, usize) {
    let mut m = MeToy {
        t: 0.0,
        x: 1.0,
        a: 1.0,
        a2: 1.0,
        level: -1.0,
        t_ev: f64::INFINITY,
        time_event_done: true,
        crossings: vec![],
        time_events: vec![],
        completed: 0,
        calls: 0,
        evaluations: 0,
    };
    let comps = [&mut m as *mut MeToy as *mut c_void];
    let info = [2usize, 1, 1, 0];
    let t = toy_fns();
    let n = 100usize;
    let (log_fmu, log_vr, log_type) = ([0usize], [0u32], [T_REAL]);
    let mut out = vec![f64::NAN; n + 1];
    let mut fail = [0i64; 3];
    let st = unsafe {
        scfmu_loop_run(
            1,
            comps.as_ptr(),
            info.as_ptr(),
            t.as_ptr(),
            params.as_ptr(),
            0,
            std::ptr::null(),
            0,
            std::ptr::null(),
            0,
            0,
            1,
            log_fmu.as_ptr(),
            log_vr.as_ptr(),
            log_type.as_ptr(),
            n,
            0.0,
            0.1,
            out.as_mut_ptr(),
            out.len(),
            1,
            fail.as_mut_ptr(),
        )
    };
    assert_eq!(st, 0, "{fail:?}");
    assert!(
        (m.x - (-10.0f64).exp()).abs() < 1e-3 * (-10.0f64).exp(),
        "x(10) = {}",
        m.x
    );
    (n, m.calls, m.evaluations)
}

fn toy_fns() -> [*const c_void; FN_SLOTS] {
    let mut t = [std::ptr::null(); FN_SLOTS];
    t[F_GET_REAL] = me_get as *const c_void;
    t[F_SET_REAL] = me_set as *const c_void;
    t[F_SET_TIME] = me_set_time as *const c_void;
    t[F_SET_STATES] = me_set_states as *const c_void;
    t[F_GET_STATES] = me_get_states as *const c_void;
    t[F_GET_DERIVATIVES] = me_der as *const c_void;
    t[F_GET_INDICATORS] = me_ind as *const c_void;
    t[F_COMPLETED_STEP] = me_completed as *const c_void;
    t[F_ENTER_EVENT_MODE] = me_plain as *const c_void;
    t[F_UPDATE_DISCRETE] = me_update as *const c_void;
    t[F_ENTER_CONT_MODE] = me_plain as *const c_void;
    t
}

fn toy_me(params: &[f64; 5]) {
    // x(0) = 1, a = 1: x reaches 0.5 at ln 2 (state event; x halves to 0.25); at t_ev = 1.0 the rate
    // becomes a2 = 3; closed form at t = 2: 0.25·e^{-(1 - ln 2)}·e^{-3·1}
    let mut m = MeToy {
        t: 0.0,
        x: 1.0,
        a: 1.0,
        a2: 3.0,
        level: 0.5,
        t_ev: 1.0,
        time_event_done: false,
        crossings: vec![],
        time_events: vec![],
        completed: 0,
        calls: 0,
        evaluations: 0,
    };
    let comps = [&mut m as *mut MeToy as *mut c_void];
    let info = [2usize, 1, 1, 1];
    let t = toy_fns();
    let (n, dt) = (20usize, 0.1);
    let log_fmu = [0usize];
    let log_vr = [0u32];
    let log_type = [T_REAL];
    let mut out = vec![f64::NAN; n + 1];
    let mut fail = [0i64; 3];
    let st = unsafe {
        scfmu_loop_run(
            1,
            comps.as_ptr(),
            info.as_ptr(),
            t.as_ptr(),
            params.as_ptr(),
            0,
            std::ptr::null(),
            0,
            std::ptr::null(),
            0,
            0,
            1,
            log_fmu.as_ptr(),
            log_vr.as_ptr(),
            log_type.as_ptr(),
            n,
            0.0,
            dt,
            out.as_mut_ptr(),
            out.len(),
            1,
            fail.as_mut_ptr(),
        )
    };
    assert_eq!(st, 0, "{fail:?}");
    let ln2 = std::f64::consts::LN_2;
    assert_eq!(m.crossings.len(), 1);
    assert!(
        (m.crossings[0] - ln2).abs() < 1e-9,
        "state event at {} (expected ln 2)",
        m.crossings[0]
    );
    assert_eq!(m.time_events, vec![1.0]);
    let exact = |t: f64| {
        if t < ln2 {
            (-t).exp()
        } else if t < 1.0 {
            0.25 * (-(t - ln2)).exp()
        } else {
            0.25 * (-(1.0 - ln2)).exp() * (-3.0 * (t - 1.0)).exp()
        }
    };
    assert!(out.len() > n, "{} outputs for {} points", out.len(), n + 1);
    for (k, &yk) in out.iter().enumerate().take(n + 1) {
        let tk = k as f64 * dt;
        let e = exact(tk);
        assert!((yk - e).abs() <= 1e-8 * e.abs().max(1e-3), "t = {tk}: {yk} vs {e}");
    }
    assert!(m.completed >= n);
}
