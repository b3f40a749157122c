//! `Triad`: the attitude from two vector observations (sun sensor and magnetometer) by the TRIAD
//! construction, anchored on the more accurate one.

use serde::{Deserialize, Serialize};

use super::shared::{check_finite, TwoObservations};
use crate::declare_variables;
use crate::math::wahba::{quat_nonneg, triad};
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct TriadVars {
        obs: TwoObservations;
        120 => anchor: Integer = 0, Parameter, "", "Observation matched exactly (the more accurate one): 0 = sun, 1 = magnetic field", Choice(&[0, 1]);
    }
}

/// A static law: no state.
#[derive(Clone, Serialize, Deserialize)]
pub struct Triad;

impl Model for Triad {
    type Vars = TriadVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Triad",
        description: "TRIAD attitude determination from the sun sensor's and the magnetometer's directions and their reference directions",
        source: "TRIAD algorithm as presented in [Markley-Crassidis-2014] Sec. 5.2",
        equations_html: "<pre>unit vectors: s_B = sun_meas/|sun_meas|, m_B = b_meas/|b_meas|, s_R, m_R likewise\n\
anchor 0: (v1, v2) = (s, m);   anchor 1: (v1, v2) = (m, s)      (v1 is matched exactly)\n\
triads:   t1 = v1,  t2 = (v1 x v2)/|v1 x v2|,  t3 = t1 x t2    (in B and in R)\n\
A      = [t1_B t2_B t3_B] [t1_R t2_R t3_R]^T                    (v_B = A v_R)\n\
q_est  = Shepperd's quaternion of A, sign chosen so that q_est_w >= 0</pre>\n\
<p>Refused with an error (never a NaN output): an input vector that is zero or not finite, and a pair \
of directions (in B or in R) closer than <code>min_separation</code> to parallel or antiparallel, where the \
rotation about their common line is undetermined. TRIAD discards the second vector's component along \
the first: with noisy inputs it is exact in v1 and suboptimal in v2 (use <code>Quest</code> for the \
weighted optimum). The output sign flips where q_est_w crosses 0 (both signs are the same attitude).</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut TriadVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(Triad)
    }

    fn outputs(&self, v: &mut TriadVars, _t: f64) -> ModelResult {
        let o = &v.obs;
        for (name, x) in [("sun_meas", &o.sun_meas), ("b_meas", &o.b_meas), ("sun_ref", &o.sun_ref), ("b_ref", &o.b_ref)] {
            check_finite(name, x)?;
        }
        let a = if v.anchor == 0 {
            triad(&o.sun_meas, &o.b_meas, &o.sun_ref, &o.b_ref, o.min_separation)
        } else {
            triad(&o.b_meas, &o.sun_meas, &o.b_ref, &o.sun_ref, o.min_separation)
        }
        .map_err(|e| format!("TRIAD: {e}"))?;
        v.obs.q_est = quat_nonneg(&a);
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
    fn exact_observations_and_refused_geometry() {
        let q = quat_from_euler321(0.4, -1.0, 2.5);
        let mut f = Fmu::<Triad>::default();
        f.initialize(&Experiment::default()).unwrap();
        let (s, b) = (Vector3::new(0.2, -0.9, 0.3), Vector3::new(2e-5, 1e-5, -3e-5));
        f.v.obs.sun_ref = s;
        f.v.obs.b_ref = b;
        f.v.obs.sun_meas = attitude_matrix(&q) * s.normalize();
        f.v.obs.b_meas = attitude_matrix(&q) * b;
        f.outputs(0.0).unwrap();
        let want = if q.w < 0.0 { -q } else { q };
        assert!((f.v.obs.q_est.coords - want.coords).norm() < 1e-14, "{:?}", f.v.obs.q_est);
        f.v.obs.b_meas = f.v.obs.sun_meas * 4e-5;
        let e = f.outputs(0.0).unwrap_err();
        assert!(e.starts_with("TRIAD: the two body-frame observations are (anti)parallel"), "{e}");
    }
}
