//! The GUID of a model: a name-based UUID (v5) of its declarations — name, flags, default
//! experiment, feed-through, every variable with its unit definition and bounds — and the package
//! version. It changes exactly when the interface (or the release) changes. Both the runtime
//! (`fmi2Instantiate`, FMU-state payloads) and the modelDescription writer use it; nothing here renders XML.

use std::fmt::Write;
use std::sync::OnceLock;

use super::{Feedthrough, ModelEntry, Start};
use crate::registry;

/// Namespace of the project's name-based GUIDs (a fixed random UUID).
const GUID_NAMESPACE: uuid::Uuid = uuid::Uuid::from_u128(0x6f1d_2b7e_3c4a_4e55_9a61_0d2f_8c3b_71a4);

/// Length of "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}".
const GUID_LEN: usize = 38;

/// The canonical text the GUID is computed from.
fn fingerprint(entry: &ModelEntry) -> String {
    let info = entry.info;
    let mut s = String::new();
    let _ = writeln!(s, "spacecraft_fmus {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(s, "{}|{}|{}|{:?}|{:?}|{:?}", info.name, info.description, info.variable_step, info.default_stop_time, info.default_step, info.feedthrough_text());
    for d in entry.decls {
        let start = match d.start {
            Start::Real(x) => format!("{x:?}"),
            Start::Integer(x) => x.to_string(),
            Start::Boolean(x) => x.to_string(),
        };
        let unit = crate::units::lookup(d.unit).map(|(_, b, disp)| format!("{b:?}{disp:?}")).unwrap_or_default();
        let _ = writeln!(
            s,
            "{}|{}|{:?}|{:?}|{:?}|{}|{}|{}|{:?}|{}",
            d.vr, d.name, d.kind, d.causality, d.variability, d.unit, unit, d.description, d.bound.min_max(), start
        );
    }
    s
}

impl super::ModelInfo {
    fn feedthrough_text(&self) -> String {
        match self.feedthrough {
            Feedthrough::None => "none".into(),
            Feedthrough::AllInputs => "all".into(),
            Feedthrough::Some(list) => format!("{list:?}"),
        }
    }
}

fn compute(entry: &ModelEntry) -> [u8; GUID_LEN] {
    let uuid = uuid::Uuid::new_v5(&GUID_NAMESPACE, fingerprint(entry).as_bytes());
    let mut out = [0u8; GUID_LEN];
    out[0] = b'{';
    uuid.hyphenated().encode_lower(&mut out[1..GUID_LEN - 1]);
    out[GUID_LEN - 1] = b'}';
    out
}

/// GUID of a registered model, computed once per process (kept in fixed-size static storage, no heap).
pub fn guid(entry: &ModelEntry) -> &'static str {
    static CACHE: OnceLock<[[u8; GUID_LEN]; registry::COUNT]> = OnceLock::new();
    let cache = CACHE.get_or_init(|| std::array::from_fn(|i| compute(&registry::ALL[i])));
    let i = registry::ALL.iter().position(|e| e.info.name == entry.info.name).expect("model is registered");
    std::str::from_utf8(&cache[i]).expect("hyphenated UUID is ASCII")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guids_are_distinct_stable_and_braced() {
        let all = registry::ALL;
        for (i, a) in all.iter().enumerate() {
            let g = guid(a);
            assert_eq!(g.as_bytes(), &compute(a)[..]);
            assert!(g.starts_with('{') && g.ends_with('}') && g.len() == GUID_LEN);
            for b in &all[i + 1..] {
                assert_ne!(g, guid(b));
            }
        }
    }
}
