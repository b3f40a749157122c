//! Sets of addresses handed to the master (instances, FMU states), so that a foreign or freed pointer
//! is recognised before it is dereferenced; hashed with one multiply, as the set is consulted on every
//! FMI call.

use std::collections::HashSet;
use std::hash::{BuildHasher, Hasher};
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

/// Addresses handed to the master (instances, FMU states): a foreign or freed pointer is recognised
/// before it is dereferenced.
pub struct LiveSet(Mutex<HashSet<usize, BuildAddrHasher>>);

impl LiveSet {
    pub const fn new() -> Self {
        LiveSet(Mutex::new(HashSet::with_hasher(BuildAddrHasher)))
    }
    pub fn lock(&self) -> MutexGuard<'_, HashSet<usize, BuildAddrHasher>> {
        self.0.lock().unwrap_or_else(|p| p.into_inner())
    }
}

impl Default for LiveSet {
    fn default() -> Self {
        Self::new()
    }
}
