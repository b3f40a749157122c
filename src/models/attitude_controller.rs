//! The common port set of every three-axis attitude controller (spec interfaces.md), declared once:
//! inputs `q_*`, `w_*`, `q_ref_*`, `w_ref_*`, output `torque_cmd_*`. A controller model declares its
//! own parameters and extra ports after these with `declare_attitude_controller_variables!`.

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::math::attitude::{attitude_matrix, error_quaternion, euler321_from_quat, wrap_pi};
use crate::model::check;

/// Measured and commanded attitude as read from the common inputs.
#[derive(Clone, Copy, Debug)]
pub struct AttitudeInputs {
    pub q: Quaternion<f64>,
    pub w: Vector3<f64>,
    pub q_ref: Quaternion<f64>,
    pub w_ref: Vector3<f64>,
}

/// `declare_variables!` with the common controller ports (value references 0–13 inputs, 20–22
/// outputs) in front of the controller's own declarations. Also generates `inputs()` and
/// `set_torque()` on the variable block.
#[macro_export]
macro_rules! declare_attitude_controller_variables {
    (pub struct $Name:ident { $($rest:tt)* }) => {
        $crate::declare_variables! {
            pub struct $Name {
                0 => q_w: Real = 1.0, Input, Continuous, "", "Measured attitude quaternion of B relative to R, scalar part";
                1 => q_x: Real = 0.0, Input, Continuous, "", "Measured attitude quaternion, x component";
                2 => q_y: Real = 0.0, Input, Continuous, "", "Measured attitude quaternion, y component";
                3 => q_z: Real = 0.0, Input, Continuous, "", "Measured attitude quaternion, z component";
                4 => w_x: Real = 0.0, Input, Continuous, "rad/s", "Measured body rate x";
                5 => w_y: Real = 0.0, Input, Continuous, "rad/s", "Measured body rate y";
                6 => w_z: Real = 0.0, Input, Continuous, "rad/s", "Measured body rate z";
                7 => q_ref_w: Real = 1.0, Input, Continuous, "", "Commanded attitude quaternion, scalar part";
                8 => q_ref_x: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, x component";
                9 => q_ref_y: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, y component";
                10 => q_ref_z: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, z component";
                11 => w_ref_x: Real = 0.0, Input, Continuous, "rad/s", "Commanded body rate x";
                12 => w_ref_y: Real = 0.0, Input, Continuous, "rad/s", "Commanded body rate y";
                13 => w_ref_z: Real = 0.0, Input, Continuous, "rad/s", "Commanded body rate z";
                20 => torque_cmd_x: Real = 0.0, Output, Continuous, "N.m", "Commanded control torque, body x";
                21 => torque_cmd_y: Real = 0.0, Output, Continuous, "N.m", "Commanded control torque, body y";
                22 => torque_cmd_z: Real = 0.0, Output, Continuous, "N.m", "Commanded control torque, body z";
                $($rest)*
            }
        }

        impl $Name {
            /// The common inputs as quaternions and vectors.
            pub fn inputs(&self) -> $crate::models::attitude_controller::AttitudeInputs {
                $crate::models::attitude_controller::AttitudeInputs {
                    q: nalgebra::Quaternion::new(self.q_w, self.q_x, self.q_y, self.q_z),
                    w: nalgebra::Vector3::new(self.w_x, self.w_y, self.w_z),
                    q_ref: nalgebra::Quaternion::new(self.q_ref_w, self.q_ref_x, self.q_ref_y, self.q_ref_z),
                    w_ref: nalgebra::Vector3::new(self.w_ref_x, self.w_ref_y, self.w_ref_z),
                }
            }

            /// Writes the torque output.
            pub fn set_torque(&mut self, t: &nalgebra::Vector3<f64>) {
                (self.torque_cmd_x, self.torque_cmd_y, self.torque_cmd_z) = (t.x, t.y, t.z);
            }
        }
    };
}

/// Rejects a measured or commanded quaternion that is far from unit norm (wrong wiring, e.g. a
/// quaternion port left unconnected at 0).
pub fn check_unit_quaternions(inp: &AttitudeInputs) -> Result<(), String> {
    for (name, q) in [("q", inp.q), ("q_ref", inp.q_ref)] {
        let n = q.norm();
        if (n - 1.0).abs() > 1e-3 {
            return Err(format!("input quaternion {name} has norm {n}, expected 1 (is it connected?)"));
        }
    }
    Ok(())
}

/// Error signal of paper 000 (controllers.md §1.1), ≈ commanded minus actual angle per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ErrorLaw {
    Quaternion,
    Dcm,
    Euler,
}

impl ErrorLaw {
    pub fn from_param(v: i32) -> Result<Self, String> {
        Ok(match check::choice("error_law", v, &[0, 1, 2])? {
            0 => ErrorLaw::Quaternion,
            1 => ErrorLaw::Dcm,
            _ => ErrorLaw::Euler,
        })
    }

    pub fn error(self, inp: &AttitudeInputs) -> Vector3<f64> {
        match self {
            // e^Q = 2 q_E,w q_E,v with q_E = q* ⊗ q_ref (paper 000 Eq. 35)
            ErrorLaw::Quaternion => {
                let e = error_quaternion(&inp.q, &inp.q_ref);
                e.vector() * (2.0 * e.w)
            }
            // A_E = A(q) A(q_ref)ᵀ, e^D = (A_E[3,2], A_E[1,3], A_E[2,1]) (paper 000 Eq. 13)
            ErrorLaw::Dcm => {
                let a = attitude_matrix(&inp.q) * attitude_matrix(&inp.q_ref).transpose();
                Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)])
            }
            // e^E = wrap(euler321(q_ref) − euler321(q)) (paper 000 Eqs. 2, 11)
            ErrorLaw::Euler => {
                let r = euler321_from_quat(&inp.q_ref);
                let m = euler321_from_quat(&inp.q);
                Vector3::new(wrap_pi(r[0] - m[0]), wrap_pi(r[1] - m[1]), wrap_pi(r[2] - m[2]))
            }
        }
    }
}

/// The per-axis linear law of paper 000's PD, LQR and pole-placement controllers:
/// T = k_e ⊙ e + k_w ⊙ ω, with e from `law` (≈ commanded minus actual angle). In the paper's
/// convention the rate gain k_w is negative (it adds +k_d·rate with k_d < 0).
pub fn linear_law(law: ErrorLaw, inp: &AttitudeInputs, k_e: &Vector3<f64>, k_w: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    check_unit_quaternions(inp)?;
    Ok(k_e.component_mul(&law.error(inp)) + k_w.component_mul(&inp.w))
}
