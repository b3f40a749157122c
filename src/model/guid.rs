//! The GUID of a registered model, for the runtime (`fmi2Instantiate`, FMU-state payloads): the
//! fingerprint of `crate::catalogue::fingerprint` over the static declarations (the packaging tool
//! computes the same from a catalogue's owned copy). Nothing here renders XML.

use super::{Feedthrough, ModelEntry};
use crate::catalogue::fingerprint::{fingerprint, guid_bytes, ClockRow, Header, StateRow, VarRow, GUID_LEN};

/// The fingerprint rows of a registry entry (borrowed: no copy of a string, except the scalar names of
/// a clock's outputs, which the catalogue carries expanded).
fn compute(entry: &ModelEntry) -> [u8; GUID_LEN] {
    let info = entry.info;
    let header = Header {
        name: info.name,
        description: info.description,
        variable_step: info.variable_step,
        default_stop_time: info.default_stop_time,
        default_step: info.default_step,
        feedthrough: match info.feedthrough {
            Feedthrough::None => "none".into(),
            Feedthrough::AllInputs => "all".into(),
            // FMI scalar names (a vector stem expanded), as the catalogue carries them
            Feedthrough::Some(_) => format!("{:?}", super::scalar_list(entry).unwrap_or_default()),
        },
    };
    let vars = entry.decls.iter().map(|d| VarRow {
        vr: d.vr,
        name: d.name,
        kind: d.kind,
        causality: d.causality,
        variability: d.variability,
        unit: d.unit,
        description: d.description,
        min_max: d.bound.min_max(),
        start: d.start,
    });
    let states = entry.states.map(|l| {
        l.iter()
            .map(|x| StateRow {
                name: x.name,
                unit: x.unit,
                description: x.description,
                depends: x.depends.map(|d| d.to_vec()),
                starts_from: x.starts_from.to_vec(),
            })
            .collect()
    });
    let outputs: Vec<Vec<String>> = entry.clocks.iter().map(|c| super::clocked_outputs(entry, c)).collect();
    let clocks: Vec<ClockRow> = entry
        .clocks
        .iter()
        .zip(&outputs)
        .map(|(c, o)| ClockRow {
            name: c.name,
            description: c.description,
            interval: c.interval,
            shift: c.shift,
            steps: c.steps,
            outputs: o.iter().map(String::as_str).collect(),
        })
        .collect();
    guid_bytes(&fingerprint(header, vars, states, &clocks))
}

/// The GUID computed afresh (uncached).
pub fn compute_fresh(entry: &ModelEntry) -> String {
    String::from_utf8(compute(entry).to_vec()).expect("hyphenated UUID is ASCII")
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
