//! `AdaptiveFuzzyController`: paper 000's adaptive-fuzzy attitude law: the MRAC law (`shared::mrac`)
//! whose reference model has per-axis λ1, λ2 set by the fuzzy system of `FuzzyPdController` from the
//! model's own error to the command.

use serde::{Deserialize, Serialize};

use super::shared::mrac::{Mrac, MracVariables, ReferenceGains};
use super::shared::AttitudeControllerPorts;
use crate::declare_variables;
use crate::math::fuzzy::{Defuzz, PdFuzzySystem};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct AdaptiveFuzzyControllerVars {
        ports: AttitudeControllerPorts;
        mrac: MracVariables;
        45 => lambda1: Vec3 = [0.0; 3], Output, "1/s", "Current reference-model damping lambda1";
        48 => lambda2: Vec3 = [0.0; 3], Output, "1/s2", "Current reference-model stiffness lambda2";
        111 => lambda1_min: Real = 2.8284271247461903, Parameter, "1/s", "Lower end of lambda1 (damping), 2 sqrt(2) (project choice)", Positive;
        112 => lambda1_max: Real = 4.0, Parameter, "1/s", "Upper end of lambda1 (project choice)", Positive;
        113 => lambda2_min: Real = 0.5, Parameter, "1/s2", "Lower end of lambda2 (stiffness) (project choice)", Positive;
        114 => lambda2_max: Real = 2.0, Parameter, "1/s2", "Upper end of lambda2 (project choice); lambda1_min^2 >= 4 lambda2_max is required", Positive;
        115 => e_scale: Real = 1.0, Parameter, "", "Fuzzy input normalisation of e_m = r - x_m", Positive;
        116 => edot_scale: Real = 0.5, Parameter, "1/s", "Fuzzy input normalisation of edot_m = -x_m'", Positive;
        117 => sigma: Real = 0.25, Parameter, "", "Width of the Gaussian output sets Small and Big", Positive;
        118 => mf_half_width: Real = 0.3333333333333333, Parameter, "", "Half-width of the seven triangular input sets (>= 1/3)";
        122 => defuzz: Integer = 0, Parameter, "", "Defuzzification: 0 = c(S) = 0, c(B) = 1; 1 = truncated-centroid representatives", Choice(Defuzz::CODES);
        215 => c_small: Real = 0.0, CalculatedParameter, "", "Representative value c(S) of the output set Small";
        216 => c_big: Real = 0.0, CalculatedParameter, "", "Representative value c(B) of the output set Big";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct AdaptiveFuzzyController(Mrac);

impl Model for AdaptiveFuzzyController {
    type Vars = AdaptiveFuzzyControllerVars;
    const EVOLVING: &'static [&'static str] = &["st"];
    const INFO: ModelInfo = ModelInfo {
        name: "AdaptiveFuzzyController",
        description: "Adaptive-fuzzy attitude controller: MRAC whose reference-model lambda1, lambda2 are fuzzy-scheduled",
        source: "[Navabi-2019], §7, Eqs. 48, 54-57",
        equations_html: "<pre>MracController with, per axis and at every instant,\n\
e_m = r - x_m,  edot_m = -x_m'          (fuzzy inputs, scaled by e_scale, edot_scale; sets and tables of FuzzyPdController)\n\
lambda2 = lambda2_min + (lambda2_max - lambda2_min) k'_p      (stiffness from the k_p table)\n\
lambda1 = lambda1_min + (lambda1_max - lambda1_min) k'_d      (damping from the k_d table)\n\
x_m'' = lambda2 (r - x_m) - lambda1 x_m'\n\
requirement checked at initialization: lambda1_min^2 >= 4 lambda2_max (real negative model roots)</pre>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut AdaptiveFuzzyControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let (l1min, l1max, l2min, l2max) = (v.lambda1_min, v.lambda1_max, v.lambda2_min, v.lambda2_max);
        check::ordered("lambda1_min", l1min, "lambda1_max", l1max)?;
        check::ordered("lambda2_min", l2min, "lambda2_max", l2max)?;
        if l1min * l1min < 4.0 * l2max * (1.0 - 1e-12) {
            return Err(format!(
                "lambda1_min^2 = {} < 4 lambda2_max = {}: the reference model could get complex roots ([Navabi-2019] requires two real negative roots)",
                l1min * l1min,
                4.0 * l2max
            ));
        }
        let defuzz = Defuzz::from_param("defuzz", v.defuzz)?;
        let fuzzy = PdFuzzySystem::new(v.mf_half_width, v.sigma, defuzz).map_err(|e| format!("parameters mf_half_width / sigma: {e}"))?;
        let gains = ReferenceGains::Fuzzy {
            fuzzy,
            lambda1_min: l1min,
            lambda1_max: l1max,
            lambda2_min: l2min,
            lambda2_max: l2max,
            e_scale: v.e_scale,
            edot_scale: v.edot_scale,
        };
        (v.c_small, v.c_big) = (fuzzy.c_small, fuzzy.c_big);
        Ok(AdaptiveFuzzyController(Mrac::new(&mut v.mrac, gains)?))
    }

    fn outputs(&self, v: &mut AdaptiveFuzzyControllerVars, _t: f64) -> ModelResult {
        let o = self.0.outputs(&mut v.ports, &mut v.mrac)?;
        (v.lambda1, v.lambda2) = (o.sig.lambda1, o.sig.lambda2);
        Ok(())
    }

    fn step(&mut self, v: &AdaptiveFuzzyControllerVars, _t: f64, h: f64) -> ModelResult {
        self.0.step(&v.ports, h)
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.0.validate(&fresh.0)
    }

    crate::mrac_model_exchange!();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    #[test]
    fn reference_root_condition_is_checked() {
        let mut m = Fmu::<AdaptiveFuzzyController>::default();
        assert!(m.initialize(&Experiment::default()).is_ok(), "defaults: (2 sqrt 2)^2 = 8 = 4 * 2");
        m.v.lambda2_max = 2.1;
        let e = m.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("lambda1_min"), "{e}");
    }

    #[test]
    fn lambdas_stay_in_range() {
        let mut m = Fmu::<AdaptiveFuzzyController>::default();
        m.initialize(&Experiment::default()).unwrap();
        let core = m.model().0.core;
        for i in 0..=40 {
            for j in 0..=40 {
                let (l1, l2) = core.gains.axis(-2.0 + 0.1 * i as f64, -2.0 + 0.1 * j as f64);
                assert!((2.0 * 2f64.sqrt() - 1e-12..=4.0 + 1e-12).contains(&l1) && (0.5 - 1e-12..=2.0 + 1e-12).contains(&l2));
                assert!(l1 * l1 >= 4.0 * l2 - 1e-12, "real roots");
            }
        }
    }
}
