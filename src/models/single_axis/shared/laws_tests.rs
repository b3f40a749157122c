//! Unit tests of `laws.rs` (kept apart so the law's file reads as the law).

use super::*;
use crate::math::fractional::gl_weights;

fn signal(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| (0.013 * k as f64).sin() + 0.3 * (0.0071 * k as f64 * k as f64 % 7.0).cos() - 0.2)
        .collect()
}

fn params(kp: f64, ki: f64, kd: f64, lambda: f64, mu: f64) -> FopidParams {
    FopidParams {
        kp,
        ki,
        kd,
        lambda,
        mu,
        h: 0.001,
        memory: 0,
        history_before_start: false,
    }
}

#[test]
fn fopid_with_unit_orders_equals_pid() {
    for hbs in [false, true] {
        for mem in [0usize, 1, 2, 50, 3000] {
            let p = FopidParams {
                memory: mem,
                history_before_start: hbs,
                ..params(2.0, 0.1, 8.0, 1.0, 1.0)
            };
            let mut f = FopidLaw::new(p).unwrap();
            let mut q = PidLaw::new(p).unwrap();
            for (n, &e) in signal(20_000).iter().enumerate() {
                let (a, b) = (f.output(e), q.output(e));
                assert!(
                    (a - b).abs() < 1e-12 * b.abs().max(1.0),
                    "L={mem} hbs={hbs} n={n}: {a} vs {b}"
                );
                f.push(e);
                q.push(e);
            }
        }
    }
}

#[test]
fn history_before_start_removes_derivative_kick() {
    let e0 = 0.5;
    for mu in [1.0, 0.7, 1.5] {
        for mem in [0usize, 30] {
            let p = FopidParams {
                memory: mem,
                history_before_start: true,
                ..params(0.0, 0.0, 1.0, 1.0, mu)
            };
            let mut f = FopidLaw::new(p).unwrap();
            // constant error that has always been there: full memory gives D^μ = 0; short memory
            // gives the truncated sum e_0 h^{-μ} Σ_{j<L} w_j from the first sample on (no kick)
            let expect = if mem == 0 {
                0.0
            } else {
                e0 * 1000f64.powf(mu) * gl_weights(mu, mem).iter().sum::<f64>()
            };
            for _ in 0..200 {
                assert!(
                    (f.output(e0) - expect).abs() < 1e-9 * expect.abs().max(1.0),
                    "μ={mu} L={mem}: {} vs {expect}",
                    f.output(e0)
                );
                f.push(e0);
            }
            let p0 = FopidParams {
                history_before_start: false,
                ..p
            };
            let f0 = FopidLaw::new(p0).unwrap();
            assert!((f0.output(e0) - e0 * 1000f64.powf(mu)).abs() < 1e-9);
        }
    }
    // μ = 0: D^0 e = e whatever the option
    let f = FopidLaw::new(FopidParams {
        history_before_start: true,
        ..params(0.0, 0.0, 1.0, 1.0, 0.0)
    })
    .unwrap();
    assert!((f.output(0.3) - 0.3).abs() < 1e-15);
}

#[test]
fn bad_parameters_are_named() {
    let e = FopidLaw::new(params(1.0, 1.0, 1.0, 2.5, 1.0)).err().unwrap();
    assert!(e.contains("lambda"), "{e}");
    let e = FopidLaw::new(params(1.0, 1.0, 1.0, 1.0, -0.1)).err().unwrap();
    assert!(e.contains("mu"), "{e}");
    let e = FopidLaw::new(params(f64::NAN, 1.0, 1.0, 1.0, 1.0)).err().unwrap();
    assert!(e.contains("kp"), "{e}");
}

#[test]
fn serialized_state_continues_bit_identically() {
    let p = FopidParams {
        ..params(2.0, 0.3, 5.0, 0.8, 1.3)
    };
    let mut a = FopidLaw::new(p).unwrap();
    let e = signal(6000);
    for &x in &e[..2500] {
        a.push(x);
    }
    let bytes = postcard::to_allocvec(&a).unwrap();
    let mut b: FopidLaw = postcard::from_bytes(&bytes).unwrap();
    for &x in &e[2500..] {
        assert_eq!(a.output(x).to_bits(), b.output(x).to_bits());
        a.push(x);
        b.push(x);
    }
}

#[test]
fn state_is_the_history_once_and_restores_bit_identically() {
    let e = signal(20_000);
    for (hbs, mem, ki) in [
        (false, 0usize, 0.3),
        (true, 0, 0.3),
        (true, 300, 0.0),
        (false, 5000, 0.2),
    ] {
        let p = FopidParams {
            memory: mem,
            history_before_start: hbs,
            ..params(2.0, ki, 5.0, 0.8, 1.3)
        };
        let mut a = FopidLaw::new(p).unwrap();
        let mut q = PidLaw::new(p).unwrap();
        for &x in &e[..12_345] {
            a.push(x);
            q.push(x);
        }
        let bytes = postcard::to_allocvec(&a).unwrap();
        // 8 bytes per sample plus the parameters
        assert!(
            bytes.len() <= 8 * 12_345 + 80,
            "{} bytes for 12,345 samples",
            bytes.len()
        );
        let mut b: FopidLaw = postcard::from_bytes(&bytes).unwrap();
        let qb = postcard::to_allocvec(&q).unwrap();
        assert!(qb.len() <= 8 * 12_345 + 80);
        let mut r: PidLaw = postcard::from_bytes(&qb).unwrap();
        for &x in &e[12_345..] {
            assert_eq!(a.output(x).to_bits(), b.output(x).to_bits(), "hbs={hbs} L={mem}");
            assert_eq!(q.output(x).to_bits(), r.output(x).to_bits(), "hbs={hbs} L={mem}");
            a.push(x);
            b.push(x);
            q.push(x);
            r.push(x);
        }
    }
    // absurd parameters in a decoded state are refused before anything is allocated
    let p = FopidParams {
        memory: usize::MAX / 2,
        history_before_start: true,
        ..params(1.0, 1.0, 1.0, 0.5, 0.5)
    };
    let bytes = postcard::to_allocvec(&StoredRef {
        p: &p,
        fast: true,
        history: &[0.1, 0.2],
    })
    .unwrap();
    let err = postcard::from_bytes::<FopidLaw>(&bytes).err().unwrap();
    let _ = err;
    assert!(FopidLaw::new(p).err().unwrap().contains("gl_memory"));
}
