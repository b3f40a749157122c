//! `PolePlacementController`: paper 000's per-axis pole-placement attitude law. Gains by Ackermann's
//! formula (`crate::math::pole_placement`) at initialization.

use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::shared::{linear_law, AttitudeControllerPorts, ErrorLaw};
use crate::declare_variables;
use crate::math::pole_placement::{ackermann, poly_from_roots, quadratic_roots, second_order_poly};
use crate::model::{check_derived, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct PolePlacementControllerVars {
        ports: AttitudeControllerPorts;
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => wn: Real = 1.0, Parameter, "rad/s", "Natural frequency of the desired per-axis polynomial s^2 + 2 zeta wn s + wn^2 (pole_mode = 0)", Positive;
        104 => zeta: Real = 1.0, Parameter, "", "Damping ratio of the desired polynomial (pole_mode = 0)", NonNegative;
        105 => pole1_re: Real = -1.0, Parameter, "1/s", "First requested pole, real part (pole_mode = 1)";
        106 => pole1_im: Real = 0.0, Parameter, "1/s", "First requested pole, imaginary part (pole_mode = 1)";
        107 => pole2_re: Real = -1.0, Parameter, "1/s", "Second requested pole, real part (pole_mode = 1; real pair or conjugate of pole 1)";
        108 => pole2_im: Real = 0.0, Parameter, "1/s", "Second requested pole, imaginary part (pole_mode = 1)";
        120 => pole_mode: Integer = 0, Parameter, "", "0 = poles from wn and zeta; 1 = explicit poles pole1_*, pole2_* (same on every axis)", Choice(&[0, 1]);
        121 => error_law: Integer = 0, Parameter, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles", Choice(ErrorLaw::CODES);
        200 => k1: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "Gain k1 on the angle error (Ackermann)";
        203 => k2: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "Gain k2 on the rate";
        206 => pole_a_re: Real = 0.0, CalculatedParameter, "1/s", "Requested pole a in use, real part";
        207 => pole_a_im: Real = 0.0, CalculatedParameter, "1/s", "Requested pole a in use, imaginary part";
        208 => pole_b_re: Real = 0.0, CalculatedParameter, "1/s", "Requested pole b in use, real part";
        209 => pole_b_im: Real = 0.0, CalculatedParameter, "1/s", "Requested pole b in use, imaginary part";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct PolePlacementController {
    law: ErrorLaw,
}

impl Model for PolePlacementController {
    type Vars = PolePlacementControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "PolePlacementController",
        description: "Per-axis pole-placement attitude controller; gains by Ackermann's formula at initialization",
        source: "[Navabi-2019], Eqs. 28-36",
        equations_html: "<pre>per axis: A = [0 1; 0 0],  b = [0; 1/I_i]\n\
phi(s) = s^2 + 2 zeta wn s + wn^2   (pole_mode = 0)   or  (s - p1)(s - p2)   (pole_mode = 1)\n\
[k1, k2] = [0 1] [b  A b]^-1 phi(A)          (Ackermann)  -> k1 = I wn^2, k2 = 2 zeta wn I\n\
T_i = k1 e_i - k2 w_i</pre>\n\
<p>e is the error of error_law (0 quaternion, 1 DCM, 2 Euler angles). [Navabi-2019]'s Eq. 32 prints an extra \
factor 2 on k2/I (typo). w_ref is not used.</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut PolePlacementControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let (coeffs, poles) = match v.pole_mode {
            0 => {
                let c = second_order_poly(v.wn, v.zeta);
                (c.to_vec(), quadratic_roots(c[0], c[1]))
            }
            _ => {
                let p = [Complex::new(v.pole1_re, v.pole1_im), Complex::new(v.pole2_re, v.pole2_im)];
                let c = poly_from_roots(&p).map_err(|e| format!("parameters pole1_*, pole2_*: {e}"))?;
                (c, p)
            }
        };
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        for i in 0..3 {
            let b = DVector::from_vec(vec![0.0, 1.0 / v.inertia[i]]);
            let k = ackermann(&a, &b, &coeffs).map_err(|e| format!("pole placement for axis {}: {e}", ["x", "y", "z"][i]))?;
            v.k1[i] = k[0];
            v.k2[i] = k[1];
        }
        (v.pole_a_re, v.pole_a_im, v.pole_b_re, v.pole_b_im) = (poles[0].re, poles[0].im, poles[1].re, poles[1].im);
        Ok(PolePlacementController { law: ErrorLaw::from_param("error_law", v.error_law)? })
    }

    fn outputs(&self, v: &mut PolePlacementControllerVars, _t: f64) -> ModelResult {
        // T = K1 e − K2 ω
        v.ports.torque_cmd = linear_law(self.law, &v.ports, &v.k1, &-v.k2)?;
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("error law", &self.law, &fresh.law)
    }
}
