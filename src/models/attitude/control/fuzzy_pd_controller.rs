//! `FuzzyPdController`: paper 000's PD attitude law with gains scheduled per axis by a 7×7-rule fuzzy
//! system (inference in `crate::math::fuzzy`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::shared::{check_unit_quaternions, AttitudeControllerPorts, ErrorLaw};
use crate::declare_variables;
use crate::math::fuzzy::{Defuzz, PdFuzzySystem};
use crate::model::{check_derived, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct FuzzyPdControllerVars {
        ports: AttitudeControllerPorts;
        30 => kp: Vec3 = [0.0; 3], Output, "N.m/rad", "Scheduled proportional gain k_p in use";
        33 => kd: Vec3 = [0.0; 3], Output, "N.m.s/rad", "Scheduled rate gain k_d in use (positive)";
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => wn: Real = 1.0, Parameter, "rad/s", "Reference PD natural frequency: k_r,i = wn^2 I_i (project choice)", Positive;
        104 => t_r: Real = 5.834, Parameter, "s", "Reference settling time T_r (project choice: 2 % settling of wn = 1, zeta = 1)", Positive;
        105 => kp_min_factor: Real = 0.28, Parameter, "", "k_p,min = kp_min_factor k_r ([Navabi-2019] Eq. 47)", NonNegative;
        106 => kp_max_factor: Real = 3.0, Parameter, "", "k_p,max = kp_max_factor k_r ([Navabi-2019] Eq. 47)", NonNegative;
        107 => kd_min_factor: Real = 0.08, Parameter, "", "k_d,min = kd_min_factor k_r T_r ([Navabi-2019] Eq. 47)", NonNegative;
        108 => kd_max_factor: Real = 0.15, Parameter, "", "k_d,max = kd_max_factor k_r T_r ([Navabi-2019] Eq. 47)", NonNegative;
        115 => e_scale: Real = 1.0, Parameter, "rad", "Error normalisation: e_bar = clamp(e / e_scale, -1, 1)", Positive;
        116 => edot_scale: Real = 0.5, Parameter, "rad/s", "Error-rate normalisation: edot_bar = clamp(edot / edot_scale, -1, 1)", Positive;
        117 => sigma: Real = 0.25, Parameter, "", "Width of the Gaussian output sets Small (centre 0) and Big (centre 1)", Positive;
        118 => mf_half_width: Real = 0.3333333333333333, Parameter, "", "Half-width of the seven triangular input sets centred at -1, -2/3, ..., 1 (>= 1/3)";
        121 => error_law: Integer = 0, Parameter, "", "Error signal: 0 = quaternion ([Navabi-2019]), 1 = DCM, 2 = Euler 321 angles", Choice(ErrorLaw::CODES);
        122 => defuzz: Integer = 0, Parameter, "", "Defuzzification: 0 = weighted average with c(S) = 0, c(B) = 1; 1 = truncated-centroid representatives", Choice(Defuzz::CODES);
        200 => kr: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "Reference gain k_r";
        203 => kp_min: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "k_p,min";
        206 => kp_max: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "k_p,max";
        209 => kd_min: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "k_d,min";
        212 => kd_max: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "k_d,max";
        215 => c_small: Real = 0.0, CalculatedParameter, "", "Representative value c(S) of the output set Small";
        216 => c_big: Real = 0.0, CalculatedParameter, "", "Representative value c(B) of the output set Big";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct FuzzyPdController {
    law: ErrorLaw,
    fuzzy: PdFuzzySystem,
}

impl Model for FuzzyPdController {
    type Vars = FuzzyPdControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "FuzzyPdController",
        description: "Quaternion PD attitude controller with gains scheduled by a 7x7-rule fuzzy system",
        source: "[Navabi-2019], §6, Eqs. 44-47, Tables 1-2",
        equations_html: "<pre>per axis: e = e^Q_i (error_law 0),  edot = -w_i\n\
e_bar = clamp(e / e_scale, -1, 1),  edot_bar = clamp(edot / edot_scale, -1, 1)\n\
mu_jk = mu_j(e_bar) mu_k(edot_bar)                         (product firing; 7 triangles NB..PB)\n\
k'_p = sum mu_jk c(P_jk) / sum mu_jk,  k'_d = sum mu_jk c(D_jk) / sum mu_jk   ([Navabi-2019] Tables 1-2)\n\
k_p = k_p,min + (k_p,max - k_p,min) k'_p,  k_d = k_d,min + (k_d,max - k_d,min) k'_d\n\
k_p,min = 0.28 k_r, k_p,max = 3 k_r, k_d,min = 0.08 k_r T_r, k_d,max = 0.15 k_r T_r,  k_r = wn^2 I\n\
T_i = k_p e - k_d w_i</pre>\n\
<p>defuzz 0: c(S) = 0, c(B) = 1; defuzz 1: centroids of the Gaussian output sets truncated to [0, 1] \
(= product implication, sum aggregation, centroid).</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut FuzzyPdControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let defuzz = Defuzz::from_param("defuzz", v.defuzz)?;
        let fuzzy = PdFuzzySystem::new(v.mf_half_width, v.sigma, defuzz).map_err(|e| format!("parameters mf_half_width / sigma: {e}"))?;
        v.kr = v.inertia * (v.wn * v.wn);
        v.kp_min = v.kr * v.kp_min_factor;
        v.kp_max = v.kr * v.kp_max_factor;
        v.kd_min = v.kr * (v.kd_min_factor * v.t_r);
        v.kd_max = v.kr * (v.kd_max_factor * v.t_r);
        (v.c_small, v.c_big) = (fuzzy.c_small, fuzzy.c_big);
        Ok(FuzzyPdController { law: ErrorLaw::from_param("error_law", v.error_law)?, fuzzy })
    }

    fn outputs(&self, v: &mut FuzzyPdControllerVars, _t: f64) -> ModelResult {
        check_unit_quaternions(&v.ports)?;
        let e = self.law.error(&v.ports);
        let w = v.ports.w;
        let mut kp = Vector3::zeros();
        let mut kd = Vector3::zeros();
        for i in 0..3 {
            let (kpn, kdn) = self.fuzzy.infer(e[i] / v.e_scale, -w[i] / v.edot_scale);
            kp[i] = v.kp_min[i] + (v.kp_max[i] - v.kp_min[i]) * kpn;
            kd[i] = v.kd_min[i] + (v.kd_max[i] - v.kd_min[i]) * kdn;
        }
        v.ports.torque_cmd = kp.component_mul(&e) - kd.component_mul(&w);
        (v.kp, v.kd) = (kp, kd);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("error law", &self.law, &fresh.law)?;
        check_derived("fuzzy system", &self.fuzzy, &fresh.fuzzy)
    }
}
