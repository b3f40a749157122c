//! Sets of addresses handed to the master (instances, FMU states), so that a foreign or freed pointer
//! is recognised before it is dereferenced; hashed with one multiply, and the instance set with a
//! lock-free cache in front, as it is consulted on every FMI call.

use std::collections::HashSet;
use std::hash::{BuildHasher, Hasher};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Hasher for addresses: one multiply (Fibonacci hashing). SipHash's DoS resistance is not needed
/// for pointers we allocated ourselves, and this set is consulted on every FMI call.
#[derive(Default)]
pub struct AddrHasher(u64);

impl Hasher for AddrHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn write_usize(&mut self, n: usize) {
        self.0 = (n as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    }
}

#[derive(Clone, Copy, Default)]
pub struct BuildAddrHasher;

impl BuildHasher for BuildAddrHasher {
    type Hasher = AddrHasher;
    fn build_hasher(&self) -> AddrHasher {
        AddrHasher(0)
    }
}

/// Slots of the lock-free cache in front of a [`LiveSet`] (a power of two).
const SLOTS: usize = 64;

/// Addresses handed to the master (instances): a foreign or freed pointer is recognised before it is
/// dereferenced. The set itself is under a lock; in front of it, a direct-mapped cache of atomic slots
/// (one address per slot, 0 = empty) answers the check of an address on every FMI call without the lock.
///
/// Why the lock-free answer is sound: a slot only ever holds an address that is in the set. An address
/// is stored into its slot only under the lock while it is in the set (on insert, or on a hit of the
/// locked lookup), and [`LiveSet::remove`] clears its slot in the same critical section that takes it
/// out of the set, before the caller frees the memory. A lookup that finds the address in its slot
/// therefore sees a live address, unless the master frees the instance in another thread without
/// ordering that against this call (a data race of the master's own, which no check can catch: FMI
/// forbids concurrent calls on one instance). With such ordering, the clearing store happens before the
/// lookup's load, which cannot read the older value. No memory of the instance is read to decide:
/// a freed pointer is refused by its address alone.
pub struct LiveSet {
    set: Mutex<HashSet<usize, BuildAddrHasher>>,
    slots: [AtomicUsize; SLOTS],
}

fn slot_of(addr: usize) -> usize {
    // the address hash's top bits (the low bits of a heap address are alignment zeros)
    ((addr as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> (64 - SLOTS.trailing_zeros())) as usize
}

impl LiveSet {
    pub const fn new() -> Self {
        LiveSet {
            set: Mutex::new(HashSet::with_hasher(BuildAddrHasher)),
            slots: [const { AtomicUsize::new(0) }; SLOTS],
        }
    }

    /// The set under its lock (for insertions, removals and questions about the whole set).
    pub fn lock(&self) -> MutexGuard<'_, HashSet<usize, BuildAddrHasher>> {
        self.set.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Whether `addr` is in the set: from its cache slot without the lock, else from the set (under
    /// the lock, remembering a hit in the slot). `addr` must not be 0.
    pub fn contains(&self, addr: usize) -> bool {
        let slot = &self.slots[slot_of(addr)];
        if slot.load(Ordering::Acquire) == addr {
            return true;
        }
        let set = self.lock();
        let live = set.contains(&addr);
        if live {
            slot.store(addr, Ordering::Release);
        }
        live
    }

    /// Adds `addr` (not 0) to the set under the lock held in `set` (from [`LiveSet::lock`]).
    pub fn insert(&self, set: &mut HashSet<usize, BuildAddrHasher>, addr: usize) {
        set.insert(addr);
        self.slots[slot_of(addr)].store(addr, Ordering::Release);
    }

    /// Takes `addr` out of the set and out of its cache slot, under the lock held in `set`; whether it was there.
    pub fn remove(&self, set: &mut HashSet<usize, BuildAddrHasher>, addr: usize) -> bool {
        let slot = &self.slots[slot_of(addr)];
        if slot.load(Ordering::Relaxed) == addr {
            slot.store(0, Ordering::Release);
        }
        set.remove(&addr)
    }
}

impl Default for LiveSet {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_answers_only_for_addresses_in_the_set() {
        let live = LiveSet::new();
        let (a, b) = (0x7f00_0000_1000usize, 0x7f00_0000_2000usize);
        assert!(!live.contains(a));
        live.insert(&mut live.lock(), a);
        assert!(live.contains(a) && !live.contains(b));
        // an address colliding with a's slot displaces it from the cache, never from the set
        let c = (1..1_000_000usize)
            .map(|k| a + 16 * k)
            .find(|c| slot_of(*c) == slot_of(a))
            .unwrap();
        live.insert(&mut live.lock(), c);
        assert!(live.contains(a) && live.contains(c) && live.contains(a));
        assert!(live.remove(&mut live.lock(), a));
        assert!(!live.contains(a) && live.contains(c));
        assert!(!live.remove(&mut live.lock(), a));
        assert!(live.remove(&mut live.lock(), c));
        assert!(!live.contains(c) && live.lock().is_empty());
        assert!(live.slots.iter().all(|s| s.load(Ordering::Relaxed) == 0));
    }
}
