//! `CommandSwitch`: the actuator commands of the mode: the torque of the safe or the pointing law (or none)
//! and the B-dot dipole (or none), selected by `ModeManager`'s codes. Feed-through, no state.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::estimate_gate::finite_vec;
use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct CommandSwitchVars {
        0 => torque_safe: Vec3 = [0.0; 3], Input, "N.m", "Torque of the safe law (SAFE, SUN_ACQUISITION, DETERMINATION)";
        3 => torque_fine: Vec3 = [0.0; 3], Input, "N.m", "Torque of the pointing law (FINE_POINTING)";
        6 => m_bdot: Vec3 = [0.0; 3], Input, "A.m2", "Dipole of the detumbling law (the BDot's m_cmd)";
        9 => torque_select: Real = 0.0, Input, "", "Torque selection (ModeManager's torque_select): 0 none, 1 torque_safe, 2 torque_fine";
        10 => dipole_select: Real = 0.0, Input, "", "Dipole selection (ModeManager's dipole_select): 0 none, 1 m_bdot";
        20 => torque_cmd: Vec3 = [0.0; 3], Output, "N.m", "Commanded torque (the plant's torque_cmd)";
        23 => m_cmd: Vec3 = [0.0; 3], Output, "A.m2", "Commanded magnetic dipole (the plant's m_cmd)";
    }
}

/// No state: the outputs are a function of the inputs.
#[derive(Clone, Serialize, Deserialize)]
pub struct CommandSwitch {}

/// The code of a selection input: the nearest integer, if it is one of `allowed` and within 0.25 of x.
fn code(name: &str, x: f64, allowed: &[(i32, &str)]) -> Result<i32, String> {
    let k = x.round();
    match allowed.iter().find(|(c, _)| *c as f64 == k) {
        Some((c, _)) if x.is_finite() && (x - k).abs() <= 0.25 => Ok(*c),
        _ => {
            let codes: Vec<String> = allowed.iter().map(|(c, what)| format!("{c} ({what})")).collect();
            Err(format!("input {name} = {x}: not within 0.25 of an allowed code {}", codes.join(", ")))
        }
    }
}

impl Model for CommandSwitch {
    type Vars = CommandSwitchVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "CommandSwitch",
        description: "Actuator command switch: the torque of the safe or the pointing law or none, and the B-dot dipole or none, by the mode manager's selection codes",
        source: "mode-dependent selection of the AOCS control laws as in [ECSS-E-ST-60-30C]; project scheme",
        equations_html: "<pre>torque_cmd = 0 (torque_select = 0),  torque_safe (1),  torque_fine (2)\n\
m_cmd      = 0 (dipole_select = 0),  m_bdot (1)</pre>\n\
<p>The selection inputs are rounded to the nearest integer; a value farther than 0.25 from an allowed code, or \
not finite, is refused with an error naming the input and the allowed codes (a wrongly wired signal is not \
read as a code). The output names are the plant's inputs, so the switch sits between the laws and the \
plant by name.</p>",
        feedthrough: Feedthrough::Some(&[
            ("torque_cmd", &["torque_safe", "torque_fine", "torque_select"]),
            ("m_cmd", &["m_bdot", "dipole_select"]),
        ]),
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut CommandSwitchVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(CommandSwitch {})
    }

    fn outputs(&self, v: &mut CommandSwitchVars, _t: f64) -> ModelResult {
        let ts = code("torque_select", v.torque_select, &[(0, "zero"), (1, "torque_safe"), (2, "torque_fine")])?;
        let ds = code("dipole_select", v.dipole_select, &[(0, "zero"), (1, "m_bdot")])?;
        let (safe, fine) = (finite_vec("torque_safe", &v.torque_safe)?, finite_vec("torque_fine", &v.torque_fine)?);
        let m = finite_vec("m_bdot", &v.m_bdot)?;
        v.torque_cmd = match ts {
            1 => safe,
            2 => fine,
            _ => Vector3::zeros(),
        };
        v.m_cmd = if ds == 1 { m } else { Vector3::zeros() };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn switch(ts: f64, ds: f64) -> Result<Fmu<CommandSwitch>, String> {
        let mut f = Fmu::<CommandSwitch>::default();
        f.initialize(&Experiment::default()).unwrap();
        f.v.torque_safe = Vector3::new(1.0, 2.0, 3.0);
        f.v.torque_fine = Vector3::new(-0.1, -0.2, -0.3);
        f.v.m_bdot = Vector3::new(0.5, 0.0, -0.5);
        (f.v.torque_select, f.v.dipole_select) = (ts, ds);
        f.outputs(0.0)?;
        Ok(f)
    }

    #[test]
    fn the_codes_select_the_commands() {
        let z = [0.0; 3];
        for (ts, ds, torque, m) in [
            (0.0, 0.0, z, z),
            (1.0, 0.0, [1.0, 2.0, 3.0], z),
            (2.0, 1.0, [-0.1, -0.2, -0.3], [0.5, 0.0, -0.5]),
            (1.25, 0.75, [1.0, 2.0, 3.0], [0.5, 0.0, -0.5]), // within 0.25 of a code
            (-0.2, 1.1, z, [0.5, 0.0, -0.5]),
        ] {
            let f = switch(ts, ds).unwrap();
            assert_eq!((f.v.torque_cmd, f.v.m_cmd), (Vector3::from(torque), Vector3::from(m)), "{ts} {ds}");
        }
    }

    #[test]
    fn codes_far_from_an_allowed_one_are_refused() {
        for (ts, ds, name) in [(1.5, 0.0, "torque_select"), (3.0, 0.0, "torque_select"), (-1.0, 0.0, "torque_select"),
            (f64::NAN, 0.0, "torque_select"), (0.0, 0.4, "dipole_select"), (0.0, 2.0, "dipole_select")]
        {
            let e = switch(ts, ds).err().unwrap_or_else(|| panic!("{ts} {ds} accepted"));
            assert!(e.contains(name) && e.contains("allowed code"), "{e}");
        }
        let e = switch(1.6, 0.0).err().unwrap();
        assert!(e.contains("0 (zero), 1 (torque_safe), 2 (torque_fine)"), "{e}");
    }
}
