//! `PdController`: paper 000's PD attitude law with a selectable error signal (quaternion, DCM or
//! Euler angles) and gains from (ω_n, ξ) and the inertia (spec controllers.md §1.1–1.2).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_attitude_controller_variables;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::attitude_controller::{linear_law, ErrorLaw};

declare_attitude_controller_variables! {
    pub struct PdControllerVars {
        100 => wn: Real = 1.0, Parameter, Fixed, "rad/s", "Natural frequency omega_n of the per-axis closed loop";
        101 => zeta: Real = 1.0, Parameter, Fixed, "", "Damping ratio xi of the per-axis closed loop";
        102 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_x";
        103 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_y";
        104 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_z";
        105 => kp_x: Real = 1000.0, Parameter, Fixed, "N.m/rad", "Explicit proportional gain k_x (gain_mode = 1)";
        106 => kp_y: Real = 500.0, Parameter, Fixed, "N.m/rad", "Explicit proportional gain k_y (gain_mode = 1)";
        107 => kp_z: Real = 700.0, Parameter, Fixed, "N.m/rad", "Explicit proportional gain k_z (gain_mode = 1)";
        108 => kd_x: Real = -2000.0, Parameter, Fixed, "N.m.s/rad", "Explicit rate gain k_d,x, negative in the paper's convention (gain_mode = 1)";
        109 => kd_y: Real = -1000.0, Parameter, Fixed, "N.m.s/rad", "Explicit rate gain k_d,y, negative (gain_mode = 1)";
        110 => kd_z: Real = -1400.0, Parameter, Fixed, "N.m.s/rad", "Explicit rate gain k_d,z, negative (gain_mode = 1)";
        120 => gain_mode: Integer = 0, Parameter, Fixed, "", "0 = gains from wn, zeta and inertia; 1 = explicit kp_*, kd_*";
        121 => error_law: Integer = 0, Parameter, Fixed, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles";
        200 => k_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Proportional gain in use, x";
        201 => k_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Proportional gain in use, y";
        202 => k_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Proportional gain in use, z";
        203 => k_d_x: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Rate gain in use (negative), x";
        204 => k_d_y: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Rate gain in use (negative), y";
        205 => k_d_z: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Rate gain in use (negative), z";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct PdController {
    v: PdControllerVars,
    law: Option<ErrorLaw>,
}

impl Model for PdController {
    type Vars = PdControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "PdController",
        description: "Paper 000 PD attitude controller with quaternion, DCM or Euler-angle error law",
        source: "paper 000 Eqs. 2, 3, 7, 11, 13, 15; shared/spec controllers.md §1.1-1.2",
        equations_html: "<pre>T_i   = k_i e_i + k_d,i w_i\n\
k_i   = wn^2 I_i,   k_d,i = -2 zeta wn I_i      (k_d is negative: the paper's law adds +k_d * rate)\n\
e^Q   = 2 q_E,w q_E,v,   q_E = q* (x) q_ref                 (error_law = 0)\n\
e^D   = (A_E[3,2], A_E[1,3], A_E[2,1]),  A_E = A(q) A(q_ref)^T  (error_law = 1)\n\
e^E   = wrap(euler321(q_ref) - euler321(q))                 (error_law = 2)</pre>\n\
<p>For a constant command and the linear small-angle plant each axis closes to s^2 + 2 zeta wn s + wn^2. \
w_ref is not used (paper 000 commands are constant).</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &PdControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut PdControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &mut self.v;
        self.law = Some(ErrorLaw::from_param(v.error_law)?);
        let (k, kd) = match check::choice("gain_mode", v.gain_mode, &[0, 1])? {
            0 => {
                let wn = check::positive("wn", v.wn)?;
                let zeta = check::non_negative("zeta", v.zeta)?;
                let i = Vector3::new(
                    check::positive("inertia_xx", v.inertia_xx)?,
                    check::positive("inertia_yy", v.inertia_yy)?,
                    check::positive("inertia_zz", v.inertia_zz)?,
                );
                (i * wn * wn, i * (-2.0 * zeta * wn))
            }
            _ => {
                let k = Vector3::new(check::finite("kp_x", v.kp_x)?, check::finite("kp_y", v.kp_y)?, check::finite("kp_z", v.kp_z)?);
                let kd = Vector3::new(check::finite("kd_x", v.kd_x)?, check::finite("kd_y", v.kd_y)?, check::finite("kd_z", v.kd_z)?);
                (k, kd)
            }
        };
        (v.k_x, v.k_y, v.k_z) = (k.x, k.y, k.z);
        (v.k_d_x, v.k_d_y, v.k_d_z) = (kd.x, kd.y, kd.z);
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let law = self.law.ok_or("controller was not initialized")?;
        let v = &self.v;
        let torque = linear_law(law, &v.inputs(), &Vector3::new(v.k_x, v.k_y, v.k_z), &Vector3::new(v.k_d_x, v.k_d_y, v.k_d_z))?;
        self.v.set_torque(&torque);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _exp: &Experiment) -> ModelResult {
        Ok(()) // static law: no internal state
    }
}
