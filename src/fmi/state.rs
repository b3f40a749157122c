//! FMU state snapshots (`fmi2GetFMUstate` & co.) and their byte format.
//!
//! Every snapshot handed to the master is recorded in a process-wide set, so a foreign, freed or
//! corrupted `fmi2FMUstate` pointer is refused with an error instead of being dereferenced.
//!
//! Byte format (little endian): magic `SCFMUST\0` (8 bytes), format version u32, payload length u32,
//! payload (postcard), CRC-32 of everything before it (u32).

use std::collections::HashSet;
use std::sync::MutexGuard;

use serde::{Deserialize, Serialize};

use super::instance::{CallResult, Fail, Instance, Run};
use super::{BuildAddrHasher, LiveSet};
use crate::model::DynModel;

const MAGIC: &[u8; 8] = b"SCFMUST\0";
const FORMAT_VERSION: u32 = 1;
const HEADER: usize = 16;
const TRAILER: usize = 4;

pub struct Snapshot {
    /// Address of the instance that created it (freed with that instance).
    pub owner: usize,
    pub model_name: &'static str,
    pub run: Run,
    pub model: Box<dyn DynModel>,
    /// Bytes computed by `fmi2SerializedFMUstateSize`, reused by `fmi2SerializeFMUstate`.
    pub serialized: Option<Vec<u8>>,
}

#[derive(Serialize, Deserialize)]
struct Payload {
    model_name: String,
    guid: String,
    run: Run,
    model: Vec<u8>,
}

fn live() -> MutexGuard<'static, HashSet<usize, BuildAddrHasher>> {
    static LIVE: LiveSet = LiveSet::new();
    LIVE.lock()
}

impl Snapshot {
    pub fn capture(inst: &Instance, owner: usize) -> Snapshot {
        Snapshot {
            owner,
            model_name: inst.entry.info.name,
            run: inst.run,
            model: inst.model.clone_box(),
            serialized: None,
        }
    }

    pub fn restore_into(&self, inst: &mut Instance) -> CallResult {
        if self.model_name != inst.entry.info.name {
            return Err(Fail::error(format!("FMU state belongs to {}, not to {}", self.model_name, inst.entry.info.name)));
        }
        inst.model = self.model.clone_box();
        inst.run = self.run;
        Ok(())
    }

    /// Hands a snapshot to the master as an opaque pointer.
    pub fn into_handle(self) -> *mut Snapshot {
        let p = Box::into_raw(Box::new(self));
        live().insert(p as usize);
        p
    }

    /// The snapshot behind a handle, if the handle is one we issued and have not freed.
    ///
    /// # Safety
    /// The caller must not keep the reference across a call that frees the handle.
    pub unsafe fn from_handle<'a>(p: *mut Snapshot) -> CallResult<&'a mut Snapshot> {
        if p.is_null() {
            return Err(Fail::error("FMUstate is NULL"));
        }
        if !live().contains(&(p as usize)) {
            return Err(Fail::error(format!("FMUstate {p:p} was not created by this FMU or was already freed")));
        }
        // SAFETY: the address is in the live set, so it came from Box::into_raw and is not freed.
        Ok(unsafe { &mut *p })
    }

    /// Frees a handle we issued; unknown handles are refused.
    pub fn free_handle(p: *mut Snapshot) -> CallResult {
        if !live().remove(&(p as usize)) {
            return Err(Fail::error(format!("FMUstate {p:p} was not created by this FMU or was already freed")));
        }
        // SAFETY: it was in the live set, so it is a Box we leaked and nobody else frees it.
        drop(unsafe { Box::from_raw(p) });
        Ok(())
    }

    /// Frees every snapshot created by the given instance (called by fmi2FreeInstance).
    pub fn free_all_of(owner: usize) {
        let mut set = live();
        let mine: Vec<usize> = set
            .iter()
            .copied()
            // SAFETY: every address in the set is a live Snapshot box.
            .filter(|p| unsafe { (*(*p as *const Snapshot)).owner } == owner)
            .collect();
        for p in mine {
            set.remove(&p);
            // SAFETY: removed from the set just now; it was a leaked Box.
            drop(unsafe { Box::from_raw(p as *mut Snapshot) });
        }
    }

    pub fn to_bytes(&self, guid: &str) -> CallResult<Vec<u8>> {
        let payload = Payload {
            model_name: self.model_name.to_string(),
            guid: guid.to_string(),
            run: self.run,
            model: self.model.to_bytes().map_err(|e| Fail::error(format!("cannot encode model state: {e}")))?,
        };
        let body = postcard::to_stdvec(&payload).map_err(|e| Fail::error(format!("cannot encode FMU state: {e}")))?;
        let mut out = Vec::with_capacity(HEADER + body.len() + TRAILER);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(body.len() as u32).to_le_bytes());
        out.extend_from_slice(&body);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        Ok(out)
    }

    /// Decodes bytes written by `to_bytes` for the instance's model; anything else is refused.
    pub fn from_bytes(bytes: &[u8], inst: &Instance, owner: usize, guid: &str) -> CallResult<Snapshot> {
        if bytes.len() < HEADER + TRAILER {
            return Err(Fail::error(format!("serialized state has {} bytes, too short to be one of ours", bytes.len())));
        }
        if &bytes[..8] != MAGIC {
            return Err(Fail::error("serialized state does not start with this library's magic bytes"));
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != FORMAT_VERSION {
            return Err(Fail::error(format!("serialized state has format version {version}, expected {FORMAT_VERSION}")));
        }
        let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
        if HEADER + len + TRAILER != bytes.len() {
            return Err(Fail::error(format!("serialized state length {} does not match its header ({})", bytes.len(), HEADER + len + TRAILER)));
        }
        let crc = u32::from_le_bytes(bytes[HEADER + len..].try_into().expect("4 bytes"));
        if crc32fast::hash(&bytes[..HEADER + len]) != crc {
            return Err(Fail::error("serialized state is corrupted (CRC-32 mismatch)"));
        }
        let p: Payload = postcard::from_bytes(&bytes[HEADER..HEADER + len]).map_err(|e| Fail::error(format!("serialized state does not decode: {e}")))?;
        if p.model_name != inst.entry.info.name {
            return Err(Fail::error(format!("serialized state belongs to {}, not to {}", p.model_name, inst.entry.info.name)));
        }
        if p.guid != guid {
            return Err(Fail::error(format!("serialized state was written by a different version of {} (GUID {})", p.model_name, p.guid)));
        }
        let mut model = inst.model.clone_box();
        model.load_bytes(&p.model).map_err(Fail::error)?;
        Ok(Snapshot { owner, model_name: inst.entry.info.name, run: p.run, model, serialized: None })
    }
}
