//! `SlidingModeController`: paper 003's quaternion sliding-mode attitude law (equivalent control plus a
//! boundary-layer switching term with one gain k on all axes, tuned by a genetic algorithm in the
//! paper). The law is shared with `Type2FuzzySmcController` (`shared::smc`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::shared::smc::{SmcLaw, SmcVariables, SMC_EQUATIONS_HTML};
use super::shared::AttitudeControllerPorts;
use crate::declare_variables;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct SlidingModeControllerVars {
        ports: AttitudeControllerPorts;
        smc: SmcVariables;
    }
}

/// Static law: the nominal inertia matrix, λ and Φ.
#[derive(Clone, Serialize, Deserialize)]
pub struct SlidingModeController {
    law: SmcLaw,
}

impl Model for SlidingModeController {
    type Vars = SlidingModeControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "SlidingModeController",
        description: "Quaternion sliding-mode attitude controller (equivalent control + boundary-layer switching, K = (k, k, k))",
        source: "[T2FSMC-LEO]; law: project choice keeping the paper's structure",
        equations_html: SMC_EQUATIONS_HTML,
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SlidingModeControllerVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(SlidingModeController { law: v.smc.law()? })
    }

    fn outputs(&self, v: &mut SlidingModeControllerVars, _t: f64) -> ModelResult {
        let sig = self.law.signals(&v.ports, &v.smc.h_wheel)?;
        v.ports.torque_cmd = v.smc.finish(&self.law, &sig, &Vector3::repeat(v.smc.k_switch))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;
    use crate::model::Fmu;

    #[test]
    fn torque_is_equivalent_control_minus_saturated_switching() {
        let mut c = Fmu::<SlidingModeController>::default();
        c.initialize(&Experiment::default()).unwrap();
        c.v.ports.q_ref = quat_from_euler321(0.349, -0.262, 0.0);
        c.v.ports.w = Vector3::new(1e-3, 0.0, 0.0);
        c.outputs(0.0).unwrap();
        // T = T_eq - k sat(s / Phi), k = 0.005, Phi = 0.005
        let s = c.v.smc.s;
        let expect = c.v.smc.torque_eq - s.map(|x| 0.005 * (x / 0.005).clamp(-1.0, 1.0));
        assert_eq!(c.v.smc.k_gain, Vector3::repeat(0.005));
        assert!((c.v.ports.torque_cmd - expect).norm() < 1e-15);
        // s = w + lambda q_e,v with q_e = q_ref* q: the reference at roll 20 deg, pitch -15 deg gives q_e,x < 0, q_e,y > 0
        assert!(s.x < -0.03 && s.y > 0.02, "{s:?}");
        c.v.smc.boundary_layer = 0.0;
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("boundary_layer"), "{e}");
    }
}
