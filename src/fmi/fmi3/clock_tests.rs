//! Clocked Co-Simulation and Scheduled Execution of the ten sampled units, through the C functions: for
//! each unit (with parameters that exercise its clocks) three masters drive the same pseudo-random
//! inputs — (a) the sampled Co-Simulation of before (eventModeUsed = false, a step from tick to tick on the
//! union of the clocks' ticks), (b) clocked Co-Simulation (Event Mode at every tick, fmi3SetClock on the
//! due clocks, fmi3UpdateDiscreteStates, fmi3DoStep to the next tick), (c) Scheduled Execution
//! (fmi3ActivateModelPartition of each due clock in priority order) — and every output read at every
//! tick is the same double in all three. The tick times are computed here from the standard's rule
//! t_start + shift + k·interval with the parameter values set, independently of the layer.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Mutex;

use super::*;
use crate::model::{Causality, ModelEntry, VarKind, CLOCK_VR_BASE};
use crate::registry::{find, ALL};

pub type Log = Mutex<Vec<(c_int, String)>>;

pub unsafe extern "C" fn record(env: *mut c_void, status: c_int, _cat: *const c_char, msg: *const c_char) {
    let log = unsafe { &*(env as *const Log) };
    log.lock()
        .unwrap()
        .push((status, unsafe { CStr::from_ptr(msg) }.to_string_lossy().into_owned()));
}

pub fn last(log: &Log) -> String {
    log.lock().unwrap().last().map(|m| m.1.clone()).unwrap_or_default()
}

/// How the master drives the unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Master {
    Sampled,
    Clocked,
    Scheduled,
}

pub fn entry(name: &str) -> &'static ModelEntry {
    find(name).unwrap()
}

pub fn instantiate(e: &'static ModelEntry, master: Master, log: &Log) -> Instance3 {
    let token = CString::new(crate::model::guid::guid(e).as_str()).unwrap();
    let env = log as *const Log as *mut c_void;
    if master == Master::Scheduled {
        return fmi3InstantiateScheduledExecution(
            ALL,
            c"se".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            env,
            Some(record),
            std::ptr::null(),
            None,
            None,
        );
    }
    let event = (master == Master::Clocked) as u8;
    fmi3InstantiateCoSimulation(
        ALL,
        c"cs".as_ptr(),
        token.as_ptr(),
        std::ptr::null(),
        0,
        0,
        event,
        0,
        std::ptr::null(),
        0,
        env,
        Some(record),
        std::ptr::null(),
    )
}

fn vr_of(e: &ModelEntry, name: &str) -> (u32, VarKind) {
    let d = e
        .decls
        .iter()
        .find(|d| d.name == name)
        .unwrap_or_else(|| panic!("{name}"));
    (d.vr, d.kind)
}

pub fn set(c: Instance3, e: &ModelEntry, name: &str, x: f64) {
    let (vr, kind) = vr_of(e, name);
    let s = match kind {
        VarKind::Real => fmi3SetFloat64(c, &vr, 1, &x, 1),
        VarKind::Integer => fmi3SetInt32(c, &vr, 1, &(x as i32), 1),
        VarKind::Boolean => fmi3SetBoolean(c, &vr, 1, &((x != 0.0) as u8), 1),
    };
    assert_eq!(s, 0, "set {name} = {x}");
}

/// Every output of the unit as raw bits, in declaration order.
pub fn outputs(c: Instance3, e: &ModelEntry) -> Vec<u64> {
    let mut out = Vec::new();
    for d in e.decls.iter().filter(|d| d.causality == Causality::Output) {
        let bits = match d.kind {
            VarKind::Real => {
                let mut x = f64::NAN;
                assert_eq!(fmi3GetFloat64(c, &d.vr, 1, &mut x, 1), 0, "{}", d.name);
                x.to_bits()
            }
            VarKind::Integer => {
                let mut i = 0i32;
                assert_eq!(fmi3GetInt32(c, &d.vr, 1, &mut i, 1), 0, "{}", d.name);
                i as u64
            }
            VarKind::Boolean => {
                let mut b = 0u8;
                assert_eq!(fmi3GetBoolean(c, &d.vr, 1, &mut b, 1), 0, "{}", d.name);
                b as u64
            }
        };
        out.push(bits);
    }
    out
}

/// Deterministic pseudo-random numbers in [-1, 1] (a 64-bit linear congruential generator).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// The inputs at tick n: every Real input its start value plus a pseudo-random perturbation (flags
/// switch with it), quaternion inputs normalised; Integer and Boolean inputs keep their start.
pub fn inputs(e: &ModelEntry, n: usize) -> Vec<(&'static str, f64)> {
    let mut rng = Lcg(0x5eed ^ (n as u64).wrapping_mul(0x9e3779b97f4a7c15));
    let mut v: Vec<(&'static str, f64)> = Vec::new();
    for d in e
        .decls
        .iter()
        .filter(|d| d.causality == Causality::Input && d.kind == VarKind::Real)
    {
        let start = match d.start {
            crate::model::Start::Real(x) => x,
            _ => 0.0,
        };
        let r = rng.next();
        let x = if d.name.contains("valid") || d.name.ends_with("request") || d.name.contains("fault") {
            (r > 0.0) as u8 as f64
        } else {
            start + 0.05 * r * start.abs().max(1.0)
        };
        v.push((d.name, x));
    }
    // quaternion stems: names ending in _w with _x, _y, _z beside them
    let stems: Vec<String> = v
        .iter()
        .filter_map(|(n, _)| n.strip_suffix("_w").map(str::to_string))
        .collect();
    for s in stems {
        let ix: Vec<usize> = ["_w", "_x", "_y", "_z"]
            .iter()
            .filter_map(|c| v.iter().position(|(n, _)| *n == format!("{s}{c}")))
            .collect();
        if ix.len() == 4 {
            let norm = ix.iter().map(|&i| v[i].1 * v[i].1).sum::<f64>().sqrt();
            for &i in &ix {
                v[i].1 /= norm;
            }
        }
    }
    v
}

/// (time, due clocks) of every tick up to `horizon`, merged over the clocks (ticks closer than 1e-9 s
/// are one instant), from t_start + shift + k·interval with the given parameter values.
pub fn schedule(e: &ModelEntry, params: &[(&str, f64)], horizon: f64) -> Vec<(f64, Vec<usize>)> {
    let value = |n: &str| {
        params
            .iter()
            .find(|(p, _)| *p == n)
            .map(|(_, x)| *x)
            .unwrap_or_else(|| match e.decls.iter().find(|d| d.name == n).unwrap().start {
                crate::model::Start::Real(x) => x,
                _ => panic!("{n}"),
            })
    };
    let mut ticks: Vec<(f64, usize)> = Vec::new();
    for (i, c) in e.clocks.iter().enumerate() {
        let (interval, shift) = (value(c.interval), if c.shift.is_empty() { 0.0 } else { value(c.shift) });
        let mut k = 0i64;
        loop {
            let t = 0.0 + shift + k as f64 * interval;
            if t > horizon + 1e-9 {
                break;
            }
            ticks.push((t, i));
            k += 1;
        }
    }
    ticks.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap().then(a.1.cmp(&b.1)));
    let mut out: Vec<(f64, Vec<usize>)> = Vec::new();
    for (t, i) in ticks {
        match out.last_mut() {
            Some((t0, clocks)) if (t - *t0).abs() < 1e-9 => clocks.push(i),
            _ => out.push((t, vec![i])),
        }
    }
    out
}

/// Runs the unit under `master` over the schedule; the outputs read at every tick.
pub fn run(name: &str, params: &[(&str, f64)], horizon: f64, master: Master) -> Vec<Vec<u64>> {
    let e = entry(name);
    let log = Log::default();
    let c = instantiate(e, master, &log);
    assert!(!c.is_null(), "{name} {master:?}: {}", last(&log));
    let ticks = schedule(e, params, horizon);
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), 0);
    for (p, x) in params {
        set(c, e, p, *x);
    }
    for (n, x) in inputs(e, 0) {
        set(c, e, n, x);
    }
    assert_eq!(fmi3ExitInitializationMode(c), 0, "{name} {master:?}: {}", last(&log));
    let mut rows = Vec::new();
    for (n, (t, due)) in ticks.iter().enumerate() {
        for (name, x) in inputs(e, n) {
            set(c, e, name, x);
        }
        let next = ticks.get(n + 1).map(|x| x.0);
        match master {
            Master::Sampled => {
                rows.push(outputs(c, e));
                if let Some(t1) = next {
                    let s = fmi3DoStep(c, *t, t1 - t, 1, &mut 0, &mut 0, &mut 0, &mut 0.0);
                    assert_eq!(s, 0, "{name} step at {t}: {}", last(&log));
                }
            }
            Master::Clocked => {
                let vrs: Vec<u32> = due.iter().map(|i| CLOCK_VR_BASE + *i as u32).collect();
                let on = vec![1u8; vrs.len()];
                assert_eq!(
                    fmi3SetClock(c, vrs.as_ptr(), vrs.len(), on.as_ptr()),
                    0,
                    "{name} at {t}: {}",
                    last(&log)
                );
                let (mut a, mut b, mut d, mut f, mut defined, mut t_next) = (9, 9, 9, 9, 0, 0.0);
                let s = fmi3UpdateDiscreteStates(c, &mut a, &mut b, &mut d, &mut f, &mut defined, &mut t_next);
                assert_eq!((s, a, b, defined), (0, 0, 0, 1), "{name} at {t}: {}", last(&log));
                if let Some(t1) = next {
                    assert!((t_next - t1).abs() < 1e-9, "{name}: next event {t_next}, schedule {t1}");
                }
                rows.push(outputs(c, e));
                assert_eq!(fmi3EnterStepMode(c), 0, "{}", last(&log));
                if let Some(t1) = next {
                    let s = fmi3DoStep(c, *t, t1 - t, 1, &mut 0, &mut 0, &mut 0, &mut 0.0);
                    assert_eq!(s, 0, "{name} step at {t}: {}", last(&log));
                    assert_eq!(fmi3EnterEventMode(c), 0, "{}", last(&log));
                }
            }
            Master::Scheduled => {
                for i in due {
                    let s = fmi3ActivateModelPartition(c, CLOCK_VR_BASE + *i as u32, *t);
                    assert_eq!(s, 0, "{name} clock {i} at {t}: {}", last(&log));
                }
                rows.push(outputs(c, e));
            }
        }
    }
    fmi3FreeInstance(c);
    rows
}

/// The three masters give the same outputs, bit for bit, at every tick.
pub fn same_in_all_three(name: &str, params: &[(&str, f64)], horizon: f64) {
    let sampled = run(name, params, horizon, Master::Sampled);
    assert!(sampled.len() > 5, "{name}: {} ticks", sampled.len());
    for master in [Master::Clocked, Master::Scheduled] {
        let other = run(name, params, horizon, master);
        assert_eq!(other.len(), sampled.len());
        for (n, (a, b)) in sampled.iter().zip(&other).enumerate() {
            assert_eq!(a, b, "{name} {master:?}: outputs differ at tick {n}");
        }
    }
    // the outputs do change over the run (the test is not comparing constants)
    assert!(sampled.windows(2).any(|w| w[0] != w[1]), "{name}: outputs never change");
}

#[test]
fn pid_with_memory() {
    same_in_all_three(
        "PidController",
        &[("step", 0.01), ("gl_memory", 7.0), ("ki", 0.7), ("kd", 0.3)],
        1.0,
    );
}

#[test]
fn fopid() {
    same_in_all_three(
        "FopidController",
        &[("step", 0.02), ("lambda", 0.6), ("mu", 0.8), ("gl_memory", 20.0)],
        1.0,
    );
}

#[test]
fn sample_hold_fractional_delay() {
    same_in_all_three(
        "SampleHold",
        &[("sample_period", 0.1), ("delay", 0.03), ("initial_output", -2.0)],
        2.0,
    );
}

#[test]
fn sample_hold_delay_of_whole_periods() {
    same_in_all_three(
        "SampleHold",
        &[("sample_period", 0.1), ("delay", 0.2), ("initial_output", -2.0)],
        2.0,
    );
}

#[test]
fn sample_hold_without_delay() {
    same_in_all_three("SampleHold", &[("sample_period", 0.05), ("delay", 0.0)], 1.0);
}

#[test]
fn gyro() {
    same_in_all_three("Gyro", &[("sample_period", 0.02), ("seed", 7.0)], 1.0);
}

#[test]
fn magnetometer() {
    same_in_all_three("Magnetometer", &[("sample_period", 0.05), ("seed", 3.0)], 2.0);
}

#[test]
fn star_tracker_with_latency() {
    same_in_all_three(
        "StarTracker",
        &[("sample_period", 0.2), ("latency", 0.1), ("seed", 5.0)],
        4.0,
    );
}

/// Latency of one period: the delivery tick coincides with the next sample tick, where the delivered
/// quaternion and its flag must come from the state before that sample is taken.
#[test]
fn star_tracker_with_a_latency_of_one_period() {
    same_in_all_three(
        "StarTracker",
        &[("sample_period", 0.2), ("latency", 0.2), ("seed", 5.0)],
        4.0,
    );
}

#[test]
fn sun_sensor() {
    same_in_all_three(
        "SunSensor",
        &[
            ("sample_period", 0.05),
            ("seed", 9.0),
            ("fov", std::f64::consts::PI),
            ("shadow", 0.0),
        ],
        2.0,
    );
}

#[test]
fn mekf() {
    same_in_all_three("Mekf", &[("sample_period", 0.02)], 1.0);
}

#[test]
fn bdot() {
    same_in_all_three("BDot", &[("sample_period", 0.05), ("filter_time_constant", 0.2)], 2.0);
}

#[test]
fn mode_manager() {
    same_in_all_three("ModeManager", &[("sample_period", 0.5), ("min_dwell", 1.0)], 10.0);
}
