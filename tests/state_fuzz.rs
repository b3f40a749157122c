//! Restored FMU states through the C ABI, for every FMU of the registry:
//! - a state fuzzer: serialized states after 300 steps at the model's own step, with 1–8 bytes
//!   changed and the CRC recomputed, are refused with fmi2Error or restore a usable instance (outputs
//!   finite or an fmi2Error, one more step OK or fmi2Error) — never fmi2Fatal, a crash or a hang;
//! - the two defects of issue 22: a FopidController state with the law's history-before-start flag
//!   flipped, and junk appended after the payload, are refused with a message naming the reason;
//! - a tolerance outside what the integrators honour is clamped with a warning.

mod common;

use std::ffi::{c_int, c_void};

use common::*;
use spacecraft_fmus::fmi::fmi2::*;
use spacecraft_fmus::model::{Causality, VarKind};
use spacecraft_fmus::registry;

const FATAL: c_int = 4;
const WARNING: c_int = 1;
const STEPS: usize = 300;

fn crc32(b: &[u8]) -> u32 {
    // bitwise CRC-32 (IEEE), written here independently of the library's crc32fast
    let mut c = 0xFFFF_FFFFu32;
    for &x in b {
        c ^= x as u32;
        for _ in 0..8 {
            c = (c >> 1) ^ (0xEDB8_8320 & 0u32.wrapping_sub(c & 1));
        }
    }
    !c
}

fn fix_crc(b: &mut [u8]) {
    let n = b.len();
    let crc = crc32(&b[..n - 4]);
    b[n - 4..].copy_from_slice(&crc.to_le_bytes());
}

/// xorshift64: deterministic mutations.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn real_inputs(p: &TestFmu) -> Vec<&'static str> {
    let e = registry::find(p.model).unwrap();
    e.decls
        .iter()
        .filter(|d| d.causality == Causality::Input && d.kind == VarKind::Real)
        .map(|d| d.name)
        .collect()
}

fn real_outputs(model: &str) -> Vec<u32> {
    let e = registry::find(model).unwrap();
    e.decls
        .iter()
        .filter(|d| d.causality == Causality::Output && d.kind == VarKind::Real)
        .map(|d| d.vr)
        .collect()
}

/// An initialized instance after STEPS steps at the model's default step with small varying inputs
/// (quaternion inputs keep their defaults); returns it and its serialized state.
fn run_and_serialize(model: &'static str) -> (TestFmu, Vec<u8>) {
    let mut p = TestFmu::new(model);
    p.init(&[], &[]);
    let h = registry::find(model).unwrap().info.default_step;
    let inputs: Vec<&str> = real_inputs(&p).into_iter().filter(|n| !n.starts_with("q")).collect();
    for k in 0..STEPS {
        for (i, n) in inputs.iter().enumerate() {
            let x = ((k + 3 * i) as f64 * 0.05).sin();
            // an atmospheric density (Orbit's rho) is non-negative and thin in orbit: 0.01 kg/m3 would
            // bring the orbit down within seconds; a variance (ModeManager's p_att) is non-negative
            let unit = registry::find(model).unwrap().decl(n).map_or("", |d| d.unit);
            p.set(
                n,
                match unit {
                    "kg/m3" => 1e-12 * (1.0 + x),
                    "rad2" => 1e-4 * (1.0 + x),
                    _ => 0.01 * x,
                },
            );
        }
        assert_eq!(p.step(k as f64 * h, h), OK, "{model} step {k}: {:?}", p.messages());
    }
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(fmi2GetFMUstate(p.c, &mut s), OK);
    let mut size = 0usize;
    assert_eq!(fmi2SerializedFMUstateSize(p.c, s, &mut size), OK);
    let mut buf = vec![0u8; size];
    assert_eq!(fmi2SerializeFMUstate(p.c, s, buf.as_mut_ptr() as *mut _, size), OK);
    assert_eq!(fmi2FreeFMUstate(p.c, &mut s), OK);
    (p, buf)
}

/// Deserializes `bytes` into `q`; if accepted, restores it and checks that the instance is usable.
/// Returns Ok(true) if accepted, Ok(false) if refused, Err(what went wrong) otherwise.
fn try_state(q: &TestFmu, bytes: &[u8], outputs: &[u32], h: f64) -> Result<bool, String> {
    let mut s: *mut c_void = std::ptr::null_mut();
    let st = fmi2DeSerializeFMUstate(q.c, bytes.as_ptr() as *const _, bytes.len(), &mut s);
    if st != OK {
        if st != ERROR || !s.is_null() {
            return Err(format!("deserialize returned {st}"));
        }
        return Ok(false);
    }
    let st = fmi2SetFMUstate(q.c, s);
    fmi2FreeFMUstate(q.c, &mut s);
    if st != OK {
        return Err(format!("set of an accepted state returned {st}: {}", q.last_message()));
    }
    let read = |when: &str| -> Result<(), String> {
        let mut v = vec![0.0; outputs.len()];
        match fmi2GetReal(q.c, outputs.as_ptr(), outputs.len(), v.as_mut_ptr()) {
            OK if v.iter().all(|x| x.is_finite()) => Ok(()),
            OK => Err(format!("fmi2OK with non-finite outputs {when}: {v:?}")),
            ERROR => Ok(()),
            st => Err(format!("fmi2GetReal {when} returned {st}: {}", q.last_message())),
        }
    };
    read("after restore")?;
    let mut t = f64::NAN;
    if fmi2GetRealStatus(q.c, 2, &mut t) == OK {
        match fmi2DoStep(q.c, t, h, 1) {
            OK | ERROR => {}
            st => return Err(format!("doStep after restore returned {st}: {}", q.last_message())),
        }
        read("after a step")?;
    }
    Ok(true)
}

#[test]
fn mutated_states_of_every_fmu_are_refused_or_usable() {
    let mut rng = Rng(0x2026_1123_dead_beef);
    let (mut total_acc, mut total_ref) = (0, 0);
    let per_model = 300;
    for entry in registry::ALL {
        let model = entry.info.name;
        let (_p, good) = run_and_serialize(model);
        let q = TestFmu::new(model);
        let outputs = real_outputs(model);
        let h = entry.info.default_step;
        assert_eq!(
            try_state(&q, &good, &outputs, h),
            Ok(true),
            "{model}: the unchanged state is refused: {}",
            q.last_message()
        );
        let payload = 16..good.len() - 4;
        let (mut acc, mut refused) = (0, 0);
        for i in 0..per_model {
            let mut b = good.clone();
            let n = 1 + rng.below(8);
            let mut what = vec![];
            for _ in 0..n {
                // half of the changes in the first 512 payload bytes (header, parameters, flags)
                let span = if rng.next().is_multiple_of(2) {
                    payload.len().min(512)
                } else {
                    payload.len()
                };
                let at = payload.start + rng.below(span);
                if rng.next().is_multiple_of(2) {
                    b[at] ^= 1 << rng.below(8);
                } else {
                    b[at] = rng.next() as u8;
                }
                what.push(at);
            }
            fix_crc(&mut b);
            match try_state(&q, &b, &outputs, h) {
                Ok(true) => acc += 1,
                Ok(false) => refused += 1,
                Err(e) => panic!("{model}, mutation {i} at bytes {what:?}: {e}"),
            }
            assert!(
                q.messages().iter().all(|(st, _)| *st != FATAL),
                "{model}, mutation {i} at {what:?}: {:?}",
                q.messages().last()
            );
        }
        println!(
            "{model:>30}: state {:>7} bytes, {per_model} mutations: {acc:>3} accepted and usable, {refused:>3} refused",
            good.len()
        );
        total_acc += acc;
        total_ref += refused;
    }
    println!(
        "{} FMUs, {} mutated states: {total_acc} accepted and usable, {total_ref} refused, 0 fatal",
        registry::COUNT,
        total_acc + total_ref
    );
}

#[test]
fn fopid_state_with_a_flipped_law_flag_is_refused_by_name() {
    let (_p, good) = run_and_serialize("FopidController");
    let q = TestFmu::new("FopidController");
    let outputs = real_outputs("FopidController");
    // every single-bit change of the low bit in the first 600 payload bytes: refused or usable; the
    // flip of history_before_start (false -> true) is among them and is refused by name
    let mut named = 0;
    for at in 16..(16 + 600).min(good.len() - 4) {
        let mut b = good.clone();
        b[at] ^= 1;
        fix_crc(&mut b);
        let before = q.messages().len();
        match try_state(&q, &b, &outputs, 0.001) {
            Ok(_) => {}
            Err(e) => panic!("byte {at}: {e}"),
        }
        if q.messages()[before..].iter().any(|(st, m)| {
            *st == ERROR && m.contains("law.p.history_before_start") && m.contains("fmi2DeSerializeFMUstate")
        }) {
            named += 1;
        }
    }
    assert!(named >= 1, "no refusal named the law's history_before_start flag");
}

#[test]
fn trailing_bytes_after_the_payload_are_refused_by_name() {
    let (_p, good) = run_and_serialize("FopidController");
    let q = TestFmu::new("FopidController");
    let n = good.len();
    let payload_len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    assert_eq!(16 + payload_len + 4, n);
    let mut b = good[..n - 4].to_vec();
    b.extend_from_slice(&[0x5a; 70]);
    b[12..16].copy_from_slice(&((payload_len + 70) as u32).to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    fix_crc(&mut b);
    let mut s: *mut c_void = std::ptr::null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(q.c, b.as_ptr() as *const _, b.len(), &mut s),
        ERROR
    );
    assert!(s.is_null());
    let m = q.last_message();
    assert!(
        m.contains("fmi2DeSerializeFMUstate") && m.contains("70 trailing bytes"),
        "{m}"
    );
}

#[test]
fn a_tolerance_outside_the_honoured_range_is_clamped_with_a_warning() {
    for (tol, used) in [(1e-300, "1e-14"), (0.5, "1e-1")] {
        let p = TestFmu::new("AttitudePlant");
        assert_eq!(fmi2SetupExperiment(p.c, 1, tol, 0.0, 0, 0.0), WARNING, "{tol}");
        let (st, m) = p.messages().last().cloned().unwrap();
        assert_eq!(st, WARNING);
        assert!(
            m.contains("fmi2SetupExperiment") && m.contains("tolerance") && m.contains(used),
            "{m}"
        );
        // the experiment is set up: initialization proceeds
        assert_eq!(fmi2EnterInitializationMode(p.c), OK);
        assert_eq!(fmi2ExitInitializationMode(p.c), OK);
    }
    let p = TestFmu::new("AttitudePlant");
    assert_eq!(fmi2SetupExperiment(p.c, 1, 1e-6, 0.0, 0, 0.0), OK);
    assert!(p.messages().is_empty());
}
