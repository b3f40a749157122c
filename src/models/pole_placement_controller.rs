//! `PolePlacementController`: paper 000's per-axis pole-placement attitude law (spec controllers.md
//! §1.4). Gains by Ackermann's formula (`crate::math::pole_placement`) at initialisation.

use nalgebra::{Complex, DMatrix, DVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_attitude_controller_variables;
use crate::math::pole_placement::{ackermann, poly_from_roots, quadratic_roots, second_order_poly};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::attitude_controller::{linear_law, ErrorLaw};

declare_attitude_controller_variables! {
    pub struct PolePlacementControllerVars {
        100 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_x";
        101 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_y";
        102 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_z";
        103 => wn: Real = 1.0, Parameter, Fixed, "rad/s", "Natural frequency of the desired per-axis polynomial s^2 + 2 zeta wn s + wn^2 (pole_mode = 0)";
        104 => zeta: Real = 1.0, Parameter, Fixed, "", "Damping ratio of the desired polynomial (pole_mode = 0)";
        105 => pole1_re: Real = -1.0, Parameter, Fixed, "1/s", "First requested pole, real part (pole_mode = 1)";
        106 => pole1_im: Real = 0.0, Parameter, Fixed, "1/s", "First requested pole, imaginary part (pole_mode = 1)";
        107 => pole2_re: Real = -1.0, Parameter, Fixed, "1/s", "Second requested pole, real part (pole_mode = 1; real pair or conjugate of pole 1)";
        108 => pole2_im: Real = 0.0, Parameter, Fixed, "1/s", "Second requested pole, imaginary part (pole_mode = 1)";
        120 => pole_mode: Integer = 0, Parameter, Fixed, "", "0 = poles from wn and zeta; 1 = explicit poles pole1_*, pole2_* (same on every axis)";
        121 => error_law: Integer = 0, Parameter, Fixed, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles";
        200 => k1_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Gain k1 on the angle error, x (Ackermann)";
        201 => k1_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Gain k1 on the angle error, y";
        202 => k1_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Gain k1 on the angle error, z";
        203 => k2_x: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Gain k2 on the rate, x";
        204 => k2_y: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Gain k2 on the rate, y";
        205 => k2_z: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "Gain k2 on the rate, z";
        206 => pole_a_re: Real = 0.0, CalculatedParameter, Fixed, "1/s", "Requested pole a in use, real part";
        207 => pole_a_im: Real = 0.0, CalculatedParameter, Fixed, "1/s", "Requested pole a in use, imaginary part";
        208 => pole_b_re: Real = 0.0, CalculatedParameter, Fixed, "1/s", "Requested pole b in use, real part";
        209 => pole_b_im: Real = 0.0, CalculatedParameter, Fixed, "1/s", "Requested pole b in use, imaginary part";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct PolePlacementController {
    v: PolePlacementControllerVars,
    law: Option<ErrorLaw>,
}

impl Model for PolePlacementController {
    type Vars = PolePlacementControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "PolePlacementController",
        description: "Paper 000 per-axis pole-placement attitude controller; gains by Ackermann's formula at initialization",
        source: "paper 000 Eqs. 28-36; shared/spec controllers.md §1.4",
        equations_html: "<pre>per axis: A = [0 1; 0 0],  b = [0; 1/I_i]\n\
phi(s) = s^2 + 2 zeta wn s + wn^2   (pole_mode = 0)   or  (s - p1)(s - p2)   (pole_mode = 1)\n\
[k1, k2] = [0 1] [b  A b]^-1 phi(A)          (Ackermann)  -> k1 = I wn^2, k2 = 2 zeta wn I\n\
T_i = k1 e_i - k2 w_i</pre>\n\
<p>e is the error of error_law (0 quaternion, 1 DCM, 2 Euler angles). Paper 000's Eq. 32 prints an extra \
factor 2 on k2/I (typo). w_ref is not used.</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &PolePlacementControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut PolePlacementControllerVars {
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
        let (coeffs, poles) = match check::choice("pole_mode", v.pole_mode, &[0, 1])? {
            0 => {
                let wn = check::positive("wn", v.wn)?;
                let zeta = check::non_negative("zeta", v.zeta)?;
                let c = second_order_poly(wn, zeta);
                (c.to_vec(), quadratic_roots(c[0], c[1]))
            }
            _ => {
                let p = [
                    Complex::new(check::finite("pole1_re", v.pole1_re)?, check::finite("pole1_im", v.pole1_im)?),
                    Complex::new(check::finite("pole2_re", v.pole2_re)?, check::finite("pole2_im", v.pole2_im)?),
                ];
                let c = poly_from_roots(&p).map_err(|e| format!("parameters pole1_*, pole2_*: {e}"))?;
                (c, p)
            }
        };
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let mut k1 = [0.0; 3];
        let mut k2 = [0.0; 3];
        for (i, &ii) in inertia.iter().enumerate() {
            let b = DVector::from_vec(vec![0.0, 1.0 / ii]);
            let k = ackermann(&a, &b, &coeffs).map_err(|e| format!("pole placement for axis {}: {e}", ["x", "y", "z"][i]))?;
            k1[i] = k[0];
            k2[i] = k[1];
        }
        [v.k1_x, v.k1_y, v.k1_z] = k1;
        [v.k2_x, v.k2_y, v.k2_z] = k2;
        (v.pole_a_re, v.pole_a_im, v.pole_b_re, v.pole_b_im) = (poles[0].re, poles[0].im, poles[1].re, poles[1].im);
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
