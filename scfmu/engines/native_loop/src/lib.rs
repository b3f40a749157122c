//! Compiled fixed-step Gauss–Seidel co-simulation loop with logging, for scfmu's `"compiled"` engine
//! (`scfmu/engines/compiled.py`).
//!
//! The FMUs (FMI 2.0 or FMI 3.0) are instantiated and initialized by Python (fmpy); Python hands this
//! library, as flat arrays, the plan that `scfmu.engines.lean.LeanMaster` runs from Python
//! (`scfmu.scenario.plan` + `scfmu.engines.lean.flat_ops`): per FMU its instance pointer, its FMI major
//! version, its interface and a table of [`FN_SLOTS`] function pointers taken from its shared library;
//! the propagation operations in Gauss–Seidel order (get source outputs into a slice of a work buffer;
//! set destination inputs from a slice of it), typed Real, Integer or Boolean; and the logged (FMU, value
//! reference, type) triples. [`scfmu_loop_run`] then executes the whole run without returning to Python:
//! for k = 0..=n_steps, t_k = t0 + k·dt: propagate, log row k (one get per run of consecutive logged
//! values of the same FMU and type, straight into the output row for Real), and, for k < n_steps, step
//! every FMU from t_k to t_k + dt in order: `doStep` of a Co-Simulation unit, or, for a Model Exchange
//! unit, the integration of its continuous states by the engines' Model Exchange stepper (the crate
//! `scfmu_fmi_stepper`: Dormand–Prince 5(4) or RK4 per unit, with its time events, state events,
//! `completedIntegratorStep` and event iteration), over the unit's Model Exchange slots as its typed table.
//! It stops at the first status above `max_ok` and reports it with the step index.
//!
//! Values: Real are `f64`, Integer `i32`, Boolean `i32` 0/1 in the work buffers (FMI 3.0's one-byte
//! `fmi3Boolean` is converted at the call). FMI 3.0 getters/setters get the value count as their extra
//! argument (scalars: the number of value references).
//!
//! No dependency on the FMU crate; no panic crosses the C boundary (arguments are validated before
//! the first call, and the body runs under `catch_unwind`).

use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

use scfmu_fmi_stepper::values::{Values, VALUE_FUNCTIONS};
use scfmu_fmi_stepper::Stop;

mod setup;
use setup::Setup;

/// Version of the calling convention of [`scfmu_loop_run`] (Python checks it before use).
pub const ABI_VERSION: u32 = 2;

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
/// An FMI 3.0 unit's `doStep`, or a Model Exchange unit, asked to terminate the simulation.
pub const PHASE_TERMINATE: i64 = 4;
/// The Model Exchange solver failed (step size below its minimum, or too many steps).
pub const PHASE_SOLVER: i64 = 5;

/// Number of `usize` entries per propagation operation: kind (`K_*`), FMU index, first value
/// reference (index into `vrs`), count, first buffer element (of the Real buffer for `K_GET_REAL` /
/// `K_SET_REAL`, of the integer buffer otherwise).
pub const OP_FIELDS: usize = 5;
pub const K_GET_REAL: usize = 0;
pub const K_SET_REAL: usize = 1;
pub const K_GET_INT: usize = 2;
pub const K_SET_INT: usize = 3;
pub const K_GET_BOOL: usize = 4;
pub const K_SET_BOOL: usize = 5;

/// Logged value types (`log_type`).
pub const T_REAL: usize = 0;
pub const T_INT: usize = 1;
pub const T_BOOL: usize = 2;

/// Function table of one FMU: [`FN_SLOTS`] pointers, in this order (the FMI 2.0 / FMI 3.0 names). The
/// slots of a type never used by the plan, and the Model Exchange slots of a Co-Simulation unit
/// (and `doStep` of a Model Exchange unit), may be null.
pub const FN_SLOTS: usize = 16;
pub const F_GET_REAL: usize = 0; // fmi2GetReal / fmi3GetFloat64
pub const F_SET_REAL: usize = 1; // fmi2SetReal / fmi3SetFloat64
pub const F_GET_INT: usize = 2; // fmi2GetInteger / fmi3GetInt32
pub const F_SET_INT: usize = 3; // fmi2SetInteger / fmi3SetInt32
pub const F_GET_BOOL: usize = 4; // fmi2GetBoolean / fmi3GetBoolean
pub const F_SET_BOOL: usize = 5; // fmi2SetBoolean / fmi3SetBoolean
pub const F_DO_STEP: usize = 6; // fmi2DoStep / fmi3DoStep
pub const F_SET_TIME: usize = 7; // fmi2SetTime / fmi3SetTime
pub const F_SET_STATES: usize = 8; // fmi2SetContinuousStates / fmi3SetContinuousStates
pub const F_GET_STATES: usize = 9; // fmi2GetContinuousStates / fmi3GetContinuousStates
pub const F_GET_DERIVATIVES: usize = 10; // fmi2GetDerivatives / fmi3GetContinuousStateDerivatives
pub const F_GET_INDICATORS: usize = 11; // fmi2GetEventIndicators / fmi3GetEventIndicators
pub const F_COMPLETED_STEP: usize = 12; // fmi2CompletedIntegratorStep / fmi3CompletedIntegratorStep
pub const F_ENTER_EVENT_MODE: usize = 13; // fmi2EnterEventMode / fmi3EnterEventMode
pub const F_UPDATE_DISCRETE: usize = 14; // fmi2NewDiscreteStates / fmi3UpdateDiscreteStates
pub const F_ENTER_CONT_MODE: usize = 15; // fmi2EnterContinuousTimeMode / fmi3EnterContinuousTimeMode
                                         // the first seven slots are the stepper crate's value table, in its order (values::VALUE_FUNCTIONS)
const _: () = assert!(F_DO_STEP - F_GET_REAL + 1 == VALUE_FUNCTIONS.len());

/// Entries per FMU in `info`: FMI major version (2 or 3), interface (0 Co-Simulation, 1 Model
/// Exchange), number of continuous states, number of event indicators.
pub const INFO_FIELDS: usize = 4;
/// Entries per FMU in `me_params` (Model Exchange units; ignored otherwise): relative tolerance,
/// absolute tolerance, next time event after initialization (NaN: none), method (0: Dormand–Prince 5(4)
/// adaptive, 1: classic Runge–Kutta 4 with a fixed step), the largest step (the fixed step's size, and a
/// bound on the adaptive steps; 0: the communication step for RK4, no bound for Dormand–Prince).
pub const ME_FIELDS: usize = 5;

#[no_mangle]
pub extern "C" fn scfmu_loop_version() -> u32 {
    ABI_VERSION
}

/// One FMU of the loop: its instance, version and function table (the value functions and `doStep`
/// typed by the stepper crate's [`Values`]).
pub struct Fmu {
    pub comp: *mut c_void,
    pub v3: bool,
    pub fns: [*const c_void; FN_SLOTS],
    values: Values,
    tmp: Vec<i32>,
}

/// What a failing call reports: its status and phase.
pub type Fail = (i32, i64);

impl Fmu {
    /// # Safety
    /// `fns` holds the functions of its slots (FMI 2.0 or 3.0 signatures per `v3`, null where not given)
    /// for the instance `comp`.
    pub unsafe fn new(comp: *mut c_void, v3: bool, fns: [*const c_void; FN_SLOTS]) -> Fmu {
        let mut slots = [std::ptr::null(); 7];
        slots.copy_from_slice(&fns[F_GET_REAL..=F_DO_STEP]);
        Fmu {
            comp,
            v3,
            fns,
            values: Values::from_slots(comp, v3, slots),
            tmp: Vec::new(),
        }
    }

    /// # Safety
    /// `vr` and `buf` point to `n` elements each.
    pub unsafe fn reals(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut f64) -> i32 {
        self.values.reals(set, vr, n, buf)
    }

    unsafe fn ints(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut i32) -> i32 {
        self.values.ints(set, vr, n, buf)
    }

    unsafe fn bools(&mut self, set: bool, vr: *const u32, n: usize, buf: *mut i32) -> i32 {
        self.values.bools(set, vr, n, buf)
    }

    /// `doStep(t, h)` of a Co-Simulation unit; an FMI 3.0 request to terminate is `(3, PHASE_TERMINATE)`.
    fn do_step(&mut self, t: f64, h: f64) -> Result<i32, Fail> {
        let (st, term) = self.values.do_step(t, h);
        if st <= 1 && term {
            return Err((3, PHASE_TERMINATE));
        }
        Ok(st)
    }
}

struct Op {
    kind: usize,
    fmu: usize,
    vr: usize,
    n: usize,
    buf: usize,
}

struct LogGroup {
    fmu: usize,
    ty: usize,
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
/// * `comps`: `n_fmus` instance pointers; `info`: `n_fmus` × [`INFO_FIELDS`]; `fns`: `n_fmus` ×
///   [`FN_SLOTS`] function pointers; `me_params`: `n_fmus` × [`ME_FIELDS`] (may be null when no FMU
///   is Model Exchange);
/// * `ops`: `n_ops` × [`OP_FIELDS`] entries, in execution order, each `[kind, fmu, vr_start, n, buf_start]`;
/// * `vrs`: `n_vrs` value references; `n_real_buf`, `n_int_buf`: lengths of the work buffers
///   (allocated here, zeroed);
/// * `log_fmu`, `log_vr`, `log_type`: `n_log` logged triples, column order of `out`;
/// * `out`: `out_len` = (`n_steps` + 1) × `n_log` doubles, row k = the logged values at t_k;
/// * `max_ok`: the highest status that lets the run go on (1: Warning tolerated);
/// * `fail`: null, or 3 `i64` set on a failing call to [step k, phase (`PHASE_*`), FMU index]
///   (-1 on argument errors).
///
/// Returns 0 (or the highest tolerated status seen) after a complete run; the first status above
/// `max_ok` (the run stops there); or a negative `ERR_*` code, before any FMI call, for bad arguments.
///
/// # Safety
/// Every non-null pointer must point to at least the stated number of valid elements, the function
/// pointers must have the FMI signatures of their slot and version, the instances must be valid for
/// them, and `out` must not alias the other arrays.
#[no_mangle]
pub unsafe extern "C" fn scfmu_loop_run(
    n_fmus: usize,
    comps: *const *mut c_void,
    info: *const usize,
    fns: *const *const c_void,
    me_params: *const f64,
    n_ops: usize,
    ops: *const usize,
    n_vrs: usize,
    vrs: *const u32,
    n_real_buf: usize,
    n_int_buf: usize,
    n_log: usize,
    log_fmu: *const usize,
    log_vr: *const u32,
    log_type: *const usize,
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
        let a = Args {
            n_fmus,
            comps,
            info,
            fns,
            me_params,
            n_ops,
            ops,
            n_vrs,
            vrs,
            n_real_buf,
            n_int_buf,
            n_log,
            log_fmu,
            log_vr,
            log_type,
            n_steps,
            t0,
            dt,
            out,
            out_len,
            max_ok,
        };
        run(&a, &mut where_)
    }));
    let status = r.unwrap_or(ERR_PANIC);
    if !fail.is_null() {
        std::ptr::copy_nonoverlapping(where_.as_ptr(), fail, 3);
    }
    status
}

struct Args {
    n_fmus: usize,
    comps: *const *mut c_void,
    info: *const usize,
    fns: *const *const c_void,
    me_params: *const f64,
    n_ops: usize,
    ops: *const usize,
    n_vrs: usize,
    vrs: *const u32,
    n_real_buf: usize,
    n_int_buf: usize,
    n_log: usize,
    log_fmu: *const usize,
    log_vr: *const u32,
    log_type: *const usize,
    n_steps: usize,
    t0: f64,
    dt: f64,
    out: *mut f64,
    out_len: usize,
    max_ok: i32,
}

impl Fmu {
    /// Gets one log group's values into its columns of `row` (Integer and Boolean as f64).
    unsafe fn log(&mut self, g: &LogGroup, log_vr: &[u32], row: *mut f64) -> i32 {
        let vr = log_vr.as_ptr().add(g.col);
        if g.ty == T_REAL {
            return self.reals(false, vr, g.n, row.add(g.col));
        }
        let mut tmp = std::mem::take(&mut self.tmp);
        tmp.resize(g.n, 0);
        let st = if g.ty == T_INT {
            self.ints(false, vr, g.n, tmp.as_mut_ptr())
        } else {
            self.bools(false, vr, g.n, tmp.as_mut_ptr())
        };
        for (i, v) in tmp.iter().enumerate() {
            *row.add(g.col + i) = *v as f64;
        }
        self.tmp = tmp;
        st
    }
}

/// The status and phase of a Model Exchange step that stopped.
fn fail_of(stop: Stop) -> Fail {
    match stop {
        Stop::Failed(st) => (st, PHASE_STEP),
        Stop::Terminate => (3, PHASE_TERMINATE),
        Stop::Solver => (3, PHASE_SOLVER),
    }
}

unsafe fn run(a: &Args, where_: &mut [i64; 3]) -> i32 {
    let Setup {
        mut fmus,
        mut solvers,
        plan,
        groups,
        vrs,
        log_vr,
        rows,
    } = match setup::setup(a) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let mut rbuf = vec![0.0f64; a.n_real_buf];
    let mut ibuf = vec![0i32; a.n_int_buf];
    let (rp, ip) = (rbuf.as_mut_ptr(), ibuf.as_mut_ptr());
    let (n_log, max_ok) = (a.n_log, a.max_ok);

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
        let t = a.t0 + (k as f64) * a.dt;
        for op in &plan {
            let f = &mut fmus[op.fmu];
            let vr = vrs.as_ptr().add(op.vr);
            let phase = if op.kind % 2 == 1 { PHASE_SET } else { PHASE_GET };
            let st = match op.kind {
                K_GET_REAL | K_SET_REAL => f.reals(op.kind == K_SET_REAL, vr, op.n, rp.add(op.buf)),
                K_GET_INT | K_SET_INT => f.ints(op.kind == K_SET_INT, vr, op.n, ip.add(op.buf)),
                _ => f.bools(op.kind == K_SET_BOOL, vr, op.n, ip.add(op.buf)),
            };
            check!(st, k, phase, op.fmu);
        }
        let row = a.out.add(k * n_log);
        for g in &groups {
            let st = fmus[g.fmu].log(g, log_vr, row);
            check!(st, k, PHASE_LOG, g.fmu);
        }
        if k < a.n_steps {
            for (i, (f, solver)) in fmus.iter_mut().zip(solvers.iter_mut()).enumerate() {
                let r = match solver {
                    None => f.do_step(t, a.dt),
                    Some((unit, s)) => s.step(unit, t, a.t0 + ((k + 1) as f64) * a.dt).map_err(fail_of),
                };
                match r {
                    Ok(st) => check!(st, k, PHASE_STEP, i),
                    Err((st, phase)) => {
                        *where_ = [k as i64, phase, i as i64];
                        return st.max(max_ok + 1);
                    }
                }
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests;
