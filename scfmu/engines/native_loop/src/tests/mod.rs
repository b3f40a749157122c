//! Two toy FMUs (an integrator plant x' = u, output y = x; a gain controller u = -g·y) driven by the
//! loop, against the same Gauss–Seidel sequence written out by hand; argument validation; a failing
//! status stops the run at its step.
use super::*;

/// The FMI 2.0 get/set and doStep signatures of the toys.
type GetSetFn = unsafe extern "C" fn(*mut c_void, *const u32, usize, *mut f64) -> i32;
type StepFn = unsafe extern "C" fn(*mut c_void, f64, f64, i32) -> i32;

#[derive(Default)]
struct Toy {
    x: f64,    // plant state, or controller output
    u: f64,    // input
    gain: f64, // controller gain (0 for the plant)
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

fn table(get: GetSetFn, set: GetSetFn, st: StepFn) -> [*const c_void; FN_SLOTS] {
    let mut t = [std::ptr::null(); FN_SLOTS];
    t[F_GET_REAL] = get as *const c_void;
    t[F_SET_REAL] = set as *const c_void;
    t[F_DO_STEP] = st as *const c_void;
    t
}

fn run_toys(plant: &mut Toy, ctl: &mut Toy, n_steps: usize, out: &mut [f64], fail: &mut [i64; 3]) -> i32 {
    let comps = [ctl as *mut Toy as *mut c_void, plant as *mut Toy as *mut c_void];
    let info = [2usize, 0, 0, 0, /**/ 2, 0, 0, 0];
    let fns: Vec<*const c_void> = [table(get, set, step), table(get, set, step)].concat();
    // controller.u <- plant.y; plant.u <- controller.y (Gauss–Seidel: controller first)
    let ops = [
        0, 1, 0, 1, 0, /**/ 1, 0, 1, 1, 0, /**/ 0, 0, 0, 1, 1, /**/ 1, 1, 2, 1, 1,
    ];
    let vrs = [0u32, 1, 1];
    let log_fmu = [1usize, 0];
    let log_vr = [0u32, 0];
    let log_type = [T_REAL, T_REAL];
    unsafe {
        scfmu_loop_run(
            2,
            comps.as_ptr(),
            info.as_ptr(),
            fns.as_ptr(),
            std::ptr::null(),
            4,
            ops.as_ptr(),
            3,
            vrs.as_ptr(),
            2,
            0,
            2,
            log_fmu.as_ptr(),
            log_vr.as_ptr(),
            log_type.as_ptr(),
            n_steps,
            0.0,
            0.1,
            out.as_mut_ptr(),
            out.len(),
            1,
            fail.as_mut_ptr(),
        )
    }
}

#[test]
fn gauss_seidel_sequence_and_values() {
    let (mut p, mut c) = (
        Toy {
            x: 1.0,
            plant: true,
            ..Default::default()
        },
        Toy {
            gain: 2.0,
            ..Default::default()
        },
    );
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
        Toy {
            x: 1.0,
            plant: true,
            fail_at_step: Some(3),
            ..Default::default()
        },
        Toy {
            gain: 2.0,
            ..Default::default()
        },
    );
    let mut out = vec![f64::NAN; 11 * 2];
    let mut fail = [0i64; 3];
    assert_eq!(run_toys(&mut p, &mut c, 10, &mut out, &mut fail), 3);
    assert_eq!(fail, [3, PHASE_STEP, 1]);
    assert!(out[2 * 3].is_finite() && out[2 * 4].is_nan()); // row 3 logged, row 4 never reached
}

#[test]
fn bad_arguments_are_refused_before_any_call() {
    let (mut p, mut c) = (
        Toy {
            plant: true,
            ..Default::default()
        },
        Toy::default(),
    );
    let mut out = vec![0.0; 5]; // wrong length for 2 steps × 2 columns
    let mut fail = [0i64; 3];
    assert_eq!(run_toys(&mut p, &mut c, 2, &mut out, &mut fail), ERR_SIZE);
    assert!(p.calls.is_empty() && c.calls.is_empty());
    let null = unsafe {
        scfmu_loop_run(
            1,
            std::ptr::null(),
            std::ptr::null(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            std::ptr::null(),
            0,
            std::ptr::null(),
            0,
            0,
            0,
            std::ptr::null(),
            std::ptr::null(),
            std::ptr::null(),
            3,
            0.0,
            0.1,
            std::ptr::null_mut(),
            0,
            1,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(null, ERR_NULL);
    assert_eq!(scfmu_loop_version(), ABI_VERSION);
}

mod model_exchange;
