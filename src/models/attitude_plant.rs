//! `AttitudePlant`: three-axis rigid body with full inertia, quaternion kinematics, ideal torque
//! actuators with saturation and loss-of-effectiveness fault (spec attitude-plant.md §1.2–1.4 mode 0).

use nalgebra::{Matrix3, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{attitude_matrix, euler321_from_quat, quat, quat_derivative, quat_from_euler321, wxyz};
use crate::math::integrate::{euler, internal_steps, rk4, FixedMethod};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct AttitudePlantVars {
        // inputs
        0 => torque_cmd_x: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body x";
        1 => torque_cmd_y: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body y";
        2 => torque_cmd_z: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body z";
        3 => torque_dist_x: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body x";
        4 => torque_dist_y: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body y";
        5 => torque_dist_z: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body z";
        // outputs
        10 => q_w: Real = 1.0, Output, Continuous, "", "Attitude quaternion of B relative to R, scalar part";
        11 => q_x: Real = 0.0, Output, Continuous, "", "Attitude quaternion, x component";
        12 => q_y: Real = 0.0, Output, Continuous, "", "Attitude quaternion, y component";
        13 => q_z: Real = 0.0, Output, Continuous, "", "Attitude quaternion, z component";
        14 => w_x: Real = 0.0, Output, Continuous, "rad/s", "Body rate of B relative to R, body x";
        15 => w_y: Real = 0.0, Output, Continuous, "rad/s", "Body rate, body y";
        16 => w_z: Real = 0.0, Output, Continuous, "rad/s", "Body rate, body z";
        17 => roll: Real = 0.0, Output, Continuous, "rad", "Roll angle of the 321 sequence";
        18 => pitch: Real = 0.0, Output, Continuous, "rad", "Pitch angle of the 321 sequence";
        19 => yaw: Real = 0.0, Output, Continuous, "rad", "Yaw angle of the 321 sequence";
        20 => roll_deg: Real = 0.0, Output, Continuous, "deg", "Roll angle of the 321 sequence in degrees";
        21 => pitch_deg: Real = 0.0, Output, Continuous, "deg", "Pitch angle of the 321 sequence in degrees";
        22 => yaw_deg: Real = 0.0, Output, Continuous, "deg", "Yaw angle of the 321 sequence in degrees";
        23 => torque_applied_x: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators, body x";
        24 => torque_applied_y: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators, body y";
        25 => torque_applied_z: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators, body z";
        26 => torque_ext_x: Real = 0.0, Output, Continuous, "N.m", "Total external torque, body x";
        27 => torque_ext_y: Real = 0.0, Output, Continuous, "N.m", "Total external torque, body y";
        28 => torque_ext_z: Real = 0.0, Output, Continuous, "N.m", "Total external torque, body z";
        29 => h_total_ref_x: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum A(q)^T (I w + h_w) in R, x";
        30 => h_total_ref_y: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum in R, y";
        31 => h_total_ref_z: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum in R, z";
        // parameters
        100 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xx (paper 000 default)";
        101 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry yy";
        102 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry zz";
        103 => inertia_xy: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xy (matrix entry, not product of inertia)";
        104 => inertia_xz: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xz";
        105 => inertia_yz: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry yz";
        106 => inertia_scale_x: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_x: I_true = S I S, S = diag(sqrt(s))";
        107 => inertia_scale_y: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_y";
        108 => inertia_scale_z: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_z";
        110 => init_euler321_roll: Real = 0.0, Parameter, Fixed, "rad", "Initial roll (321 sequence)";
        111 => init_euler321_pitch: Real = 0.0, Parameter, Fixed, "rad", "Initial pitch (321 sequence)";
        112 => init_euler321_yaw: Real = 0.0, Parameter, Fixed, "rad", "Initial yaw (321 sequence)";
        113 => init_w_x: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate x";
        114 => init_w_y: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate y";
        115 => init_w_z: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate z";
        120 => u_max_x: Real = 1e30, Parameter, Fixed, "N.m", "Actuator torque limit x (1e30 = no limit)";
        121 => u_max_y: Real = 1e30, Parameter, Fixed, "N.m", "Actuator torque limit y (1e30 = no limit)";
        122 => u_max_z: Real = 1e30, Parameter, Fixed, "N.m", "Actuator torque limit z (1e30 = no limit)";
        123 => effectiveness_x: Real = 1.0, Parameter, Fixed, "", "Actuator effectiveness a_x in [0, 1] after fault_time (paper 004)";
        124 => effectiveness_y: Real = 1.0, Parameter, Fixed, "", "Actuator effectiveness a_y in [0, 1] after fault_time";
        125 => effectiveness_z: Real = 1.0, Parameter, Fixed, "", "Actuator effectiveness a_z in [0, 1] after fault_time";
        126 => fault_time: Real = 0.0, Parameter, Fixed, "s", "Onset time of the loss-of-effectiveness fault";
        130 => max_internal_step: Real = 0.01, Parameter, Fixed, "s", "Largest internal integration step";
        // Integer parameters
        140 => integrator: Integer = 0, Parameter, Fixed, "", "Internal integrator: 0 = classical RK4, 1 = explicit Euler";
        141 => kinematics: Integer = 0, Parameter, Fixed, "", "Kinematics: 0 = quaternion";
        142 => actuator_mode: Integer = 0, Parameter, Fixed, "", "Actuators: 0 = ideal torque with saturation and fault";
    }
}

/// Rigid-body state [q_w, q_x, q_y, q_z, w_x, w_y, w_z].
type State = SVector<f64, 7>;

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AttitudePlant {
    v: AttitudePlantVars,
    x: State,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// Integrator chosen at initialization (None before).
    method: Option<FixedMethod>,
}

impl AttitudePlant {
    fn cmd(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_cmd_x, self.v.torque_cmd_y, self.v.torque_cmd_z)
    }
    fn dist(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_dist_x, self.v.torque_dist_y, self.v.torque_dist_z)
    }

    /// Per-axis actuator limit at time t (paper 004 Eqs. 8–9): a_i u_max,i after the fault onset.
    fn limits(&self, t: f64) -> Vector3<f64> {
        let v = &self.v;
        let umax = Vector3::new(v.u_max_x, v.u_max_y, v.u_max_z);
        if t >= v.fault_time {
            umax.component_mul(&Vector3::new(v.effectiveness_x, v.effectiveness_y, v.effectiveness_z))
        } else {
            umax
        }
    }

    fn applied_torque(&self, t: f64) -> Vector3<f64> {
        let l = self.limits(t);
        let c = self.cmd();
        Vector3::new(c.x.clamp(-l.x, l.x), c.y.clamp(-l.y, l.y), c.z.clamp(-l.z, l.z))
    }

    /// ẋ with the inputs held: quaternion kinematics and Euler's equations.
    fn derivative(&self, t: f64, x: &State) -> State {
        let q = quat(x[0], x[1], x[2], x[3]);
        let w = Vector3::new(x[4], x[5], x[6]);
        let qdot = quat_derivative(&q, &w);
        let tau = self.applied_torque(t) + self.dist();
        let wdot = self.inertia_inv * (tau - w.cross(&(self.inertia * w)));
        State::from_column_slice(&[qdot.w, qdot.i, qdot.j, qdot.k, wdot.x, wdot.y, wdot.z])
    }
}

impl Model for AttitudePlant {
    type Vars = AttitudePlantVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudePlant",
        description: "Three-axis rigid spacecraft with full inertia, quaternion kinematics and saturating, fault-prone torque actuators",
        source: "shared/spec attitude-plant.md §1 (papers 000, 003, 004)",
        equations_html: "<pre>I dw/dt = tau_act + tau_ext - w x (I w)          (Euler's equations, full inertia matrix)\n\
dq/dt   = 1/2 q (x) (0, w)                          (Hamilton product, scalar first)\n\
l_i(t)  = a_i u_max,i for t >= fault_time, else u_max,i\n\
tau_act = clamp(torque_cmd, -l, +l)                 (paper 004 Eqs. 8-9)\n\
tau_ext = torque_dist\n\
I_true  = S I S,  S = diag(sqrt(inertia_scale))</pre>\n\
<p>Fixed-step RK4 (or explicit Euler) with ceil(step / max_internal_step) equal internal steps per communication step, \
cut at fault_time; inputs are held over the step; the quaternion is renormalised after every internal step.</p>",
        feedthrough: Feedthrough::Some(&[
            ("torque_applied_x", &["torque_cmd_x"]),
            ("torque_applied_y", &["torque_cmd_y"]),
            ("torque_applied_z", &["torque_cmd_z"]),
            ("torque_ext_x", &["torque_dist_x"]),
            ("torque_ext_y", &["torque_dist_y"]),
            ("torque_ext_z", &["torque_dist_z"]),
        ]),
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &AttitudePlantVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut AttitudePlantVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let method = match check::choice("integrator", v.integrator, &[0, 1])? {
            0 => FixedMethod::Rk4,
            _ => FixedMethod::Euler,
        };
        check::choice("kinematics", v.kinematics, &[0])?;
        check::choice("actuator_mode", v.actuator_mode, &[0])?;
        check::positive("max_internal_step", v.max_internal_step)?;
        for (n, x) in [("u_max_x", v.u_max_x), ("u_max_y", v.u_max_y), ("u_max_z", v.u_max_z)] {
            check::limit(n, x)?;
        }
        for (n, x) in [("effectiveness_x", v.effectiveness_x), ("effectiveness_y", v.effectiveness_y), ("effectiveness_z", v.effectiveness_z)] {
            check::in_range(n, x, 0.0, 1.0)?;
        }
        check::finite("fault_time", v.fault_time)?;
        for (n, x) in [
            ("inertia_xx", v.inertia_xx),
            ("inertia_yy", v.inertia_yy),
            ("inertia_zz", v.inertia_zz),
            ("inertia_xy", v.inertia_xy),
            ("inertia_xz", v.inertia_xz),
            ("inertia_yz", v.inertia_yz),
            ("init_euler321_roll", v.init_euler321_roll),
            ("init_euler321_pitch", v.init_euler321_pitch),
            ("init_euler321_yaw", v.init_euler321_yaw),
            ("init_w_x", v.init_w_x),
            ("init_w_y", v.init_w_y),
            ("init_w_z", v.init_w_z),
        ] {
            check::finite(n, x)?;
        }
        let s = Vector3::new(
            check::positive("inertia_scale_x", v.inertia_scale_x)?.sqrt(),
            check::positive("inertia_scale_y", v.inertia_scale_y)?.sqrt(),
            check::positive("inertia_scale_z", v.inertia_scale_z)?.sqrt(),
        );
        let nominal = Matrix3::new(
            v.inertia_xx, v.inertia_xy, v.inertia_xz, v.inertia_xy, v.inertia_yy, v.inertia_yz, v.inertia_xz, v.inertia_yz, v.inertia_zz,
        );
        let s = Matrix3::from_diagonal(&s);
        let inertia = s * nominal * s;
        // Positive definite iff the Cholesky factorisation exists.
        let chol = nalgebra::Cholesky::new(inertia)
            .ok_or_else(|| format!("inertia matrix {:?} is not positive definite", inertia.as_slice()))?;
        self.inertia = inertia;
        self.inertia_inv = chol.inverse();
        self.method = Some(method);
        let q0 = quat_from_euler321(v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw);
        self.x = State::from_column_slice(&[q0.w, q0.i, q0.j, q0.k, v.init_w_x, v.init_w_y, v.init_w_z]);
        Ok(())
    }

    fn update_outputs(&mut self, t: f64) -> ModelResult {
        let x = self.x;
        let q = quat(x[0], x[1], x[2], x[3]);
        let w = Vector3::new(x[4], x[5], x[6]);
        let [rl, pt, yw] = euler321_from_quat(&q);
        let tau = self.applied_torque(t);
        let ext = self.dist();
        let h_ref = attitude_matrix(&q).transpose() * (self.inertia * w);
        let v = &mut self.v;
        [v.q_w, v.q_x, v.q_y, v.q_z] = wxyz(&q);
        (v.w_x, v.w_y, v.w_z) = (w.x, w.y, w.z);
        (v.roll, v.pitch, v.yaw) = (rl, pt, yw);
        (v.roll_deg, v.pitch_deg, v.yaw_deg) = (rl.to_degrees(), pt.to_degrees(), yw.to_degrees());
        (v.torque_applied_x, v.torque_applied_y, v.torque_applied_z) = (tau.x, tau.y, tau.z);
        (v.torque_ext_x, v.torque_ext_y, v.torque_ext_z) = (ext.x, ext.y, ext.z);
        (v.h_total_ref_x, v.h_total_ref_y, v.h_total_ref_z) = (h_ref.x, h_ref.y, h_ref.z);
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let method = self.method.ok_or("plant was not initialized")?;
        let mut x = self.x;
        for (ts, dt) in internal_steps(t, h, self.v.max_internal_step, &[self.v.fault_time]) {
            let mut f = |tt: f64, xx: &State| self.derivative(tt, xx);
            x = match method {
                FixedMethod::Rk4 => rk4(&mut f, ts, &x, dt),
                FixedMethod::Euler => euler(&mut f, ts, &x, dt),
            };
            let n = x.fixed_rows::<4>(0).norm();
            if !(n.is_finite() && n > 0.0) || !x.iter().all(|c| c.is_finite()) {
                return Err(format!("state became non-finite at t = {ts}"));
            }
            x.fixed_rows_mut::<4>(0).unscale_mut(n);
        }
        self.x = x;
        Ok(())
    }
}
