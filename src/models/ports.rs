//! Shared port blocks: the ports every unit of a kind has, declared once and embedded by name in each
//! unit's declaration (`ports: AttitudeControllerPorts;`), so that units of a kind swap as black boxes.
//! Public (re-exported by `crate::export`): a model crate's controller embeds the same block and then
//! plugs into the project's `AttitudePlant` and `AttitudeCommand` like the project's own controllers.
//!
//! - [`AttitudeControllerPorts`]: three-axis attitude controllers (measured and commanded attitude and
//!   rate in, torque command out), with [`check_unit_quaternions`].

use crate::catalogue::{Causality, TerminalDescription, VarDecl};
use crate::declare_variables;

declare_variables! {
    /// Common controller ports: measured and commanded attitude in, commanded torque out
    /// (value references 0–13 inputs, 20–22 outputs).
    pub struct AttitudeControllerPorts {
        0 => q: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Measured attitude quaternion of B relative to R";
        4 => w: Vec3 = [0.0; 3], Input, "rad/s", "Measured body rate";
        7 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Commanded attitude quaternion";
        11 => w_ref: Vec3 = [0.0; 3], Input, "rad/s", "Commanded body rate";
        20 => torque_cmd: Vec3 = [0.0; 3], Output, "N.m", "Commanded control torque, body axes";
    }
}

declare_variables! {
    /// The attitude estimate in (the Mekf's outputs), value references 0–6.
    pub struct EstimateInputs {
        0 => q_est: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Estimated attitude quaternion (the Mekf's q_est; normalised here)";
        4 => w_est: Vec3 = [0.0; 3], Input, "rad/s", "Estimated body rate (the Mekf's w_est)";
    }
}

declare_variables! {
    /// The commanded attitude in (the AttitudeCommand's outputs), value references 7–13.
    pub struct CommandInputs {
        7 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Commanded attitude quaternion (the AttitudeCommand's q_ref; normalised here)";
        11 => w_ref: Vec3 = [0.0; 3], Input, "rad/s", "Commanded body rate, commanded body axes (the AttitudeCommand's w_ref)";
    }
}

/// Rejects a measured or commanded quaternion that is far from unit norm (wrong wiring, e.g. a
/// quaternion port left unconnected at 0).
pub fn check_unit_quaternions(p: &AttitudeControllerPorts) -> Result<(), String> {
    for (name, q) in [("q", p.q), ("q_ref", p.q_ref)] {
        let n = q.norm();
        if (n - 1.0).abs() > 1e-3 {
            return Err(format!(
                "input quaternion {name} has norm {n}, expected 1 (is it connected?)"
            ));
        }
    }
    Ok(())
}

/// The groups of ports that connect together as one FMI 3.0 terminal, wherever a model has every listed
/// port with one causality: (terminal name, description, members as (member name, port stem)). The
/// member names are the ones another terminal of the same kind must have (`plug` matching), whatever
/// the ports are called: the plant's `q`, `w` and the Mekf's `q_est`, `w_est` are both `q_*`, `w_*`.
/// One group: (terminal name, description, members as (member name, port stem)).
pub type TerminalGroup = (&'static str, &'static str, &'static [(&'static str, &'static str)]);

pub const TERMINAL_GROUPS: &[TerminalGroup] = &[
    (
        "attitude",
        "Attitude quaternion and body rate",
        &[("q", "q"), ("w", "w")],
    ),
    (
        "attitude_ref",
        "Commanded attitude quaternion and body rate",
        &[("q", "q_ref"), ("w", "w_ref")],
    ),
    (
        "attitude_est",
        "Estimated attitude quaternion and body rate",
        &[("q", "q_est"), ("w", "w_est")],
    ),
];

/// `terminalKind` of [`TERMINAL_GROUPS`] (vendor-specific kinds start with `_scfmu_`, as FMI 3.0 asks).
pub const ATTITUDE_STATE_KIND: &str = "_scfmu_AttitudeState";

/// The meaning of a three-component port by its unit: the `terminalKind` of its own terminal.
const VECTOR_MEANINGS: &[(&str, &str)] = &[
    ("rad/s", "_scfmu_AngularVelocity"),
    ("rad/s2", "_scfmu_AngularAcceleration"),
    ("N.m", "_scfmu_Torque"),
    ("N.m.s", "_scfmu_AngularMomentum"),
    ("A.m2", "_scfmu_MagneticDipole"),
    ("T", "_scfmu_MagneticFluxDensity"),
    ("m", "_scfmu_Position"),
    ("m/s", "_scfmu_Velocity"),
    ("m/s2", "_scfmu_Acceleration"),
    ("N", "_scfmu_Force"),
];

/// The kind of a four-component port (every one is a scalar-first attitude quaternion).
pub const QUATERNION_KIND: &str = "_scfmu_AttitudeQuaternion";
/// The kind of a dimensionless direction whose stem names the sun (`sun_eci`, `sun_meas`, `sun_ref`).
pub const SUN_DIRECTION_KIND: &str = "_scfmu_SunDirection";
/// The kind of any other three-component port (its unit, compared on connection, says the rest).
pub const VECTOR_KIND: &str = "_scfmu_Vector3";
/// The kind of numbered channels `u_1 … u_n` (matched by position: `sequence`).
pub const CHANNELS_KIND: &str = "_scfmu_Channels";

/// One vector port of a declaration table: its stem, the component suffixes and its variables.
struct VectorPort<'a> {
    stem: &'a str,
    decls: Vec<&'a VarDecl>,
    suffixes: Vec<&'a str>,
}

/// The vector ports (inputs and outputs) of a table: `<stem>_w/_x/_y/_z` (a quaternion), `<stem>_x/_y/_z`
/// and numbered channels `<stem>_1 … <stem>_n` (n ≥ 2), each a run of consecutive declarations of one
/// causality and unit.
fn vector_ports(decls: &[VarDecl]) -> Vec<VectorPort<'_>> {
    let split = |d: &VarDecl| d.name.rsplit_once('_');
    let is_port = |d: &VarDecl| matches!(d.causality, Causality::Input | Causality::Output);
    let mut out = vec![];
    let mut i = 0;
    while i < decls.len() {
        let first = &decls[i];
        let Some((stem, suffix)) = split(first).filter(|_| is_port(first)) else {
            i += 1;
            continue;
        };
        let same = |d: &VarDecl, want: &str| {
            split(d) == Some((stem, want)) && d.causality == first.causality && d.unit == first.unit
        };
        let pattern: Vec<String> = match suffix {
            "w" => ["w", "x", "y", "z"].map(String::from).to_vec(),
            "x" => ["x", "y", "z"].map(String::from).to_vec(),
            "1" => (1..)
                .map(|k: usize| k.to_string())
                .take_while(|k| {
                    decls
                        .get(i + k.parse::<usize>().unwrap() - 1)
                        .is_some_and(|d| same(d, k))
                })
                .collect(),
            _ => vec![],
        };
        let n = pattern.len();
        if n >= 2 && decls.len() >= i + n && decls[i..i + n].iter().zip(&pattern).all(|(d, k)| same(d, k)) {
            out.push(VectorPort {
                stem,
                decls: decls[i..i + n].iter().collect(),
                suffixes: decls[i..i + n].iter().map(|d| split(d).unwrap().1).collect(),
            });
            i += n;
        } else {
            i += 1;
        }
    }
    out
}

/// The FMI 3.0 terminals of a model, from its declaration table alone: first each group of
/// [`TERMINAL_GROUPS`] the model has (member names `q_w` … `w_z`), then one terminal per vector port,
/// named after its stem, with the port's meaning as its kind and the component suffixes as member names
/// (`plug`; numbered channels: `sequence`). Every vector input and output belongs to a terminal.
pub fn terminals(decls: &[VarDecl]) -> Vec<TerminalDescription> {
    let ports = vector_ports(decls);
    let port = |stem: &str| ports.iter().find(|p| p.stem == stem);
    let member = |m: &str, v: &str| (m.to_string(), v.to_string());
    let mut out = vec![];
    for (name, description, members) in TERMINAL_GROUPS {
        let found: Vec<&VectorPort> = members.iter().filter_map(|(_, s)| port(s)).collect();
        if found.len() != members.len()
            || found
                .iter()
                .any(|p| p.decls[0].causality != found[0].decls[0].causality)
        {
            continue;
        }
        out.push(TerminalDescription {
            name: name.to_string(),
            kind: ATTITUDE_STATE_KIND.into(),
            matching_rule: "plug".into(),
            description: description.to_string(),
            members: members
                .iter()
                .zip(&found)
                .flat_map(|((m, _), p)| {
                    p.decls
                        .iter()
                        .zip(&p.suffixes)
                        .map(move |(d, x)| member(&format!("{m}_{x}"), d.name))
                })
                .collect(),
        });
    }
    for p in &ports {
        let d = p.decls[0];
        let kind = match (p.suffixes[0], d.unit) {
            ("w", _) => QUATERNION_KIND,
            ("1", _) => CHANNELS_KIND,
            (_, "") if p.stem.contains("sun") => SUN_DIRECTION_KIND,
            (_, unit) => VECTOR_MEANINGS
                .iter()
                .find(|(u, _)| *u == unit)
                .map_or(VECTOR_KIND, |(_, k)| *k),
        };
        // the port's description, without the component ("…, x", "…, scalar part")
        let description = d.description.rsplit_once(", ").map_or(d.description, |(head, _)| head);
        out.push(TerminalDescription {
            name: p.stem.to_string(),
            kind: kind.into(),
            matching_rule: if kind == CHANNELS_KIND { "sequence" } else { "plug" }.into(),
            description: description.to_string(),
            members: p
                .decls
                .iter()
                .zip(&p.suffixes)
                .map(|(d, x)| member(x, d.name))
                .collect(),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vector_port_of_every_model_is_in_a_terminal_of_its_meaning() {
        for e in crate::registry::ALL {
            let t = terminals(e.decls);
            let mut names: Vec<&str> = t.iter().map(|x| x.name.as_str()).collect();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), t.len(), "{}: terminal names are unique", e.info.name);
            for d in e
                .decls
                .iter()
                .filter(|d| matches!(d.causality, Causality::Input | Causality::Output))
            {
                let comp = d.name.rsplit_once('_').map(|(_, x)| x);
                if matches!(comp, Some("x" | "y" | "z" | "w")) {
                    assert!(
                        t.iter().any(|x| x.members.iter().any(|(_, v)| v == d.name)),
                        "{}.{} is in no terminal",
                        e.info.name,
                        d.name
                    );
                }
            }
        }
        let plant = terminals(crate::registry::find("AttitudePlant").unwrap().decls);
        let att = &plant[0];
        assert_eq!(
            (att.name.as_str(), att.kind.as_str()),
            ("attitude", ATTITUDE_STATE_KIND)
        );
        let m: Vec<&str> = att.members.iter().map(|(m, _)| m.as_str()).collect();
        assert_eq!(m, ["q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z"]);
        let tc = plant.iter().find(|x| x.name == "torque_cmd").unwrap();
        assert_eq!(
            (tc.kind.as_str(), tc.members[2].1.as_str()),
            ("_scfmu_Torque", "torque_cmd_z")
        );
        let hold = terminals(crate::registry::find("SampleHold").unwrap().decls);
        assert_eq!(
            hold.iter()
                .map(|x| (x.name.as_str(), x.members.len()))
                .collect::<Vec<_>>(),
            [("u", 8), ("y", 8)]
        );
        assert!(hold.iter().all(|x| x.matching_rule == "sequence"));
    }
}
