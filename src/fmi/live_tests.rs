//! Tests of the token tables (`live.rs`).

use super::*;

fn boxed(v: u64) -> *mut u64 {
    Box::into_raw(Box::new(v))
}

fn free(p: *mut u64) -> u64 {
    // SAFETY: every pointer here comes from `boxed` and is freed once
    *unsafe { Box::from_raw(p) }
}

#[test]
fn a_freed_token_is_refused_after_any_number_of_reuses_of_its_slot() {
    let t: Handles<u64> = Handles::new(KIND_INSTANCE);
    let first = t.insert(boxed(0), || {}).unwrap();
    assert!(first & TAG != 0 && t.get(first).is_some());
    let mut stale = vec![first];
    free(t.remove(first).unwrap());
    for k in 1..10_000u64 {
        let tok = t.insert(boxed(k), || {}).unwrap();
        assert_eq!(tok & INDEX_MASK, first & INDEX_MASK, "the slot is reused at once");
        for s in &stale {
            assert!(t.get(*s).is_none() && t.remove(*s).is_none());
        }
        // SAFETY: live
        assert_eq!(unsafe { *t.get(tok).unwrap() }, k);
        free(t.remove(tok).unwrap());
        if k % 1000 == 0 {
            stale.push(tok);
        }
    }
    assert!(t.get(0).is_none() && t.get(usize::MAX).is_none() && t.get(first | KIND_STATE).is_none());
}

#[test]
fn past_the_fast_slots_tokens_go_to_the_locked_map_and_are_never_reissued_either() {
    let t: Handles<u64> = Handles::new(KIND_INSTANCE);
    let mut firsts = 0;
    let toks: Vec<usize> = (0..FAST as u64 + 300)
        .map(|k| t.insert(boxed(k), || firsts += 1).unwrap())
        .collect();
    assert_eq!(firsts, 1);
    assert_eq!(toks.iter().filter(|x| *x & INDEX_MASK == OVERFLOW).count(), 300);
    for (k, tok) in toks.iter().enumerate() {
        // SAFETY: live
        assert_eq!(unsafe { *t.get(*tok).unwrap() }, k as u64);
    }
    for tok in &toks {
        free(t.remove(*tok).unwrap());
        assert!(t.get(*tok).is_none());
    }
    let mut empty = false;
    t.when_empty(|| empty = true);
    assert!(empty);
    let again = t.insert(boxed(7), || {}).unwrap();
    assert!(toks.iter().all(|x| t.get(*x).is_none() && *x != again));
    free(t.remove(again).unwrap());
}

#[test]
fn eight_threads_churning_never_see_a_stale_token_accepted() {
    static T: Handles<u64> = Handles::new(KIND_INSTANCE);
    let threads: Vec<_> = (0..8u64)
        .map(|id| {
            std::thread::spawn(move || {
                let mut stale = Vec::new();
                for k in 0..2_000u64 {
                    let v = id << 32 | k;
                    // keep up to 100 instances per thread alive (past the fast slots with 8 threads)
                    let toks: Vec<usize> = (0..1 + k % 100).map(|_| T.insert(boxed(v), || {}).unwrap()).collect();
                    for tok in &toks {
                        // SAFETY: live, and only this thread frees it
                        assert_eq!(unsafe { *T.get(*tok).unwrap() }, v);
                    }
                    for s in stale.iter().rev().take(50) {
                        assert!(T.get(*s).is_none());
                    }
                    for tok in toks {
                        free(T.remove(tok).unwrap());
                        stale.push(tok);
                    }
                }
            })
        })
        .collect();
    for th in threads {
        th.join().unwrap();
    }
    assert!(T.lock().live == 0);
}

#[test]
fn serials_count_up_and_stop_before_they_would_wrap() {
    let s = Serials::new(KIND_STATE);
    let (a, b) = (s.token().unwrap(), s.token().unwrap());
    assert!(a != b && a & KIND_STATE != 0 && a & TAG != 0);
    s.count.store(MAX_SERIAL - 1, Ordering::Relaxed);
    assert!(s.token().is_ok());
    assert!(s.token().unwrap_err().contains("used up"));
}

#[test]
fn two_tables_start_their_serials_at_different_points() {
    // as two loaded libraries would: each table's tokens miss the other's
    let (a, b) = (Serials::new(KIND_INSTANCE), Serials::new(KIND_INSTANCE));
    let (ta, tb) = (a.token().unwrap(), b.token().unwrap());
    assert_ne!(ta, tb);
    let serial = |t: usize| (t & !(TAG | KIND_STATE)) >> INDEX_BITS;
    assert_eq!(serial(a.token().unwrap()), (serial(ta) + 1) & MAX_SERIAL);
}
