//! `EstimateGate`: passes the estimate (q_est, w_est) to a pointing controller only while `enable` is set,
//! else the reference itself (q_ref, w_ref): the controller then sees a zero error. Feed-through, no state.

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};
use crate::models::ports::{CommandInputs, EstimateInputs};

declare_variables! {
    pub struct EstimateGateVars {
        estimate: EstimateInputs;
        command: CommandInputs;
        14 => enable: Real = 0.0, Input, "", "Gate (ModeManager's controller_enable): >= 0.5 passes the estimate, else the reference";
        20 => q: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Attitude quaternion for the controller's q input (unit norm)";
        24 => w: Vec3 = [0.0; 3], Output, "rad/s", "Body rate for the controller's w input";
    }
}

/// No state: the outputs are a function of the inputs.
#[derive(Clone, Serialize, Deserialize)]
pub struct EstimateGate {}

/// A quaternion input normalised; zero or non-finite is refused with its name.
pub(crate) fn unit_quat(name: &str, q: &Quaternion<f64>) -> Result<Quaternion<f64>, String> {
    let n = q.norm();
    if !(n.is_finite() && n > 0.0) {
        return Err(format!(
            "input quaternion {name} = [{}, {}, {}, {}] has norm {n}: a non-zero finite quaternion is needed (is it connected?)",
            q.w, q.i, q.j, q.k
        ));
    }
    Ok(q / n)
}

/// A vector input, refused when not finite.
pub(crate) fn finite_vec(name: &str, x: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    if x.iter().all(|c| c.is_finite()) {
        Ok(*x)
    } else {
        Err(format!("input {name} = {:?} is not finite", x.as_slice()))
    }
}

impl Model for EstimateGate {
    type Vars = EstimateGateVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "EstimateGate",
        description: "Estimate gate: the pointing controller sees the estimate while enabled, else the reference itself (zero error), so a law with internal state starts its mode from its initial state",
        source: "mode-dependent enabling of the AOCS control laws as in [ECSS-E-ST-60-30C]; rate error w - A(q) A(q_ref)^T w_ref as in [Markley-Crassidis-2014]; project scheme",
        equations_html: "<pre>enable &gt;= 0.5:  q = q_est/|q_est|,  w = w_est\n\
otherwise:      q = q_ref/|q_ref|,  w = w_ref</pre>\n\
<p>A pointing controller (any unit with the inputs q, w, q_ref, w_ref) forms its attitude error from q and q_ref \
and its rate error w - A(q) A(q_ref)^T w_ref; with q = q_ref this is w - w_ref, so passing w = w_ref makes both \
errors zero. Outside its mode the controller therefore sees a zero error and its internal states (integrators, \
adaptive gains) stay at their initial values: at the entry into its mode it starts from them, a reset by \
construction for any black-box unit. Both quaternions are refused when zero or not finite (an unconnected \
input), the one passed on is normalised; its sign is kept.</p>",
        feedthrough: Feedthrough::Some(&[("q", &["q_est", "q_ref", "enable"]), ("w", &["w_est", "w_ref", "enable"])]),
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut EstimateGateVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(EstimateGate {})
    }

    fn outputs(&self, v: &mut EstimateGateVars, _t: f64) -> ModelResult {
        let q_est = unit_quat("q_est", &v.estimate.q_est)?;
        let q_ref = unit_quat("q_ref", &v.command.q_ref)?;
        let w_est = finite_vec("w_est", &v.estimate.w_est)?;
        let w_ref = finite_vec("w_ref", &v.command.w_ref)?;
        if !v.enable.is_finite() {
            return Err(format!("input enable = {} is not finite", v.enable));
        }
        (v.q, v.w) = if v.enable >= 0.5 { (q_est, w_est) } else { (q_ref, w_ref) };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn gate() -> Fmu<EstimateGate> {
        let mut f = Fmu::<EstimateGate>::default();
        f.initialize(&Experiment::default()).unwrap();
        f.v.estimate.q_est = Quaternion::new(2.0, 0.0, 0.0, 2.0); // 90 deg about z, norm 2*sqrt(2)
        f.v.estimate.w_est = Vector3::new(0.1, -0.2, 0.3);
        f.v.command.q_ref = Quaternion::new(0.0, 0.0, 3.0, 0.0); // 180 deg about y, norm 3
        f.v.command.w_ref = Vector3::new(0.0, -0.001, 0.0);
        f
    }

    #[test]
    fn the_gate_passes_the_estimate_only_when_enabled() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for (enable, q, w) in [
            (0.0, [0.0, 0.0, 1.0, 0.0], [0.0, -0.001, 0.0]),
            (0.49, [0.0, 0.0, 1.0, 0.0], [0.0, -0.001, 0.0]),
            (0.5, [h, 0.0, 0.0, h], [0.1, -0.2, 0.3]),
            (1.0, [h, 0.0, 0.0, h], [0.1, -0.2, 0.3]),
        ] {
            let mut f = gate();
            f.v.enable = enable;
            f.outputs(0.0).unwrap();
            let got = [f.v.q.w, f.v.q.i, f.v.q.j, f.v.q.k];
            assert!(got.iter().zip(q).all(|(a, b)| (a - b).abs() < 1e-15), "enable {enable}: {got:?}");
            assert_eq!(f.v.w, Vector3::from(w), "enable {enable}");
        }
    }

    #[test]
    fn zero_or_non_finite_inputs_are_refused_by_name() {
        let mut f = gate();
        f.v.estimate.q_est = Quaternion::new(0.0, 0.0, 0.0, 0.0);
        let e = f.outputs(0.0).unwrap_err();
        assert!(e.contains("q_est") && e.contains("norm 0"), "{e}");
        let mut f = gate();
        f.v.command.w_ref.y = f64::NAN;
        let e = f.outputs(0.0).unwrap_err();
        assert!(e.contains("w_ref") && e.contains("not finite"), "{e}");
    }
}
