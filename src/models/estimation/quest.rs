//! `Quest`: the optimal attitude (Wahba's problem) from up to four weighted vector observations by
//! Davenport's q-method, solved by a symmetric eigen-decomposition, and the loss at the optimum.

use serde::{Deserialize, Serialize};

use super::shared::{check_finite, TwoObservations};
use crate::declare_variables;
use crate::math::wahba::{q_method, Observation};
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct QuestVars {
        obs: TwoObservations;
        6 => v3_meas: Vec3 = [0.0, 0.0, 1.0], Input, "", "Third observed direction, body axes (used when weight_v3 > 0; normalised here)";
        9 => v4_meas: Vec3 = [0.0, 0.0, 1.0], Input, "", "Fourth observed direction, body axes (used when weight_v4 > 0; normalised here)";
        18 => v3_ref: Vec3 = [0.0, 0.0, 1.0], Input, "", "Third direction in the reference frame R";
        21 => v4_ref: Vec3 = [0.0, 0.0, 1.0], Input, "", "Fourth direction in the reference frame R";
        44 => loss: Real = 0.0, Output, "", "Wahba's loss at the optimum, L = 1/2 sum a_i |b_i - A(q_est) r_i|^2 (unit vectors, the given weights)";
        101 => weight_sun: Real = 1.0, Parameter, "", "Weight a of the sun observation (e.g. 1/sigma^2 of its angular noise; 0 = unused)", NonNegative;
        102 => weight_b: Real = 1.0, Parameter, "", "Weight a of the magnetic-field observation (0 = unused)", NonNegative;
        103 => weight_v3: Real = 0.0, Parameter, "", "Weight a of the third observation (0 = unused)", NonNegative;
        104 => weight_v4: Real = 0.0, Parameter, "", "Weight a of the fourth observation (0 = unused)", NonNegative;
    }
}

const NAMES: [&str; 4] = ["sun", "b", "v3", "v4"];

/// A static law: no state.
#[derive(Clone, Serialize, Deserialize)]
pub struct Quest;

impl Model for Quest {
    type Vars = QuestVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Quest",
        description: "Optimal attitude from up to four weighted vector observations (Wahba's problem, Davenport's q-method solved by a symmetric eigen-decomposition) and the loss at the optimum",
        source: "Wahba's problem and Davenport's q-method (the problem QUEST solves) as presented in [Markley-Crassidis-2014] Sec. 5.3-5.4",
        equations_html: "<pre>observations i = sun, b, v3, v4 with weight a_i > 0 (zero weights are skipped):\n\
b_i, r_i = the body and reference directions, normalised\n\
L(A)   = 1/2 sum a_i |b_i - A r_i|^2 = lambda_0 - tr(A B^T),  lambda_0 = sum a_i,  B = sum a_i b_i r_i^T\n\
K      = [[S - sigma I, z], [z^T, sigma]],  S = B + B^T,  sigma = tr B,  z = sum a_i b_i x r_i\n\
q_est  = unit eigenvector of K's largest eigenvalue lambda_max, reordered scalar first, q_est_w >= 0\n\
loss   = L(A(q_est)) = lambda_0 - lambda_max (computed from the residuals)</pre>\n\
<p>QUEST proper finds lambda_max by Newton iteration on K's characteristic polynomial and needs \
sequential rotations near 180 degrees; this unit solves the same eigenproblem with a symmetric \
eigen-decomposition (nalgebra), which has neither the iteration nor the singularity and gives the \
same optimum. Refused with an error (never a NaN output): fewer than two observations of positive \
weight, an input vector that is zero or not finite, and observations whose directions (in B or in R) \
all lie within <code>min_separation</code> of one line. The output sign flips where q_est_w crosses 0.</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut QuestVars, _exp: &Experiment) -> Result<Self, String> {
        let used = [v.weight_sun, v.weight_b, v.weight_v3, v.weight_v4].iter().filter(|a| **a > 0.0).count();
        if used < 2 {
            return Err(format!(
                "parameters weight_sun = {}, weight_b = {}, weight_v3 = {}, weight_v4 = {}: at least two must be > 0",
                v.weight_sun, v.weight_b, v.weight_v3, v.weight_v4
            ));
        }
        Ok(Quest)
    }

    fn outputs(&self, v: &mut QuestVars, _t: f64) -> ModelResult {
        let o = &v.obs;
        let pairs = [(o.sun_meas, o.sun_ref, v.weight_sun), (o.b_meas, o.b_ref, v.weight_b), (v.v3_meas, v.v3_ref, v.weight_v3), (v.v4_meas, v.v4_ref, v.weight_v4)];
        let mut obs = Vec::with_capacity(4);
        for (name, (b, r, a)) in NAMES.iter().zip(pairs) {
            if a > 0.0 {
                check_finite(&format!("{name}_meas"), &b)?;
                check_finite(&format!("{name}_ref"), &r)?;
            }
            obs.push(Observation { body: b, reference: r, weight: a });
        }
        let s = q_method(&obs, &NAMES, o.min_separation).map_err(|e| format!("QUEST: {e}"))?;
        v.obs.q_est = s.q;
        v.loss = s.loss;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::{attitude_matrix, quat_from_euler321};
    use crate::model::Fmu;
    use nalgebra::Vector3;

    #[test]
    fn exact_observations_weights_and_refusals() {
        let q = quat_from_euler321(-2.0, 0.5, 1.0);
        let mut f = Fmu::<Quest>::default();
        f.v.weight_v3 = 0.5;
        f.initialize(&Experiment::default()).unwrap();
        let (s, b, r3) = (Vector3::new(0.2, -0.9, 0.3), Vector3::new(2e-5, 1e-5, -3e-5), Vector3::new(1.0, 1.0, 1.0));
        (f.v.obs.sun_ref, f.v.obs.b_ref, f.v.v3_ref) = (s, b, r3);
        let a = attitude_matrix(&q);
        (f.v.obs.sun_meas, f.v.obs.b_meas, f.v.v3_meas) = (a * s, a * b, a * r3);
        f.outputs(0.0).unwrap();
        let want = if q.w < 0.0 { -q } else { q };
        assert!((f.v.obs.q_est.coords - want.coords).norm() < 1e-14, "{:?}", f.v.obs.q_est);
        assert!(f.v.loss < 1e-28);
        f.v.v4_meas = Vector3::new(f64::NAN, 0.0, 0.0); // unused (weight 0): ignored
        f.outputs(0.0).unwrap();
        f.v.obs.b_meas = Vector3::zeros();
        let e = f.outputs(0.0).unwrap_err();
        assert!(e.contains("QUEST: vector b (body)") && e.contains("no direction"), "{e}");
        let mut g = Fmu::<Quest>::default();
        g.v.weight_b = 0.0;
        let e = g.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("at least two must be > 0"), "{e}");
    }
}
