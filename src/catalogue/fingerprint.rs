//! The GUID of a model: a name-based UUID (v5) of its declarations — name, flags, default
//! experiment, feed-through, every variable with its unit definition and bounds, the continuous states
//! and the FMI 3.0 clocks — and the package version. It changes exactly when the interface (or the release) changes. The runtime computes it
//! from the static declarations (`crate::model::guid`, at `fmi2Instantiate` and for FMU states) and
//! the packaging tool from a catalogue's owned copy ([`guid_of`]); both go through [`fingerprint`],
//! over borrowed rows, so the two cannot disagree.

use std::fmt::Write;

use super::decl::{Causality, Start, VarKind, Variability};
use super::library::{FeedthroughDescription, ModelDescription};

/// Namespace of the project's name-based GUIDs (a fixed random UUID).
const GUID_NAMESPACE: uuid::Uuid = uuid::Uuid::from_u128(0x6f1d_2b7e_3c4a_4e55_9a61_0d2f_8c3b_71a4);

/// Length of "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}".
pub const GUID_LEN: usize = 38;

/// The header fields that enter the GUID; `feedthrough` is "none", "all" or the Debug text of the list.
pub struct Header<'a> {
    pub name: &'a str,
    pub description: &'a str,
    pub variable_step: bool,
    pub default_stop_time: f64,
    pub default_step: f64,
    pub feedthrough: String,
}

/// One variable as it enters the GUID.
pub struct VarRow<'a> {
    pub vr: u32,
    pub name: &'a str,
    pub kind: VarKind,
    pub causality: Causality,
    pub variability: Variability,
    pub unit: &'a str,
    pub description: &'a str,
    pub min_max: (Option<f64>, Option<f64>),
    pub start: Start,
}

/// One continuous state as it enters the GUID.
pub struct StateRow<'a> {
    pub name: &'a str,
    pub unit: &'a str,
    pub description: &'a str,
    pub depends: Option<Vec<&'a str>>,
    pub starts_from: Vec<&'a str>,
}

/// One FMI 3.0 clock as it enters the GUID (`outputs`: FMI scalar names, as the catalogue carries them).
pub struct ClockRow<'a> {
    pub name: &'a str,
    pub description: &'a str,
    pub interval: &'a str,
    pub shift: &'a str,
    pub steps: bool,
    pub outputs: Vec<&'a str>,
}

/// The canonical text the GUID is computed from.
pub fn fingerprint<'a>(
    h: Header<'_>,
    vars: impl Iterator<Item = VarRow<'a>>,
    states: Option<Vec<StateRow<'_>>>,
    clocks: &[ClockRow<'_>],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "spacecraft_fmus {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(
        s,
        "{}|{}|{}|{:?}|{:?}|{:?}",
        h.name, h.description, h.variable_step, h.default_stop_time, h.default_step, h.feedthrough
    );
    for d in vars {
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
            d.vr, d.name, d.kind, d.causality, d.variability, d.unit, unit, d.description, d.min_max, start
        );
    }
    // Model Exchange models only, so that a Co-Simulation-only model keeps its GUID.
    if let Some(states) = states {
        let _ = writeln!(s, "model exchange: {} states", states.len());
        for x in states {
            let _ = writeln!(
                s,
                "state|{}|{}|{}|{:?}|{:?}",
                x.name, x.unit, x.description, x.depends, x.starts_from
            );
        }
    }
    // clocked models only, so that a model without clocks keeps its GUID
    for c in clocks {
        let _ = writeln!(
            s,
            "clock|{}|{}|{}|{}|{}|{:?}",
            c.name, c.description, c.interval, c.shift, c.steps, c.outputs
        );
    }
    s
}

/// "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}" of a fingerprint, as bytes (no heap).
pub fn guid_bytes(fingerprint: &str) -> [u8; GUID_LEN] {
    let uuid = uuid::Uuid::new_v5(&GUID_NAMESPACE, fingerprint.as_bytes());
    let mut out = [0u8; GUID_LEN];
    out[0] = b'{';
    uuid.hyphenated().encode_lower(&mut out[1..GUID_LEN - 1]);
    out[GUID_LEN - 1] = b'}';
    out
}

/// The GUID computed afresh from a catalogue's description (its own `guid` field is not read): the
/// packaging tool's check that a library and the tool come from the same `spacecraft_fmus`.
pub fn guid_of(m: &ModelDescription) -> String {
    let feedthrough = match &m.feedthrough {
        FeedthroughDescription::None => "none".into(),
        FeedthroughDescription::AllInputs => "all".into(),
        FeedthroughDescription::Some(list) => format!("{list:?}"),
    };
    let header = Header {
        name: &m.name,
        description: &m.description,
        variable_step: m.variable_step,
        default_stop_time: m.default_stop_time,
        default_step: m.default_step,
        feedthrough,
    };
    let vars = m.variables.iter().map(|d| VarRow {
        vr: d.vr,
        name: &d.name,
        kind: d.kind,
        causality: d.causality,
        variability: d.variability,
        unit: &d.unit,
        description: &d.description,
        min_max: d.bound.min_max(),
        start: d.start,
    });
    let states = m.states.as_ref().map(|l| {
        l.iter()
            .map(|x| StateRow {
                name: &x.name,
                unit: &x.unit,
                description: &x.description,
                depends: x.depends.as_ref().map(|d| d.iter().map(String::as_str).collect()),
                starts_from: x.starts_from.iter().map(String::as_str).collect(),
            })
            .collect()
    });
    let clocks: Vec<ClockRow> = m
        .clocks
        .iter()
        .map(|c| ClockRow {
            name: &c.name,
            description: &c.description,
            interval: &c.interval,
            shift: &c.shift,
            steps: c.steps,
            outputs: c.outputs.iter().map(String::as_str).collect(),
        })
        .collect();
    let bytes = guid_bytes(&fingerprint(header, vars, states, &clocks));
    String::from_utf8(bytes.to_vec()).expect("hyphenated UUID is ASCII")
}
