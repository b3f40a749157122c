//! `AttitudeMetrics`: running performance integrals of an attitude run: EULERINT (paper 000 Eq. 5),
//! ISE, ISF and control effort.

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{euler321_from_quat, euler_axis_angle, wrap_pi};
use crate::model::{check_finite_state, Experiment, Feedthrough, Model, ModelInfo, ModelResult, StateDecl};

declare_variables! {
    pub struct AttitudeMetricsVars {
        0 => q: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Attitude quaternion";
        4 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Input, "", "Commanded attitude quaternion";
        8 => torque_applied: Vec3 = [0.0; 3], Input, "N.m", "Applied control torque, body axes";
        20 => eulerint_deg_s: Real = 0.0, Output, "deg.s", "EULERINT: integral of alpha_deg over [0, t] ([Navabi-2019] Eq. 5)";
        21 => alpha_deg: Real = 0.0, Output, "deg", "Euler-axis angle between body and reference ([Navabi-2019] Eq. 4)";
        22 => ise: Real = 0.0, Output, "rad2.s", "Integral of the squared 321 Euler-angle errors, summed over axes";
        23 => isf: Real = 0.0, Output, "N2.m2.s", "Integral of the squared applied torques, summed over axes";
        24 => effort_abs: Real = 0.0, Output, "N.m.s", "Integral of the sum of absolute applied torques";
        25 => effort_sq: Real = 0.0, Output, "N2.m2.s", "Integral of the squared norm of the applied torque (= isf)";
    }
}

/// Integrals [eulerint, ise, isf, effort_abs] at the current communication point.
#[derive(Clone, Serialize, Deserialize)]
pub struct AttitudeMetrics {
    integrals: [f64; 4],
}

fn alpha(v: &AttitudeMetricsVars) -> f64 {
    euler_axis_angle(&v.q, &v.q_ref)
}

/// Integrands [alpha_deg, Σe², Στ², Σ|τ|] at the inputs held.
fn integrands(v: &AttitudeMetricsVars) -> [f64; 4] {
    let e = euler321_from_quat(&v.q);
    let r = euler321_from_quat(&v.q_ref);
    let err: f64 = (0..3).map(|i| wrap_pi(r[i] - e[i]).powi(2)).sum();
    let tau = v.torque_applied;
    [alpha(v).to_degrees(), err, tau.norm_squared(), tau.abs().sum()]
}

impl Model for AttitudeMetrics {
    type Vars = AttitudeMetricsVars;
    const EVOLVING: &'static [&'static str] = &["integrals"];
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudeMetrics",
        description: "Running attitude performance integrals: EULERINT, ISE, ISF and control effort",
        source: "EULERINT: [Navabi-2019], Eqs. 4-5; ISE and ISF as in [T2FSMC-LEO]",
        equations_html: "<pre>alpha      = 2 atan2(|q_E,v|, |q_E,w|),  q_E = q* (x) q_ref    (Euler-axis angle, [Navabi-2019] Eq. 4)\n\
eulerint   = integral of alpha [deg] dt                         ([Navabi-2019] Eq. 5)\n\
ise        = integral of sum_i wrap(euler321(q_ref) - euler321(q))_i^2 dt\n\
isf        = effort_sq = integral of |tau_applied|^2 dt\n\
effort_abs = integral of sum_i |tau_applied,i| dt</pre>\n\
<p>Co-Simulation: left-rectangle rule on the communication grid: I(t_k+1) = I(t_k) + f(t_k) * step, with the inputs of t_k \
(consistent with inputs held over the step). Integral outputs at t are over [start, t].</p>\n\
<p>Model Exchange: the four integrals are the continuous states state_eulerint, state_ise, state_isf and state_effort_abs \
with the integrands above as derivatives; the importer's solver integrates them together with the plant.</p>",
        feedthrough: Feedthrough::Some(&[("alpha_deg", &["q_w", "q_x", "q_y", "q_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"])]),
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut AttitudeMetricsVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(AttitudeMetrics { integrals: [0.0; 4] })
    }

    fn outputs(&self, v: &mut AttitudeMetricsVars, _t: f64) -> ModelResult {
        let [eulerint, ise, isf, effort_abs] = self.integrals;
        let alpha_deg = alpha(v).to_degrees();
        (v.eulerint_deg_s, v.alpha_deg, v.ise, v.isf, v.effort_abs, v.effort_sq) = (eulerint, alpha_deg, ise, isf, effort_abs, isf);
        Ok(())
    }

    fn step(&mut self, v: &AttitudeMetricsVars, _t: f64, h: f64) -> ModelResult {
        for (acc, x) in self.integrals.iter_mut().zip(integrands(v)) {
            *acc += x * h;
        }
        Ok(())
    }

    fn validate(&self, _fresh: &Self) -> ModelResult {
        check_finite_state("integrals", &self.integrals)
    }

    // Model Exchange: the integrals are the states, the integrands their derivatives.
    const STATES: Option<&'static [StateDecl]> = Some(&[
        StateDecl::new("state_eulerint", "deg.s", "Continuous state: EULERINT, integral of alpha_deg").depends_on(&Q_AND_REF),
        StateDecl::new("state_ise", "rad2.s", "Continuous state: ISE, integral of the squared 321 Euler-angle errors").depends_on(&Q_AND_REF),
        StateDecl::new("state_isf", "N2.m2.s", "Continuous state: ISF, integral of the squared applied torques").depends_on(&TORQUE),
        StateDecl::new("state_effort_abs", "N.m.s", "Continuous state: integral of the sum of absolute applied torques").depends_on(&TORQUE),
    ]);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(&self.integrals);
    }
    fn set_states(&mut self, x: &[f64]) {
        self.integrals.copy_from_slice(x);
    }
    fn derivatives(&self, v: &AttitudeMetricsVars, _t: f64, dx: &mut [f64]) -> ModelResult {
        dx.copy_from_slice(&integrands(v));
        Ok(())
    }
}

const Q_AND_REF: [&str; 8] = ["q_w", "q_x", "q_y", "q_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"];
const TORQUE: [&str; 3] = ["torque_applied_x", "torque_applied_y", "torque_applied_z"];
