//! Model Exchange for the MRAC-type controllers (`MracController`, `AdaptiveFuzzyController`): the
//! reference model x_m, ẋ_m and the inertia estimate Î of [`Mrac`] as continuous states, what each
//! derivative reads, and the `impl Model` members both controllers share ([`mrac_model_exchange!`]).

use nalgebra::SVector;

use super::mrac::{Mrac, MracState};
use crate::model::StateDecl;
use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};

const Q: [&str; 4] = ["q_w", "q_x", "q_y", "q_z"];
const W: [&str; 3] = ["w_x", "w_y", "w_z"];
const Q_REF: [&str; 4] = ["q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z"];
const fn names<const N: usize>(parts: &[&[&'static str]]) -> [&'static str; N] {
    crate::model::concat(parts, "")
}
// ẍ_m,i reads r_i (every q_ref entry: the 321 angles in coordinates 1), x_m,i and ẋ_m,i (also through
// the fuzzy-scheduled gains); Î̇_i reads the measurement x, ẋ (q, ω), r, x_m,i, ẋ_m,i and Î_i itself (the
// projection at the bound). The start x_m(0) = x(0) is taken from q.
const XM_DOT_X: [&str; 6] = names(&[&Q_REF, &["state_xm_x", "state_xm_dot_x"]]);
const XM_DOT_Y: [&str; 6] = names(&[&Q_REF, &["state_xm_y", "state_xm_dot_y"]]);
const XM_DOT_Z: [&str; 6] = names(&[&Q_REF, &["state_xm_z", "state_xm_dot_z"]]);
const IHAT_X: [&str; 14] = names(&[&Q, &W, &Q_REF, &["state_xm_x", "state_xm_dot_x", "state_ihat_x"]]);
const IHAT_Y: [&str; 14] = names(&[&Q, &W, &Q_REF, &["state_xm_y", "state_xm_dot_y", "state_ihat_y"]]);
const IHAT_Z: [&str; 14] = names(&[&Q, &W, &Q_REF, &["state_xm_z", "state_xm_dot_z", "state_ihat_z"]]);

/// The continuous states of an MRAC-type controller under Model Exchange: x_m, ẋ_m, Î.
pub const MRAC_STATES: [StateDecl; 9] = [
    StateDecl::new("state_xm_x", "", "Continuous state: reference-model state x_m,x")
        .depends_on(&["state_xm_dot_x"])
        .starting_from(&Q),
    StateDecl::new("state_xm_y", "", "Continuous state: reference-model state x_m,y")
        .depends_on(&["state_xm_dot_y"])
        .starting_from(&Q),
    StateDecl::new("state_xm_z", "", "Continuous state: reference-model state x_m,z")
        .depends_on(&["state_xm_dot_z"])
        .starting_from(&Q),
    StateDecl::new("state_xm_dot_x", "1/s", "Continuous state: reference-model rate x_m,x'").depends_on(&XM_DOT_X),
    StateDecl::new("state_xm_dot_y", "1/s", "Continuous state: reference-model rate x_m,y'").depends_on(&XM_DOT_Y),
    StateDecl::new("state_xm_dot_z", "1/s", "Continuous state: reference-model rate x_m,z'").depends_on(&XM_DOT_Z),
    StateDecl::new(
        "state_ihat_x",
        "kg.m2",
        "Continuous state: inertia estimate I^_x (kept at or above ihat_min_x)",
    )
    .depends_on(&IHAT_X),
    StateDecl::new("state_ihat_y", "kg.m2", "Continuous state: inertia estimate I^_y").depends_on(&IHAT_Y),
    StateDecl::new("state_ihat_z", "kg.m2", "Continuous state: inertia estimate I^_z").depends_on(&IHAT_Z),
];

/// The Model Exchange members of `impl Model` for a controller that wraps [`Mrac`] (`struct C(Mrac)`)
/// and embeds the controller ports (`v.ports`): the states [`MRAC_STATES`], Î kept at its bound by an
/// event after any solver step that left it below.
#[macro_export]
#[doc(hidden)]
macro_rules! mrac_model_exchange {
    () => {
        const STATES: Option<&'static [$crate::model::StateDecl]> =
            Some(&$crate::models::attitude::control::shared::mrac_exchange::MRAC_STATES);
        fn get_states(&self, v: &Self::Vars, x: &mut [f64]) {
            self.0.get_states(&v.ports, x)
        }
        fn set_states(&mut self, x: &[f64]) {
            self.0.set_states(x)
        }
        fn derivatives(&self, v: &Self::Vars, _t: f64, dx: &mut [f64]) -> $crate::model::ModelResult {
            self.0.derivatives(&v.ports, dx)
        }
        fn completed_integrator_step(&mut self, _v: &Self::Vars, _t: f64) -> bool {
            self.0.below_bound()
        }
        fn event_update(&mut self, _v: &Self::Vars, _t: f64) -> Result<bool, String> {
            Ok(self.0.project())
        }
    };
}

impl Mrac {
    /// The state in use (before the first step or `set_states`: x_m = x of the inputs, ẋ_m = 0).
    pub fn get_states(&self, ports: &AttitudeControllerPorts, x: &mut [f64]) {
        let e = self.core.effective(&self.st, &self.core.measure(ports));
        x[0..3].copy_from_slice(&e.xm);
        x[3..6].copy_from_slice(&e.xm_dot);
        x[6..9].copy_from_slice(&e.ihat);
    }

    pub fn set_states(&mut self, x: &[f64]) {
        let v3 = |i: usize| [x[i], x[i + 1], x[i + 2]];
        self.st = MracState {
            xm: v3(0),
            xm_dot: v3(3),
            ihat: v3(6),
            started: true,
        };
    }

    /// d/dt [x_m, ẋ_m, Î] for the current inputs (Î held at its bound where the law would push it below).
    pub fn derivatives(&self, ports: &AttitudeControllerPorts, dx: &mut [f64]) -> Result<(), String> {
        check_unit_quaternions(ports)?;
        let m = self.core.measure(ports);
        let e = self.core.effective(&self.st, &m);
        let y = SVector::<f64, 9>::from_iterator(e.xm.iter().chain(e.xm_dot.iter()).chain(e.ihat.iter()).copied());
        dx.copy_from_slice(self.core.derivative(&m, &y).as_slice());
        Ok(())
    }

    /// After an accepted solver step: whether Î went below its bound (an event clamps it).
    pub fn below_bound(&self) -> bool {
        self.st.ihat.iter().zip(&self.core.ihat_min).any(|(i, m)| i < m)
    }

    /// Event update: Î clamped at Î_min (the projection the Co-Simulation step makes after every
    /// internal step); whether a state changed.
    pub fn project(&mut self) -> bool {
        let before = self.st.ihat;
        for (i, m) in self.st.ihat.iter_mut().zip(&self.core.ihat_min) {
            *i = i.max(*m);
        }
        self.st.ihat != before
    }
}
