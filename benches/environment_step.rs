//! Benchmark (issue 43, item 5): cost of one `Environment` evaluation (IGRF-14 to degree 13 + sun +
//! shadow + density, at a new time and position; both density models) and of one `Orbit` communication
//! step (numerical two-body + J2 + drag at 0.1 s and at 10 s; SGP4), side by side with one
//! `AttitudePlant` communication step of 0.1 s, so that the numbers read as ratios. Each unit is measured
//! twice: through the exported FMI 2.0 C functions (a master's cycle: `fmi2SetReal` of the inputs,
//! `fmi2DoStep`, `fmi2GetReal` of the outputs) and directly in Rust (inputs written into the variable
//! block, `Fmu::step`, `Fmu::outputs`). Plain `std::time::Instant` loops, no harness.
//!
//! Run: `cargo bench --bench environment_step` (release profile). Results go to docs/benchmarks.md by hand.

use std::ffi::c_int;
use std::hint::black_box;
use std::time::Instant;

use nalgebra::Vector3;
use spacecraft_fmus::fmi::fmi2::*;
use spacecraft_fmus::math::atmosphere::exponential_density;
use spacecraft_fmus::math::igrf;
use spacecraft_fmus::math::sun::{shadow_factor, sun_position};
use spacecraft_fmus::math::time_scales::{decimal_year, eci_to_ecef, geodetic, JD_J2000};
use spacecraft_fmus::model::{Experiment, Fmu, Model, SlotMut, Value, Variables};
use spacecraft_fmus::models::attitude::AttitudePlant;
use spacecraft_fmus::models::environment::{Environment, Orbit};
use spacecraft_fmus::registry;

/// Interleaved rounds; each measurement reports the minimum (least disturbed) and the median round.
const ROUNDS: usize = 25;

type Params = (&'static [(&'static str, f64)], &'static [(&'static str, i32)]);

/// The epoch of `leo/nadir`: 2026-03-20 12:00:00 UTC.
const EPOCH_INTS: &[(&str, i32)] = &[
    ("epoch_year", 2026),
    ("epoch_month", 3),
    ("epoch_day", 20),
    ("epoch_hour", 12),
];
const ENV_HP_INTS: &[(&str, i32)] = &[
    ("epoch_year", 2026),
    ("epoch_month", 3),
    ("epoch_day", 20),
    ("epoch_hour", 12),
    ("density_model", 1),
];
const ENV_OUT: &[&str] = &[
    "b_eci_x",
    "b_eci_y",
    "b_eci_z",
    "sun_eci_x",
    "sun_eci_y",
    "sun_eci_z",
    "eclipse",
    "rho",
];

/// 500 km circular, i = 97.4°, RAAN 337.5°, epoch JD of 2026-03-20 12:00 UTC; B = 10 kg / (2.2 · 0.0366 m²).
const ORBIT_REALS: &[(&str, f64)] = &[
    ("semi_major_axis", 6_878_137.0),
    ("inclination", 1.6999506914424771),
    ("raan", 5.890486225480862),
    ("epoch_jd_utc", 2_461_120.0),
    ("ballistic_coeff", 124.2),
];
const SGP4_REALS: &[(&str, f64)] = &[
    ("epoch_jd_utc", 2_461_120.0),
    ("tle_epoch_jd_utc", 2_461_120.0),
    ("tle_mean_motion", 0.0011069),
    ("tle_eccentricity", 0.0001),
    ("tle_inclination", 1.6999506914424771),
    ("tle_raan", 5.890486225480862),
    ("tle_bstar", 3.0e-4 / 6_378_135.0),
];
const ORBIT_OUT: &[&str] = &["r_x", "r_y", "r_z", "v_x", "v_y", "v_z"];

/// Paper 003 configuration of plant_step.rs (one module for both benches).
mod shared;
use shared::{INTS as P003_INTS, REALS as P003_REALS};

/// The 6U of `leo/nadir` in its environment: six box facets about a centre of mass offset by
/// (0.005, 0.010, 0.020) m, residual dipole, wheels, magnetorquers, gravity gradient from r; one RK4 step per
/// 0.1 s communication step, as `leo/nadir` runs it (`max_internal_step` 0.1 s).
const LEO_REALS: &[(&str, f64)] = &[
    ("max_internal_step", 0.1),
    ("inertia_xx", 0.1543),
    ("inertia_yy", 0.1200),
    ("inertia_zz", 0.0510),
    ("residual_dipole_x", 0.02),
    ("residual_dipole_y", -0.01),
    ("residual_dipole_z", 0.015),
    ("facet1_area", 0.0828),
    ("facet1_normal_x", 1.0),
    ("facet1_centre_x", 0.045),
    ("facet1_centre_y", -0.010),
    ("facet1_centre_z", -0.020),
    ("facet2_area", 0.0828),
    ("facet2_normal_x", -1.0),
    ("facet2_centre_x", -0.055),
    ("facet2_centre_y", -0.010),
    ("facet2_centre_z", -0.020),
    ("facet3_area", 0.0366),
    ("facet3_normal_y", 1.0),
    ("facet3_centre_x", -0.005),
    ("facet3_centre_y", 0.10315),
    ("facet3_centre_z", -0.020),
    ("facet4_area", 0.0366),
    ("facet4_normal_y", -1.0),
    ("facet4_centre_x", -0.005),
    ("facet4_centre_y", -0.12315),
    ("facet4_centre_z", -0.020),
    ("facet5_area", 0.02263),
    ("facet5_normal_z", 1.0),
    ("facet5_centre_x", -0.005),
    ("facet5_centre_y", -0.010),
    ("facet5_centre_z", 0.163),
    ("facet6_area", 0.02263),
    ("facet6_normal_z", -1.0),
    ("facet6_centre_x", -0.005),
    ("facet6_centre_y", -0.010),
    ("facet6_centre_z", -0.203),
];
const LEO_INTS: &[(&str, i32)] = &[
    ("actuator_mode", 1),
    ("mtq_enable", 1),
    ("gg_enable", 1),
    ("environment_inputs", 1),
];
const PLANT_OUT: &[&str] = &[
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "w_x",
    "w_y",
    "w_z",
    "h_wheel_x",
    "h_wheel_y",
    "h_wheel_z",
];

/// Position and velocity on the 500 km circular orbit at t (a new position at every evaluation).
fn orbit_at(t: f64) -> ([f64; 3], [f64; 3]) {
    let (a, n, inc) = (6_878_137.0, 1.1068e-3, 1.6999506914424771_f64);
    let (s, c) = (n * t).sin_cos();
    let r = [a * c, a * s * inc.cos(), a * s * inc.sin()];
    let v = [-a * n * s, a * n * c * inc.cos(), a * n * c * inc.sin()];
    (r, v)
}

fn plant_inputs(t: f64, env: bool) -> Vec<f64> {
    let mut u = vec![2e-5 * (0.3 * t).sin(), 2e-5 * (0.2 * t).cos(), -1e-5];
    if env {
        let (r, v) = orbit_at(t);
        u.extend(r);
        u.extend(v);
        u.extend([2.0e-5, -1.0e-5, 3.0e-5, 0.6, 0.7, 0.387298, 1.0, 6.0e-13]);
    }
    u
}
const PLANT_IN: &[&str] = &["torque_cmd_x", "torque_cmd_y", "torque_cmd_z"];
const PLANT_ENV_IN: &[&str] = &[
    "torque_cmd_x",
    "torque_cmd_y",
    "torque_cmd_z",
    "r_x",
    "r_y",
    "r_z",
    "v_x",
    "v_y",
    "v_z",
    "b_eci_x",
    "b_eci_y",
    "b_eci_z",
    "sun_eci_x",
    "sun_eci_y",
    "sun_eci_z",
    "eclipse",
    "rho",
];

/// One measured unit: its model, parameters, step, input names and values, output names.
struct Case {
    label: &'static str,
    model: &'static str,
    params: Params,
    h: f64,
    block: usize,
    inputs: &'static [&'static str],
    input_values: fn(f64) -> Vec<f64>,
    outputs: &'static [&'static str],
}

/// One cycle of a unit at step index k.
type Cycle = Box<dyn FnMut(usize)>;

fn vr(model: &str, name: &str) -> u32 {
    registry::find(model)
        .unwrap()
        .decl(name)
        .unwrap_or_else(|| panic!("{model}: no variable {name}"))
        .vr
}

fn index<M: Model>(name: &str) -> usize {
    M::Vars::DECLS
        .iter()
        .position(|d| d.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
}

fn write<M: Model>(m: &mut Fmu<M>, ix: &[usize], u: &[f64]) {
    for (i, x) in ix.iter().zip(u) {
        if let Some(SlotMut::Real(s)) = m.v.slot(*i) {
            *s = *x;
        }
    }
}

/// A master's cycle directly in Rust: inputs written, `step`, `outputs` at the new time, outputs read.
fn direct<M: Model + 'static>(case: &Case) -> Cycle {
    let mut m = Fmu::<M>::default();
    for (n, v) in case.params.0 {
        if let Some(SlotMut::Real(x)) = m.v.slot(index::<M>(n)) {
            *x = *v;
        }
    }
    for (n, v) in case.params.1 {
        match m.v.slot(index::<M>(n)) {
            Some(SlotMut::Integer(x)) => *x = *v,
            Some(SlotMut::Boolean(x)) => *x = *v != 0,
            _ => panic!("{n}"),
        }
    }
    let in_ix: Vec<usize> = case.inputs.iter().map(|n| index::<M>(n)).collect();
    let out_ix: Vec<usize> = case.outputs.iter().map(|n| index::<M>(n)).collect();
    write(&mut m, &in_ix, &(case.input_values)(0.0));
    m.initialize(&Experiment::default()).unwrap();
    let (h, values) = (case.h, case.input_values);
    let mut buf = vec![0.0; out_ix.len()];
    Box::new(move |k| {
        let t = k as f64 * h;
        write(&mut m, &in_ix, &values(t));
        m.step(t, h).unwrap();
        m.outputs(t + h).unwrap();
        for (b, i) in buf.iter_mut().zip(&out_ix) {
            if let Some(Value::Real(x)) = m.v.value(*i) {
                *b = x;
            }
        }
        black_box(&buf);
    })
}

/// The same cycle through the exported FMI 2.0 functions: `fmi2SetReal`, `fmi2DoStep`, `fmi2GetReal`.
fn abi(case: &Case) -> Cycle {
    let c = shared::instantiate(case.model);
    let (rv, rx): (Vec<u32>, Vec<f64>) = case.params.0.iter().map(|(n, v)| (vr(case.model, n), *v)).unzip();
    assert_eq!(fmi2SetReal(c, rv.as_ptr(), rv.len(), rx.as_ptr()), 0);
    for (n, v) in case.params.1 {
        let r = vr(case.model, n);
        let ok = fmi2SetInteger(c, &r, 1, &(*v as c_int)) == 0 || fmi2SetBoolean(c, &r, 1, &(*v as c_int)) == 0;
        assert!(ok, "{n}");
    }
    let in_vr: Vec<u32> = case.inputs.iter().map(|n| vr(case.model, n)).collect();
    let out_vr: Vec<u32> = case.outputs.iter().map(|n| vr(case.model, n)).collect();
    let u0 = (case.input_values)(0.0);
    assert_eq!(fmi2SetReal(c, in_vr.as_ptr(), in_vr.len(), u0.as_ptr()), 0);
    assert_eq!(fmi2ExitInitializationMode(c), 0);
    let (h, values) = (case.h, case.input_values);
    let mut buf = vec![0.0; out_vr.len()];
    Box::new(move |k| {
        let t = k as f64 * h;
        let u = values(t);
        assert_eq!(fmi2SetReal(c, in_vr.as_ptr(), in_vr.len(), u.as_ptr()), 0);
        assert_eq!(fmi2DoStep(c, t, h, 1), 0);
        assert_eq!(fmi2GetReal(c, out_vr.as_ptr(), out_vr.len(), buf.as_mut_ptr()), 0);
        black_box(&buf);
    })
}

fn cases() -> Vec<Case> {
    let env = |label, ints: &'static [(&'static str, i32)]| Case {
        label,
        model: "Environment",
        params: (&[], ints),
        h: 0.1,
        block: 1000,
        inputs: &["r_x", "r_y", "r_z"],
        input_values: |t| orbit_at(t).0.to_vec(),
        outputs: ENV_OUT,
    };
    let orbit = |label, params, h, block| Case {
        label,
        model: "Orbit",
        params,
        h,
        block,
        inputs: &["rho"],
        input_values: |_| vec![6.0e-13],
        outputs: ORBIT_OUT,
    };
    vec![
        env("Environment, exponential density", EPOCH_INTS),
        env("Environment, Harris-Priester density", ENV_HP_INTS),
        orbit("Orbit, J2 + drag, step 0.1 s", (ORBIT_REALS, &[]), 0.1, 4000),
        orbit("Orbit, J2 + drag, step 10 s", (ORBIT_REALS, &[]), 10.0, 400),
        orbit("Orbit, SGP4, step 0.1 s", (SGP4_REALS, &[("propagator", 1)]), 0.1, 4000),
        Case {
            label: "AttitudePlant, paper 003 (plant_step.rs), step 0.1 s = 10 RK4 steps",
            model: "AttitudePlant",
            params: (P003_REALS, P003_INTS),
            h: 0.1,
            block: 2000,
            inputs: PLANT_IN,
            input_values: |t| plant_inputs(t, false),
            outputs: PLANT_OUT,
        },
        Case {
            label: "AttitudePlant, 6U leo/nadir (env inputs, 6 facets), step 0.1 s = 1 RK4 step",
            model: "AttitudePlant",
            params: (LEO_REALS, LEO_INTS),
            h: 0.1,
            block: 2000,
            inputs: PLANT_ENV_IN,
            input_values: |t| plant_inputs(t, true),
            outputs: PLANT_OUT,
        },
    ]
}

/// The pieces of one `Environment` evaluation, directly in Rust (what `Environment::outputs` calls), at the
/// day and position of cycle k: where its cost goes.
fn pieces() -> Vec<(String, usize, Cycle)> {
    let day = |k: usize| 9_575.0 + k as f64 * 0.1 / 86_400.0; // days from J2000.0 (2026-03-20 12:00 UTC on)
    let pos = |k: usize| Vector3::from(orbit_at(k as f64 * 0.1).0);
    let coeffs = igrf::coefficients(decimal_year(JD_J2000 + day(0))).unwrap();
    let piece = |label: &str, f: Cycle| (format!("  piece of Environment: {label} — direct Rust"), 1000, f);
    vec![
        piece(
            "IGRF-14 coefficients at the date (secular variation)",
            Box::new(move |k| {
                black_box(igrf::coefficients(decimal_year(JD_J2000 + day(k))).unwrap());
            }),
        ),
        piece(
            "IGRF-14 field to degree 13 at r_ecef (given coefficients)",
            Box::new(move |k| {
                black_box(igrf::field_ecef(&coeffs, &pos(k)));
            }),
        ),
        piece(
            "ECI to ECEF (precession + GMST) and geodetic coordinates",
            Box::new(move |k| {
                let r = eci_to_ecef(day(k)) * pos(k);
                black_box(geodetic(&r));
            }),
        ),
        piece(
            "sun position and conical shadow",
            Box::new(move |k| {
                let (sun, dist) = sun_position(day(k));
                black_box(shadow_factor(&pos(k), &(sun * dist)));
            }),
        ),
        piece(
            "exponential density",
            Box::new(move |k| {
                black_box(exponential_density(pos(k).norm() - 6_378_137.0));
            }),
        ),
    ]
}

fn main() {
    let cases = cases();
    let mut loops: Vec<(String, usize, Cycle)> = Vec::new();
    for c in &cases {
        let d = match c.model {
            "Environment" => direct::<Environment>(c),
            "Orbit" => direct::<Orbit>(c),
            _ => direct::<AttitudePlant>(c),
        };
        loops.push((format!("{} — direct Rust", c.label), c.block, d));
        loops.push((format!("{} — C ABI", c.label), c.block, abi(c)));
    }
    let n_units = loops.len();
    loops.extend(pieces());
    println!("one cycle = inputs set, one communication step, outputs read (at a new time and position);");
    println!("{ROUNDS} interleaved rounds; per round the mean over its block of cycles\n");
    let mut idx = vec![0usize; loops.len()];
    let mut res = vec![Vec::new(); loops.len()];
    for round in 0..=ROUNDS {
        for (i, (_, block, f)) in loops.iter_mut().enumerate() {
            let n = if round == 0 { *block / 4 } else { *block };
            let t0 = Instant::now();
            for k in idx[i]..idx[i] + n {
                f(k);
            }
            idx[i] += n;
            if round > 0 {
                res[i].push(t0.elapsed().as_secs_f64() / n as f64);
            }
        }
    }
    // minimum and median per measurement; the ratio (of the minima, the least disturbed rounds on a shared
    // machine) is to the paper 003 plant over the same interface
    let stats: Vec<(f64, f64)> = res
        .iter_mut()
        .map(|r| {
            r.sort_by(f64::total_cmp);
            (r[0], r[r.len() / 2])
        })
        .collect();
    let plant = loops
        .iter()
        .position(|l| l.0.starts_with("AttitudePlant, paper 003"))
        .unwrap();
    println!(
        "{:<96} {:>8} {:>10} {:>12}",
        "µs per cycle", "min", "median", "min ÷ plant"
    );
    for (i, (lo, mid)) in stats.iter().enumerate() {
        // units: the plant over the same interface; pieces of Environment: the plant in direct Rust
        let base = stats[plant + if i < n_units { i % 2 } else { 0 }].0;
        println!(
            "{:<96} {:>8.3} {:>10.3} {:>12.2}",
            loops[i].0,
            lo * 1e6,
            mid * 1e6,
            lo / base
        );
    }
}
