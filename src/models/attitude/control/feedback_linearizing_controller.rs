//! `FeedbackLinearizingController`: paper 004's feedback-linearising quaternion law. It cancels the
//! rigid-body and kinematic nonlinearities so that the vector part of the quaternion follows
//! ë + k_q̇ ė + k_q e = 0 (e = q_v − q_ref,v) while no torque saturates.

use serde::{Deserialize, Serialize};

use super::shared::feedback_linearization::{control_torque, Gains, Reference};
use super::shared::{check_unit_quaternions, AttitudeControllerPorts};
use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct FeedbackLinearizingControllerVars {
        ports: AttitudeControllerPorts;
        50 => q_ref_dot: Vec3 = [0.0; 3], Input, "1/s", "Time derivative of the commanded quaternion's vector part (0 = constant command)";
        53 => q_ref_ddot: Vec3 = [0.0; 3], Input, "1/s2", "Second time derivative of the commanded quaternion's vector part (0 = constant command)";
        100 => inertia: Diag3 = [449.5, 264.5, 312.5], Parameter, "kg.m2", "Controller's nominal inertia (diagonal; [Moradi-FTC] default)", Positive;
        160 => k_q: Vec3 = [0.5; 3], Parameter, "1/s2", "Stiffness k_q of the error dynamics e'' + k_qdot e' + k_q e = 0 ([Moradi-FTC])", Positive;
        163 => k_qdot: Vec3 = [2.0; 3], Parameter, "1/s", "Damping k_qdot of the error dynamics ([Moradi-FTC])", Positive;
    }
}

/// A static law: gains and inertia are read from the variables at every output evaluation.
#[derive(Clone, Serialize, Deserialize)]
pub struct FeedbackLinearizingController;

impl Model for FeedbackLinearizingController {
    type Vars = FeedbackLinearizingControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "FeedbackLinearizingController",
        description: "Feedback-linearising quaternion attitude law with reference-derivative inputs",
        source: "[Moradi-FTC], Eqs. 1-7",
        equations_html: "<pre>q_v'   = 1/2 (q_w w + q_v x w)                          (from the measured q and w)\n\
u''    = q_ref_ddot - k_qdot (q_v' - q_ref_dot) - k_q (q_v - q_ref_v)      (componentwise)\n\
g      = ((I_y - I_z)/I_x w_y w_z, (I_z - I_x)/I_y w_x w_z, (I_x - I_y)/I_z w_x w_y)\n\
chi    = -1/4 q_v |w|^2 + 1/2 M(q) g,      M(q) = q_w I3 + [q_v x]\n\
u'     = 2 M(q)^-1 (u'' - chi)\n\
torque_cmd = I u'                                     (componentwise; the plant saturates)</pre>\n\
<p>Without saturation e = q_v - q_ref_v obeys e'' + k_qdot e' + k_q e = 0 on each axis; with the defaults \
k_q = 0.5, k_qdot = 2 the poles are -1 +- sqrt(2)/2 = -0.293 and -1.707 1/s. Only the vector part of q_ref is \
used; q is not sign-flipped. det M(q) = q_w: when |q_w| &lt; 1e-6 (attitude near 180 degrees) the law is \
undefined and the FMU returns fmi2Error with a message instead of a torque. The measured q and the \
commanded q_ref must have unit norm (within 1e-3).</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut FeedbackLinearizingControllerVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(FeedbackLinearizingController)
    }

    fn outputs(&self, v: &mut FeedbackLinearizingControllerVars, _t: f64) -> ModelResult {
        check_unit_quaternions(&v.ports)?;
        let p = &v.ports;
        let r = Reference { q_v: p.q_ref.vector().into_owned(), q_v_dot: v.q_ref_dot, q_v_ddot: v.q_ref_ddot };
        let gains = Gains { k_q: v.k_q, k_qdot: v.k_qdot };
        v.ports.torque_cmd = control_torque(&p.q, &p.w, &r, &v.inertia, &gains)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;
    use nalgebra::{Quaternion, Vector3};

    #[test]
    fn singular_attitude_and_bad_gains_are_errors() {
        let mut c = Fmu::<FeedbackLinearizingController>::default();
        c.initialize(&Experiment::default()).unwrap();
        c.v.ports.q = Quaternion::new(0.0, 1.0, 0.0, 0.0);
        let e = c.outputs(0.0).unwrap_err();
        assert!(e.contains("singular"), "{e}");
        c.v.k_qdot = Vector3::new(2.0, -1.0, 2.0);
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("k_qdot_y"), "{e}");
    }
}
