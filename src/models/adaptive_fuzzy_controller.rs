//! `AdaptiveFuzzyController`: paper 000's adaptive-fuzzy attitude law (spec controllers.md §1.7): the
//! MRAC law of `mrac_controller` whose reference model has per-axis λ1, λ2 set by the fuzzy system of
//! `FuzzyPdController` from the model's own error to the command.

use serde::{Deserialize, Serialize};

use crate::declare_mrac_controller_variables;
use crate::math::fuzzy::PdFuzzySystem;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::fuzzy_pd_controller::defuzz_from_param;
use crate::models::mrac_controller::{initial_inertia, mrac_outputs, MracCoordinates, MracCore, MracState, ReferenceGains};

declare_mrac_controller_variables! {
    pub struct AdaptiveFuzzyControllerVars {
        45 => lambda1_x: Real = 0.0, Output, Continuous, "1/s", "Current reference-model damping lambda1, x";
        46 => lambda1_y: Real = 0.0, Output, Continuous, "1/s", "Current reference-model damping lambda1, y";
        47 => lambda1_z: Real = 0.0, Output, Continuous, "1/s", "Current reference-model damping lambda1, z";
        48 => lambda2_x: Real = 0.0, Output, Continuous, "1/s2", "Current reference-model stiffness lambda2, x";
        49 => lambda2_y: Real = 0.0, Output, Continuous, "1/s2", "Current reference-model stiffness lambda2, y";
        50 => lambda2_z: Real = 0.0, Output, Continuous, "1/s2", "Current reference-model stiffness lambda2, z";
        111 => lambda1_min: Real = 2.8284271247461903, Parameter, Fixed, "1/s", "Lower end of lambda1 (damping), 2 sqrt(2) (project choice)";
        112 => lambda1_max: Real = 4.0, Parameter, Fixed, "1/s", "Upper end of lambda1 (project choice)";
        113 => lambda2_min: Real = 0.5, Parameter, Fixed, "1/s2", "Lower end of lambda2 (stiffness) (project choice)";
        114 => lambda2_max: Real = 2.0, Parameter, Fixed, "1/s2", "Upper end of lambda2 (project choice); lambda1_min^2 >= 4 lambda2_max is required";
        115 => e_scale: Real = 1.0, Parameter, Fixed, "", "Fuzzy input normalisation of e_m = r - x_m";
        116 => edot_scale: Real = 0.5, Parameter, Fixed, "1/s", "Fuzzy input normalisation of edot_m = -x_m'";
        117 => sigma: Real = 0.25, Parameter, Fixed, "", "Width of the Gaussian output sets Small and Big";
        118 => mf_half_width: Real = 0.3333333333333333, Parameter, Fixed, "", "Half-width of the seven triangular input sets (>= 1/3)";
        121 => defuzz: Integer = 0, Parameter, Fixed, "", "Defuzzification: 0 = c(S) = 0, c(B) = 1; 1 = truncated-centroid representatives";
        206 => c_small: Real = 0.0, CalculatedParameter, Fixed, "", "Representative value c(S) of the output set Small";
        207 => c_big: Real = 0.0, CalculatedParameter, Fixed, "", "Representative value c(B) of the output set Big";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AdaptiveFuzzyController {
    v: AdaptiveFuzzyControllerVars,
    core: Option<MracCore>,
    st: MracState,
}

impl Model for AdaptiveFuzzyController {
    type Vars = AdaptiveFuzzyControllerVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AdaptiveFuzzyController",
        description: "Paper 000 adaptive-fuzzy attitude controller: MRAC whose reference-model lambda1, lambda2 are fuzzy-scheduled",
        source: "paper 000 §7, Eqs. 48, 54-57; shared/spec controllers.md §1.5-1.7",
        equations_html: "<pre>MracController with, per axis and at every instant,\n\
e_m = r - x_m,  edot_m = -x_m'          (fuzzy inputs, scaled by e_scale, edot_scale; sets and tables of FuzzyPdController)\n\
lambda2 = lambda2_min + (lambda2_max - lambda2_min) k'_p      (stiffness from the k_p table)\n\
lambda1 = lambda1_min + (lambda1_max - lambda1_min) k'_d      (damping from the k_d table)\n\
x_m'' = lambda2 (r - x_m) - lambda1 x_m'\n\
requirement checked at initialization: lambda1_min^2 >= 4 lambda2_max (real negative model roots)</pre>",
        feedthrough: Feedthrough::AllInputs,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &AdaptiveFuzzyControllerVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut AdaptiveFuzzyControllerVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &mut self.v;
        let coordinates = MracCoordinates::from_param(v.coordinates)?;
        let defuzz = defuzz_from_param(v.defuzz)?;
        let (i0, imin) = initial_inertia(
            [("inertia_xx", v.inertia_xx), ("inertia_yy", v.inertia_yy), ("inertia_zz", v.inertia_zz)],
            [("ihat0_x", v.ihat0_x), ("ihat0_y", v.ihat0_y), ("ihat0_z", v.ihat0_z)],
            v.ihat_min_ratio,
        )?;
        let l1min = check::positive("lambda1_min", v.lambda1_min)?;
        let l1max = check::positive("lambda1_max", v.lambda1_max)?;
        let l2min = check::positive("lambda2_min", v.lambda2_min)?;
        let l2max = check::positive("lambda2_max", v.lambda2_max)?;
        if l1max < l1min || l2max < l2min {
            return Err(format!("need lambda1_min <= lambda1_max and lambda2_min <= lambda2_max, got [{l1min}, {l1max}] and [{l2min}, {l2max}]"));
        }
        if l1min * l1min < 4.0 * l2max * (1.0 - 1e-12) {
            return Err(format!(
                "lambda1_min^2 = {} < 4 lambda2_max = {}: the reference model could get complex roots (paper 000 requires two real negative roots)",
                l1min * l1min,
                4.0 * l2max
            ));
        }
        let e_scale = check::positive("e_scale", v.e_scale)?;
        let edot_scale = check::positive("edot_scale", v.edot_scale)?;
        let fuzzy = PdFuzzySystem::new(v.mf_half_width, v.sigma, defuzz).map_err(|e| format!("parameters mf_half_width / sigma: {e}"))?;
        let gains = ReferenceGains::Fuzzy { fuzzy, lambda1_min: l1min, lambda1_max: l1max, lambda2_min: l2min, lambda2_max: l2max, e_scale, edot_scale };
        let core = MracCore { coordinates, lambda: check::positive("lambda", v.lambda)?, gamma: check::non_negative("gamma", v.gamma)?, ihat_min: imin, gains };
        [v.ihat_init_x, v.ihat_init_y, v.ihat_init_z] = i0;
        [v.ihat_min_x, v.ihat_min_y, v.ihat_min_z] = imin;
        (v.c_small, v.c_big) = (fuzzy.c_small, fuzzy.c_big);
        self.core = Some(core);
        self.st = MracState { xm: [0.0; 3], xm_dot: [0.0; 3], ihat: i0, started: false };
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let core = self.core.ok_or("controller was not initialized")?;
        let inp = self.v.inputs();
        let o = mrac_outputs(&core, &self.st, &inp)?;
        self.v.set_mrac_outputs(&o);
        let v = &mut self.v;
        (v.lambda1_x, v.lambda1_y, v.lambda1_z) = (o.sig.lambda1.x, o.sig.lambda1.y, o.sig.lambda1.z);
        (v.lambda2_x, v.lambda2_y, v.lambda2_z) = (o.sig.lambda2.x, o.sig.lambda2.y, o.sig.lambda2.z);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let core = self.core.ok_or("controller was not initialized")?;
        self.st = core.advance(&self.st, &self.v.inputs(), h)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_root_condition_is_checked() {
        let mut m = AdaptiveFuzzyController::default();
        assert!(m.initialize(&Experiment::default()).is_ok(), "defaults: (2 sqrt 2)^2 = 8 = 4 * 2");
        m.v.lambda2_max = 2.1;
        let e = m.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("lambda1_min"), "{e}");
    }

    #[test]
    fn lambdas_stay_in_range() {
        let mut m = AdaptiveFuzzyController::default();
        m.initialize(&Experiment::default()).unwrap();
        let core = m.core.unwrap();
        for i in 0..=40 {
            for j in 0..=40 {
                let (l1, l2) = core.gains.axis(-2.0 + 0.1 * i as f64, -2.0 + 0.1 * j as f64);
                assert!((2.0 * 2f64.sqrt() - 1e-12..=4.0 + 1e-12).contains(&l1) && (0.5 - 1e-12..=2.0 + 1e-12).contains(&l2));
                assert!(l1 * l1 >= 4.0 * l2 - 1e-12, "real roots");
            }
        }
    }
}
