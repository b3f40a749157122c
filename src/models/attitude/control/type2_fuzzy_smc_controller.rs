//! `Type2FuzzySmcController`: paper 003's sliding-mode attitude law whose switching gain is scheduled
//! per axis by an interval type-2 fuzzy system of the error and its rate (Karnik–Mendel type
//! reduction in `crate::math::type2_fuzzy`; the law in `shared::smc`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::shared::smc::{SmcLaw, SmcVariables};
use super::shared::AttitudeControllerPorts;
use crate::declare_variables;
use crate::math::type2_fuzzy::SmcGainFuzzy;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct Type2FuzzySmcControllerVars {
        ports: AttitudeControllerPorts;
        smc: SmcVariables;
        36 => fuzzy_y: Vec3 = [0.0; 3], Output, "", "Type-reduced fuzzy output y = (y_l + y_r)/2 per axis, in [-1, 1]";
        45 => fuzzy_y_l: Vec3 = [0.0; 3], Output, "", "Left end y_l of the Karnik-Mendel type-reduced interval per axis";
        48 => fuzzy_y_r: Vec3 = [0.0; 3], Output, "", "Right end y_r of the Karnik-Mendel type-reduced interval per axis";
        115 => e_scale: Real = 0.05, Parameter, "", "Error normalisation: e_bar = clamp(q_e,v,i / e_scale, -1, 1)", Positive;
        116 => edot_scale: Real = 0.01, Parameter, "1/s", "Error-rate normalisation: edot_bar = clamp(dq_e,v,i/dt / edot_scale, -1, 1)", Positive;
        123 => table_transpose: Integer = 0, Parameter, "", "Rule table reading: 0 = rows e, columns edot; 1 = transposed", Choice(SWITCH);
        132 => kappa: Real = 0.5, Parameter, "", "Gain schedule depth: K_i = k (1 + kappa y_i)", Range(0.0, 1.0);
        133 => sigma_lo: Real = 0.3, Parameter, "", "Lower width of the interval Gaussian input sets N, Z, P (centres -1, 0, 1)", Positive;
        134 => sigma_up: Real = 0.5, Parameter, "", "Upper width of the interval Gaussian input sets (>= sigma_lo)", Positive;
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct Type2FuzzySmcController {
    law: SmcLaw,
    fuzzy: SmcGainFuzzy,
}

impl Model for Type2FuzzySmcController {
    type Vars = Type2FuzzySmcControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Type2FuzzySmcController",
        description: "Quaternion sliding-mode attitude controller with the switching gain scheduled by an interval type-2 fuzzy system",
        source: "[T2FSMC-LEO]; law, sets and type reduction: project choice keeping the paper's structure",
        equations_html: "<pre>q_e   = q_ref* (x) q, sign flipped so that q_e,w >= 0\n\
w_e   = w - A(q_e) w_ref,   s = w_e + lambda q_e,v,   q_e,v' = 1/2 (q_e,w w_e + q_e,v x w_e)\n\
T_eq  = w x (I w + h_w) - I (lambda q_e,v' + w_e x A(q_e) w_ref)\n\
T     = T_eq - K (.) sat(s / Phi),   K_i = k (1 + kappa y_i)\n\
per axis: e_bar = clamp(q_e,v,i / e_scale, -1, 1),  edot_bar = clamp(q_e,v,i' / edot_scale, -1, 1)\n\
sets N, Z, P: Gaussians at -1, 0, 1 with width in [sigma_lo, sigma_up] (lower / upper membership)\n\
rule firing [f, f_up] = product of lower / upper memberships; consequents N = -1, Z = 0, P = 1:\n\
            edot=N  edot=Z  edot=P\n\
   e = N      P       P       Z\n\
   e = Z      Z       N       Z\n\
   e = P      Z       P       P          (table_transpose = 1: rows edot, columns e)\n\
Karnik-Mendel: y_l = min over L, y_r = max over R of the switch-point weighted averages\n\
(exhaustive search over all 10 switch points), y = (y_l + y_r)/2</pre>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut Type2FuzzySmcControllerVars, _exp: &Experiment) -> Result<Self, String> {
        let law = v.smc.law()?;
        let fuzzy = SmcGainFuzzy::new(v.sigma_lo, v.sigma_up, v.table_transpose == 1).map_err(|e| format!("parameters sigma_lo / sigma_up: {e}"))?;
        Ok(Type2FuzzySmcController { law, fuzzy })
    }

    fn outputs(&self, v: &mut Type2FuzzySmcControllerVars, _t: f64) -> ModelResult {
        let sig = self.law.signals(&v.ports, &v.smc.h_wheel)?;
        let (mut y, mut y_l, mut y_r) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        for i in 0..3 {
            let e = (sig.q_ev[i] / v.e_scale).clamp(-1.0, 1.0);
            let d = (sig.q_ev_dot[i] / v.edot_scale).clamp(-1.0, 1.0);
            let o = self.fuzzy.infer(e, d).ok_or_else(|| {
                format!("type-2 fuzzy gain: no rule fires for axis {i} (e_bar = {e}, edot_bar = {d}); increase sigma_lo / sigma_up")
            })?;
            (y[i], y_l[i], y_r[i]) = (o.y, o.y_l, o.y_r);
        }
        let k = y.map(|yi| v.smc.k_switch * (1.0 + v.kappa * yi));
        v.ports.torque_cmd = v.smc.finish(&self.law, &sig, &k)?;
        (v.fuzzy_y, v.fuzzy_y_l, v.fuzzy_y_r) = (y, y_l, y_r);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;
    use crate::model::Fmu;

    #[test]
    fn gain_follows_the_fuzzy_schedule() {
        let mut c = Fmu::<Type2FuzzySmcController>::default();
        c.initialize(&Experiment::default()).unwrap();
        // at the reference and at rest: e = edot = 0, rule (Z, Z) -> N dominates, gain below k
        c.outputs(0.0).unwrap();
        assert!(c.v.fuzzy_y.iter().all(|&y| y < -0.5), "{:?}", c.v.fuzzy_y);
        assert!(c.v.smc.k_gain.iter().all(|&k| k < 0.005 && k > 0.0025));
        // large error, no rate: (P or N, Z) -> P, gain above k
        c.v.ports.q_ref = quat_from_euler321(0.349, -0.262, 0.3);
        c.outputs(0.0).unwrap();
        assert!(c.v.fuzzy_y.iter().all(|&y| y > 0.3), "{:?}", c.v.fuzzy_y);
        let k = c.v.smc.k_gain;
        let sat = c.v.smc.s.map(|s| (s / 0.005).clamp(-1.0, 1.0));
        assert!((c.v.ports.torque_cmd - (c.v.smc.torque_eq - k.component_mul(&sat))).norm() < 1e-15);
        // kappa = 0 is the plain sliding-mode law
        c.v.kappa = 0.0;
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.0).unwrap();
        assert!(c.v.smc.k_gain.iter().all(|&k| k == 0.005));
    }

    #[test]
    fn bad_widths_are_refused_with_the_parameter_name() {
        let mut c = Fmu::<Type2FuzzySmcController>::default();
        (c.v.sigma_lo, c.v.sigma_up) = (0.6, 0.5);
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("sigma_up"), "{e}");
    }
}
