//! `LqrController`: paper 000's per-axis LQR attitude law (spec controllers.md §1.3). The gains solve
//! the continuous algebraic Riccati equation numerically at initialisation (`crate::math::riccati`).

use nalgebra::{DMatrix, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_attitude_controller_variables;
use crate::math::riccati::lqr;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::attitude_controller::{linear_law, ErrorLaw};

declare_attitude_controller_variables! {
    pub struct LqrControllerVars {
        100 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_x";
        101 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_y";
        102 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_z";
        103 => q11: Real = 1.0, Parameter, Fixed, "", "State weight Q[1,1] on the angle error (paper 000 Eq. 26)";
        104 => q22: Real = 2.0, Parameter, Fixed, "", "State weight Q[2,2] on the rate (paper 000 Eq. 26)";
        105 => q12: Real = 0.0, Parameter, Fixed, "", "Off-diagonal state weight Q[1,2] = Q[2,1] (project addition; Q must be positive semi-definite)";
        106 => lqr_r_scale: Real = 1.0, Parameter, Fixed, "", "Control weight scale: R_i = lqr_r_scale / I_i^2 (paper 000 Eq. 26)";
        121 => error_law: Integer = 0, Parameter, Fixed, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles";
        200 => k1_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "LQR gain K_x1 on the angle error (from the Riccati equation)";
        201 => k1_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "LQR gain K_y1 on the angle error";
        202 => k1_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "LQR gain K_z1 on the angle error";
        203 => k2_x: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "LQR gain K_x2 on the rate";
        204 => k2_y: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "LQR gain K_y2 on the rate";
        205 => k2_z: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "LQR gain K_z2 on the rate";
        206 => r_x: Real = 0.0, CalculatedParameter, Fixed, "", "Control weight R_x in use";
        207 => r_y: Real = 0.0, CalculatedParameter, Fixed, "", "Control weight R_y in use";
        208 => r_z: Real = 0.0, CalculatedParameter, Fixed, "", "Control weight R_z in use";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct LqrController {
    v: LqrControllerVars,
    law: Option<ErrorLaw>,
}

impl Model for LqrController {
    type Vars = LqrControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "LqrController",
        description: "Paper 000 per-axis LQR attitude controller; gains from the Riccati equation solved at initialization",
        source: "paper 000 Eqs. 19-27; shared/spec controllers.md §1.3",
        equations_html: "<pre>per axis: A = [0 1; 0 0],  B = [0; 1/I_i],  Q = [q11 q12; q12 q22],  R_i = lqr_r_scale / I_i^2\n\
A^T P + P A + Q - P B R^-1 B^T P = 0    (solved numerically: Hamiltonian sign function + Newton-Kleinman)\n\
K_i = R_i^-1 B^T P = [K_i1, K_i2]\n\
T_i = K_i1 e_i - K_i2 w_i               (u = -K [x - x_com; w], x - x_com = -e; paper 000 Eq. 27)</pre>\n\
<p>e is the error of error_law (0 quaternion, 1 DCM, 2 Euler angles), as in PdController. \
Defaults give K_i = [I_i, 2 I_i] (closed loop s^2 + 2 s + 1). w_ref is not used.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &LqrControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut LqrControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &mut self.v;
        self.law = Some(ErrorLaw::from_param(v.error_law)?);
        let inertia = [
            check::positive("inertia_xx", v.inertia_xx)?,
            check::positive("inertia_yy", v.inertia_yy)?,
            check::positive("inertia_zz", v.inertia_zz)?,
        ];
        let q11 = check::non_negative("q11", v.q11)?;
        let q22 = check::non_negative("q22", v.q22)?;
        let q12 = check::finite("q12", v.q12)?;
        if q11 * q22 - q12 * q12 < -1e-12 * (q11 * q22).max(q12 * q12) {
            return Err(format!("parameters q11 = {q11}, q22 = {q22}, q12 = {q12}: Q must be positive semi-definite"));
        }
        let scale = check::positive("lqr_r_scale", v.lqr_r_scale)?;
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let q = DMatrix::from_row_slice(2, 2, &[q11, q12, q12, q22]);
        let mut k1 = [0.0; 3];
        let mut k2 = [0.0; 3];
        let mut rs = [0.0; 3];
        for (i, &ii) in inertia.iter().enumerate() {
            let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0 / ii]);
            rs[i] = scale / (ii * ii);
            let r = DMatrix::from_element(1, 1, rs[i]);
            let (k, _p) = lqr(&a, &b, &q, &r).map_err(|e| format!("LQR design for axis {}: {e} (check q11, q22, q12, lqr_r_scale)", ["x", "y", "z"][i]))?;
            k1[i] = k[(0, 0)];
            k2[i] = k[(0, 1)];
        }
        [v.k1_x, v.k1_y, v.k1_z] = k1;
        [v.k2_x, v.k2_y, v.k2_z] = k2;
        [v.r_x, v.r_y, v.r_z] = rs;
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let law = self.law.ok_or("controller was not initialized")?;
        let v = &self.v;
        // T = K1 e − K2 ω
        let torque = linear_law(law, &v.inputs(), &Vector3::new(v.k1_x, v.k1_y, v.k1_z), &-Vector3::new(v.k2_x, v.k2_y, v.k2_z))?;
        self.v.set_torque(&torque);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _exp: &Experiment) -> ModelResult {
        Ok(()) // static law
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_give_paper_gains_and_bad_q_is_rejected() {
        let mut m = LqrController::default();
        m.initialize(&Experiment::default()).unwrap();
        for (k1, k2, i) in [(m.v.k1_x, m.v.k2_x, 1000.0), (m.v.k1_y, m.v.k2_y, 500.0), (m.v.k1_z, m.v.k2_z, 700.0)] {
            assert!((k1 - i).abs() < 1e-12 * i && (k2 - 2.0 * i).abs() < 1e-12 * i);
        }
        m.v.q12 = 5.0; // q11 q22 − q12² < 0
        assert!(m.initialize(&Experiment::default()).is_err());
    }
}
