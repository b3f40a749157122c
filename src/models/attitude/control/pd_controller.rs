//! `PdController`: paper 000's PD attitude law with a selectable error signal (quaternion, DCM or
//! Euler angles) and gains from (ω_n, ξ) and the nominal inertia, or given explicitly.

use serde::{Deserialize, Serialize};

use super::shared::{linear_law, AttitudeControllerPorts, ErrorLaw};
use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct PdControllerVars {
        ports: AttitudeControllerPorts;
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => wn: Real = 1.0, Parameter, "rad/s", "Natural frequency omega_n of the per-axis closed loop", Positive;
        104 => zeta: Real = 1.0, Parameter, "", "Damping ratio xi of the per-axis closed loop", NonNegative;
        105 => kp: Vec3 = [1000.0, 500.0, 700.0], Parameter, "N.m/rad", "Explicit proportional gain k (gain_mode = 1)";
        108 => kd: Vec3 = [-2000.0, -1000.0, -1400.0], Parameter, "N.m.s/rad", "Explicit rate gain k_d, negative in the paper's convention (gain_mode = 1)";
        120 => gain_mode: Integer = 0, Parameter, "", "0 = gains from wn, zeta and inertia; 1 = explicit kp_*, kd_*", Choice(&[0, 1]);
        121 => error_law: Integer = 0, Parameter, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles", Choice(ErrorLaw::CODES);
        200 => k: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "Proportional gain in use";
        203 => k_d: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "Rate gain in use (negative)";
    }
}

/// A static law: the error law and the gains (in the calculated parameters) are all it needs.
#[derive(Clone, Serialize, Deserialize)]
pub struct PdController {
    law: ErrorLaw,
}

impl Model for PdController {
    type Vars = PdControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "PdController",
        description: "Paper 000 PD attitude controller with quaternion, DCM or Euler-angle error law",
        source: "paper 000 (adaptive-fuzzy EULERINT design), Eqs. 2, 3, 7, 11, 13, 15",
        equations_html: "<pre>T_i   = k_i e_i + k_d,i w_i\n\
k_i   = wn^2 I_i,   k_d,i = -2 zeta wn I_i      (k_d is negative: the paper's law adds +k_d * rate)\n\
e^Q   = 2 q_E,w q_E,v,   q_E = q* (x) q_ref                 (error_law = 0)\n\
e^D   = (A_E[3,2], A_E[1,3], A_E[2,1]),  A_E = A(q) A(q_ref)^T  (error_law = 1)\n\
e^E   = wrap(euler321(q_ref) - euler321(q))                 (error_law = 2)</pre>\n\
<p>For a constant command and the linear small-angle plant each axis closes to s^2 + 2 zeta wn s + wn^2. \
w_ref is not used (paper 000 commands are constant).</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut PdControllerVars, _exp: &Experiment) -> Result<Self, String> {
        (v.k, v.k_d) = match v.gain_mode {
            0 => (v.inertia * v.wn * v.wn, v.inertia * (-2.0 * v.zeta * v.wn)),
            _ => (v.kp, v.kd),
        };
        Ok(PdController { law: ErrorLaw::from_param("error_law", v.error_law)? })
    }

    fn outputs(&self, v: &mut PdControllerVars, _t: f64) -> ModelResult {
        v.ports.torque_cmd = linear_law(self.law, &v.ports, &v.k, &v.k_d)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;
    use nalgebra::Vector3;

    #[test]
    fn gains_follow_wn_zeta_and_inertia() {
        let mut c = Fmu::<PdController>::default();
        (c.v.wn, c.v.zeta) = (2.0, 0.5);
        c.initialize(&Experiment::default()).unwrap();
        assert_eq!(c.v.k, Vector3::new(4000.0, 2000.0, 2800.0));
        assert_eq!(c.v.k_d, Vector3::new(-2000.0, -1000.0, -1400.0));
        c.v.wn = -1.0;
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("wn = -1"), "{e}");
    }
}
