//! The checked set-up of one run of the compiled loop: every argument of `scfmu_loop_run` is validated
//! (null pointers, sizes, value-reference and buffer ranges, the function slots each unit needs) before
//! the first FMI call, and turned into the units, their solvers, the propagation plan and the log groups.

use scfmu_fmi_stepper::{MeUnit, Method, Settings, Stepper, Table};

use super::*;

// the nine Model Exchange slots are consecutive, in the order of the stepper's table (fmi::ME_FUNCTIONS)
const _: () = assert!(F_ENTER_CONT_MODE - F_SET_TIME + 1 == scfmu_fmi_stepper::fmi::ME_FUNCTIONS.len());

/// A Model Exchange unit's stepper, with the unit as its typed function table.
pub(crate) type MeStepper = (MeUnit, Stepper);

const CS_SLOTS: [usize; 3] = [F_GET_REAL, F_SET_REAL, F_DO_STEP];
const ME_SLOTS: [usize; 11] = [
    F_GET_REAL,
    F_SET_REAL,
    F_SET_TIME,
    F_SET_STATES,
    F_GET_STATES,
    F_GET_DERIVATIVES,
    F_GET_INDICATORS,
    F_COMPLETED_STEP,
    F_ENTER_EVENT_MODE,
    F_UPDATE_DISCRETE,
    F_ENTER_CONT_MODE,
];

/// What [`run`](super::run) executes: built only from arguments that passed every check.
pub(crate) struct Setup<'a> {
    pub fmus: Vec<Fmu>,
    pub solvers: Vec<Option<MeStepper>>,
    pub plan: Vec<Op>,
    pub groups: Vec<LogGroup>,
    pub vrs: &'a [u32],
    pub log_vr: &'a [u32],
    pub rows: usize,
}

/// Checks the arguments; `Err` is [`ERR_NULL`] or [`ERR_SIZE`].
pub(crate) unsafe fn setup(a: &Args) -> Result<Setup<'_>, i32> {
    let n_fmus = a.n_fmus;
    let (Some(n_info), Some(n_fns), Some(n_me)) = (
        n_fmus.checked_mul(INFO_FIELDS),
        n_fmus.checked_mul(FN_SLOTS),
        n_fmus.checked_mul(ME_FIELDS),
    ) else {
        return Err(ERR_SIZE);
    };
    let (Some(comps), Some(info), Some(fns)) = (slice(a.comps, n_fmus), slice(a.info, n_info), slice(a.fns, n_fns))
    else {
        return Err(ERR_NULL);
    };
    let Some(n_op_fields) = a.n_ops.checked_mul(OP_FIELDS) else {
        return Err(ERR_SIZE);
    };
    let (Some(ops), Some(vrs), Some(log_fmu), Some(log_vr), Some(log_type)) = (
        slice(a.ops, n_op_fields),
        slice(a.vrs, a.n_vrs),
        slice(a.log_fmu, a.n_log),
        slice(a.log_vr, a.n_log),
        slice(a.log_type, a.n_log),
    ) else {
        return Err(ERR_NULL);
    };
    let any_me = (0..n_fmus).any(|i| info[i * INFO_FIELDS + 1] == 1);
    let me_params = if any_me {
        match slice(a.me_params, n_me) {
            Some(p) => p,
            None => return Err(ERR_NULL),
        }
    } else {
        &[]
    };
    let mut fmus = Vec::with_capacity(n_fmus);
    let mut solvers: Vec<Option<MeStepper>> = Vec::with_capacity(n_fmus);
    for i in 0..n_fmus {
        let (fmu, solver) = unit(i, comps, info, fns, me_params)?;
        fmus.push(fmu);
        solvers.push(solver);
    }
    let mut plan = Vec::with_capacity(a.n_ops);
    for o in ops.chunks_exact(OP_FIELDS) {
        plan.push(plan_op(o, a, &fmus)?);
    }
    let Some(rows) = a.n_steps.checked_add(1) else {
        return Err(ERR_SIZE);
    };
    if rows.checked_mul(a.n_log) != Some(a.out_len) || (a.out_len > 0 && a.out.is_null()) {
        return Err(if a.out.is_null() && a.out_len > 0 {
            ERR_NULL
        } else {
            ERR_SIZE
        });
    }
    let groups = log_groups(log_fmu, log_type, &fmus)?;
    Ok(Setup {
        fmus,
        solvers,
        plan,
        groups,
        vrs,
        log_vr,
        rows,
    })
}

/// Unit `i`: its instance, FMI version and function table (every slot its interface calls present) and,
/// for a Model Exchange unit, its stepper from the unit's row of `me_params`.
unsafe fn unit(
    i: usize,
    comps: &[*mut c_void],
    info: &[usize],
    fns: &[*const c_void],
    me_params: &[f64],
) -> Result<(Fmu, Option<MeStepper>), i32> {
    let inf = &info[i * INFO_FIELDS..(i + 1) * INFO_FIELDS];
    let (version, interface, nx, nz) = (inf[0], inf[1], inf[2], inf[3]);
    if comps[i].is_null() {
        return Err(ERR_NULL);
    }
    if !(version == 2 || version == 3) || interface > 1 {
        return Err(ERR_SIZE);
    }
    let mut table = [std::ptr::null(); FN_SLOTS];
    table.copy_from_slice(&fns[i * FN_SLOTS..(i + 1) * FN_SLOTS]);
    let needed: &[usize] = if interface == 1 { &ME_SLOTS } else { &CS_SLOTS };
    if needed.iter().any(|&s| table[s].is_null()) {
        return Err(ERR_NULL);
    }
    let fmu = Fmu::new(comps[i], version == 3, table);
    if interface != 1 {
        return Ok((fmu, None));
    }
    let p = &me_params[i * ME_FIELDS..(i + 1) * ME_FIELDS];
    if !(p[0] > 0.0 && p[1] > 0.0) || !(p[3] == 0.0 || p[3] == 1.0) || !(p[4] >= 0.0) {
        return Err(ERR_SIZE);
    }
    let settings = Settings {
        method: if p[3] == 1.0 {
            Method::Rk4
        } else {
            Method::DormandPrince
        },
        rtol: p[0],
        atol: p[1],
        max_step: p[4],
    };
    // the Model Exchange slots F_SET_TIME..=F_ENTER_CONT_MODE are the stepper's table, in its order
    let mut slots = [std::ptr::null(); 9];
    slots.copy_from_slice(&fmu.fns[F_SET_TIME..=F_ENTER_CONT_MODE]);
    let table = Table::from_slots(fmu.v3, slots).ok_or(ERR_NULL)?;
    let unit = MeUnit { comp: fmu.comp, table };
    let next = if p[2].is_nan() { None } else { Some(p[2]) };
    Ok((fmu, Some((unit, Stepper::new(nx, nz, settings, next)))))
}

/// One propagation operation (kind, unit, value-reference offset, count, buffer offset), range-checked.
fn plan_op(o: &[usize], a: &Args, fmus: &[Fmu]) -> Result<Op, i32> {
    let op = Op {
        kind: o[0],
        fmu: o[1],
        vr: o[2],
        n: o[3],
        buf: o[4],
    };
    let n_buf = if op.kind <= K_SET_REAL {
        a.n_real_buf
    } else {
        a.n_int_buf
    };
    let vr_ok = op.vr.checked_add(op.n).is_some_and(|e| e <= a.n_vrs);
    let buf_ok = op.buf.checked_add(op.n).is_some_and(|e| e <= n_buf);
    if op.kind > K_SET_BOOL || op.fmu >= fmus.len() || !vr_ok || !buf_ok {
        return Err(ERR_SIZE);
    }
    let slot = [F_GET_REAL, F_SET_REAL, F_GET_INT, F_SET_INT, F_GET_BOOL, F_SET_BOOL][op.kind];
    if fmus[op.fmu].fns[slot].is_null() {
        return Err(ERR_NULL);
    }
    Ok(op)
}

/// The logged columns grouped into runs of the same unit and type (one get per run and row).
fn log_groups(log_fmu: &[usize], log_type: &[usize], fmus: &[Fmu]) -> Result<Vec<LogGroup>, i32> {
    let mut groups: Vec<LogGroup> = Vec::new();
    for (col, (&f, &ty)) in log_fmu.iter().zip(log_type.iter()).enumerate() {
        if f >= fmus.len() || ty > T_BOOL {
            return Err(ERR_SIZE);
        }
        let slot = [F_GET_REAL, F_GET_INT, F_GET_BOOL][ty];
        if fmus[f].fns[slot].is_null() {
            return Err(ERR_NULL);
        }
        match groups.last_mut() {
            Some(g) if g.fmu == f && g.ty == ty => g.n += 1,
            _ => groups.push(LogGroup { fmu: f, ty, col, n: 1 }),
        }
    }
    Ok(groups)
}
