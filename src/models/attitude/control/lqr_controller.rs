//! `LqrController`: paper 000's per-axis LQR attitude law. The gains solve the continuous algebraic
//! Riccati equation numerically at initialization (`crate::math::riccati`).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::shared::{linear_law, AttitudeControllerPorts, ErrorLaw};
use crate::declare_variables;
use crate::math::riccati::lqr;
use crate::model::{check_derived, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct LqrControllerVars {
        ports: AttitudeControllerPorts;
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => q11: Real = 1.0, Parameter, "", "State weight Q[1,1] on the angle error ([Navabi-2019] Eq. 26)", NonNegative;
        104 => q22: Real = 2.0, Parameter, "", "State weight Q[2,2] on the rate ([Navabi-2019] Eq. 26)", NonNegative;
        105 => q12: Real = 0.0, Parameter, "", "Off-diagonal state weight Q[1,2] = Q[2,1] (project addition; Q must be positive semi-definite)";
        106 => lqr_r_scale: Real = 1.0, Parameter, "", "Control weight scale: R_i = lqr_r_scale / I_i^2 ([Navabi-2019] Eq. 26)", Positive;
        121 => error_law: Integer = 0, Parameter, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles", Choice(ErrorLaw::CODES);
        200 => k1: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "LQR gain K_1 on the angle error (from the Riccati equation)";
        203 => k2: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "LQR gain K_2 on the rate";
        206 => r: Vec3 = [0.0; 3], CalculatedParameter, "", "Control weight R in use";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct LqrController {
    law: ErrorLaw,
}

impl Model for LqrController {
    type Vars = LqrControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "LqrController",
        description: "Per-axis LQR attitude controller; gains from the Riccati equation solved at initialization",
        source: "[Navabi-2019], Eqs. 19-27",
        equations_html: "<pre>per axis: A = [0 1; 0 0],  B = [0; 1/I_i],  Q = [q11 q12; q12 q22],  R_i = lqr_r_scale / I_i^2\n\
A^T P + P A + Q - P B R^-1 B^T P = 0    (solved numerically: Hamiltonian sign function + Newton-Kleinman)\n\
K_i = R_i^-1 B^T P = [K_i1, K_i2]\n\
T_i = K_i1 e_i - K_i2 w_i               (u = -K [x - x_com; w], x - x_com = -e; [Navabi-2019] Eq. 27)</pre>\n\
<p>e is the error of error_law (0 quaternion, 1 DCM, 2 Euler angles), as in PdController. \
Defaults give K_i = [I_i, 2 I_i] (closed loop s^2 + 2 s + 1). w_ref is not used.</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut LqrControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let (q11, q22, q12) = (v.q11, v.q22, v.q12);
        if q11 * q22 - q12 * q12 < -1e-12 * (q11 * q22).max(q12 * q12) {
            return Err(format!("parameters q11 = {q11}, q22 = {q22}, q12 = {q12}: Q must be positive semi-definite"));
        }
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let q = DMatrix::from_row_slice(2, 2, &[q11, q12, q12, q22]);
        for i in 0..3 {
            let ii = v.inertia[i];
            let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0 / ii]);
            v.r[i] = v.lqr_r_scale / (ii * ii);
            let r = DMatrix::from_element(1, 1, v.r[i]);
            let (k, _p) = lqr(&a, &b, &q, &r).map_err(|e| format!("LQR design for axis {}: {e} (check q11, q22, q12, lqr_r_scale)", ["x", "y", "z"][i]))?;
            v.k1[i] = k[(0, 0)];
            v.k2[i] = k[(0, 1)];
        }
        Ok(LqrController { law: ErrorLaw::from_param("error_law", v.error_law)? })
    }

    fn outputs(&self, v: &mut LqrControllerVars, _t: f64) -> ModelResult {
        // T = K1 e − K2 ω
        v.ports.torque_cmd = linear_law(self.law, &v.ports, &v.k1, &-v.k2)?;
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("error law", &self.law, &fresh.law)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    #[test]
    fn defaults_give_paper_gains_and_bad_q_is_rejected() {
        let mut m = Fmu::<LqrController>::default();
        m.initialize(&Experiment::default()).unwrap();
        for (k1, k2, i) in [(m.v.k1.x, m.v.k2.x, 1000.0), (m.v.k1.y, m.v.k2.y, 500.0), (m.v.k1.z, m.v.k2.z, 700.0)] {
            assert!((k1 - i).abs() < 1e-12 * i && (k2 - 2.0 * i).abs() < 1e-12 * i);
        }
        m.v.q12 = 5.0; // q11 q22 − q12² < 0
        assert!(m.initialize(&Experiment::default()).is_err());
    }
}
