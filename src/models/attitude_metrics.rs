//! `AttitudeMetrics`: running performance integrals of an attitude run (spec
//! metrics-and-scenarios.md §1.1): EULERINT (paper 000 Eq. 5), ISE, ISF and control effort.

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{euler321_from_quat, euler_axis_angle, wrap_pi};
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct AttitudeMetricsVars {
        0 => q_w: Real = 1.0, Input, Continuous, "", "Attitude quaternion, scalar part";
        1 => q_x: Real = 0.0, Input, Continuous, "", "Attitude quaternion, x component";
        2 => q_y: Real = 0.0, Input, Continuous, "", "Attitude quaternion, y component";
        3 => q_z: Real = 0.0, Input, Continuous, "", "Attitude quaternion, z component";
        4 => q_ref_w: Real = 1.0, Input, Continuous, "", "Commanded attitude quaternion, scalar part";
        5 => q_ref_x: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, x component";
        6 => q_ref_y: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, y component";
        7 => q_ref_z: Real = 0.0, Input, Continuous, "", "Commanded attitude quaternion, z component";
        8 => torque_applied_x: Real = 0.0, Input, Continuous, "N.m", "Applied control torque, body x";
        9 => torque_applied_y: Real = 0.0, Input, Continuous, "N.m", "Applied control torque, body y";
        10 => torque_applied_z: Real = 0.0, Input, Continuous, "N.m", "Applied control torque, body z";
        20 => eulerint_deg_s: Real = 0.0, Output, Continuous, "deg.s", "EULERINT: integral of alpha_deg over [0, t] (paper 000 Eq. 5)";
        21 => alpha_deg: Real = 0.0, Output, Continuous, "deg", "Euler-axis angle between body and reference (paper 000 Eq. 4)";
        22 => ise: Real = 0.0, Output, Continuous, "rad2.s", "Integral of the squared 321 Euler-angle errors, summed over axes";
        23 => isf: Real = 0.0, Output, Continuous, "N2.m2.s", "Integral of the squared applied torques, summed over axes";
        24 => effort_abs: Real = 0.0, Output, Continuous, "N.m.s", "Integral of the sum of absolute applied torques";
        25 => effort_sq: Real = 0.0, Output, Continuous, "N2.m2.s", "Integral of the squared norm of the applied torque (= isf)";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AttitudeMetrics {
    v: AttitudeMetricsVars,
    /// Integrals [eulerint, ise, isf, effort_abs] at the current communication point.
    integrals: [f64; 4],
}

impl AttitudeMetrics {
    fn alpha(&self) -> f64 {
        let v = &self.v;
        euler_axis_angle(&Quaternion::new(v.q_w, v.q_x, v.q_y, v.q_z), &Quaternion::new(v.q_ref_w, v.q_ref_x, v.q_ref_y, v.q_ref_z))
    }

    /// Integrands [alpha_deg, Σe², Στ², Σ|τ|] at the inputs held.
    fn integrands(&self) -> [f64; 4] {
        let v = &self.v;
        let e = euler321_from_quat(&Quaternion::new(v.q_w, v.q_x, v.q_y, v.q_z));
        let r = euler321_from_quat(&Quaternion::new(v.q_ref_w, v.q_ref_x, v.q_ref_y, v.q_ref_z));
        let err: f64 = (0..3).map(|i| wrap_pi(r[i] - e[i]).powi(2)).sum();
        let tau = Vector3::new(v.torque_applied_x, v.torque_applied_y, v.torque_applied_z);
        [self.alpha().to_degrees(), err, tau.norm_squared(), tau.abs().sum()]
    }
}

impl Model for AttitudeMetrics {
    type Vars = AttitudeMetricsVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudeMetrics",
        description: "Running attitude performance integrals: EULERINT, ISE, ISF and control effort",
        source: "paper 000 Eqs. 4-5, paper 003 (ISE, ISF); shared/spec metrics-and-scenarios.md §1.1",
        equations_html: "<pre>alpha      = 2 atan2(|q_E,v|, |q_E,w|),  q_E = q* (x) q_ref    (Euler-axis angle, paper 000 Eq. 4)\n\
eulerint   = integral of alpha [deg] dt                         (paper 000 Eq. 5)\n\
ise        = integral of sum_i wrap(euler321(q_ref) - euler321(q))_i^2 dt\n\
isf        = effort_sq = integral of |tau_applied|^2 dt\n\
effort_abs = integral of sum_i |tau_applied,i| dt</pre>\n\
<p>Left-rectangle rule on the communication grid: I(t_k+1) = I(t_k) + f(t_k) * step, with the inputs of t_k \
(consistent with inputs held over the step). Integral outputs at t are over [start, t].</p>",
        feedthrough: Feedthrough::Some(&[(
            "alpha_deg",
            &["q_w", "q_x", "q_y", "q_z", "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"],
        )]),
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &AttitudeMetricsVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut AttitudeMetricsVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        self.integrals = [0.0; 4];
        Ok(())
    }

    fn update_outputs(&mut self, _t: f64) -> ModelResult {
        let alpha_deg = self.alpha().to_degrees();
        let [eulerint, ise, isf, effort_abs] = self.integrals;
        let v = &mut self.v;
        (v.eulerint_deg_s, v.alpha_deg, v.ise, v.isf, v.effort_abs, v.effort_sq) = (eulerint, alpha_deg, ise, isf, effort_abs, isf);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let f = self.integrands();
        for (acc, x) in self.integrals.iter_mut().zip(f) {
            *acc += x * h;
        }
        Ok(())
    }
}
