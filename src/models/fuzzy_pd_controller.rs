//! `FuzzyPdController`: paper 000's PD attitude law with fuzzy-scheduled gains (spec controllers.md
//! §1.6). Inference in `crate::math::fuzzy`.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_attitude_controller_variables;
use crate::math::fuzzy::{Defuzz, PdFuzzySystem};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::attitude_controller::{check_unit_quaternions, ErrorLaw};

declare_attitude_controller_variables! {
    pub struct FuzzyPdControllerVars {
        30 => kp_x: Real = 0.0, Output, Continuous, "N.m/rad", "Scheduled proportional gain k_p in use, x";
        31 => kp_y: Real = 0.0, Output, Continuous, "N.m/rad", "Scheduled proportional gain k_p in use, y";
        32 => kp_z: Real = 0.0, Output, Continuous, "N.m/rad", "Scheduled proportional gain k_p in use, z";
        33 => kd_x: Real = 0.0, Output, Continuous, "N.m.s/rad", "Scheduled rate gain k_d in use (positive), x";
        34 => kd_y: Real = 0.0, Output, Continuous, "N.m.s/rad", "Scheduled rate gain k_d in use (positive), y";
        35 => kd_z: Real = 0.0, Output, Continuous, "N.m.s/rad", "Scheduled rate gain k_d in use (positive), z";
        100 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_x";
        101 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_y";
        102 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Controller's nominal inertia I_z";
        103 => wn: Real = 1.0, Parameter, Fixed, "rad/s", "Reference PD natural frequency: k_r,i = wn^2 I_i (project choice)";
        104 => t_r: Real = 5.834, Parameter, Fixed, "s", "Reference settling time T_r (project choice: 2 % settling of wn = 1, zeta = 1)";
        105 => kp_min_factor: Real = 0.28, Parameter, Fixed, "", "k_p,min = kp_min_factor k_r (paper 000 Eq. 47)";
        106 => kp_max_factor: Real = 3.0, Parameter, Fixed, "", "k_p,max = kp_max_factor k_r (paper 000 Eq. 47)";
        107 => kd_min_factor: Real = 0.08, Parameter, Fixed, "", "k_d,min = kd_min_factor k_r T_r (paper 000 Eq. 47)";
        108 => kd_max_factor: Real = 0.15, Parameter, Fixed, "", "k_d,max = kd_max_factor k_r T_r (paper 000 Eq. 47)";
        109 => e_scale: Real = 1.0, Parameter, Fixed, "rad", "Error normalisation: e_bar = clamp(e / e_scale, -1, 1)";
        110 => edot_scale: Real = 0.5, Parameter, Fixed, "rad/s", "Error-rate normalisation: edot_bar = clamp(edot / edot_scale, -1, 1)";
        111 => sigma: Real = 0.25, Parameter, Fixed, "", "Width of the Gaussian output sets Small (centre 0) and Big (centre 1)";
        112 => mf_half_width: Real = 0.3333333333333333, Parameter, Fixed, "", "Half-width of the seven triangular input sets centred at -1, -2/3, ..., 1 (>= 1/3)";
        120 => defuzz: Integer = 0, Parameter, Fixed, "", "Defuzzification: 0 = weighted average with c(S) = 0, c(B) = 1; 1 = truncated-centroid representatives";
        121 => error_law: Integer = 0, Parameter, Fixed, "", "Error signal: 0 = quaternion (paper 000), 1 = DCM, 2 = Euler 321 angles";
        200 => kr_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Reference gain k_r,x";
        201 => kr_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Reference gain k_r,y";
        202 => kr_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "Reference gain k_r,z";
        203 => kp_min_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,min,x";
        204 => kp_min_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,min,y";
        205 => kp_min_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,min,z";
        206 => kp_max_x: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,max,x";
        207 => kp_max_y: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,max,y";
        208 => kp_max_z: Real = 0.0, CalculatedParameter, Fixed, "N.m/rad", "k_p,max,z";
        209 => kd_min_x: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,min,x";
        210 => kd_min_y: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,min,y";
        211 => kd_min_z: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,min,z";
        212 => kd_max_x: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,max,x";
        213 => kd_max_y: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,max,y";
        214 => kd_max_z: Real = 0.0, CalculatedParameter, Fixed, "N.m.s/rad", "k_d,max,z";
        215 => c_small: Real = 0.0, CalculatedParameter, Fixed, "", "Representative value c(S) of the output set Small";
        216 => c_big: Real = 0.0, CalculatedParameter, Fixed, "", "Representative value c(B) of the output set Big";
    }
}

/// Parses `defuzz`.
pub fn defuzz_from_param(v: i32) -> Result<Defuzz, String> {
    Ok(match check::choice("defuzz", v, &[0, 1])? {
        0 => Defuzz::Singleton,
        _ => Defuzz::TruncatedCentroid,
    })
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct FuzzyPdController {
    v: FuzzyPdControllerVars,
    law: Option<ErrorLaw>,
    fuzzy: Option<PdFuzzySystem>,
}

impl Model for FuzzyPdController {
    type Vars = FuzzyPdControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "FuzzyPdController",
        description: "Paper 000 quaternion PD attitude controller with gains scheduled by a 7x7-rule fuzzy system",
        source: "paper 000 §6, Eqs. 44-47, Tables 1-2; shared/spec controllers.md §1.6",
        equations_html: "<pre>per axis: e = e^Q_i (error_law 0),  edot = -w_i\n\
e_bar = clamp(e / e_scale, -1, 1),  edot_bar = clamp(edot / edot_scale, -1, 1)\n\
mu_jk = mu_j(e_bar) mu_k(edot_bar)                         (product firing; 7 triangles NB..PB)\n\
k'_p = sum mu_jk c(P_jk) / sum mu_jk,  k'_d = sum mu_jk c(D_jk) / sum mu_jk   (paper 000 Tables 1-2)\n\
k_p = k_p,min + (k_p,max - k_p,min) k'_p,  k_d = k_d,min + (k_d,max - k_d,min) k'_d\n\
k_p,min = 0.28 k_r, k_p,max = 3 k_r, k_d,min = 0.08 k_r T_r, k_d,max = 0.15 k_r T_r,  k_r = wn^2 I\n\
T_i = k_p e - k_d w_i</pre>\n\
<p>defuzz 0: c(S) = 0, c(B) = 1; defuzz 1: centroids of the Gaussian output sets truncated to [0, 1] \
(= product implication, sum aggregation, centroid).</p>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &FuzzyPdControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut FuzzyPdControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &mut self.v;
        self.law = Some(ErrorLaw::from_param(v.error_law)?);
        let defuzz = defuzz_from_param(v.defuzz)?;
        let inertia = Vector3::new(
            check::positive("inertia_xx", v.inertia_xx)?,
            check::positive("inertia_yy", v.inertia_yy)?,
            check::positive("inertia_zz", v.inertia_zz)?,
        );
        let wn = check::positive("wn", v.wn)?;
        let tr = check::positive("t_r", v.t_r)?;
        let kp_lo = check::non_negative("kp_min_factor", v.kp_min_factor)?;
        let kp_hi = check::non_negative("kp_max_factor", v.kp_max_factor)?;
        let kd_lo = check::non_negative("kd_min_factor", v.kd_min_factor)?;
        let kd_hi = check::non_negative("kd_max_factor", v.kd_max_factor)?;
        check::positive("e_scale", v.e_scale)?;
        check::positive("edot_scale", v.edot_scale)?;
        let fuzzy = PdFuzzySystem::new(v.mf_half_width, v.sigma, defuzz).map_err(|e| format!("parameters mf_half_width / sigma: {e}"))?;
        let kr = inertia * (wn * wn);
        [v.kr_x, v.kr_y, v.kr_z] = kr.into();
        [v.kp_min_x, v.kp_min_y, v.kp_min_z] = (kr * kp_lo).into();
        [v.kp_max_x, v.kp_max_y, v.kp_max_z] = (kr * kp_hi).into();
        [v.kd_min_x, v.kd_min_y, v.kd_min_z] = (kr * (kd_lo * tr)).into();
        [v.kd_max_x, v.kd_max_y, v.kd_max_z] = (kr * (kd_hi * tr)).into();
        (v.c_small, v.c_big) = (fuzzy.c_small, fuzzy.c_big);
        self.fuzzy = Some(fuzzy);
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let law = self.law.ok_or("controller was not initialized")?;
        let fuzzy = self.fuzzy.ok_or("controller was not initialized")?;
        let inp = self.v.inputs();
        check_unit_quaternions(&inp)?;
        let v = &mut self.v;
        let e = law.error(&inp);
        let (kp_min, kp_max) = (Vector3::new(v.kp_min_x, v.kp_min_y, v.kp_min_z), Vector3::new(v.kp_max_x, v.kp_max_y, v.kp_max_z));
        let (kd_min, kd_max) = (Vector3::new(v.kd_min_x, v.kd_min_y, v.kd_min_z), Vector3::new(v.kd_max_x, v.kd_max_y, v.kd_max_z));
        let mut kp = Vector3::zeros();
        let mut kd = Vector3::zeros();
        for i in 0..3 {
            let (kpn, kdn) = fuzzy.infer(e[i] / v.e_scale, -inp.w[i] / v.edot_scale);
            kp[i] = kp_min[i] + (kp_max[i] - kp_min[i]) * kpn;
            kd[i] = kd_min[i] + (kd_max[i] - kd_min[i]) * kdn;
        }
        let torque = kp.component_mul(&e) - kd.component_mul(&inp.w);
        v.set_torque(&torque);
        [v.kp_x, v.kp_y, v.kp_z] = kp.into();
        [v.kd_x, v.kd_y, v.kd_z] = kd.into();
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _exp: &Experiment) -> ModelResult {
        Ok(()) // static law
    }
}
