//! Compiled fixed-step Gauss–Seidel co-simulation loop with logging, for scfmu's `"compiled"` engine
//! (`scfmu/engines/compiled.py`).
//!
//! The FMUs are instantiated and initialized by Python (fmpy); Python hands this library, as flat
//! arrays, the plan that `scfmu.engines.lean.LeanMaster` runs from Python: per FMU its component
//! pointer and its `fmi2GetReal` / `fmi2SetReal` / `fmi2DoStep` function pointers, the propagation
//! operations in Gauss–Seidel order (get source outputs into a slice of a work buffer; set destination
//! inputs from a slice of it), and the logged (FMU, value reference) pairs. [`scfmu_loop_run`] then
//! executes the whole run without returning to Python: for k = 0..=n_steps, t_k = t0 + k·dt:
//! propagate, log row k (one `fmi2GetReal` per run of consecutive logged pairs of the same FMU,
//! straight into the output row), and, for k < n_steps, `fmi2DoStep(t_k, dt)` of every FMU in order.
//! It stops at the first status above `max_ok` and reports it with the step index.
//!
//! No dependency on the FMU crate; no panic crosses the C boundary (arguments are validated before
//! the first call, and the body runs under `catch_unwind`).

use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// `fmi2GetReal` / `fmi2SetReal`: (component, vr[], nvr, value[]) -> fmi2Status.
pub type GetSetFn = unsafe extern "C" fn(*mut c_void, *const u32, usize, *mut f64) -> i32;
/// `fmi2DoStep`: (component, currentCommunicationPoint, communicationStepSize, noSetFMUStatePriorToCurrentPoint).
pub type StepFn = unsafe extern "C" fn(*mut c_void, f64, f64, i32) -> i32;

/// Version of the calling convention of [`scfmu_loop_run`] (Python checks it before use).
pub const ABI_VERSION: u32 = 1;

/// A null pointer where an array or a function was required.
pub const ERR_NULL: i32 = -1;
/// Sizes that do not fit (an index or a slice out of range, an output buffer of the wrong length).
pub const ERR_SIZE: i32 = -2;
/// A panic inside the loop (a bug of this library): caught, never propagated.
pub const ERR_PANIC: i32 = -3;

/// Phases reported in `fail[1]`.
pub const PHASE_GET: i64 = 0;
pub const PHASE_SET: i64 = 1;
pub const PHASE_LOG: i64 = 2;
pub const PHASE_STEP: i64 = 3;

/// Number of `usize` entries per propagation operation: kind (0 get, 1 set), FMU index, first value
/// reference (index into `vrs`), count, first buffer element.
pub const OP_FIELDS: usize = 5;

#[no_mangle]
pub extern "C" fn scfmu_loop_version() -> u32 {
    ABI_VERSION
}

struct Fmu {
    comp: *mut c_void,
    get: GetSetFn,
    set: GetSetFn,
    step: StepFn,
}

struct Op {
    set: bool,
    fmu: usize,
    vr: usize,
    n: usize,
    buf: usize,
}

struct LogGroup {
    fmu: usize,
    col: usize,
    n: usize,
}

unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

/// Runs a whole co-simulation (see the crate documentation).
///
/// * `comps`, `get_fns`, `set_fns`, `step_fns`: `n_fmus` component pointers and function pointers;
/// * `ops`: `n_ops` × [`OP_FIELDS`] entries, in execution order, each `[kind, fmu, vr_start, n, buf_start]`
///   (kind 0: `get(fmu, vrs[vr_start..][..n]) -> buf[buf_start..][..n]`; kind 1: `set` from the buffer);
/// * `vrs`: `n_vrs` value references; `n_buf`: length of the work buffer (allocated here, zeroed);
/// * `log_fmu`, `log_vr`: `n_log` logged pairs, column order of `out`; consecutive pairs of the same
///   FMU are read by one `fmi2GetReal`;
/// * `out`: `out_len` = (`n_steps` + 1) × `n_log` doubles, row k = the logged values at t_k;
/// * `max_ok`: the highest status that lets the run go on (1: fmi2Warning tolerated);
/// * `fail`: null, or 3 `i64` set on a failing FMI call to [step k, phase (`PHASE_*`), FMU index]
///   (-1 on argument errors).
///
/// Returns 0 (or the highest tolerated status seen) after a complete run; the first status above
/// `max_ok` (the run stops there); or a negative `ERR_*` code, before any FMI call, for bad arguments.
///
/// # Safety
/// Every non-null pointer must point to at least the stated number of valid elements, the function
/// pointers must have the FMI 2.0 signatures and the components must be valid for them, and `out` must
/// not alias the other arrays.
#[no_mangle]
pub unsafe extern "C" fn scfmu_loop_run(
    n_fmus: usize,
    comps: *const *mut c_void,
    get_fns: *const Option<GetSetFn>,
    set_fns: *const Option<GetSetFn>,
    step_fns: *const Option<StepFn>,
    n_ops: usize,
    ops: *const usize,
    n_vrs: usize,
    vrs: *const u32,
    n_buf: usize,
    n_log: usize,
    log_fmu: *const usize,
    log_vr: *const u32,
    n_steps: usize,
    t0: f64,
    dt: f64,
    out: *mut f64,
    out_len: usize,
    max_ok: i32,
    fail: *mut i64,
) -> i32 {
    let mut where_ = [-1i64; 3];
    let r = catch_unwind(AssertUnwindSafe(|| {
        run(
            n_fmus, comps, get_fns, set_fns, step_fns, n_ops, ops, n_vrs, vrs, n_buf, n_log, log_fmu,
            log_vr, n_steps, t0, dt, out, out_len, max_ok, &mut where_,
        )
    }));
    let status = r.unwrap_or(ERR_PANIC);
    if !fail.is_null() {
        std::ptr::copy_nonoverlapping(where_.as_ptr(), fail, 3);
    }
    status
}

#[allow(clippy::too_many_arguments)]
unsafe fn run(
    n_fmus: usize,
    comps: *const *mut c_void,
    get_fns: *const Option<GetSetFn>,
    set_fns: *const Option<GetSetFn>,
    step_fns: *const Option<StepFn>,
    n_ops: usize,
    ops: *const usize,
    n_vrs: usize,
    vrs: *const u32,
    n_buf: usize,
    n_log: usize,
    log_fmu: *const usize,
    log_vr: *const u32,
    n_steps: usize,
    t0: f64,
    dt: f64,
    out: *mut f64,
    out_len: usize,
    max_ok: i32,
    where_: &mut [i64; 3],
) -> i32 {
    // ----- validation: nothing is called before every argument has been checked
    let (Some(comps), Some(gets), Some(sets), Some(steps)) = (
        slice(comps, n_fmus),
        slice(get_fns, n_fmus),
        slice(set_fns, n_fmus),
        slice(step_fns, n_fmus),
    ) else {
        return ERR_NULL;
    };
    let Some(n_op_fields) = n_ops.checked_mul(OP_FIELDS) else {
        return ERR_SIZE;
    };
    let (Some(ops), Some(vrs), Some(log_fmu), Some(log_vr)) =
        (slice(ops, n_op_fields), slice(vrs, n_vrs), slice(log_fmu, n_log), slice(log_vr, n_log))
    else {
        return ERR_NULL;
    };
    let mut fmus = Vec::with_capacity(n_fmus);
    for i in 0..n_fmus {
        let (Some(get), Some(set), Some(step)) = (gets[i], sets[i], steps[i]) else {
            return ERR_NULL;
        };
        if comps[i].is_null() {
            return ERR_NULL;
        }
        fmus.push(Fmu { comp: comps[i], get, set, step });
    }
    let mut plan = Vec::with_capacity(n_ops);
    for o in ops.chunks_exact(OP_FIELDS) {
        let op = Op { set: o[0] == 1, fmu: o[1], vr: o[2], n: o[3], buf: o[4] };
        let vr_ok = op.vr.checked_add(op.n).is_some_and(|e| e <= n_vrs);
        let buf_ok = op.buf.checked_add(op.n).is_some_and(|e| e <= n_buf);
        if o[0] > 1 || op.fmu >= n_fmus || !vr_ok || !buf_ok {
            return ERR_SIZE;
        }
        plan.push(op);
    }
    let Some(rows) = n_steps.checked_add(1) else {
        return ERR_SIZE;
    };
    if rows.checked_mul(n_log) != Some(out_len) || (out_len > 0 && out.is_null()) {
        return if out.is_null() && out_len > 0 { ERR_NULL } else { ERR_SIZE };
    }
    let mut groups: Vec<LogGroup> = Vec::new();
    for (col, &f) in log_fmu.iter().enumerate() {
        if f >= n_fmus {
            return ERR_SIZE;
        }
        match groups.last_mut() {
            Some(g) if g.fmu == f => g.n += 1,
            _ => groups.push(LogGroup { fmu: f, col, n: 1 }),
        }
    }
    let mut buf = vec![0.0f64; n_buf];
    let bufp = buf.as_mut_ptr();

    // ----- the loop: LeanMaster.run's calls, in its order
    let mut worst = 0;
    macro_rules! check {
        ($st:expr, $k:expr, $phase:expr, $fmu:expr) => {{
            let st: i32 = $st;
            if st > max_ok || st < 0 {
                *where_ = [$k as i64, $phase, $fmu as i64];
                return st;
            }
            if st > worst {
                worst = st;
            }
        }};
    }
    for k in 0..rows {
        let t = t0 + (k as f64) * dt;
        for op in &plan {
            let f = &fmus[op.fmu];
            let vr = vrs.as_ptr().add(op.vr);
            let b = bufp.add(op.buf);
            if op.set {
                check!((f.set)(f.comp, vr, op.n, b), k, PHASE_SET, op.fmu);
            } else {
                check!((f.get)(f.comp, vr, op.n, b), k, PHASE_GET, op.fmu);
            }
        }
        let row = out.add(k * n_log);
        for g in &groups {
            let f = &fmus[g.fmu];
            check!((f.get)(f.comp, log_vr.as_ptr().add(g.col), g.n, row.add(g.col)), k, PHASE_LOG, g.fmu);
        }
        if k < n_steps {
            for (i, f) in fmus.iter().enumerate() {
                check!((f.step)(f.comp, t, dt, 1), k, PHASE_STEP, i);
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    //! Two toy FMUs (an integrator plant x' = u, output y = x; a gain controller u = -g·y) driven by the
    //! loop, against the same Gauss–Seidel sequence written out by hand; argument validation; a failing
    //! status stops the run at its step.
    use super::*;

    #[derive(Default)]
    struct Toy {
        x: f64,     // plant state, or controller output
        u: f64,     // input
        gain: f64,  // controller gain (0 for the plant)
        plant: bool,
        steps: usize,
        fail_at_step: Option<usize>,
        calls: Vec<String>,
    }

    unsafe extern "C" fn get(c: *mut c_void, vr: *const u32, n: usize, v: *mut f64) -> i32 {
        let t = &mut *(c as *mut Toy);
        for i in 0..n {
            let r = *vr.add(i);
            *v.add(i) = match r {
                0 => t.x,
                1 => t.u,
                _ => return 3,
            };
        }
        t.calls.push(format!("get{n}"));
        0
    }

    unsafe extern "C" fn set(c: *mut c_void, vr: *const u32, n: usize, v: *mut f64) -> i32 {
        let t = &mut *(c as *mut Toy);
        for i in 0..n {
            if *vr.add(i) != 1 {
                return 3;
            }
            t.u = *v.add(i);
            if !t.plant {
                t.x = -t.gain * t.u;
            }
        }
        t.calls.push(format!("set{n}"));
        0
    }

    unsafe extern "C" fn step(c: *mut c_void, _t: f64, h: f64, _no: i32) -> i32 {
        let t = &mut *(c as *mut Toy);
        if t.fail_at_step == Some(t.steps) {
            return 3;
        }
        if t.plant {
            t.x += h * t.u;
        }
        t.steps += 1;
        t.calls.push("step".into());
        if t.steps == 2 {
            1 // a warning: tolerated with max_ok = 1
        } else {
            0
        }
    }

    fn run_toys(plant: &mut Toy, ctl: &mut Toy, n_steps: usize, out: &mut [f64], fail: &mut [i64; 3]) -> i32 {
        let comps = [ctl as *mut Toy as *mut c_void, plant as *mut Toy as *mut c_void];
        let g: [Option<GetSetFn>; 2] = [Some(get), Some(get)];
        let s: [Option<GetSetFn>; 2] = [Some(set), Some(set)];
        let st: [Option<StepFn>; 2] = [Some(step), Some(step)];
        // controller.u <- plant.y; plant.u <- controller.y (Gauss–Seidel: controller first)
        let ops = [0, 1, 0, 1, 0, /**/ 1, 0, 1, 1, 0, /**/ 0, 0, 0, 1, 1, /**/ 1, 1, 2, 1, 1];
        let vrs = [0u32, 1, 1];
        let log_fmu = [1usize, 0];
        let log_vr = [0u32, 0];
        unsafe {
            scfmu_loop_run(
                2, comps.as_ptr(), g.as_ptr(), s.as_ptr(), st.as_ptr(), 4, ops.as_ptr(), 3, vrs.as_ptr(), 2, 2,
                log_fmu.as_ptr(), log_vr.as_ptr(), n_steps, 0.0, 0.1, out.as_mut_ptr(), out.len(), 1,
                fail.as_mut_ptr(),
            )
        }
    }

    #[test]
    fn gauss_seidel_sequence_and_values() {
        let (mut p, mut c) = (Toy { x: 1.0, plant: true, ..Default::default() }, Toy { gain: 2.0, ..Default::default() });
        let n = 5;
        let mut out = vec![f64::NAN; (n + 1) * 2];
        let mut fail = [0i64; 3];
        assert_eq!(run_toys(&mut p, &mut c, n, &mut out, &mut fail), 1); // the warning is reported
        // by hand: at each t_k, u = -g·x (same point), log (x, u), then x += dt·u
        let mut x = 1.0f64;
        for k in 0..=n {
            let u = -2.0 * x;
            assert_eq!(out[2 * k], x, "x at {k}");
            assert_eq!(out[2 * k + 1], u, "u at {k}");
            if k < n {
                x += 0.1 * u;
            }
        }
        assert_eq!(c.calls[..5], ["set1", "get1", "get1", "step", "set1"].map(String::from));
        assert_eq!(p.steps, n);
        assert_eq!(fail, [-1; 3]);
    }

    #[test]
    fn failing_status_stops_at_its_step() {
        let (mut p, mut c) = (
            Toy { x: 1.0, plant: true, fail_at_step: Some(3), ..Default::default() },
            Toy { gain: 2.0, ..Default::default() },
        );
        let mut out = vec![f64::NAN; 11 * 2];
        let mut fail = [0i64; 3];
        assert_eq!(run_toys(&mut p, &mut c, 10, &mut out, &mut fail), 3);
        assert_eq!(fail, [3, PHASE_STEP, 1]);
        assert!(out[2 * 3].is_finite() && out[2 * 4].is_nan()); // row 3 logged, row 4 never reached
    }

    #[test]
    fn bad_arguments_are_refused_before_any_call() {
        let (mut p, mut c) = (Toy { plant: true, ..Default::default() }, Toy::default());
        let mut out = vec![0.0; 5]; // wrong length for 2 steps × 2 columns
        let mut fail = [0i64; 3];
        assert_eq!(run_toys(&mut p, &mut c, 2, &mut out, &mut fail), ERR_SIZE);
        assert!(p.calls.is_empty() && c.calls.is_empty());
        let null = unsafe {
            scfmu_loop_run(
                1, std::ptr::null(), std::ptr::null(), std::ptr::null(), std::ptr::null(), 0, std::ptr::null(),
                0, std::ptr::null(), 0, 0, std::ptr::null(), std::ptr::null(), 3, 0.0, 0.1, std::ptr::null_mut(),
                0, 1, std::ptr::null_mut(),
            )
        };
        assert_eq!(null, ERR_NULL);
        assert_eq!(scfmu_loop_version(), ABI_VERSION);
    }
}
