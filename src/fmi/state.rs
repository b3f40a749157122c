//! FMU state snapshots (the bodies of both rooms' FMU-state calls) and their byte format.
//!
//! Every snapshot handed to the master is recorded in a process-wide table under a token that is never
//! handed out twice (`live.rs` says why not its address: a freed state's address goes to the next one),
//! with its owning instance, so a foreign, freed or corrupted FMU-state handle is refused with an
//! error, also after its memory went to a new state; the master never holds an address of ours. Every
//! read or write of a snapshot happens while that table's lock is held, so instances on different
//! threads never touch a snapshot at the same time (FMI allows independent instances on independent
//! threads).
//!
//! Byte format (little endian): magic `SCFMUST\0` (8 bytes), format version u32, payload length u32,
//! payload (postcard), CRC-32 of everything before it (u32).

use std::collections::HashMap;
use std::sync::{Mutex, MutexGuard};

use serde::{Deserialize, Serialize};

use super::instance::{CallResult, ClockMode, Clocks, Fail, Instance, Reason, Run};
use super::live::{BuildAddrHasher, Serials, KIND_STATE};
use super::types::{Dialect, FsmState};
use crate::model::DynModel;

const MAGIC: &[u8; 8] = b"SCFMUST\0";
// 2: the run carries the time of the last event (Model Exchange); 3: the FMI version of the instance;
// 4: the states of the version-neutral state machine, the interface recorded by its name
const FORMAT_VERSION: u32 = 5;
const HEADER: usize = 16;
const TRAILER: usize = 4;

pub struct Snapshot {
    pub model_name: &'static str,
    /// The interface of the instance that took it (restored only into an instance of the same: a state
    /// belongs to the interface version that made it, see `docs/hardening.md`).
    pub dialect: &'static Dialect,
    pub run: Run,
    pub model: Box<dyn DynModel>,
    /// The clocks' bookkeeping (active flags, next ticks, held outputs).
    pub clocks: Clocks,
    /// Bytes computed by the serialized-size call, reused by the serialize call that follows.
    pub serialized: Option<Vec<u8>>,
}

#[derive(Serialize, Deserialize)]
struct Payload {
    model_name: String,
    /// the `version` of the dialect of the instance that took it
    interface: String,
    guid: String,
    run: Run,
    model: Vec<u8>,
    clocks: Clocks,
}

/// Live snapshots: token → (snapshot, token of the instance that created it, freed with that instance).
type Table = HashMap<usize, (*mut Snapshot, usize), BuildAddrHasher>;

/// A raw pointer in a static: every access is under the table's lock.
struct Locked(Mutex<Table>);
// SAFETY: the snapshots behind the pointers are touched only with the lock held.
unsafe impl Sync for Locked {}

/// Tokens of FMU states (distinct from instance tokens by their kind bit).
static SERIALS: Serials = Serials::new(KIND_STATE);

fn live() -> MutexGuard<'static, Table> {
    static LIVE: Locked = Locked(Mutex::new(HashMap::with_hasher(BuildAddrHasher)));
    LIVE.0.lock().unwrap_or_else(|p| p.into_inner())
}

/// Gives the table's memory back once it is empty, so an unloaded library leaves nothing behind.
fn release_if_empty(table: &mut Table) {
    if table.is_empty() {
        table.shrink_to_fit();
    }
}

/// A state taken through one interface is refused by the other interface's calls.
fn check_version(taken_by: &str, inst: &Instance, what: &'static str) -> CallResult {
    if taken_by == inst.dialect.version {
        return Ok(());
    }
    Err(Fail::error(Reason::OtherInterface {
        what,
        taken_by: taken_by.to_string(),
    }))
}

/// A state taken in a Model Exchange mode is refused by a Co-Simulation instance and the reverse (at
/// restore and already at deserialize, so that an accepted serialized state can always be set).
fn check_kind(run: &Run, inst: &Instance) -> CallResult {
    // a clocked Co-Simulation instance has Event Mode too, a scheduled one the Activation state
    let clocked = match run.fsm {
        FsmState::EventMode => inst.clocks.mode == ClockMode::Stepped,
        FsmState::Activation => inst.clocks.mode == ClockMode::Scheduled,
        _ => false,
    };
    if clocked && !inst.model_exchange {
        return Ok(());
    }
    let scheduled = inst.clocks.mode == ClockMode::Scheduled;
    if scheduled != (run.fsm == FsmState::Activation)
        && (!scheduled
            || matches!(
                run.fsm,
                FsmState::StepMode | FsmState::EventMode | FsmState::ContinuousTimeMode
            ))
    {
        return Err(Fail::error(format!(
            "FMU state was taken in state {:?}; this instance {} Scheduled Execution",
            run.fsm,
            if scheduled { "runs" } else { "does not run" }
        )));
    }
    if run.fsm == FsmState::EventMode && !inst.model_exchange && !inst.entry.clocks.is_empty() {
        return Err(Fail::error(
            "FMU state was taken in Event Mode of a clocked Co-Simulation instance; this instance runs Co-Simulation without clocks",
        ));
    }
    let me_state = matches!(run.fsm, FsmState::EventMode | FsmState::ContinuousTimeMode);
    if (me_state && !inst.model_exchange) || (inst.model_exchange && run.fsm == FsmState::StepMode) {
        let kind = |me: bool| if me { "Model Exchange" } else { "Co-Simulation" };
        return Err(Fail::error(format!(
            "FMU state was taken from a {} instance; this instance runs {}",
            kind(me_state),
            kind(inst.model_exchange)
        )));
    }
    Ok(())
}

impl Snapshot {
    pub fn capture(inst: &Instance) -> Snapshot {
        Snapshot {
            model_name: inst.entry.info.name,
            dialect: inst.dialect,
            run: inst.run,
            model: inst.model.clone_box(),
            clocks: inst.clocks.clone(),
            serialized: None,
        }
    }

    pub fn restore_into(&self, inst: &mut Instance) -> CallResult {
        if self.model_name != inst.entry.info.name {
            return Err(Fail::error(format!(
                "FMU state belongs to {}, not to {}",
                self.model_name, inst.entry.info.name
            )));
        }
        check_version(self.dialect.version, inst, "FMU state")?;
        check_kind(&self.run, inst)?;
        inst.check_clocks(&self.clocks)?;
        inst.model = self.model.clone_box();
        inst.run = self.run;
        inst.clocks = self.clocks.clone();
        Ok(())
    }

    /// Hands a snapshot of instance `owner` to the master as a new token.
    pub fn into_handle(self, owner: usize) -> CallResult<usize> {
        let t = SERIALS.token().map_err(Fail::error)?;
        live().insert(t, (Box::into_raw(Box::new(self)), owner));
        Ok(t)
    }

    /// Runs `f` on the snapshot behind a handle, if the handle is one we issued and have not freed,
    /// with the table locked for the whole access.
    pub fn with_handle<T>(t: usize, f: impl FnOnce(&mut Snapshot) -> CallResult<T>) -> CallResult<T> {
        if t == 0 {
            return Err(Fail::error("FMUstate is NULL"));
        }
        let table = live();
        let Some(&(p, _)) = table.get(&t) else {
            return Err(Fail::error(format!(
                "FMUstate {t:#x} was not created by this FMU or was already freed"
            )));
        };
        // SAFETY: the token is in the table, so p came from Box::into_raw and is not freed; the
        // lock held until the end of this function keeps every other thread away from it.
        let r = f(unsafe { &mut *p });
        drop(table);
        r
    }

    /// Frees a handle we issued; unknown handles are refused.
    pub fn free_handle(t: usize) -> CallResult {
        let mut table = live();
        let Some((p, _)) = table.remove(&t) else {
            return Err(Fail::error(format!(
                "FMUstate {t:#x} was not created by this FMU or was already freed"
            )));
        };
        release_if_empty(&mut table);
        // SAFETY: it was in the table, so it is a Box we leaked and nobody else frees it.
        drop(unsafe { Box::from_raw(p) });
        Ok(())
    }

    /// Frees every snapshot created by the given instance (called when the instance is freed).
    pub fn free_all_of(owner: usize) {
        let mut table = live();
        let mine: Vec<usize> = table
            .iter()
            .filter(|(_, (_, o))| *o == owner)
            .map(|(t, _)| *t)
            .collect();
        for t in mine {
            if let Some((p, _)) = table.remove(&t) {
                // SAFETY: removed from the table just now; it was a leaked Box.
                drop(unsafe { Box::from_raw(p) });
            }
        }
        release_if_empty(&mut table);
    }

    pub fn to_bytes(&self, guid: &str) -> CallResult<Vec<u8>> {
        let payload = Payload {
            model_name: self.model_name.to_string(),
            interface: self.dialect.version.to_string(),
            guid: guid.to_string(),
            run: self.run,
            model: self
                .model
                .to_bytes()
                .map_err(|e| Fail::error(format!("cannot encode model state: {e}")))?,
            clocks: self.clocks.clone(),
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

    /// Decodes bytes written by `to_bytes` for the instance's model; anything else is refused, and the
    /// decoded state is validated like parameters at initialization (see `Fmu::validate`).
    pub fn from_bytes(bytes: &[u8], inst: &Instance, guid: &str) -> CallResult<Snapshot> {
        if bytes.len() < HEADER + TRAILER {
            return Err(Fail::error(format!(
                "serialized state has {} bytes, too short to be one of ours",
                bytes.len()
            )));
        }
        if &bytes[..8] != MAGIC {
            return Err(Fail::error(
                "serialized state does not start with this library's magic bytes",
            ));
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != FORMAT_VERSION {
            return Err(Fail::error(format!(
                "serialized state has format version {version}, expected {FORMAT_VERSION}"
            )));
        }
        let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
        if HEADER + len + TRAILER != bytes.len() {
            return Err(Fail::error(format!(
                "serialized state length {} does not match its header ({})",
                bytes.len(),
                HEADER + len + TRAILER
            )));
        }
        let crc = u32::from_le_bytes(bytes[HEADER + len..].try_into().expect("4 bytes"));
        if crc32fast::hash(&bytes[..HEADER + len]) != crc {
            return Err(Fail::error("serialized state is corrupted (CRC-32 mismatch)"));
        }
        let (p, rest): (Payload, &[u8]) = postcard::take_from_bytes(&bytes[HEADER..HEADER + len])
            .map_err(|e| Fail::error(format!("serialized state does not decode: {e}")))?;
        if !rest.is_empty() {
            return Err(Fail::error(format!(
                "serialized state has {} trailing bytes after its payload",
                rest.len()
            )));
        }
        if p.model_name != inst.entry.info.name {
            return Err(Fail::error(format!(
                "serialized state belongs to {}, not to {}",
                p.model_name, inst.entry.info.name
            )));
        }
        check_version(&p.interface, inst, "serialized state")?;
        if p.guid != guid {
            return Err(Fail::error(format!(
                "serialized state was written by a different version of {} (GUID {})",
                p.model_name, p.guid
            )));
        }
        let mut model = inst.model.clone_box();
        model.load_bytes(&p.model).map_err(Fail::error)?;
        p.run
            .validate()
            .map_err(|e| Fail::error(format!("serialized state is invalid: {e}")))?;
        check_kind(&p.run, inst)?;
        if !model.is_initialized() && !matches!(p.run.fsm, FsmState::Instantiated | FsmState::InitializationMode) {
            return Err(Fail::error(format!(
                "serialized state is invalid: state machine state {:?} without applied parameters",
                p.run.fsm
            )));
        }
        model
            .validate(&p.run.exp)
            .map_err(|e| Fail::error(format!("serialized state is invalid: {e}")))?;
        inst.check_clocks(&p.clocks)?;
        Ok(Snapshot {
            model_name: inst.entry.info.name,
            dialect: inst.dialect,
            run: p.run,
            model,
            clocks: p.clocks,
            serialized: None,
        })
    }
}
