//! `AttitudePlant`: three-axis rigid body (gyrostat) with full inertia, selectable kinematics
//! (quaternion, DCM, paper 000's Euler-angle rates, linear small-angle model), ideal torque actuators
//! or reaction wheels with magnetorquers, actuator faults, disturbance generator and gravity
//! gradient on a circular orbit (spec attitude-plant.md §1).

use nalgebra::{Matrix3, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{
    align_sign, attitude_matrix, euler213_rates, euler321_from_dcm, euler321_from_quat, orthonormalize, quat, quat_derivative,
    quat_from_dcm, quat_from_euler321, skew, wxyz,
};
use crate::math::environment::{gravity_gradient, CircularOrbit};
use crate::math::integrate::{pieces, Method, Stepper};
use crate::math::random::{hold_index, normal};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct AttitudePlantVars {
        // inputs
        0 => torque_cmd_x: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body x";
        1 => torque_cmd_y: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body y";
        2 => torque_cmd_z: Real = 0.0, Input, Continuous, "N.m", "Commanded control torque, body z";
        3 => torque_dist_x: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body x (added to the internal generator)";
        4 => torque_dist_y: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body y";
        5 => torque_dist_z: Real = 0.0, Input, Continuous, "N.m", "External disturbance torque, body z";
        // outputs
        10 => q_w: Real = 1.0, Output, Continuous, "", "Attitude quaternion of B relative to R, scalar part";
        11 => q_x: Real = 0.0, Output, Continuous, "", "Attitude quaternion, x component";
        12 => q_y: Real = 0.0, Output, Continuous, "", "Attitude quaternion, y component";
        13 => q_z: Real = 0.0, Output, Continuous, "", "Attitude quaternion, z component";
        14 => w_x: Real = 0.0, Output, Continuous, "rad/s", "Body rate of B relative to R, body x (kinematics 3: roll rate)";
        15 => w_y: Real = 0.0, Output, Continuous, "rad/s", "Body rate, body y (kinematics 3: pitch rate)";
        16 => w_z: Real = 0.0, Output, Continuous, "rad/s", "Body rate, body z (kinematics 3: yaw rate)";
        17 => roll: Real = 0.0, Output, Continuous, "rad", "Roll angle of the 321 sequence (kinematics 2, 3: the state angle)";
        18 => pitch: Real = 0.0, Output, Continuous, "rad", "Pitch angle of the 321 sequence (kinematics 2, 3: the state angle)";
        19 => yaw: Real = 0.0, Output, Continuous, "rad", "Yaw angle of the 321 sequence (kinematics 2, 3: the state angle)";
        20 => roll_deg: Real = 0.0, Output, Continuous, "deg", "Roll angle in degrees";
        21 => pitch_deg: Real = 0.0, Output, Continuous, "deg", "Pitch angle in degrees";
        22 => yaw_deg: Real = 0.0, Output, Continuous, "deg", "Yaw angle in degrees";
        23 => torque_applied_x: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators (wheels + magnetorquers), body x";
        24 => torque_applied_y: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators, body y";
        25 => torque_applied_z: Real = 0.0, Output, Continuous, "N.m", "Control torque acting on the body after the actuators, body z";
        26 => torque_ext_x: Real = 0.0, Output, Continuous, "N.m", "Total external torque (input + generator + gravity gradient), body x";
        27 => torque_ext_y: Real = 0.0, Output, Continuous, "N.m", "Total external torque, body y";
        28 => torque_ext_z: Real = 0.0, Output, Continuous, "N.m", "Total external torque, body z";
        29 => h_total_ref_x: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum A(q)^T (I w + h_w) in R, x";
        30 => h_total_ref_y: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum in R, y";
        31 => h_total_ref_z: Real = 0.0, Output, Continuous, "N.m.s", "Total angular momentum in R, z";
        32 => h_wheel_x: Real = 0.0, Output, Continuous, "N.m.s", "Reaction-wheel momentum h_w about body x (actuator_mode 1)";
        33 => h_wheel_y: Real = 0.0, Output, Continuous, "N.m.s", "Reaction-wheel momentum about body y";
        34 => h_wheel_z: Real = 0.0, Output, Continuous, "N.m.s", "Reaction-wheel momentum about body z";
        35 => wheel_speed_x: Real = 0.0, Output, Continuous, "rad/s", "Wheel spin relative to the body h_w/J_w, x";
        36 => wheel_speed_y: Real = 0.0, Output, Continuous, "rad/s", "Wheel spin relative to the body, y";
        37 => wheel_speed_z: Real = 0.0, Output, Continuous, "rad/s", "Wheel spin relative to the body, z";
        38 => dipole_x: Real = 0.0, Output, Continuous, "A.m2", "Magnetorquer dipole m, body x";
        39 => dipole_y: Real = 0.0, Output, Continuous, "A.m2", "Magnetorquer dipole, body y";
        40 => dipole_z: Real = 0.0, Output, Continuous, "A.m2", "Magnetorquer dipole, body z";
        41 => b_body_x: Real = 0.0, Output, Continuous, "T", "Geomagnetic field in body axes, x";
        42 => b_body_y: Real = 0.0, Output, Continuous, "T", "Geomagnetic field in body axes, y";
        43 => b_body_z: Real = 0.0, Output, Continuous, "T", "Geomagnetic field in body axes, z";
        // parameters: body
        100 => inertia_xx: Real = 1000.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xx (paper 000 default)";
        101 => inertia_yy: Real = 500.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry yy";
        102 => inertia_zz: Real = 700.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry zz";
        103 => inertia_xy: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xy (matrix entry, not product of inertia)";
        104 => inertia_xz: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry xz";
        105 => inertia_yz: Real = 0.0, Parameter, Fixed, "kg.m2", "Inertia matrix entry yz";
        106 => inertia_scale_x: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_x: I_true = S I S, S = diag(sqrt(s))";
        107 => inertia_scale_y: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_y";
        108 => inertia_scale_z: Real = 1.0, Parameter, Fixed, "", "Uncertainty factor s_z";
        110 => init_euler321_roll: Real = 0.0, Parameter, Fixed, "rad", "Initial roll (321 sequence; kinematics 2, 3: initial state angle)";
        111 => init_euler321_pitch: Real = 0.0, Parameter, Fixed, "rad", "Initial pitch (321 sequence)";
        112 => init_euler321_yaw: Real = 0.0, Parameter, Fixed, "rad", "Initial yaw (321 sequence)";
        113 => init_w_x: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate x (kinematics 3: roll rate)";
        114 => init_w_y: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate y";
        115 => init_w_z: Real = 0.0, Parameter, Fixed, "rad/s", "Initial body rate z";
        116 => init_h_wheel_x: Real = 0.0, Parameter, Fixed, "N.m.s", "Initial wheel momentum x (actuator_mode 1)";
        117 => init_h_wheel_y: Real = 0.0, Parameter, Fixed, "N.m.s", "Initial wheel momentum y";
        118 => init_h_wheel_z: Real = 0.0, Parameter, Fixed, "N.m.s", "Initial wheel momentum z";
        // parameters: actuator mode 0 and faults
        120 => u_max_x: Real = 1e30, Parameter, Fixed, "N.m", "Actuator mode 0: torque limit x (1e30 = no limit)";
        121 => u_max_y: Real = 1e30, Parameter, Fixed, "N.m", "Actuator mode 0: torque limit y (1e30 = no limit)";
        122 => u_max_z: Real = 1e30, Parameter, Fixed, "N.m", "Actuator mode 0: torque limit z (1e30 = no limit)";
        123 => effectiveness_x: Real = 1.0, Parameter, Fixed, "", "Effectiveness a_x in [0, 1] after fault_time: limit a_x u_max_x (mode 0) or a_x k_t i_max (mode 1) (paper 004)";
        124 => effectiveness_y: Real = 1.0, Parameter, Fixed, "", "Effectiveness a_y in [0, 1] after fault_time";
        125 => effectiveness_z: Real = 1.0, Parameter, Fixed, "", "Effectiveness a_z in [0, 1] after fault_time";
        126 => fault_time: Real = 0.0, Parameter, Fixed, "s", "Onset time of all actuator faults (effectiveness, bias, stuck)";
        127 => fault_bias_x: Real = 0.0, Parameter, Fixed, "N.m", "Bias fault: added to the torque command x after fault_time (before the limits)";
        128 => fault_bias_y: Real = 0.0, Parameter, Fixed, "N.m", "Bias fault y";
        129 => fault_bias_z: Real = 0.0, Parameter, Fixed, "N.m", "Bias fault z";
        131 => fault_stuck_value_x: Real = 0.0, Parameter, Fixed, "N.m", "Stuck fault: torque command x is replaced by this value after fault_time if fault_stuck_x = 1";
        132 => fault_stuck_value_y: Real = 0.0, Parameter, Fixed, "N.m", "Stuck-at value y";
        133 => fault_stuck_value_z: Real = 0.0, Parameter, Fixed, "N.m", "Stuck-at value z";
        130 => max_internal_step: Real = 0.01, Parameter, Fixed, "s", "Internal step of RK4/Euler (integrator 2 ignores it: adaptive steps)";
        // Integer parameters
        140 => integrator: Integer = 0, Parameter, Fixed, "", "Internal integrator: 0 = classical RK4, 1 = explicit Euler, 2 = adaptive Dormand-Prince 5(4) (tolerance from fmi2SetupExperiment, default 1e-8)";
        141 => kinematics: Integer = 0, Parameter, Fixed, "", "Kinematics: 0 = quaternion, 1 = DCM, 2 = paper 000 Euler-angle rates (213 rates, angles output as 321), 3 = linear small-angle double integrator";
        142 => actuator_mode: Integer = 0, Parameter, Fixed, "", "Actuators: 0 = ideal torque with saturation and fault, 1 = three reaction wheels (+ magnetorquers if mtq_enable = 1)";
        143 => dcm_orthonormalize: Integer = 0, Parameter, Fixed, "", "Kinematics 1 only: 1 = re-orthonormalise the DCM after every internal step, 0 = never";
        144 => mtq_enable: Integer = 0, Parameter, Fixed, "", "Actuator mode 1: 1 = magnetorquers dump wheel momentum, 0 = off";
        145 => gg_enable: Integer = 0, Parameter, Fixed, "", "1 = gravity-gradient torque of the circular orbit, 0 = off";
        146 => dist_noise_seed: Integer = 1, Parameter, Fixed, "", "Seed of the counter-based white-noise generator";
        147 => fault_stuck_x: Integer = 0, Parameter, Fixed, "", "1 = actuator x stuck at fault_stuck_value_x after fault_time";
        148 => fault_stuck_y: Integer = 0, Parameter, Fixed, "", "1 = actuator y stuck after fault_time";
        149 => fault_stuck_z: Integer = 0, Parameter, Fixed, "", "1 = actuator z stuck after fault_time";
        // reaction wheels (paper 003 values, all project choice)
        150 => wheel_time_constant: Real = 0.0, Parameter, Fixed, "s", "Wheel torque lag T_w (0 = no lag) (paper 002 Eq. 7 form)";
        151 => wheel_gain: Real = 1.0, Parameter, Fixed, "", "Wheel gain K_w";
        152 => wheel_inertia: Real = 1.2e-3, Parameter, Fixed, "kg.m2", "Wheel spin inertia J_w";
        153 => wheel_torque_coeff: Real = 0.05, Parameter, Fixed, "N.m/A", "Wheel motor torque coefficient k_t";
        154 => wheel_max_current: Real = 1.0, Parameter, Fixed, "A", "Wheel motor current limit i_max (torque limit k_t i_max)";
        155 => wheel_max_speed: Real = 420.0, Parameter, Fixed, "rad/s", "Wheel speed limit Omega_max (momentum limit J_w Omega_max)";
        // magnetorquers (project choice)
        156 => mtq_turns: Real = 500.0, Parameter, Fixed, "", "Magnetorquer coil turns N";
        157 => mtq_coil_area: Real = 0.01, Parameter, Fixed, "m2", "Magnetorquer coil area A";
        158 => mtq_max_current: Real = 0.2, Parameter, Fixed, "A", "Magnetorquer current limit (dipole limit N A i)";
        159 => mtq_k_dump: Real = 0.005, Parameter, Fixed, "1/s", "Momentum-dumping gain k_dump (> 0 dumps): m = k_dump (h_w x B)/|B|^2";
        // environment (project choice)
        160 => mu: Real = 3.986004418e14, Parameter, Fixed, "m3/s2", "Earth gravitational parameter";
        161 => orbit_radius: Real = 7078137.0, Parameter, Fixed, "m", "Circular orbit radius (700 km altitude)";
        162 => orbit_inclination: Real = 1.7104226669544429, Parameter, Fixed, "rad", "Orbit inclination (98 deg)";
        163 => orbit_arg_lat0: Real = 0.0, Parameter, Fixed, "rad", "Argument of latitude at t = 0";
        164 => earth_dipole: Real = 7.96e15, Parameter, Fixed, "T.m3", "Earth dipole strength M_E";
        // disturbance generator
        170 => dist_const_x: Real = 0.0, Parameter, Fixed, "N.m", "Constant disturbance torque c_x";
        171 => dist_const_y: Real = 0.0, Parameter, Fixed, "N.m", "Constant disturbance torque c_y";
        172 => dist_const_z: Real = 0.0, Parameter, Fixed, "N.m", "Constant disturbance torque c_z";
        173 => dist_sin_amp_x: Real = 0.0, Parameter, Fixed, "N.m", "Sinusoidal disturbance amplitude A_x";
        174 => dist_sin_amp_y: Real = 0.0, Parameter, Fixed, "N.m", "Sinusoidal disturbance amplitude A_y";
        175 => dist_sin_amp_z: Real = 0.0, Parameter, Fixed, "N.m", "Sinusoidal disturbance amplitude A_z";
        176 => dist_sin_freq: Real = 0.0, Parameter, Fixed, "rad/s", "Sinusoidal disturbance frequency Omega_d";
        177 => dist_sin_phase_x: Real = 0.0, Parameter, Fixed, "rad", "Sinusoidal disturbance phase phi_x";
        178 => dist_sin_phase_y: Real = 0.0, Parameter, Fixed, "rad", "Sinusoidal disturbance phase phi_y";
        179 => dist_sin_phase_z: Real = 0.0, Parameter, Fixed, "rad", "Sinusoidal disturbance phase phi_z";
        180 => dist_noise_std_x: Real = 0.0, Parameter, Fixed, "N.m", "White-noise standard deviation sigma_x (zero-order held)";
        181 => dist_noise_std_y: Real = 0.0, Parameter, Fixed, "N.m", "White-noise standard deviation sigma_y";
        182 => dist_noise_std_z: Real = 0.0, Parameter, Fixed, "N.m", "White-noise standard deviation sigma_z";
        183 => dist_noise_hold: Real = 0.1, Parameter, Fixed, "s", "Hold interval T_n of the noise (PSD about sigma^2 T_n)";
        // calculated parameters
        200 => wheel_torque_max: Real = 0.05, CalculatedParameter, Fixed, "N.m", "Wheel torque limit k_t i_max before faults";
        201 => wheel_momentum_max: Real = 0.504, CalculatedParameter, Fixed, "N.m.s", "Wheel momentum limit J_w Omega_max";
        202 => mtq_dipole_max: Real = 1.0, CalculatedParameter, Fixed, "A.m2", "Magnetorquer dipole limit N A i_max";
        203 => orbit_rate: Real = 0.0, CalculatedParameter, Fixed, "rad/s", "Orbital rate n = sqrt(mu / r^3)";
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
/// - `W..W+3`: body rate ω (kinematics 0–2) or the angle rates (φ̇, θ̇, ψ̇) (kinematics 3);
/// - `HW..HW+3`: wheel momentum h_w (actuator mode 1);
/// - `TW..TW+3`: lagged wheel torque τ_w (actuator mode 1 with T_w > 0).
const N: usize = 18;
const ATT: usize = 0;
const W: usize = 9;
const HW: usize = 12;
const TW: usize = 15;
type State = SVector<f64, N>;

/// What is constant over one internal step (steps are cut at fault_time and at noise-hold boundaries).
#[derive(Clone, Copy, Debug)]
struct Segment {
    faulted: bool,
    noise: Vector3<f64>,
}

/// Actuator outputs at one instant.
#[derive(Clone, Copy, Debug, Default)]
struct Actuation {
    /// τ_act = τ_rw + τ_mtq (mode 1) or the clamped command (mode 0).
    torque: Vector3<f64>,
    /// Wheel torque on the body τ_rw; ḣ_w = −τ_rw.
    wheel: Vector3<f64>,
    /// dτ_w/dt of the wheel lag.
    lag_rate: Vector3<f64>,
    dipole: Vector3<f64>,
}

/// Parameters derived at initialization.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct Derived {
    orbit: CircularOrbit,
    n2: f64,
    wheel_torque_max: f64,
    wheel_momentum_max: f64,
    dipole_max: f64,
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AttitudePlant {
    v: AttitudePlantVars,
    x: State,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// Integrator chosen at initialization (None before), with its adaptive step proposal.
    stepper: Option<Stepper>,
    kin: Option<Kinematics>,
    d: Derived,
    /// Quaternion output of the DCM mode: Shepperd's quaternion of A with the sign continuous with the
    /// previous output (updated after every internal step).
    q_dcm: [f64; 4],
}

fn v3(x: &State, i: usize) -> Vector3<f64> {
    Vector3::new(x[i], x[i + 1], x[i + 2])
}

fn clamp3(v: Vector3<f64>, l: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x.clamp(-l.x, l.x), v.y.clamp(-l.y, l.y), v.z.clamp(-l.z, l.z))
}

impl AttitudePlant {
    fn cmd(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_cmd_x, self.v.torque_cmd_y, self.v.torque_cmd_z)
    }
    fn dist(&self) -> Vector3<f64> {
        Vector3::new(self.v.torque_dist_x, self.v.torque_dist_y, self.v.torque_dist_z)
    }
    fn effectiveness(&self, faulted: bool) -> Vector3<f64> {
        let v = &self.v;
        if faulted { Vector3::new(v.effectiveness_x, v.effectiveness_y, v.effectiveness_z) } else { Vector3::repeat(1.0) }
    }
    fn wheels(&self) -> bool {
        self.v.actuator_mode == 1
    }
    fn mtq(&self) -> bool {
        self.wheels() && self.v.mtq_enable == 1
    }
    fn noise_on(&self) -> bool {
        let v = &self.v;
        v.dist_noise_std_x != 0.0 || v.dist_noise_std_y != 0.0 || v.dist_noise_std_z != 0.0
    }

    /// Command after the stuck/bias faults (project choice: both act on the command entering the
    /// actuator, so the torque and momentum limits still hold).
    fn faulty_cmd(&self, faulted: bool) -> Vector3<f64> {
        let c = self.cmd();
        if !faulted {
            return c;
        }
        let v = &self.v;
        let one = |cmd: f64, bias: f64, stuck: i32, value: f64| if stuck == 1 { value } else { cmd + bias };
        Vector3::new(
            one(c.x, v.fault_bias_x, v.fault_stuck_x, v.fault_stuck_value_x),
            one(c.y, v.fault_bias_y, v.fault_stuck_y, v.fault_stuck_value_y),
            one(c.z, v.fault_bias_z, v.fault_stuck_z, v.fault_stuck_value_z),
        )
    }

    /// Zero-order-held white noise of hold interval k: σ_i N(seed, k, i) (counter-based, `math::random`).
    fn noise(&self, k: i64) -> Vector3<f64> {
        if !self.noise_on() {
            return Vector3::zeros();
        }
        let v = &self.v;
        let s = v.dist_noise_seed as i64;
        Vector3::new(v.dist_noise_std_x * normal(s, k, 0), v.dist_noise_std_y * normal(s, k, 1), v.dist_noise_std_z * normal(s, k, 2))
    }

    /// Segment of the instant t (for outputs): fault active from fault_time on, noise interval ⌊t/T_n⌋.
    fn segment_at(&self, t: f64) -> Segment {
        Segment { faulted: t >= self.v.fault_time, noise: self.noise(hold_index(t, self.v.dist_noise_hold)) }
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

    /// Geomagnetic field in body axes, B_b = A B_R(t).
    fn field_body(&self, t: f64, a: &Matrix3<f64>) -> Vector3<f64> {
        a * self.d.orbit.field_ref(t)
    }

    /// Disturbance generator + gravity gradient + input: τ_ext (spec §1.6).
    fn external(&self, t: f64, a: &Matrix3<f64>, seg: &Segment) -> Vector3<f64> {
        let v = &self.v;
        let mut tau = self.dist() + Vector3::new(v.dist_const_x, v.dist_const_y, v.dist_const_z) + seg.noise;
        if v.dist_sin_amp_x != 0.0 || v.dist_sin_amp_y != 0.0 || v.dist_sin_amp_z != 0.0 {
            let wt = v.dist_sin_freq * t;
            tau += Vector3::new(
                v.dist_sin_amp_x * (wt + v.dist_sin_phase_x).sin(),
                v.dist_sin_amp_y * (wt + v.dist_sin_phase_y).sin(),
                v.dist_sin_amp_z * (wt + v.dist_sin_phase_z).sin(),
            );
        }
        if v.gg_enable == 1 {
            tau += gravity_gradient(self.d.n2, &(a * self.d.orbit.r_hat(t)), &self.inertia);
        }
        tau
    }

    /// Actuators (spec §1.4) for state x at time t.
    fn actuate(&self, t: f64, x: &State, a: &Matrix3<f64>, seg: &Segment) -> Actuation {
        let u = self.faulty_cmd(seg.faulted);
        let eff = self.effectiveness(seg.faulted);
        if !self.wheels() {
            let v = &self.v;
            let l = Vector3::new(v.u_max_x, v.u_max_y, v.u_max_z).component_mul(&eff);
            return Actuation { torque: clamp3(u, l), ..Default::default() };
        }
        let v = &self.v;
        let hw = v3(x, HW);
        // magnetorquers: momentum dumping m = k (h_w × B)/|B|², uniformly scaled into ±m_max
        let mut dipole = Vector3::zeros();
        let mut tau_mtq = Vector3::zeros();
        if self.mtq() {
            let b = self.field_body(t, a);
            let b2 = b.norm_squared();
            if b2.sqrt() >= 1e-12 {
                let raw = hw.cross(&b) * (v.mtq_k_dump / b2);
                let peak = raw.amax();
                dipole = if peak > self.d.dipole_max { raw * (self.d.dipole_max / peak) } else { raw };
                tau_mtq = dipole.cross(&b);
            }
        }
        // wheel torque command with the known magnetic torque fed forward, first-order lag
        let rw_cmd = (u - tau_mtq) * v.wheel_gain;
        let (tau_w, lag_rate) = if v.wheel_time_constant > 0.0 {
            let tw = v3(x, TW);
            (tw, (rw_cmd - tw) / v.wheel_time_constant)
        } else {
            (rw_cmd, Vector3::zeros())
        };
        let mut tau_rw = clamp3(tau_w, eff * self.d.wheel_torque_max);
        // momentum (speed) limit: no torque that would grow |h_w| beyond h_max (ḣ_w = −τ_rw)
        for i in 0..3 {
            if hw[i].abs() >= self.d.wheel_momentum_max && -tau_rw[i] * hw[i] > 0.0 {
                tau_rw[i] = 0.0;
            }
        }
        Actuation { torque: tau_rw + tau_mtq, wheel: tau_rw, lag_rate, dipole }
    }

    /// ẋ with the inputs held.
    fn derivative(&self, t: f64, x: &State, seg: &Segment) -> State {
        let w = v3(x, W);
        let needs_a = self.v.gg_enable == 1 || self.mtq();
        let a = if needs_a { self.attitude(x) } else { Matrix3::identity() };
        let act = self.actuate(t, x, &a, seg);
        let tau = act.torque + self.external(t, &a, seg);
        let mut d = State::zeros();
        if self.wheels() {
            d.fixed_rows_mut::<3>(HW).copy_from(&(-act.wheel));
            d.fixed_rows_mut::<3>(TW).copy_from(&act.lag_rate);
        }
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
        // gyrostat: I ω̇ = τ_act + τ_ext − ω × (I ω + h_w)
        let hw = v3(x, HW);
        let wdot = self.inertia_inv * (tau - w.cross(&(self.inertia * w + hw)));
        d.fixed_rows_mut::<3>(W).copy_from(&wdot);
        d
    }

    /// Projection after every internal step: quaternion renormalisation (mode 0), optional DCM
    /// re-orthonormalisation (mode 1); also updates the sign-continuous DCM quaternion.
    fn post_step(kin: Kinematics, orthonormalize_dcm: bool, q_dcm: &mut [f64; 4], x: &mut State, t: f64) -> ModelResult {
        if !x.iter().all(|c| c.is_finite()) {
            return Err(format!("state became non-finite at t = {t}"));
        }
        match kin {
            Kinematics::Quaternion => {
                let n = x.fixed_rows::<4>(ATT).norm();
                if !(n > 0.0) {
                    return Err(format!("quaternion norm became zero at t = {t}"));
                }
                x.fixed_rows_mut::<4>(ATT).unscale_mut(n);
            }
            Kinematics::Dcm => {
                let mut a = Matrix3::from_column_slice(&x.as_slice()[ATT..ATT + 9]);
                if orthonormalize_dcm {
                    a = orthonormalize(&a);
                    x.as_mut_slice()[ATT..ATT + 9].copy_from_slice(a.as_slice());
                }
                let prev = quat(q_dcm[0], q_dcm[1], q_dcm[2], q_dcm[3]);
                // A drifts off SO(3) without re-orthonormalisation; report a unit quaternion
                let q = align_sign(quat_from_dcm(&a), &prev).normalize();
                *q_dcm = wxyz(&q);
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

    /// Breakpoints inside (t, t + h): fault onset and the noise-hold boundaries k T_n.
    fn breakpoints(&self, t: f64, h: f64) -> Result<Vec<f64>, String> {
        let mut b = vec![self.v.fault_time];
        if self.noise_on() {
            let tn = self.v.dist_noise_hold;
            let (k0, k1) = (hold_index(t, tn) + 1, hold_index(t + h, tn));
            if k1 - k0 > 1_000_000 {
                return Err(format!("dist_noise_hold = {tn} s gives more than 1e6 noise intervals in one step of {h} s"));
            }
            b.extend((k0..=k1).map(|k| k as f64 * tn));
        }
        Ok(b)
    }
}

impl Model for AttitudePlant {
    type Vars = AttitudePlantVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudePlant",
        description: "Three-axis rigid spacecraft (gyrostat) with full inertia, selectable kinematics, saturating fault-prone torque actuators or reaction wheels with magnetorquers, disturbance generator and gravity gradient",
        source: "shared/spec attitude-plant.md §1 (papers 000, 002, 003, 004)",
        equations_html: EQUATIONS_HTML,
        feedthrough: Feedthrough::Some(&[
            // per axis also in wheel mode: τ_applied,i = sat(K_w (u_i − τ_mtq,i)) + τ_mtq,i with τ_mtq from the state
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

    fn initialize(&mut self, exp: &Experiment) -> ModelResult {
        let v = &self.v;
        let method = Method::from_param(v.integrator)?;
        let kin = match check::choice("kinematics", v.kinematics, &[0, 1, 2, 3])? {
            0 => Kinematics::Quaternion,
            1 => Kinematics::Dcm,
            2 => Kinematics::Euler213Rates,
            _ => Kinematics::LinearSmallAngle,
        };
        check::choice("actuator_mode", v.actuator_mode, &[0, 1])?;
        for (n, x) in [
            ("dcm_orthonormalize", v.dcm_orthonormalize),
            ("mtq_enable", v.mtq_enable),
            ("gg_enable", v.gg_enable),
            ("fault_stuck_x", v.fault_stuck_x),
            ("fault_stuck_y", v.fault_stuck_y),
            ("fault_stuck_z", v.fault_stuck_z),
        ] {
            check::choice(n, x, &[0, 1])?;
        }
        check::positive("max_internal_step", v.max_internal_step)?;
        for (n, x) in [("u_max_x", v.u_max_x), ("u_max_y", v.u_max_y), ("u_max_z", v.u_max_z)] {
            check::limit(n, x)?;
        }
        for (n, x) in [("effectiveness_x", v.effectiveness_x), ("effectiveness_y", v.effectiveness_y), ("effectiveness_z", v.effectiveness_z)] {
            check::in_range(n, x, 0.0, 1.0)?;
        }
        for (n, x) in [
            ("fault_time", v.fault_time),
            ("fault_bias_x", v.fault_bias_x),
            ("fault_bias_y", v.fault_bias_y),
            ("fault_bias_z", v.fault_bias_z),
            ("fault_stuck_value_x", v.fault_stuck_value_x),
            ("fault_stuck_value_y", v.fault_stuck_value_y),
            ("fault_stuck_value_z", v.fault_stuck_value_z),
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
            ("init_h_wheel_x", v.init_h_wheel_x),
            ("init_h_wheel_y", v.init_h_wheel_y),
            ("init_h_wheel_z", v.init_h_wheel_z),
            ("wheel_gain", v.wheel_gain),
            ("orbit_inclination", v.orbit_inclination),
            ("orbit_arg_lat0", v.orbit_arg_lat0),
            ("earth_dipole", v.earth_dipole),
            ("dist_const_x", v.dist_const_x),
            ("dist_const_y", v.dist_const_y),
            ("dist_const_z", v.dist_const_z),
            ("dist_sin_amp_x", v.dist_sin_amp_x),
            ("dist_sin_amp_y", v.dist_sin_amp_y),
            ("dist_sin_amp_z", v.dist_sin_amp_z),
            ("dist_sin_freq", v.dist_sin_freq),
            ("dist_sin_phase_x", v.dist_sin_phase_x),
            ("dist_sin_phase_y", v.dist_sin_phase_y),
            ("dist_sin_phase_z", v.dist_sin_phase_z),
        ] {
            check::finite(n, x)?;
        }
        for (n, x) in [
            ("wheel_time_constant", v.wheel_time_constant),
            ("wheel_torque_coeff", v.wheel_torque_coeff),
            ("wheel_max_current", v.wheel_max_current),
            ("mtq_turns", v.mtq_turns),
            ("mtq_coil_area", v.mtq_coil_area),
            ("mtq_max_current", v.mtq_max_current),
            ("mtq_k_dump", v.mtq_k_dump),
            ("dist_noise_std_x", v.dist_noise_std_x),
            ("dist_noise_std_y", v.dist_noise_std_y),
            ("dist_noise_std_z", v.dist_noise_std_z),
        ] {
            check::non_negative(n, x)?;
        }
        check::positive("wheel_inertia", v.wheel_inertia)?;
        check::limit("wheel_max_speed", v.wheel_max_speed)?;
        check::positive("mu", v.mu)?;
        check::positive("orbit_radius", v.orbit_radius)?;
        check::positive("dist_noise_hold", v.dist_noise_hold)?;
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
        let orbit = CircularOrbit {
            mu: v.mu,
            radius: v.orbit_radius,
            inclination: v.orbit_inclination,
            arg_lat0: v.orbit_arg_lat0,
            dipole: v.earth_dipole,
        };
        let d = Derived {
            orbit,
            n2: v.mu / v.orbit_radius.powi(3),
            wheel_torque_max: v.wheel_torque_coeff * v.wheel_max_current,
            wheel_momentum_max: v.wheel_inertia * v.wheel_max_speed,
            dipole_max: v.mtq_turns * v.mtq_coil_area * v.mtq_max_current,
        };
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
        if v.actuator_mode == 1 {
            x.as_mut_slice()[HW..HW + 3].copy_from_slice(&[v.init_h_wheel_x, v.init_h_wheel_y, v.init_h_wheel_z]);
        }
        self.inertia = inertia;
        self.inertia_inv = chol.inverse();
        // adaptive tolerance from fmi2SetupExperiment (default 1e-8)
        self.stepper = Some(Stepper::new(method, v.max_internal_step, exp.tolerance.filter(|x| *x > 0.0).unwrap_or(1e-8)));
        self.kin = Some(kin);
        self.d = d;
        self.q_dcm = wxyz(&q0);
        self.x = x;
        let v = &mut self.v;
        v.wheel_torque_max = d.wheel_torque_max;
        v.wheel_momentum_max = d.wheel_momentum_max;
        v.mtq_dipole_max = d.dipole_max;
        v.orbit_rate = d.n2.sqrt();
        Ok(())
    }

    fn update_outputs(&mut self, t: f64) -> ModelResult {
        let x = self.x;
        let q = self.quaternion(&x);
        let a = self.attitude(&x);
        let w = v3(&x, W);
        let hw = v3(&x, HW);
        let [rl, pt, yw] = match self.kin() {
            Kinematics::Quaternion => euler321_from_quat(&q),
            Kinematics::Dcm => euler321_from_dcm(&a),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => [x[ATT], x[ATT + 1], x[ATT + 2]],
        };
        let seg = self.segment_at(t);
        let act = self.actuate(t, &x, &a, &seg);
        let ext = self.external(t, &a, &seg);
        let b = self.field_body(t, &a);
        let h_ref = a.transpose() * (self.inertia * w + hw);
        let ws = hw / self.v.wheel_inertia;
        let v = &mut self.v;
        [v.q_w, v.q_x, v.q_y, v.q_z] = wxyz(&q);
        (v.w_x, v.w_y, v.w_z) = (w.x, w.y, w.z);
        (v.roll, v.pitch, v.yaw) = (rl, pt, yw);
        (v.roll_deg, v.pitch_deg, v.yaw_deg) = (rl.to_degrees(), pt.to_degrees(), yw.to_degrees());
        (v.torque_applied_x, v.torque_applied_y, v.torque_applied_z) = (act.torque.x, act.torque.y, act.torque.z);
        (v.torque_ext_x, v.torque_ext_y, v.torque_ext_z) = (ext.x, ext.y, ext.z);
        (v.h_total_ref_x, v.h_total_ref_y, v.h_total_ref_z) = (h_ref.x, h_ref.y, h_ref.z);
        (v.h_wheel_x, v.h_wheel_y, v.h_wheel_z) = (hw.x, hw.y, hw.z);
        (v.wheel_speed_x, v.wheel_speed_y, v.wheel_speed_z) = (ws.x, ws.y, ws.z);
        (v.dipole_x, v.dipole_y, v.dipole_z) = (act.dipole.x, act.dipole.y, act.dipole.z);
        (v.b_body_x, v.b_body_y, v.b_body_z) = (b.x, b.y, b.z);
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64, _exp: &Experiment) -> ModelResult {
        let mut stepper = self.stepper.ok_or("plant was not initialized")?;
        let (kin, ortho) = (self.kin(), self.v.dcm_orthonormalize == 1);
        let mut q_dcm = self.q_dcm;
        let mut x = self.x;
        let tn = self.v.dist_noise_hold;
        // fault state and noise are constant over a piece: pieces are cut at the events
        for (ts, len) in pieces(t, h, &self.breakpoints(t, h)?) {
            let mid = ts + 0.5 * len;
            let seg = Segment { faulted: mid >= self.v.fault_time, noise: self.noise((mid / tn).floor() as i64) };
            let mut f = |tt: f64, xx: &State| self.derivative(tt, xx, &seg);
            stepper.piece(&mut f, ts, len, &mut x, |xx, tt| Self::post_step(kin, ortho, &mut q_dcm, xx, tt))?;
        }
        self.x = x;
        self.q_dcm = q_dcm;
        self.stepper = Some(stepper);
        Ok(())
    }
}

const EQUATIONS_HTML: &str = "<h3>Dynamics</h3><pre>\
I_true dw/dt = tau_act + tau_ext - w x (I_true w + h_w)     (Euler's equations of a gyrostat; full inertia matrix)\n\
dh_w/dt      = -tau_rw                                       (actuator_mode 1; h_w = 0 otherwise)\n\
I_true       = S I S,  S = diag(sqrt(inertia_scale_x, _y, _z))\n\
h_total_ref  = A(q)^T (I_true w + h_w)                       (conserved without external torque)</pre>\
<h3>Kinematics (parameter kinematics)</h3><pre>\
0 quaternion: dq/dt = 1/2 q (x) (0, w); q renormalised after every internal step\n\
1 DCM:        dA/dt = -[w x] A (paper 000 Eq. 12); re-orthonormalised (SVD polar factor) only if dcm_orthonormalize = 1;\n\
              output q = Shepperd's quaternion of A, sign continuous with the previous output; roll/pitch/yaw = 321 angles of A\n\
2 Euler:      d(phi)/dt   = w_x cos(psi) - w_y sin(psi)\n\
              d(theta)/dt = (w_x sin(psi) + w_y cos(psi)) / cos(phi)\n\
              d(psi)/dt   = (w_x sin(psi) + w_y cos(psi)) tan(phi) + w_z      (paper 000 Eq. 8 with the corrected sign = 213 rates)\n\
              the angles are read as 321 angles: q = q321(phi, theta, psi), roll/pitch/yaw = (phi, theta, psi) (paper 000 Eq. 6)\n\
3 linear:     I_xx phi'' = tau_x, I_yy theta'' = tau_y, I_zz psi'' = tau_z (paper 000 Eq. 1; diagonal of I_true, no coupling);\n\
              w outputs = (phi', theta', psi'); q = q321(phi, theta, psi)</pre>\
<h3>Actuators (parameter actuator_mode)</h3><pre>\
faults (t >= fault_time): u_i = fault_stuck_value_i if fault_stuck_i = 1, else torque_cmd_i + fault_bias_i;  a_i = effectiveness_i\n\
          (t <  fault_time): u_i = torque_cmd_i, a_i = 1\n\
mode 0:   tau_act,i = clamp(u_i, -a_i u_max_i, +a_i u_max_i)                    (paper 004 Eqs. 8-9)\n\
mode 1:   m_raw  = k_dump (h_w x B_b) / |B_b|^2   (mtq_enable = 1; m = 0 if |B_b| < 1e-12 T)\n\
          m      = m_raw min(1, m_max / max_i |m_raw,i|),  m_max = N A i_mtq,max,  tau_mtq = m x B_b\n\
          T_w d(tau_w)/dt = K_w (u - tau_mtq) - tau_w        (T_w = 0: tau_w = K_w (u - tau_mtq))\n\
          tau_rw,i = clamp(tau_w,i, -a_i k_t i_max, +a_i k_t i_max)\n\
          tau_rw,i = 0 if |h_w,i| >= J_w Omega_max and -tau_rw,i has the sign of h_w,i   (speed limit)\n\
          tau_act = tau_rw + tau_mtq,  wheel_speed = h_w / J_w</pre>\
<p>The speed limit is checked on the integrated state, so |h_w,i| may exceed J_w Omega_max by at most one internal step's \
increment (k_t i_max times the internal step).</p>\
<h3>Environment (circular orbit, R = Earth-centred inertial)</h3><pre>\
n = sqrt(mu / r_orb^3),  u = orbit_arg_lat0 + n t\n\
r_hat = [cos u, sin u cos i, sin u sin i],   B_R = (M_E / r_orb^3) (z - 3 (z . r_hat) r_hat),   B_b = A B_R\n\
tau_gg = 3 n^2 r_hat_b x (I_true r_hat_b),   r_hat_b = A r_hat        (gg_enable = 1)</pre>\
<h3>Disturbances</h3><pre>\
tau_ext = torque_dist + c + A_i sin(Omega_d t + phi_i) + n(t) + tau_gg\n\
n_i(t)  = sigma_i N(seed, k, i)  for t in [k T_n, (k+1) T_n)         (zero-order-held white noise, PSD about sigma^2 T_n)</pre>\
<p>Random numbers (counter-based, no hidden state, independent of step sizes and call order):</p><pre>\
splitmix64(z): z += 0x9E3779B97F4A7C15; z = (z ^ z>>30) * 0xBF58476D1CE4E5B9; z = (z ^ z>>27) * 0x94D049BB133111EB; z ^ z>>31\n\
key(j) = splitmix64(splitmix64(splitmix64(seed) ^ k) ^ j)     (wrapping 64-bit arithmetic; seed sign-extended, k two's complement)\n\
U_j    = ((key(j) >> 11) + 0.5) 2^-53\n\
N(seed, k, i) = sqrt(-2 ln U_2i) cos(2 pi U_2i+1)              (Box-Muller)</pre>\
<h3>Integration</h3>\
<p>integrator 0: classical RK4, 1: explicit Euler, each with ceil(piece / max_internal_step) equal steps per piece; \
integrator 2: adaptive Dormand-Prince 5(4) with rtol = atol = the tolerance of fmi2SetupExperiment (default 1e-8), \
error norm RMS(e_i / (atol + rtol max(|x_i|, |x_new,i|))), step size free (max_internal_step is not used), \
A communication step is cut into pieces at fault_time and at the noise-hold boundaries k T_n; the fault state and the noise \
are constant within a piece (with noise on, internal steps are therefore never longer than dist_noise_hold). \
Inputs are held over the step. The quaternion is renormalised after every internal step \
(RK4/Euler) or piece (Dormand-Prince).</p>";
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
    fn href(p: &AttitudePlant) -> Vector3<f64> {
        Vector3::new(p.v.h_total_ref_x, p.v.h_total_ref_y, p.v.h_total_ref_z)
    }

    fn energy(p: &AttitudePlant) -> f64 {
        let w = Vector3::new(p.v.w_x, p.v.w_y, p.v.w_z);
        0.5 * w.dot(&(p.inertia * w))
    }

    fn tumbling(v: &mut AttitudePlantVars) {
        full_inertia(v);
        (v.init_w_x, v.init_w_y, v.init_w_z) = (0.06, -0.05, 0.06);
    }

    fn free_run(p: &mut AttitudePlant, t_end: f64, dt: f64, exp: &Experiment) -> (f64, f64) {
        p.update_outputs(0.0).unwrap();
        let (h0, e0) = (href(p), energy(p));
        let (mut dh, mut de): (f64, f64) = (0.0, 0.0);
        let n = (t_end / dt).round() as usize;
        for k in 0..n {
            p.do_step(k as f64 * dt, dt, exp).unwrap();
            p.update_outputs((k + 1) as f64 * dt).unwrap();
            dh = dh.max((href(p) - h0).norm() / h0.norm());
            de = de.max((energy(p) - e0).abs() / e0);
        }
        (dh, de)
    }

    #[test]
    fn torque_free_conservation_rk4() {
        // spec §1.7 test 1: relative drift < 1e-9 over 100 s, RK4 0.01 s, full inertia, |ω| ≈ 0.1 rad/s
        let mut p = plant(tumbling);
        let (dh, de) = free_run(&mut p, 100.0, 0.1, &Experiment::default());
        println!("torque-free RK4 0.01 s, 100 s: momentum drift {dh:.3e}, energy drift {de:.3e}");
        assert!(dh < 1e-9 && de < 1e-9);
    }

    #[test]
    fn torque_free_conservation_dopri_one_orbit() {
        // issue 3: adaptive integrator, relative drift ≤ 1e-10 over one orbit period (5926 s)
        let mut p = plant(|v| {
            tumbling(v);
            v.integrator = 2;
        });
        // the tolerance of fmi2SetupExperiment reaches the plant at initialization
        let exp = Experiment { tolerance: Some(1e-12), ..Default::default() };
        p.initialize(&exp).unwrap();
        let (dh, de) = free_run(&mut p, 5926.0, 1.0, &exp);
        println!("torque-free Dormand-Prince tol 1e-12, 5926 s: momentum drift {dh:.3e}, energy drift {de:.3e}");
        assert!(dh <= 1e-10 && de <= 1e-10);
    }

    #[test]
    fn gyrostat_conserves_total_momentum_with_wheels_commanded() {
        let mut p = plant(|v| {
            tumbling(v);
            v.actuator_mode = 1;
            v.wheel_time_constant = 0.5;
            (v.init_h_wheel_x, v.init_h_wheel_y, v.init_h_wheel_z) = (0.2, -0.1, 0.3);
        });
        p.update_outputs(0.0).unwrap();
        let h0 = href(&p);
        let mut worst: f64 = 0.0;
        let mut sat = false;
        for k in 0..1000 {
            let t = k as f64 * 0.1;
            (p.v.torque_cmd_x, p.v.torque_cmd_y, p.v.torque_cmd_z) = (0.08 * (0.1 * t).sin(), -0.03, 0.1 * (0.05 * t).cos());
            p.do_step(t, 0.1, &Experiment::default()).unwrap();
            p.update_outputs(t + 0.1).unwrap();
            worst = worst.max((href(&p) - h0).norm() / h0.norm());
            sat |= p.v.h_wheel_z.abs() >= p.d.wheel_momentum_max;
        }
        println!("gyrostat with commanded wheels, 100 s: momentum drift {worst:.3e} (wheel z saturated: {sat})");
        assert!(worst < 1e-9);
    }

    #[test]
    fn limits_never_exceeded_and_default_is_unlimited() {
        // mode 0: |τ_act| ≤ a_i u_max,i after the fault, u_max,i before it
        let mut p = plant(|v| {
            (v.u_max_x, v.u_max_y, v.u_max_z) = (10.0, 10.0, 10.0);
            (v.effectiveness_x, v.effectiveness_y, v.effectiveness_z) = (0.1, 1.0, 0.5);
            v.fault_time = 1.05;
        });
        for k in 0..30 {
            let t = k as f64 * 0.1;
            (p.v.torque_cmd_x, p.v.torque_cmd_y, p.v.torque_cmd_z) = (50.0, -50.0, -3.0);
            p.update_outputs(t).unwrap();
            let l = if t >= 1.05 { [1.0, 10.0, 5.0] } else { [10.0; 3] };
            assert!(p.v.torque_applied_x.abs() <= l[0] && p.v.torque_applied_y.abs() <= l[1] && p.v.torque_applied_z.abs() <= l[2]);
            assert_eq!(p.v.torque_applied_z, -3.0, "below the limit the command passes unchanged");
            p.do_step(t, 0.1, &Experiment::default()).unwrap();
        }
        // the fault onset is not smeared: ω_x(3) = (10·1.05 + 1·1.95)/1000 exactly (single axis, no coupling)
        let mut p = plant(|v| {
            v.u_max_x = 10.0;
            v.effectiveness_x = 0.1;
            v.fault_time = 1.05;
            v.torque_cmd_x = 50.0;
        });
        for k in 0..30 {
            p.do_step(k as f64 * 0.1, 0.1, &Experiment::default()).unwrap();
        }
        p.update_outputs(3.0).unwrap();
        assert!((p.v.w_x - (10.0 * 1.05 + 1.95) / 1000.0).abs() < 1e-15, "{}", p.v.w_x);
        let mut q = plant(|v| v.torque_cmd_x = 1e20);
        q.update_outputs(0.0).unwrap();
        assert_eq!(q.v.torque_applied_x, 1e20);
    }

    #[test]
    fn stuck_and_bias_faults() {
        let mut p = plant(|v| {
            v.fault_time = 0.5;
            (v.fault_bias_x, v.fault_stuck_y, v.fault_stuck_value_y, v.u_max_x) = (2.0, 1, 7.0, 5.0);
            (v.torque_cmd_x, v.torque_cmd_y) = (1.0, -1.0);
        });
        p.update_outputs(0.0).unwrap();
        assert_eq!((p.v.torque_applied_x, p.v.torque_applied_y), (1.0, -1.0));
        p.update_outputs(0.5).unwrap();
        assert_eq!((p.v.torque_applied_x, p.v.torque_applied_y), (3.0, 7.0));
        p.v.torque_cmd_x = 4.0;
        p.update_outputs(0.6).unwrap();
        assert_eq!(p.v.torque_applied_x, 5.0);
    }

    #[test]
    fn wheel_limits_and_lag() {
        let mut p = plant(|v| {
            v.actuator_mode = 1;
            v.wheel_time_constant = 0.3;
            v.effectiveness_y = 0.4;
            v.fault_time = 2.0;
        });
        let (tmax, hmax) = (p.d.wheel_torque_max, p.d.wheel_momentum_max);
        assert!((tmax - 0.05).abs() < 1e-15 && (hmax - 0.504).abs() < 1e-15);
        let mut hpeak: f64 = 0.0;
        for k in 0..300 {
            let t = k as f64 * 0.1;
            (p.v.torque_cmd_x, p.v.torque_cmd_y, p.v.torque_cmd_z) = (0.01, -1.0, 1.0);
            p.update_outputs(t).unwrap();
            let ly = if t >= 2.0 { 0.4 * tmax } else { tmax };
            assert!(p.v.torque_applied_y.abs() <= ly + 1e-15 && p.v.torque_applied_z.abs() <= tmax + 1e-15);
            hpeak = hpeak.max(p.v.h_wheel_z.abs());
            p.do_step(t, 0.1, &Experiment::default()).unwrap();
        }
        // first-order lag: τ_x = 0.02 (1 − e^{−t/0.3}), h_x = −∫τ_x
        p.update_outputs(30.0).unwrap();
        let hx = -0.01 * (30.0 - 0.3 * (1.0 - (-100f64).exp()));
        assert!((p.v.h_wheel_x - hx).abs() < 1e-9, "{} vs {hx}", p.v.h_wheel_x);
        // speed limit reached on z and held (overshoot below one internal step's increment)
        assert!(hpeak >= hmax && hpeak <= hmax + tmax * 0.01, "{hpeak}");
        assert_eq!(p.v.torque_applied_z, 0.0);
        assert!((p.v.wheel_speed_z.abs() - 420.0).abs() < tmax * 0.01 / 1.2e-3);
    }

    #[test]
    fn magnetorquer_torque_is_perpendicular_to_b_and_dumps() {
        // attitude held by a huge inertia; the wheels absorb the magnetic torque (feed-forward), so the
        // body sees τ_cmd = 0 while h_w ⊥ B decays; the total momentum changes only along m × B ⟂ B
        let mut p = plant(|v| {
            (v.inertia_xx, v.inertia_yy, v.inertia_zz) = (1e12, 1e12, 1e12);
            v.actuator_mode = 1;
            v.mtq_enable = 1;
            v.mtq_k_dump = 0.1;
            v.mtq_max_current = 1e4; // unsaturated: τ_mtq = −k h_w⊥
            (v.init_h_wheel_x, v.init_h_wheel_y, v.init_h_wheel_z) = (0.01, 0.02, -0.015);
        });
        let mut worst: f64 = 0.0;
        let mut worst_dh: f64 = 0.0;
        p.update_outputs(0.0).unwrap();
        let hperp = |p: &AttitudePlant| {
            let b = Vector3::new(p.v.b_body_x, p.v.b_body_y, p.v.b_body_z).normalize();
            let h = Vector3::new(p.v.h_wheel_x, p.v.h_wheel_y, p.v.h_wheel_z);
            (h - b * h.dot(&b)).norm()
        };
        let hp0 = hperp(&p);
        for k in 0..60 {
            let t = k as f64;
            let b = Vector3::new(p.v.b_body_x, p.v.b_body_y, p.v.b_body_z);
            let m = Vector3::new(p.v.dipole_x, p.v.dipole_y, p.v.dipole_z);
            let tau_mtq = m.cross(&b);
            worst = worst.max((tau_mtq.dot(&b) / (tau_mtq.norm() * b.norm())).abs());
            assert!(Vector3::new(p.v.torque_applied_x, p.v.torque_applied_y, p.v.torque_applied_z).norm() < 1e-15);
            let h0 = href(&p);
            p.do_step(t, 1.0, &Experiment::default()).unwrap();
            p.update_outputs(t + 1.0).unwrap();
            let b1 = Vector3::new(p.v.b_body_x, p.v.b_body_y, p.v.b_body_z);
            let dh = href(&p) - h0;
            // B turns by ~1e-3 rad per second of orbit: bound the component along the mean field
            worst_dh = worst_dh.max((dh.dot(&(b + b1)) / (dh.norm() * (b + b1).norm())).abs());
        }
        println!("magnetorquer: max |cos(m x B, B)| = {worst:.3e}, max |cos(dH_total, B)| over 1 s = {worst_dh:.3e}");
        assert!(worst < 1e-12 && worst_dh < 2e-3);
        // h_w⊥ decays like e^{−k t} (k t = 6 after 60 s) while B turns slowly in the body
        let hp = hperp(&p);
        println!("magnetorquer: |h_w perp B| {hp0:.3e} -> {hp:.3e} after 60 s with k_dump = 0.1 (e^-6 = 2.5e-3)");
        // floor from B turning (≤ 2n ≈ 2e-3 rad/s) with h_w,par ≈ 0.018: about h_par 2n / k ≈ 4e-4
        assert!(hp < 0.05 * hp0, "{hp} vs {hp0}");
    }

    #[test]
    fn noise_is_reproducible_and_step_independent() {
        let noisy = |seed: i32| {
            plant(move |v| {
                (v.dist_noise_std_x, v.dist_noise_std_y, v.dist_noise_std_z) = (1.0, 2.0, 3.0);
                v.dist_noise_seed = seed;
                v.dist_noise_hold = 0.1;
            })
        };
        let trace = |mut p: AttitudePlant, dt: f64| {
            let mut out = Vec::new();
            let n = (10.0 / dt).round() as usize;
            for k in 0..n {
                p.do_step(k as f64 * dt, dt, &Experiment::default()).unwrap();
            }
            p.update_outputs(10.0).unwrap();
            out.push(p.v.w_x);
            out.push(p.v.w_z);
            out
        };
        let a = trace(noisy(1), 0.1);
        let b = trace(noisy(1), 0.1);
        let c = trace(noisy(2), 0.1);
        let d = trace(noisy(1), 0.04);
        assert_eq!(a[0].to_bits(), b[0].to_bits());
        assert_ne!(a[0], c[0]);
        // the held noise is piecewise constant in hold intervals, so ω (its integral) does not depend on
        // the communication step (0.04 s does not divide 0.1 s): agreement to rounding
        assert!((a[0] - d[0]).abs() < 1e-13 && (a[1] - d[1]).abs() < 1e-13, "{a:?} {d:?}");
        // ω_x(10) = Σ_k σ N_k T_n / I_xx exactly (rest, diagonal inertia, noise only on... all axes: check x
        // through the sum of the generator values)
        // single axis (no gyroscopic coupling): ω_x(10) = Σ_k σ N_k T_n / I_xx
        let mut p = plant(|v| {
            v.dist_noise_std_x = 1.0;
            v.dist_noise_seed = 1;
        });
        let sum: f64 = (0..100).map(|k| p.noise(k).x * 0.1).sum();
        for k in 0..250 {
            p.do_step(k as f64 * 0.04, 0.04, &Experiment::default()).unwrap();
        }
        p.update_outputs(10.0).unwrap();
        assert!((p.v.w_x - sum / 1000.0).abs() < 1e-15, "{} vs {}", p.v.w_x, sum / 1000.0);
    }
}
