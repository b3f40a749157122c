//! The handles handed to the master (instances and FMU states, in either interface)
//! are tokens, never addresses, and no token is ever handed out twice while the library is loaded.
//!
//! Why not addresses: a check of a handle against the set of live addresses refuses a freed object only
//! until the allocator gives the same address to a new one, which it does at once most of the time; the
//! stale handle then reaches the new object (a freed instance steps its successor). A token is
//! `TAG | KIND | serial << INDEX_BITS | index`: `serial` comes from a counter that only counts up (one
//! per table, kept in static memory, never reset while the library is loaded, never wrapped: when it
//! would, creation is refused; it starts at a point of its range mixed from the address of the counter,
//! different for every loaded library, so that another FMU's handles in the same process miss ours but
//! by a chance of about n in 2^50 for n handles made), `index` says where to look the object up. A freed object's token keeps
//! its serial; whatever takes its place later carries a larger one, so the stale token matches nothing,
//! after any number of reuses of the same memory or slot, on any thread.
//!
//! The token is not a usable pointer: its top bit is set, which on x86-64 (and on AArch64 where the top
//! byte is not ignored) makes it an address in the kernel's half or not canonical, so a master that
//! dereferences it faults instead of reading our memory. Where the top byte is ignored (AArch64 Linux user
//! space), the remaining bits may name any address, but no instance is ever found through them: we never
//! dereference a token, we decode and compare it, and a stale one is refused. NULL is never a token (`TAG`
//! is set). `KIND` (the bit below the top) tells instance tokens from FMU-state tokens, so one is never
//! accepted as the other even where their serials coincide.
//!
//! Instances ([`Handles`]) are looked up on every FMI call, so without a lock: `FAST` slots in static
//! memory hold (serial, pointer) pairs; the serial is compared, the pointer read, the serial read again
//! (a slot freed and given to a newer instance in between is noticed: [`Handles::get`] says why).
//! Creation and freeing take the lock. Past `FAST` live instances, new ones get the index `OVERFLOW` and
//! are found in a map under the lock, as addresses past the cache were before. FMU states are looked up under their
//! own lock anyway (`state.rs`), so they only take their tokens from [`Serials`] here.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};
use std::sync::atomic::{AtomicPtr, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Hasher for tokens and addresses: one multiply (Fibonacci hashing). SipHash's DoS resistance is
/// not needed for keys we made ourselves.
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

/// Set in every token: a token is never NULL and never an address in the user half.
const TAG: usize = 1 << (usize::BITS - 1);
/// Token kinds (the bit below `TAG`).
pub const KIND_INSTANCE: usize = 0;
pub const KIND_STATE: usize = 1 << (usize::BITS - 2);
/// Low bits of a token: the fast slot, or `OVERFLOW`.
const INDEX_BITS: u32 = 11;
const INDEX_MASK: usize = (1 << INDEX_BITS) - 1;
/// Lock-free slots for live instances (16 KiB of static memory on 64-bit).
const FAST: usize = 1024;
/// The index of a token kept in the locked overflow map.
const OVERFLOW: usize = INDEX_MASK;
/// The serials a token can carry: 1 ..= MAX_SERIAL (2^51 - 1 on 64-bit).
const MAX_SERIAL: usize = (1 << (usize::BITS - 2 - INDEX_BITS)) - 1;

fn token(kind: usize, serial: usize, index: usize) -> usize {
    TAG | kind | (serial << INDEX_BITS) | index
}

/// A counter of serials that only counts up: each call of [`Serials::token`] gives a token no earlier
/// call gave.
pub struct Serials {
    kind: usize,
    /// How many serials were handed out (never more than `MAX_SERIAL`).
    count: AtomicUsize,
    /// Where this library's serials start in their range (random, drawn at the first use; 0 = not yet).
    base: AtomicUsize,
}

impl Serials {
    pub const fn new(kind: usize) -> Self {
        Serials {
            kind,
            count: AtomicUsize::new(0),
            base: AtomicUsize::new(0),
        }
    }

    /// The start of this counter's serials, from the address of this counter: every loaded library has
    /// its own copy of these statics at its own address (a different one in every run, with address
    /// space randomisation), and the address is mixed over the 2^51 serials, so that a handle of one FMU's
    /// library is not, but by a tiny chance, a handle of another's in the same process.
    fn base(&self) -> usize {
        let b = self.base.load(Ordering::Relaxed);
        if b != 0 {
            return b;
        }
        let mut h = (self as *const Self as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        h = (h ^ (h >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h ^= h >> 32;
        let r = (h as usize & MAX_SERIAL).max(1);
        match self.base.compare_exchange(0, r, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => r,
            Err(first) => first,
        }
    }

    /// The next serial: `base + count` modulo 2^51 for a count that only counts up, so no two calls
    /// give the same serial; 0 (never a serial) is skipped.
    fn next(&self) -> Result<usize, String> {
        let base = self.base();
        loop {
            let count = self
                .count
                .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |c| {
                    (c < MAX_SERIAL).then_some(c + 1)
                })
                .map_err(|_| format!("all {MAX_SERIAL} handles of this library are used up (load it again)"))?
                + 1;
            let serial = base.wrapping_add(count) & MAX_SERIAL;
            if serial != 0 {
                return Ok(serial);
            }
        }
    }

    /// A new token of this counter's kind with index 0.
    pub fn token(&self) -> Result<usize, String> {
        Ok(token(self.kind, self.next()?, 0))
    }
}

/// One lock-free slot: the serial of its occupant (0 = free) and the occupant.
struct Slot<T> {
    serial: AtomicUsize,
    ptr: AtomicPtr<T>,
}

/// What creation and freeing change, under the lock.
struct Inner<T> {
    /// Fast slots never used since the table was last empty: `fresh..FAST`.
    fresh: usize,
    /// Freed fast slots, most recently freed last (a slot is handed out again at once: its new
    /// occupant has a new serial, which is the whole point).
    free: Vec<u16>,
    /// Instances past the fast slots: token → object.
    overflow: HashMap<usize, *mut T, BuildAddrHasher>,
    live: usize,
}

/// The live objects of one kind behind their tokens (see the module documentation).
pub struct Handles<T> {
    serials: Serials,
    slots: [Slot<T>; FAST],
    inner: Mutex<Inner<T>>,
}

// SAFETY: the raw pointers are owned by the table's users; the table only stores and compares them,
// with atomics or under the lock.
unsafe impl<T> Sync for Handles<T> {}
unsafe impl<T> Send for Handles<T> {}

impl<T> Handles<T> {
    pub const fn new(kind: usize) -> Self {
        Handles {
            serials: Serials::new(kind),
            slots: [const {
                Slot {
                    serial: AtomicUsize::new(0),
                    ptr: AtomicPtr::new(std::ptr::null_mut()),
                }
            }; FAST],
            inner: Mutex::new(Inner {
                fresh: 0,
                free: Vec::new(),
                overflow: HashMap::with_hasher(BuildAddrHasher),
                live: 0,
            }),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner<T>> {
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Registers `p` under a new token; `first` runs (under the lock) when the table was empty.
    pub fn insert(&self, p: *mut T, first: impl FnOnce()) -> Result<usize, String> {
        let serial = self.serials.next()?;
        let mut inner = self.lock();
        if inner.live == 0 {
            first();
        }
        let index = match inner.free.pop() {
            Some(i) => usize::from(i),
            None if inner.fresh < FAST => {
                inner.fresh += 1;
                inner.fresh - 1
            }
            None => OVERFLOW,
        };
        let t = token(self.serials.kind, serial, index);
        if index == OVERFLOW {
            inner.overflow.insert(t, p);
        } else {
            let slot = &self.slots[index];
            // the pointer first, then the serial that makes it visible to `get`
            slot.ptr.store(p, Ordering::Release);
            slot.serial.store(serial, Ordering::Release);
        }
        inner.live += 1;
        Ok(t)
    }

    /// The object behind `t` if `t` is a live token of this table; without a lock for fast slots.
    ///
    /// Why the answer is sound: a slot's serial equals the token's only while the object registered
    /// under that token occupies it (serials are never reused). The serial is read (acquire, so the
    /// pointer stored before it is seen), then the pointer (acquire), then the serial again. A slot
    /// freed and re-occupied meanwhile stores 0 and later the newer pointer with release ordering after
    /// it, so having read a newer pointer, the second read cannot see the old serial any more. As with
    /// any check, an object freed by another thread right after the check is the master's own race
    /// (FMI forbids concurrent calls on one instance).
    #[inline]
    pub fn get(&self, t: usize) -> Option<*mut T> {
        let (serial, index) = self.decode(t)?;
        if index == OVERFLOW {
            return self.get_overflow(t);
        }
        let slot = &self.slots[index];
        if slot.serial.load(Ordering::Acquire) != serial {
            return None;
        }
        let p = slot.ptr.load(Ordering::Acquire);
        (slot.serial.load(Ordering::Relaxed) == serial).then_some(p)
    }

    /// [`Handles::get`] past the fast slots (out of line: the fast path stays small).
    #[cold]
    #[inline(never)]
    fn get_overflow(&self, t: usize) -> Option<*mut T> {
        self.lock().overflow.get(&t).copied()
    }

    /// (serial, index) of a token of this table's kind, if it is one.
    #[inline]
    fn decode(&self, t: usize) -> Option<(usize, usize)> {
        if t & (TAG | KIND_STATE) != TAG | self.serials.kind {
            return None;
        }
        let index = t & INDEX_MASK;
        let serial = (t & !(TAG | KIND_STATE)) >> INDEX_BITS;
        (serial != 0 && (index < FAST || index == OVERFLOW)).then_some((serial, index))
    }

    /// Takes `t` out of the table: its object, if it was live (exactly one caller gets it). When the
    /// table becomes empty, its heap memory is given back.
    pub fn remove(&self, t: usize) -> Option<*mut T> {
        let (serial, index) = self.decode(t)?;
        let mut inner = self.lock();
        let p = if index == OVERFLOW {
            inner.overflow.remove(&t)?
        } else {
            let slot = &self.slots[index];
            if slot.serial.load(Ordering::Relaxed) != serial {
                return None;
            }
            slot.serial.store(0, Ordering::Release);
            // release: a `get` that reads this null pointer then sees the serial 0 stored before it
            let p = slot.ptr.swap(std::ptr::null_mut(), Ordering::AcqRel);
            inner.free.push(index as u16);
            p
        };
        inner.live -= 1;
        if inner.live == 0 {
            // every fast slot is free: start again from the first, with no heap left behind
            inner.fresh = 0;
            inner.free = Vec::new();
            inner.overflow = HashMap::with_hasher(BuildAddrHasher);
        }
        Some(p)
    }

    /// Runs `f` under the lock if no object is registered.
    pub fn when_empty(&self, f: impl FnOnce()) {
        let inner = self.lock();
        if inner.live == 0 {
            f();
        }
        drop(inner);
    }
}

#[cfg(test)]
#[path = "live_tests.rs"]
mod tests;
