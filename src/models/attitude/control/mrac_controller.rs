//! `MracController`: paper 000's model-reference adaptive attitude law (Slotine & Li's adaptation of the
//! inertia per axis) with a fixed second-order reference model. The adaptive core is shared with
//! `AdaptiveFuzzyController` (`shared::mrac`).

use serde::{Deserialize, Serialize};

use super::shared::mrac::{Mrac, MracVariables, ReferenceGains, EQUATIONS_HTML};
use super::shared::AttitudeControllerPorts;
use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct MracControllerVars {
        ports: AttitudeControllerPorts;
        mrac: MracVariables;
        107 => lambda1: Real = 2.0, Parameter, "1/s", "Reference-model damping coefficient lambda1 ([Navabi-2019] Eq. 37)", Positive;
        108 => lambda2: Real = 1.0, Parameter, "1/s2", "Reference-model stiffness lambda2 ([Navabi-2019] Eq. 37)", Positive;
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct MracController(Mrac);

impl Model for MracController {
    type Vars = MracControllerVars;
    const EVOLVING: &'static [&'static str] = &["st"];
    const INFO: ModelInfo = ModelInfo {
        name: "MracController",
        description: "Model-reference adaptive attitude controller (Slotine-Li adaptation of the inertia per axis)",
        source: "[Navabi-2019], Eqs. 37-43",
        equations_html: EQUATIONS_HTML,
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut MracControllerVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(MracController(Mrac::new(&mut v.mrac, ReferenceGains::Fixed { lambda1: v.lambda1, lambda2: v.lambda2 })?))
    }

    fn outputs(&self, v: &mut MracControllerVars, _t: f64) -> ModelResult {
        self.0.outputs(&mut v.ports, &mut v.mrac).map(|_| ())
    }

    fn step(&mut self, v: &MracControllerVars, _t: f64, h: f64) -> ModelResult {
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
    use crate::math::attitude::quat;
    use crate::model::Fmu;
    use nalgebra::Quaternion;

    #[test]
    fn outputs_do_not_change_state_and_first_step_starts_at_measurement() {
        let mut m = Fmu::<MracController>::default();
        m.initialize(&Experiment::default()).unwrap();
        let q = quat(0.95, 0.1, -0.2, 0.2).normalize();
        m.v.ports.q = q;
        m.v.ports.q_ref = Quaternion::new(0.75f64.sqrt(), 0.0, 0.0, 0.5);
        let before = m.model().0.st;
        m.outputs(0.0).unwrap();
        let t1 = m.v.ports.torque_cmd;
        m.outputs(0.0).unwrap();
        assert_eq!(m.model().0.st, before);
        assert_eq!(t1, m.v.ports.torque_cmd);
        // x_m(0) = x(0): zero tracking error at t0
        assert!(m.v.mrac.track_err.abs().sum() < 1e-15);
        m.step(0.0, 0.01).unwrap();
        assert!(m.model().0.st.started && m.model().0.st != before);
        assert!((m.model().0.st.xm[0] - 2.0 * q.i).abs() < 1e-3);
    }
}
