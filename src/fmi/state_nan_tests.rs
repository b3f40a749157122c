//! Issue 45, item 3: no non-finite value survives a restore. For every FMU of the registry, after some
//! steps, a NaN (and, for every tenth field, +Inf and -Inf) is written into every f64 of its serialized
//! state — the model's variable block and internal state and the run (time, experiment, time of the last
//! event) — with the CRC-32 recomputed; `Snapshot::from_bytes` (the body of both rooms' deserialize
//! call) must refuse each with a message naming the field. The byte offsets come from
//! the serialized form's field walk (`model::leaves`) and are checked against the bytes themselves (the
//! 8 bytes at each offset must be that field's value) before anything is written.
//! Also item 4: a state taken through one interface is refused by the other (two dialects of its own
//! stand for the rooms' here).

use std::ffi::CString;

use super::instance::{Instance, Logger};
use super::state::Snapshot;
use super::types::{Arg, Dialect, FsmState};
use crate::model::guid::guid;
use crate::model::leaves::{Leaf, Leaves};
use crate::registry;

const fn dialect(version: &'static str) -> Dialect {
    fn argument(_: Arg) -> &'static str {
        "states[]"
    }
    fn state_name(_: FsmState) -> &'static str {
        "some state"
    }
    Dialect {
        version,
        token_argument: "token",
        setup_experiment: "setup",
        set_continuous_states: "set states",
        argument,
        state_name,
    }
}

static OLD: Dialect = dialect("OLD 1.0");
static NEW: Dialect = dialect("NEW 1.0");

fn instance(entry: &'static crate::model::ModelEntry, new: bool) -> Instance {
    let d = if new { &NEW } else { &OLD };
    Instance::new(
        CString::new("nan").unwrap(),
        entry,
        d,
        Logger::None,
        std::ptr::null_mut(),
        false,
    )
}

/// An initialized instance after 20 steps at the model's default step.
fn stepped(entry: &'static crate::model::ModelEntry, new: bool) -> Instance {
    let mut inst = instance(entry, new);
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode()
        .unwrap_or_else(|f| panic!("{}: {:?}", entry.info.name, f.reason));
    let h = entry.info.default_step;
    for k in 0..20 {
        inst.do_step(k as f64 * h, h)
            .unwrap_or_else(|f| panic!("{}: {:?}", entry.info.name, f.reason));
    }
    inst
}

/// Where `needle` starts in `hay` (it must occur exactly once).
fn find_once(hay: &[u8], needle: &[u8]) -> usize {
    let hits: Vec<usize> = hay
        .windows(needle.len())
        .enumerate()
        .filter(|(_, w)| *w == needle)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(hits.len(), 1, "a serialized part occurs {} times", hits.len());
    hits[0]
}

fn fix_crc(b: &mut [u8]) {
    let n = b.len();
    let crc = crc32fast::hash(&b[..n - 4]);
    b[n - 4..].copy_from_slice(&crc.to_le_bytes());
}

/// The last named segment of a field path (nalgebra stores vectors under `data`, quaternions under
/// `coords`: the field is the one that holds them).
fn field_name(path: &str) -> String {
    let inner = path
        .strip_prefix("v.")
        .or_else(|| path.strip_prefix("state."))
        .unwrap_or(path);
    let named: Vec<&str> = inner.split('.').filter(|s| !matches!(*s, "data" | "coords")).collect();
    named.last().copied().unwrap_or(inner).to_string()
}

/// (name the message must contain, absolute byte offset) of every f64 of a serialized state.
fn float_fields(inst: &Instance, bytes: &[u8]) -> Vec<(String, usize, u64)> {
    let model_bytes = inst.model.to_bytes().unwrap();
    let m0 = find_once(bytes, &model_bytes);
    // the message names the field by its path inside the state, or by its FMI name
    let mut out: Vec<(String, usize, u64)> = inst
        .model
        .float_leaves()
        .into_iter()
        .map(|(path, off, bits)| (field_name(&path), m0 + off, bits))
        .collect();
    let run = postcard::to_stdvec(&inst.run).unwrap();
    let r0 = find_once(&bytes[..m0], &run);
    let l = Leaves::of(&inst.run).unwrap();
    for ((p, leaf), off) in l.leaves.iter().zip(&l.offsets) {
        if let Leaf::F64(bits) = leaf {
            out.push((field_name(l.path(*p)), r0 + off, *bits));
        }
    }
    out
}

#[test]
fn a_non_finite_value_in_any_f64_of_any_state_is_refused_with_its_name() {
    let (mut fields, mut models) = (0, 0);
    for entry in registry::ALL {
        let name = entry.info.name;
        let inst = stepped(entry, false);
        let g = guid(entry);
        let bytes = Snapshot::capture(&inst).to_bytes(&g).unwrap();
        // the unchanged state is accepted (no model keeps a non-finite value of its own)
        Snapshot::from_bytes(&bytes, &inst, &g)
            .unwrap_or_else(|f| panic!("{name}: unchanged state refused: {:?}", f.reason));
        let found = float_fields(&inst, &bytes);
        assert!(!found.is_empty(), "{name}: no f64 found in its state");
        for (i, (field, off, bits)) in found.iter().enumerate() {
            // the walk's offset is right: the 8 bytes there are this field's value
            let here = u64::from_le_bytes(bytes[*off..off + 8].try_into().unwrap());
            assert_eq!(here, *bits, "{name}: byte {off} does not hold {field}");
            let bad: &[f64] = if i % 10 == 0 {
                &[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]
            } else {
                &[f64::NAN]
            };
            for x in bad {
                let mut b = bytes.clone();
                b[*off..off + 8].copy_from_slice(&x.to_le_bytes());
                fix_crc(&mut b);
                let e = match Snapshot::from_bytes(&b, &inst, &g) {
                    Ok(_) => panic!("{name}: {x} in {field} (byte {off}) is accepted"),
                    Err(f) => f.reason.render(&OLD),
                };
                assert!(
                    e.contains(field.as_str()) && (e.contains("NaN") || e.contains("inf")),
                    "{name}: {x} in {field}: {e}"
                );
            }
            fields += 1;
        }
        models += 1;
    }
    println!("{models} models, {fields} f64 fields: NaN in each refused with its name");
    assert_eq!(models, registry::COUNT);
}

/// Item 4: an FMU state belongs to the interface of the instance that took it; the other interface's
/// set and deserialize refuse it, naming both (and the same interface accepts it).
#[test]
fn a_state_is_refused_by_the_other_interface() {
    let entry = registry::find("PidController").unwrap();
    for (from_new, to_new) in [(false, true), (true, false)] {
        let src = stepped(entry, from_new);
        let mut dst = stepped(entry, to_new);
        let snap = Snapshot::capture(&src);
        let e = snap.restore_into(&mut dst).unwrap_err().reason.render(dst.dialect);
        let (taken, runs) = if from_new { ("NEW", "OLD") } else { ("OLD", "NEW") };
        let want = format!("FMU state was taken by an {taken} 1.0 instance; this instance runs {runs} 1.0");
        assert!(e.contains(&want), "{e}");
        let bytes = snap.to_bytes(&guid(entry)).unwrap();
        let e = Snapshot::from_bytes(&bytes, &dst, &guid(entry))
            .err()
            .unwrap()
            .reason
            .render(dst.dialect);
        assert!(e.contains("serialized state was taken by an"), "{e}");
        let mut same = stepped(entry, from_new);
        assert!(snap.restore_into(&mut same).is_ok());
        assert!(Snapshot::from_bytes(&bytes, &same, &guid(entry)).is_ok());
        assert_eq!(same.run, src.run);
    }
}
