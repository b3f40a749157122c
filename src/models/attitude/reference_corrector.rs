//! `ReferenceCorrector`: paper 004's reference correction. In mode 1 it integrates a copy of the
//! faulty plant driven open loop by a spline torque u_ol(t) and outputs the attitude reference (with
//! its first two derivatives) that makes `FeedbackLinearizingController` command exactly u_ol: the
//! closed loop then retraces the open-loop manoeuvre, and feedback still acts on any deviation.
//! Mode 0 outputs the identity attitude (no correction).

use nalgebra::{Quaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::control::shared::feedback_linearization::{Gains, OpenLoopCopy};
use crate::declare_variables;
use crate::math::attitude::quat_from_euler321;
use crate::math::spline::NotAKnotSpline;
use crate::model::{Experiment, Model, ModelInfo, ModelResult, StateDecl};

/// Number of spline nodes per axis (paper 004: 6 equally spaced nodes).
pub const N_NODES: usize = 6;

declare_variables! {
    pub struct ReferenceCorrectorVars {
        10 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Corrected attitude reference; scalar part sqrt(max(0, 1 - |q_ref_v|^2))";
        14 => w_ref: Vec3 = [0.0; 3], Output, "rad/s", "Commanded body rate (always 0; the law uses q_ref_dot instead)";
        50 => q_ref_dot: Vec3 = [0.0; 3], Output, "1/s", "Time derivative of the reference's vector part";
        53 => q_ref_ddot: Vec3 = [0.0; 3], Output, "1/s2", "Second time derivative of the reference's vector part ([Moradi-FTC] Eq. 17)";
        56 => u_ol: Vec3 = [0.0; 3], Output, "N.m", "Open-loop torque: the spline through the node parameters up to spline_t_end, 0 after";
        100 => inertia: Diag3 = [449.5, 264.5, 312.5], Parameter, "kg.m2", "Inertia of the internal plant copy and of the law (diagonal; [Moradi-FTC])", Positive;
        160 => k_q: Vec3 = [0.5; 3], Parameter, "1/s2", "Stiffness k_q of the controller's error dynamics (same value as the controller)", Positive;
        163 => k_qdot: Vec3 = [2.0; 3], Parameter, "1/s", "Damping k_qdot of the controller's error dynamics (same value as the controller)", Positive;
        110 => init_euler321_roll: Real = 0.0, Parameter, "rad", "Initial roll of the plant (321 sequence)";
        111 => init_euler321_pitch: Real = 0.0, Parameter, "rad", "Initial pitch of the plant (321 sequence)";
        112 => init_euler321_yaw: Real = 0.0, Parameter, "rad", "Initial yaw of the plant (321 sequence)";
        113 => init_w: Vec3 = [0.0; 3], Parameter, "rad/s", "Initial body rate of the plant";
        120 => u_max: Vec3 = [10.0; 3], Parameter, "N.m", "Torque limit of the plant before the fault ([Moradi-FTC]: 10 N m)", Limit;
        123 => effectiveness: Vec3 = [0.1; 3], Parameter, "", "Effectiveness a of the faulty actuators: the copy's limit is a u_max ([Moradi-FTC]: 0.1)", Range(0.0, 1.0);
        130 => max_internal_step: Real = 0.01, Parameter, "s", "Internal RK4 step of the plant copy (use the plant's value)", Positive;
        150 => mode: Integer = 0, Parameter, "", "0 = identity reference (no correction), 1 = reference corrected by the open-loop spline", Choice(&[0, 1]);
        170 => node_x_0: Real = 0.0, Parameter, "N.m", "Spline node value x at t = 0";
        171 => node_x_1: Real = 0.0, Parameter, "N.m", "Spline node value x at t = spline_t_end/5";
        172 => node_x_2: Real = 0.0, Parameter, "N.m", "Spline node value x at t = 2 spline_t_end/5";
        173 => node_x_3: Real = 0.0, Parameter, "N.m", "Spline node value x at t = 3 spline_t_end/5";
        174 => node_x_4: Real = 0.0, Parameter, "N.m", "Spline node value x at t = 4 spline_t_end/5";
        175 => node_x_5: Real = 0.0, Parameter, "N.m", "Spline node value x at t = spline_t_end";
        176 => node_y_0: Real = 0.0, Parameter, "N.m", "Spline node value y at t = 0";
        177 => node_y_1: Real = 0.0, Parameter, "N.m", "Spline node value y at t = spline_t_end/5";
        178 => node_y_2: Real = 0.0, Parameter, "N.m", "Spline node value y at t = 2 spline_t_end/5";
        179 => node_y_3: Real = 0.0, Parameter, "N.m", "Spline node value y at t = 3 spline_t_end/5";
        180 => node_y_4: Real = 0.0, Parameter, "N.m", "Spline node value y at t = 4 spline_t_end/5";
        181 => node_y_5: Real = 0.0, Parameter, "N.m", "Spline node value y at t = spline_t_end";
        182 => node_z_0: Real = 0.0, Parameter, "N.m", "Spline node value z at t = 0";
        183 => node_z_1: Real = 0.0, Parameter, "N.m", "Spline node value z at t = spline_t_end/5";
        184 => node_z_2: Real = 0.0, Parameter, "N.m", "Spline node value z at t = 2 spline_t_end/5";
        185 => node_z_3: Real = 0.0, Parameter, "N.m", "Spline node value z at t = 3 spline_t_end/5";
        186 => node_z_4: Real = 0.0, Parameter, "N.m", "Spline node value z at t = 4 spline_t_end/5";
        187 => node_z_5: Real = 0.0, Parameter, "N.m", "Spline node value z at t = spline_t_end";
        188 => spline_t_end: Real = 20.0, Parameter, "s", "Time of the last node (nodes equally spaced on [0, spline_t_end]; [Moradi-FTC]: 20 s)", Positive;
        190 => init_ref_error: Vec3 = [0.0; 3], Parameter, "", "Initial reference error e(0) = q_v(0) - q_ref_v(0) (0: the reference starts on the plant)";
        193 => init_ref_error_rate: Vec3 = [0.0; 3], Parameter, "1/s", "Initial reference error rate e'(0)";
    }
}

#[derive(Clone, Serialize, Deserialize)]
pub struct ReferenceCorrector {
    corrected: bool,
    splines: [NotAKnotSpline; 3],
    t_end: f64,
    copy: OpenLoopCopy,
    /// Model Exchange: the drift of the copy's |q| that asks for a projection event.
    projection_threshold: f64,
}

impl ReferenceCorrector {
    /// u_ol(t): the spline up to the last node, 0 after it.
    fn u_ol(&self, t: f64) -> Vector3<f64> {
        if t > self.t_end {
            return Vector3::zeros();
        }
        Vector3::new(self.splines[0].eval(t), self.splines[1].eval(t), self.splines[2].eval(t))
    }
}

fn nodes(v: &ReferenceCorrectorVars) -> [[f64; N_NODES]; 3] {
    [
        [v.node_x_0, v.node_x_1, v.node_x_2, v.node_x_3, v.node_x_4, v.node_x_5],
        [v.node_y_0, v.node_y_1, v.node_y_2, v.node_y_3, v.node_y_4, v.node_y_5],
        [v.node_z_0, v.node_z_1, v.node_z_2, v.node_z_3, v.node_z_4, v.node_z_5],
    ]
}

impl Model for ReferenceCorrector {
    type Vars = ReferenceCorrectorVars;
    const EVOLVING: &'static [&'static str] = &["copy.x"];
    const INFO: ModelInfo = ModelInfo {
        name: "ReferenceCorrector",
        description: "Reference corrector: attitude reference from an internal open-loop plant copy driven by a spline torque",
        source: "[Moradi-FTC], section 3-3, Eq. 17",
        equations_html: "<pre>u_ol(t)  = not-a-knot cubic spline through (k spline_t_end/5, node_*_k), k = 0..5;  0 for t &gt; spline_t_end\n\
mode 0:  q_ref = (1, 0, 0, 0), q_ref_dot = q_ref_ddot = 0\n\
mode 1:  internal copy of the plant (same inertia, limit a u_max, initial state, RK4 step):\n\
         I w' = sat(u_ol) - w x I w,   q' = 1/2 q (x) (0, w)      (u_ol held over each communication step)\n\
         e'' = -k_qdot e' - k_q e,     e(0) = init_ref_error, e'(0) = init_ref_error_rate\n\
         q_ref_v    = q_v - e\n\
         q_ref_dot  = 1/2 (q_w w + q_v x w) - e'\n\
         q_ref_ddot = k_qdot (q_v' - q_ref_dot) + k_q (q_v - q_ref_v) + chi + 1/2 M(q) sat(u_ol)/I      ([Moradi-FTC] Eq. 17)\n\
         q_ref_w    = sqrt(max(0, 1 - |q_ref_v|^2)),  w_ref = 0\n\
chi = -1/4 q_v |w|^2 + 1/2 M(q) g, M(q) = q_w I3 + [q_v x], g as in FeedbackLinearizingController</pre>\n\
<p>Eq. 17 is the feedback-linearising law solved for the reference acceleration: with this reference the \
controller commands exactly u_ol. Integrating e = q_v - q_ref_v (whose dynamics Eq. 17 makes linear) instead \
of q_ref itself is the same solution; with e(0) = e'(0) = 0 the reference equals the copy's attitude to the \
last bit, and a closed loop with the same plant parameters, RK4 step and communication step reproduces the \
open-loop run to round-off. Other initial errors decay with the controller's error poles. u_ol is output in \
both modes (e.g. to drive the plant open loop).</p>\n\
<p>Model Exchange: the copy's state (q, w, e, e') is published as the continuous states state_q_*, state_w_*, \
state_e_*, state_e_dot_* (constant in mode 0); u_ol(t) is evaluated at every instant instead of being held over a \
communication step; the spline knots are time events (u_ol drops to 0 after the last); the copy's quaternion is \
renormalised at an event whenever | |q| - 1 | exceeds the importer's tolerance (fmi2SetupExperiment, at most 1e-3) \
or 1e-9 without one; within 8 ulp of 1 the event changes nothing (a repeated event pass settles).</p>",
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut ReferenceCorrectorVars, exp: &Experiment) -> Result<Self, String> {
        let t_end = v.spline_t_end;
        let times: Vec<f64> = (0..N_NODES).map(|k| t_end * k as f64 / (N_NODES - 1) as f64).collect();
        let n = nodes(v);
        let mk = |axis: usize| NotAKnotSpline::new(&times, &n[axis]).map_err(|e| format!("node_{}_*: {e}", ["x", "y", "z"][axis]));
        let splines = [mk(0)?, mk(1)?, mk(2)?];
        let q0 = quat_from_euler321(v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw);
        let limit = v.u_max.component_mul(&v.effectiveness);
        let gains = Gains { k_q: v.k_q, k_qdot: v.k_qdot };
        let copy = OpenLoopCopy::new(&v.inertia, &limit, gains, v.max_internal_step, &q0, &v.init_w, &v.init_ref_error, &v.init_ref_error_rate)?;
        let projection_threshold = crate::math::attitude::projection_threshold(exp.tolerance, NORM_TOLERANCE);
        Ok(ReferenceCorrector { corrected: v.mode == 1, splines, t_end, copy, projection_threshold })
    }

    fn outputs(&self, v: &mut ReferenceCorrectorVars, t: f64) -> ModelResult {
        let u = self.u_ol(t);
        v.u_ol = u;
        v.w_ref = Vector3::zeros();
        if !self.corrected {
            v.q_ref = Quaternion::identity();
            (v.q_ref_dot, v.q_ref_ddot) = (Vector3::zeros(), Vector3::zeros());
            return Ok(());
        }
        let r = self.copy.reference(&u);
        let w = (1.0 - r.q_v.norm_squared()).max(0.0).sqrt();
        v.q_ref = Quaternion::new(w, r.q_v.x, r.q_v.y, r.q_v.z);
        (v.q_ref_dot, v.q_ref_ddot) = (r.q_v_dot, r.q_v_ddot);
        Ok(())
    }

    fn step(&mut self, _v: &ReferenceCorrectorVars, t: f64, h: f64) -> ModelResult {
        if self.corrected {
            let u = self.u_ol(t);
            self.copy.step(t, h, &u)?;
        }
        Ok(())
    }

    // Model Exchange: the copy's state is continuous (mode 0: constant); u_ol(t) is evaluated at
    // every instant (Co-Simulation holds it over the communication step); the knots are time events
    // (u_ol drops to 0 after the last); |q| of the copy is kept by projection at events.
    const STATES: Option<&'static [StateDecl]> = Some(&STATES);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(self.copy.x.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.copy.x.copy_from_slice(x);
    }
    fn derivatives(&self, _v: &Self::Vars, t: f64, dx: &mut [f64]) -> ModelResult {
        if self.corrected {
            dx.copy_from_slice(self.copy.rate(&self.u_ol(t)).as_slice());
        } else {
            dx.fill(0.0);
        }
        Ok(())
    }
    fn next_time_event(&self, _v: &Self::Vars, t: f64) -> Option<f64> {
        (1..N_NODES).map(|k| self.t_end * k as f64 / (N_NODES - 1) as f64).find(|tk| *tk > t)
    }
    fn completed_integrator_step(&mut self, _v: &Self::Vars, _t: f64) -> bool {
        self.corrected && self.drift() > self.projection_threshold
    }
    fn event_update(&mut self, _v: &Self::Vars, t: f64) -> Result<bool, String> {
        // within round-off of |q| = 1 nothing changes (idempotent: a repeated event pass reports no change)
        if !self.corrected || self.drift() <= crate::math::attitude::NORM_ROUNDOFF {
            return Ok(false);
        }
        let n = self.copy.x.fixed_rows::<4>(0).norm();
        if !(n > 0.0) {
            return Err(format!("reference corrector: quaternion norm became zero at t = {t}"));
        }
        self.copy.x.fixed_rows_mut::<4>(0).unscale_mut(n);
        Ok(true)
    }
}

/// Largest drift of the copy's |q| accepted between events under Model Exchange.
pub const NORM_TOLERANCE: f64 = 1e-9;

const fn st(name: &'static str, unit: &'static str, description: &'static str, on: &'static [&'static str]) -> StateDecl {
    StateDecl::new(name, unit, description).depends_on(on)
}

/// The copy's state [q, ω, e, ė] under Model Exchange. q̇ = ½ q ⊗ ω (entry i not on q_i), diagonal
/// inertia (ω̇_i on the other two rates), ë = −k_qdot ė − k_q e per axis; no inputs.
const STATES: [StateDecl; 13] = [
    st("state_q_w", "", "Continuous state: copy's attitude quaternion, scalar part", &["state_q_x", "state_q_y", "state_q_z", "state_w_x", "state_w_y", "state_w_z"]),
    st("state_q_x", "", "Continuous state: copy's attitude quaternion x", &["state_q_w", "state_q_y", "state_q_z", "state_w_x", "state_w_y", "state_w_z"]),
    st("state_q_y", "", "Continuous state: copy's attitude quaternion y", &["state_q_w", "state_q_x", "state_q_z", "state_w_x", "state_w_y", "state_w_z"]),
    st("state_q_z", "", "Continuous state: copy's attitude quaternion z", &["state_q_w", "state_q_x", "state_q_y", "state_w_x", "state_w_y", "state_w_z"]),
    st("state_w_x", "rad/s", "Continuous state: copy's body rate x", &["state_w_y", "state_w_z"]),
    st("state_w_y", "rad/s", "Continuous state: copy's body rate y", &["state_w_x", "state_w_z"]),
    st("state_w_z", "rad/s", "Continuous state: copy's body rate z", &["state_w_x", "state_w_y"]),
    st("state_e_x", "", "Continuous state: reference error e_x = q_v,x - q_ref_v,x", &["state_e_dot_x"]),
    st("state_e_y", "", "Continuous state: reference error e_y", &["state_e_dot_y"]),
    st("state_e_z", "", "Continuous state: reference error e_z", &["state_e_dot_z"]),
    st("state_e_dot_x", "1/s", "Continuous state: reference error rate e_x'", &["state_e_x", "state_e_dot_x"]),
    st("state_e_dot_y", "1/s", "Continuous state: reference error rate e_y'", &["state_e_y", "state_e_dot_y"]),
    st("state_e_dot_z", "1/s", "Continuous state: reference error rate e_z'", &["state_e_z", "state_e_dot_z"]),
];

impl ReferenceCorrector {
    fn drift(&self) -> f64 {
        (self.copy.x.fixed_rows::<4>(0).norm() - 1.0).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    #[test]
    fn mode_0_is_the_identity_and_outputs_the_spline() {
        let mut c = Fmu::<ReferenceCorrector>::default();
        (c.v.node_x_0, c.v.node_x_1, c.v.node_y_2, c.v.node_z_5) = (0.5, -0.25, 1.0, 0.75);
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.0).unwrap();
        assert_eq!(c.v.q_ref, Quaternion::identity());
        assert_eq!((c.v.u_ol.x, c.v.u_ol.y, c.v.u_ol.z), (0.5, 0.0, 0.0));
        c.outputs(20.0).unwrap();
        assert_eq!(c.v.u_ol.z, 0.75);
        c.outputs(20.5).unwrap();
        assert_eq!(c.v.u_ol, Vector3::zeros());
    }

    #[test]
    fn mode_1_starts_on_the_plant_attitude() {
        let mut c = Fmu::<ReferenceCorrector>::default();
        c.v.mode = 1;
        (c.v.init_euler321_roll, c.v.init_euler321_pitch, c.v.init_euler321_yaw) = (0.14, -0.07, 0.1);
        c.initialize(&Experiment::default()).unwrap();
        c.outputs(0.0).unwrap();
        let q0 = quat_from_euler321(0.14, -0.07, 0.1);
        assert!((c.v.q_ref.coords - q0.coords).norm() < 1e-15);
        assert_eq!(c.v.q_ref_dot, Vector3::zeros());
    }
}
