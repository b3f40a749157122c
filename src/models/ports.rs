//! Shared port blocks: the ports every unit of a kind has, declared once and embedded by name in each
//! unit's declaration (`ports: AttitudeControllerPorts;`), so that units of a kind swap as black boxes.
//! Public (re-exported by `crate::export`): a model crate's controller embeds the same block and then
//! plugs into the project's `AttitudePlant` and `AttitudeCommand` like the project's own controllers.
//!
//! - [`AttitudeControllerPorts`]: three-axis attitude controllers (measured and commanded attitude and
//!   rate in, torque command out), with [`check_unit_quaternions`].

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
