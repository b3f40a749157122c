//! `AttitudePlant`: three-axis rigid body with full inertia, selectable kinematics (quaternion, DCM,
//! paper 000's Euler-angle rates, linear small-angle model), ideal torque actuators with saturation
//! and loss-of-effectiveness fault (spec attitude-plant.md §1.2–1.4).

use nalgebra::{Matrix3, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{
    align_sign, attitude_matrix, euler213_rates, euler321_from_dcm, euler321_from_quat, orthonormalize, quat, quat_derivative,
    quat_from_dcm, quat_from_euler321, skew, wxyz,
};
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
        141 => kinematics: Integer = 0, Parameter, Fixed, "", "Kinematics: 0 = quaternion, 1 = DCM, 2 = paper 000 Euler-angle rates (213 rates, angles output as 321), 3 = linear small-angle double integrator";
        142 => actuator_mode: Integer = 0, Parameter, Fixed, "", "Actuators: 0 = ideal torque with saturation and fault";
        143 => dcm_orthonormalize: Integer = 0, Parameter, Fixed, "", "Kinematics 1 only: 1 = re-orthonormalise the DCM after every internal step, 0 = never";
    }
}

/// Kinematics option (`kinematics` parameter, spec §1.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Kinematics {
    Quaternion,
    Dcm,
    Euler213Rates,
    LinearSmallAngle,
}

/// Length of the state vector. Layout (unused entries stay 0):
/// - `ATT..ATT+9`: attitude — quaternion (w, x, y, z) in mode 0, the DCM A column-major in mode 1,
///   the angles (φ, θ, ψ) in modes 2 and 3;
/// - `W..W+3`: body rate ω (modes 0–2) or the angle rates (φ̇, θ̇, ψ̇) (mode 3).
const N: usize = 12;
const ATT: usize = 0;
const W: usize = 9;
type State = SVector<f64, N>;

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AttitudePlant {
    v: AttitudePlantVars,
    x: State,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// Integrator chosen at initialization (None before).
    method: Option<FixedMethod>,
    kin: Option<Kinematics>,
    /// Quaternion output of the DCM mode: Shepperd's quaternion of A with the sign continuous with the
    /// previous output (updated after every internal step).
    q_dcm: [f64; 4],
}

fn v3(x: &State, i: usize) -> Vector3<f64> {
    Vector3::new(x[i], x[i + 1], x[i + 2])
}

impl AttitudePlant {
    fn cmd(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_cmd_x, self.v.torque_cmd_y, self.v.torque_cmd_z)
    }
    fn dist(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_dist_x, self.v.torque_dist_y, self.v.torque_dist_z)
    }

    /// Per-axis actuator limit (paper 004 Eqs. 8–9): a_i u_max,i once the fault is active.
    fn limits(&self, faulted: bool) -> Vector3<f64> {
        let v = &self.v;
        let umax = Vector3::new(v.u_max_x, v.u_max_y, v.u_max_z);
        if faulted {
            umax.component_mul(&Vector3::new(v.effectiveness_x, v.effectiveness_y, v.effectiveness_z))
        } else {
            umax
        }
    }

    fn applied_torque(&self, faulted: bool) -> Vector3<f64> {
        let l = self.limits(faulted);
        let c = self.cmd();
        Vector3::new(c.x.clamp(-l.x, l.x), c.y.clamp(-l.y, l.y), c.z.clamp(-l.z, l.z))
    }

    fn kin(&self) -> Kinematics {
        self.kin.unwrap_or(Kinematics::Quaternion)
    }

    /// Attitude matrix A (v_B = A v_R) of a state: A(q) in mode 0, the integrated DCM in mode 1,
    /// A321 of the state angles in modes 2 and 3 (paper 000 reads its angles as 321, spec §1.3).
    fn attitude(&self, x: &State) -> Matrix3<f64> {
        match self.kin() {
            Kinematics::Quaternion => attitude_matrix(&quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3])),
            Kinematics::Dcm => Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => {
                attitude_matrix(&quat_from_euler321(x[ATT], x[ATT + 1], x[ATT + 2]))
            }
        }
    }

    /// Output quaternion of a state (never sign-flipped in mode 0; sign-continuous in mode 1).
    fn quaternion(&self, x: &State) -> nalgebra::Quaternion<f64> {
        match self.kin() {
            Kinematics::Quaternion => quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3]),
            Kinematics::Dcm => quat(self.q_dcm[0], self.q_dcm[1], self.q_dcm[2], self.q_dcm[3]),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => quat_from_euler321(x[ATT], x[ATT + 1], x[ATT + 2]),
        }
    }

    /// ẋ with the inputs held.
    fn derivative(&self, _t: f64, x: &State, faulted: bool) -> State {
        let w = v3(x, W);
        let tau = self.applied_torque(faulted) + self.dist();
        let mut d = State::zeros();
        match self.kin() {
            Kinematics::LinearSmallAngle => {
                // per-axis double integrator with the diagonal of I_true (paper 000 Eq. 1)
                d.fixed_rows_mut::<3>(ATT).copy_from(&w);
                let diag = self.inertia.diagonal();
                d.fixed_rows_mut::<3>(W).copy_from(&tau.component_div(&diag));
                return d;
            }
            Kinematics::Quaternion => {
                let qdot = quat_derivative(&quat(x[ATT], x[ATT + 1], x[ATT + 2], x[ATT + 3]), &w);
                // nalgebra stores (i, j, k, w); the state holds (w, x, y, z)
                (d[ATT], d[ATT + 1], d[ATT + 2], d[ATT + 3]) = (qdot.w, qdot.i, qdot.j, qdot.k);
            }
            Kinematics::Dcm => {
                // Ȧ = −[ω×] A (paper 000 Eq. 12)
                let a = Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]);
                let adot = -skew(&w) * a;
                d.as_mut_slice()[ATT..ATT + 9].copy_from_slice(adot.as_slice());
            }
            Kinematics::Euler213Rates => {
                // paper 000 Eq. 8, corrected sign (213 rates)
                let r = euler213_rates(x[ATT], x[ATT + 2], &w);
                d.fixed_rows_mut::<3>(ATT).copy_from(&r);
            }
        }
        let wdot = self.inertia_inv * (tau - w.cross(&(self.inertia * w)));
        d.fixed_rows_mut::<3>(W).copy_from(&wdot);
        d
    }

    /// Projection after every internal step: quaternion renormalisation (mode 0), optional DCM
    /// re-orthonormalisation (mode 1); also updates the sign-continuous DCM quaternion.
    fn post_step(&mut self, x: &mut State, t: f64) -> ModelResult {
        if !x.iter().all(|c| c.is_finite()) {
            return Err(format!("state became non-finite at t = {t}"));
        }
        match self.kin() {
            Kinematics::Quaternion => {
                let n = x.fixed_rows::<4>(ATT).norm();
                if !(n > 0.0) {
                    return Err(format!("quaternion norm became zero at t = {t}"));
                }
                x.fixed_rows_mut::<4>(ATT).unscale_mut(n);
            }
            Kinematics::Dcm => {
                let mut a = Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]);
                if self.v.dcm_orthonormalize == 1 {
                    a = orthonormalize(&a);
                    x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(a.as_slice());
                }
                let prev = quat(self.q_dcm[0], self.q_dcm[1], self.q_dcm[2], self.q_dcm[3]);
                let mut q = align_sign(quat_from_dcm(&a), &prev);
                // A drifts off SO(3) without re-orthonormalisation; report a unit quaternion
                q = q.normalize();
                self.q_dcm = wxyz(&q);
            }
            Kinematics::Euler213Rates => {
                if x[ATT].cos().abs() < 1e-9 {
                    return Err(format!("Euler-angle kinematics (mode 2) reached the singularity roll = ±90° at t = {t}"));
                }
            }
            Kinematics::LinearSmallAngle => {}
        }
        Ok(())
    }
}

impl Model for AttitudePlant {
    type Vars = AttitudePlantVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudePlant",
        description: "Three-axis rigid spacecraft with full inertia, quaternion kinematics and saturating, fault-prone torque actuators",
        source: "shared/spec attitude-plant.md §1 (papers 000, 003, 004)",
        equations_html: "<pre>I dw/dt = tau_act + tau_ext - w x (I w)          (Euler's equations, full inertia matrix)\n\
l_i(t)  = a_i u_max,i for t >= fault_time, else u_max,i\n\
tau_act = clamp(torque_cmd, -l, +l)                 (paper 004 Eqs. 8-9)\n\
tau_ext = torque_dist\n\
I_true  = S I S,  S = diag(sqrt(inertia_scale))</pre>\n\
<p>Kinematics (parameter <code>kinematics</code>):</p><pre>\
0 quaternion: dq/dt = 1/2 q (x) (0, w); q renormalised after every internal step\n\
1 DCM:        dA/dt = -[w x] A (paper 000 Eq. 12); re-orthonormalised (SVD polar factor) only if dcm_orthonormalize = 1;\n\
              output q = Shepperd's quaternion of A, sign chosen continuous with the previous output; roll/pitch/yaw = 321 angles of A\n\
2 Euler:      d(phi)/dt = w_x cos(psi) - w_y sin(psi)\n\
              d(theta)/dt = (w_x sin(psi) + w_y cos(psi)) / cos(phi)\n\
              d(psi)/dt = (w_x sin(psi) + w_y cos(psi)) tan(phi) + w_z      (paper 000 Eq. 8 with the corrected sign = 213 rates)\n\
              the angles are read as 321 angles: q = q321(phi, theta, psi), roll/pitch/yaw = (phi, theta, psi) (paper 000 Eq. 6)\n\
3 linear:     I_xx phi'' = tau_x, I_yy theta'' = tau_y, I_zz psi'' = tau_z (paper 000 Eq. 1; diagonal of I_true only, no coupling);\n\
              w outputs = (phi', theta', psi'); q = q321(phi, theta, psi)</pre>\n\
<p>Fixed-step RK4 (or explicit Euler) with ceil(step / max_internal_step) equal internal steps per communication step, \
cut at fault_time (the fault state is constant within an internal step); inputs are held over the step.</p>",
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
        let kin = match check::choice("kinematics", v.kinematics, &[0, 1, 2, 3])? {
            0 => Kinematics::Quaternion,
            1 => Kinematics::Dcm,
            2 => Kinematics::Euler213Rates,
            _ => Kinematics::LinearSmallAngle,
        };
        check::choice("dcm_orthonormalize", v.dcm_orthonormalize, &[0, 1])?;
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
        self.kin = Some(kin);
        let (r0, p0, y0) = (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw);
        let q0 = quat_from_euler321(r0, p0, y0);
        let mut x = State::zeros();
        match kin {
            Kinematics::Quaternion => x.as_mut_slice()[ATT..ATT + 4].copy_from_slice(&wxyz(&q0)),
            Kinematics::Dcm => x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(attitude_matrix(&q0).as_slice()),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => {
                if kin == Kinematics::Euler213Rates && r0.cos().abs() < 1e-9 {
                    return Err(format!("init_euler321_roll = {r0} is the singularity of the Euler-angle kinematics (kinematics = 2)"));
                }
                x.as_mut_slice()[ATT..ATT + 3].copy_from_slice(&[r0, p0, y0]);
            }
        }
        x.as_mut_slice()[W..W + 3].copy_from_slice(&[v.init_w_x, v.init_w_y, v.init_w_z]);
        self.q_dcm = wxyz(&q0);
        self.x = x;
        Ok(())
    }

    fn update_outputs(&mut self, t: f64) -> ModelResult {
        let x = self.x;
        let q = self.quaternion(&x);
        let a = self.attitude(&x);
        let w = v3(&x, W);
        let [rl, pt, yw] = match self.kin() {
            Kinematics::Quaternion => euler321_from_quat(&q),
            Kinematics::Dcm => euler321_from_dcm(&a),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => [x[ATT], x[ATT + 1], x[ATT + 2]],
        };
        let tau = self.applied_torque(t >= self.v.fault_time);
        let ext = self.dist();
        let h_ref = a.transpose() * (self.inertia * w);
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
        let fault_time = self.v.fault_time;
        for (ts, dt) in internal_steps(t, h, self.v.max_internal_step, &[fault_time]) {
            // the fault state is constant over an internal step (steps are cut at fault_time)
            let faulted = ts + 0.5 * dt >= fault_time;
            let mut f = |tt: f64, xx: &State| self.derivative(tt, xx, faulted);
            x = match method {
                FixedMethod::Rk4 => rk4(&mut f, ts, &x, dt),
                FixedMethod::Euler => euler(&mut f, ts, &x, dt),
            };
            self.post_step(&mut x, ts + dt)?;
        }
        self.x = x;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plant(setup: impl FnOnce(&mut AttitudePlantVars)) -> AttitudePlant {
        let mut p = AttitudePlant::default();
        setup(&mut p.v);
        p.initialize(&Experiment::default()).unwrap();
        p.update_outputs(0.0).unwrap();
        p
    }

    fn q_of(p: &AttitudePlant) -> nalgebra::Quaternion<f64> {
        quat(p.v.q_w, p.v.q_x, p.v.q_y, p.v.q_z)
    }

    /// A fixed, smooth torque history applied as zero-order hold at 0.1 s.
    fn torque(t: f64) -> [f64; 3] {
        [20.0 * (0.3 * t).sin(), -15.0 * (0.2 * t + 0.5).cos(), 10.0 * (0.11 * t).sin() + 3.0]
    }

    fn run(p: &mut AttitudePlant, t_end: f64, dt: f64, mut each: impl FnMut(&AttitudePlant)) {
        let n = (t_end / dt).round() as usize;
        for k in 0..n {
            let t = k as f64 * dt;
            let c = torque(t);
            (p.v.torque_cmd_x, p.v.torque_cmd_y, p.v.torque_cmd_z) = (c[0], c[1], c[2]);
            p.update_outputs(t).unwrap();
            each(p);
            p.do_step(t, dt, &Experiment::default()).unwrap();
        }
        p.update_outputs(t_end).unwrap();
        each(p);
    }

    fn full_inertia(v: &mut AttitudePlantVars) {
        (v.inertia_xx, v.inertia_yy, v.inertia_zz, v.inertia_xy, v.inertia_xz, v.inertia_yz) = (1000.0, 500.0, 700.0, 30.0, -20.0, 15.0);
        (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw) = (0.3, -0.4, 1.0);
        (v.init_w_x, v.init_w_y, v.init_w_z) = (0.05, -0.03, 0.02);
    }

    #[test]
    fn dcm_mode_matches_quaternion_mode() {
        // spec §1.7 test 3: same q(t) within 1e-6 over 30 s for the same torque history
        let mut a = plant(full_inertia);
        let mut b = plant(|v| {
            full_inertia(v);
            v.kinematics = 1;
        });
        let mut qa = Vec::new();
        run(&mut a, 30.0, 0.1, |p| qa.push(q_of(p)));
        let mut k = 0;
        let mut worst: f64 = 0.0;
        let mut prev = q_of(&b);
        run(&mut b, 30.0, 0.1, |p| {
            let q = q_of(p);
            worst = worst.max((q.coords - qa[k].coords).abs().max());
            // sign continuity: consecutive outputs never jump to the antipode
            assert!(q.coords.dot(&prev.coords) > 0.9);
            prev = q;
            k += 1;
        });
        println!("kinematics 0 vs 1: max |q_dcm - q_quat| over 30 s = {worst:.3e}");
        assert!(worst < 1e-6, "{worst}");
        // 321 angles from A agree with those from q
        assert!((a.v.roll - b.v.roll).abs() < 1e-6 && (a.v.pitch - b.v.pitch).abs() < 1e-6 && (a.v.yaw - b.v.yaw).abs() < 1e-6);
    }

    #[test]
    fn dcm_orthonormalisation_option() {
        let mut b = plant(|v| {
            full_inertia(v);
            v.kinematics = 1;
            v.dcm_orthonormalize = 1;
            v.max_internal_step = 0.1;
        });
        run(&mut b, 30.0, 0.1, |_| {});
        let a = Matrix3::from_column_slice(&b.x.as_slice()[ATT..ATT + 9]);
        assert!((a.transpose() * a - Matrix3::identity()).abs().max() < 1e-13);
    }

    #[test]
    fn dcm_quaternion_sign_is_continuous_through_half_turns() {
        // spin about z at 1 rad/s for 20 s: Shepperd alone would switch pivots and signs
        let mut b = plant(|v| {
            v.kinematics = 1;
            v.init_w_z = 1.0;
        });
        let mut prev = q_of(&b);
        let mut qlast = prev;
        for k in 0..400 {
            b.do_step(k as f64 * 0.05, 0.05, &Experiment::default()).unwrap();
            b.update_outputs((k + 1) as f64 * 0.05).unwrap();
            let q = q_of(&b);
            assert!(q.coords.dot(&prev.coords) > 0.99, "sign jump");
            prev = q;
            qlast = q;
        }
        // continuous integration of q̇ gives q(20) = (cos 10, 0, 0, sin 10) (no sign flips)
        assert!((qlast.w - 10f64.cos()).abs() < 1e-8 && (qlast.k - 10f64.sin()).abs() < 1e-8, "{qlast:?}");
    }

    #[test]
    fn euler_mode_reproduces_213_kinematics_read_as_321() {
        // Mode 2 integrates the 213 rates. Independent check: the DCM integrated from the same ω(t)
        // (mode 1) equals A213 of the mode-2 angles; the output q is q321 of those angles.
        let mut e = plant(|v| {
            full_inertia(v);
            v.kinematics = 2;
            (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw) = (0.0, 0.0, 0.0);
        });
        let mut d = plant(|v| {
            full_inertia(v);
            v.kinematics = 1;
            (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw) = (0.0, 0.0, 0.0);
        });
        run(&mut e, 10.0, 0.1, |_| {});
        run(&mut d, 10.0, 0.1, |_| {});
        let a_dcm = Matrix3::from_column_slice(&d.x.as_slice()[ATT..ATT + 9]);
        let a213 = crate::math::attitude::dcm_from_euler213(e.v.roll, e.v.pitch, e.v.yaw);
        let err = (a_dcm - a213).abs().max();
        println!("kinematics 2: max |A213(angles) - A_dcm| after 10 s = {err:.3e}");
        assert!(err < 1e-8, "{err}");
        // rates are the same body rates in both
        assert!((e.v.w_x - d.v.w_x).abs() < 1e-10);
        let q321 = quat_from_euler321(e.v.roll, e.v.pitch, e.v.yaw);
        assert!((q_of(&e).coords - q321.coords).abs().max() < 1e-15);
    }

    #[test]
    fn small_angle_modes_agree_to_first_order() {
        // spec §1.7 test 3: modes 2 and 3 agree to first order for angles below 1e-3 rad
        let tiny = |v: &mut AttitudePlantVars| {
            (v.inertia_xx, v.inertia_yy, v.inertia_zz) = (1000.0, 500.0, 700.0);
            v.init_euler321_roll = 2e-4;
            v.init_w_y = 1e-5;
        };
        let mut e = plant(|v| {
            tiny(v);
            v.kinematics = 2;
        });
        let mut l = plant(|v| {
            tiny(v);
            v.kinematics = 3;
        });
        let small = |t: f64| [1e-4 * (0.3 * t).sin(), -5e-5, 2e-5 * t.cos()];
        let mut worst: f64 = 0.0;
        let mut biggest: f64 = 0.0;
        for k in 0..100 {
            let t = k as f64 * 0.1;
            for p in [&mut e, &mut l] {
                let c = small(t);
                (p.v.torque_cmd_x, p.v.torque_cmd_y, p.v.torque_cmd_z) = (c[0], c[1], c[2]);
                p.do_step(t, 0.1, &Experiment::default()).unwrap();
                p.update_outputs(t + 0.1).unwrap();
            }
            let de = [e.v.roll - l.v.roll, e.v.pitch - l.v.pitch, e.v.yaw - l.v.yaw];
            worst = worst.max(de.iter().fold(0.0, |m: f64, x| m.max(x.abs())));
            biggest = biggest.max(l.v.roll.abs().max(l.v.pitch.abs()).max(l.v.yaw.abs()));
        }
        println!("kinematics 2 vs 3: max angle {biggest:.3e} rad, max difference {worst:.3e} rad");
        assert!(biggest < 1e-3);
        // second-order terms: difference ≤ a few × (max angle)²
        assert!(worst < 5.0 * biggest * biggest, "{worst} vs {biggest}");
    }

    #[test]
    fn linear_mode_is_a_double_integrator() {
        // constant torque: φ = φ0 + φ̇0 t + ½ (τ/I_xx) t², exact for RK4
        let mut l = plant(|v| {
            v.kinematics = 3;
            v.init_euler321_roll = 0.1;
            v.init_w_x = 0.01;
            v.torque_cmd_x = 5.0;
            v.torque_cmd_z = -7.0;
            v.inertia_scale_x = 1.1;
        });
        for k in 0..50 {
            l.do_step(k as f64 * 0.1, 0.1, &Experiment::default()).unwrap();
        }
        l.update_outputs(5.0).unwrap();
        let phi = 0.1 + 0.01 * 5.0 + 0.5 * (5.0 / 1100.0) * 25.0;
        let psi = 0.5 * (-7.0 / 700.0) * 25.0;
        assert!((l.v.roll - phi).abs() < 1e-12 && (l.v.yaw - psi).abs() < 1e-12);
        assert!((l.v.w_x - (0.01 + 5.0 / 1100.0 * 5.0)).abs() < 1e-12);
    }

    #[test]
    fn euler_mode_rejects_singular_start() {
        let mut p = AttitudePlant::default();
        p.v.kinematics = 2;
        p.v.init_euler321_roll = std::f64::consts::FRAC_PI_2;
        assert!(p.initialize(&Experiment::default()).is_err());
    }
}
