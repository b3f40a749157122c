//! The bodies of the FMU-state C functions, shared by both rooms (their `state.rs`): each C function
//! checks its pointers, then calls one of these inside its room's call wrapper (state machine, panic
//! guard, logging).

use std::ffi::c_void;

use super::instance::{CallResult, Fail, Instance};
use super::state::Snapshot;
use crate::model::guid::guid;

/// Stores `snap` in `*slot`: a new handle owned by instance `owner` when the slot is NULL, else the
/// state the slot already holds is overwritten (reuse of a handed-out state is allowed by both standards).
fn store(snap: Snapshot, slot: &mut *mut c_void, owner: usize) -> CallResult {
    if slot.is_null() {
        *slot = snap.into_handle(owner)? as *mut c_void;
        Ok(())
    } else {
        Snapshot::with_handle(*slot as usize, |s| {
            *s = snap;
            Ok(())
        })
    }
}

/// Get FMU state.
pub(crate) fn get(inst: &Instance, slot: &mut *mut c_void, owner: usize) -> CallResult {
    store(Snapshot::capture(inst), slot, owner)
}

/// Set FMU state.
pub(crate) fn set(inst: &mut Instance, state: *mut c_void) -> CallResult {
    Snapshot::with_handle(state as usize, |snap| snap.restore_into(inst))
}

/// Free FMU state: freeing NULL is a no-op.
pub(crate) fn free(slot: &mut *mut c_void) -> CallResult {
    if slot.is_null() {
        return Ok(());
    }
    Snapshot::free_handle(*slot as usize)?;
    *slot = std::ptr::null_mut();
    Ok(())
}

/// Serialized FMU state size: serializes once and keeps the bytes
/// for the serialize call that follows.
pub(crate) fn serialized_size(inst: &Instance, state: *mut c_void, out: &mut usize) -> CallResult {
    Snapshot::with_handle(state as usize, |snap| {
        let bytes = snap.to_bytes(&guid(inst.entry))?;
        *out = bytes.len();
        snap.serialized = Some(bytes);
        Ok(())
    })
}

/// Serialize FMU state into the master's buffer of `size` bytes, which
/// `buffer` borrows once the size is known to match (`size_function` names the size call in the message).
pub(crate) fn serialize<'a>(
    inst: &Instance,
    state: *mut c_void,
    size: usize,
    size_function: &str,
    buffer: impl FnOnce() -> CallResult<&'a mut [u8]>,
) -> CallResult {
    Snapshot::with_handle(state as usize, |snap| {
        let bytes = match snap.serialized.take() {
            Some(b) => b,
            None => snap.to_bytes(&guid(inst.entry))?,
        };
        if size != bytes.len() {
            return Err(Fail::error(format!(
                "size {size} differs from {size_function} = {}",
                bytes.len()
            )));
        }
        buffer()?.copy_from_slice(&bytes);
        Ok(())
    })
}

/// Deserialize FMU state: a validated state into `*slot`.
pub(crate) fn deserialize(inst: &Instance, bytes: &[u8], slot: &mut *mut c_void, owner: usize) -> CallResult {
    let snap = Snapshot::from_bytes(bytes, inst, &guid(inst.entry))?;
    store(snap, slot, owner)
}
