//! The GUID of a model: a name-based UUID (v5) of its declarations — name, flags, default
//! experiment, feed-through, every variable with its unit definition and bounds — and the package
//! version. It changes exactly when the interface (or the release) changes. Both the runtime
//! (`fmi2Instantiate`, FMU-state payloads) and the packaging tool (through the catalogue a binary
//! exports, `crate::export`) use it; nothing here renders XML.

use std::fmt::Write;

use super::{Feedthrough, ModelEntry, Start};

/// Namespace of the project's name-based GUIDs (a fixed random UUID).
const GUID_NAMESPACE: uuid::Uuid = uuid::Uuid::from_u128(0x6f1d_2b7e_3c4a_4e55_9a61_0d2f_8c3b_71a4);

/// Length of "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}".
const GUID_LEN: usize = 38;

/// The canonical text the GUID is computed from.
fn fingerprint(entry: &ModelEntry) -> String {
    let info = entry.info;
    let mut s = String::new();
    let _ = writeln!(s, "spacecraft_fmus {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(
        s,
        "{}|{}|{}|{:?}|{:?}|{:?}",
        info.name,
        info.description,
        info.variable_step,
        info.default_stop_time,
        info.default_step,
        feedthrough_text(entry)
    );
    for d in entry.decls {
        let start = match d.start {
            Start::Real(x) => format!("{x:?}"),
            Start::Integer(x) => x.to_string(),
            Start::Boolean(x) => x.to_string(),
        };
        let unit = crate::units::lookup(d.unit)
            .map(|(_, b, disp)| format!("{b:?}{disp:?}"))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "{}|{}|{:?}|{:?}|{:?}|{}|{}|{}|{:?}|{}",
            d.vr,
            d.name,
            d.kind,
            d.causality,
            d.variability,
            d.unit,
            unit,
            d.description,
            d.bound.min_max(),
            start
        );
    }
    // Model Exchange models only, so that a Co-Simulation-only model keeps its GUID.
    if let Some(states) = entry.states {
        let _ = writeln!(s, "model exchange: {} states", states.len());
        for x in states {
            let _ = writeln!(
                s,
                "state|{}|{}|{}|{:?}|{:?}",
                x.name, x.unit, x.description, x.depends, x.starts_from
            );
        }
    }
    s
}

/// The feed-through list with FMI scalar names (a vector stem expanded, so the GUID does not depend on
/// how the list was written).
fn feedthrough_text(entry: &ModelEntry) -> String {
    match entry.info.feedthrough {
        Feedthrough::None => "none".into(),
        Feedthrough::AllInputs => "all".into(),
        Feedthrough::Some(_) => format!("{:?}", super::feedthrough::scalar_list(entry).unwrap_or_default()),
    }
}

/// The GUID computed afresh (uncached), e.g. to check one read from a catalogue.
pub fn compute_fresh(entry: &ModelEntry) -> String {
    String::from_utf8(compute(entry).to_vec()).expect("hyphenated UUID is ASCII")
}

fn compute(entry: &ModelEntry) -> [u8; GUID_LEN] {
    let uuid = uuid::Uuid::new_v5(&GUID_NAMESPACE, fingerprint(entry).as_bytes());
    let mut out = [0u8; GUID_LEN];
    out[0] = b'{';
    uuid.hyphenated().encode_lower(&mut out[1..GUID_LEN - 1]);
    out[GUID_LEN - 1] = b'}';
    out
}

/// A GUID as text, "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}", held inline (no heap).
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Guid([u8; GUID_LEN]);

impl Guid {
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.0).expect("hyphenated UUID is ASCII")
    }
}

impl std::ops::Deref for Guid {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl std::fmt::Display for Guid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Debug for Guid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// GUID of a model, computed when asked (a few microseconds, at fmi2Instantiate and when a state is
/// serialized). Nothing is cached: a library whose last instance is freed holds no heap memory, so a
/// master that loads and unloads it per run does not grow.
pub fn guid(entry: &ModelEntry) -> Guid {
    Guid(compute(entry))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guids_are_distinct_stable_and_braced() {
        let all = crate::registry::ALL;
        for (i, a) in all.iter().enumerate() {
            let g = guid(a);
            assert_eq!(g.as_bytes(), &compute(a)[..]);
            assert_eq!(g.as_str(), compute_fresh(a));
            assert!(g.starts_with('{') && g.ends_with('}') && g.len() == GUID_LEN);
            for b in &all[i + 1..] {
                assert_ne!(g, guid(b));
            }
        }
    }
}
