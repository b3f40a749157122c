//! The declared variables of `AttitudePlant` (ports 0–80, parameters 100–198, calculated 200–203, facets
//! 210–269).

use super::kinematics::Kinematics;
use crate::declare_variables;
use crate::math::integrate::Method;
use crate::math::surface_forces::Facet;
use crate::model::{ParamEnum, SWITCH};

declare_variables! {
    pub struct AttitudePlantVars {
        // inputs
        0 => torque_cmd: Vec3 = [0.0; 3], Input, "N.m", "Commanded control torque, body axes";
        3 => torque_dist: Vec3 = [0.0; 3], Input, "N.m", "External disturbance torque, body axes (added to the internal generator)";
        // outputs
        10 => q: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Attitude quaternion of B relative to R";
        14 => w: Vec3 = [0.0; 3], Output, "rad/s", "Body rate of B relative to R, body axes (kinematics 3: the angle rates)";
        17 => roll: Real = 0.0, Output, "rad", "Roll angle of the 321 sequence (kinematics 2, 3: the state angle)";
        18 => pitch: Real = 0.0, Output, "rad", "Pitch angle of the 321 sequence (kinematics 2, 3: the state angle)";
        19 => yaw: Real = 0.0, Output, "rad", "Yaw angle of the 321 sequence (kinematics 2, 3: the state angle)";
        20 => roll_deg: Real = 0.0, Output, "deg", "Roll angle in degrees";
        21 => pitch_deg: Real = 0.0, Output, "deg", "Pitch angle in degrees";
        22 => yaw_deg: Real = 0.0, Output, "deg", "Yaw angle in degrees";
        23 => torque_applied: Vec3 = [0.0; 3], Output, "N.m", "Control torque acting on the body after the actuators (wheels + magnetorquers)";
        26 => torque_ext: Vec3 = [0.0; 3], Output, "N.m", "Total external torque (input + generator + gravity gradient)";
        29 => h_total_ref: Vec3 = [0.0; 3], Output, "N.m.s", "Total angular momentum A(q)^T (I w + h_w) in R";
        32 => h_wheel: Vec3 = [0.0; 3], Output, "N.m.s", "Reaction-wheel momentum h_w, body axes (actuator_mode 1)";
        35 => wheel_speed: Vec3 = [0.0; 3], Output, "rad/s", "Wheel spin relative to the body h_w/J_w";
        38 => dipole: Vec3 = [0.0; 3], Output, "A.m2", "Magnetorquer dipole m, body axes";
        41 => b_body: Vec3 = [0.0; 3], Output, "T", "Geomagnetic field in body axes";
        // appended (issue 37): external magnetorquer command
        44 => m_cmd: Vec3 = [0.0; 3], Input, "A.m2", "Magnetorquer dipole command, body axes (mtq_mode = 1, or 2 added to the dumping dipole; e.g. from BDot)";
        // appended (issue 43): the environment as inputs (environment_inputs = 1), by the Environment/Orbit port names
        47 => r: Vec3 = [0.0; 3], Input, "m", "Spacecraft position, Earth-centred inertial axes (environment_inputs = 1; R is then that frame)";
        50 => v: Vec3 = [0.0; 3], Input, "m/s", "Spacecraft velocity, inertial axes (environment_inputs = 1)";
        53 => b_eci: Vec3 = [0.0; 3], Input, "T", "Geomagnetic field at the spacecraft, inertial axes (environment_inputs = 1; the start value 0 is refused)";
        56 => sun_eci: Vec3 = [0.0; 3], Input, "", "Unit vector Earth to sun, inertial axes (environment_inputs = 1 with facets; the start value 0 is refused)";
        59 => eclipse: Real = 1.0, Input, "", "Visible fraction of the solar disk, 0 (umbra) to 1 (full sun) (environment_inputs = 1; unwired: always full sun)";
        60 => rho: Real = 0.0, Input, "kg/m3", "Atmospheric density at the spacecraft (environment_inputs = 1; unwired: no air)";
        61 => sun_distance: Real = 149_597_870_700.0, Input, "m", "Distance Earth to sun (environment_inputs = 1)";
        // appended (issue 43): the disturbance budget, each torque on its own
        62 => torque_gg: Vec3 = [0.0; 3], Output, "N.m", "Gravity-gradient torque, body axes";
        65 => torque_aero: Vec3 = [0.0; 3], Output, "N.m", "Aerodynamic torque of the facets, body axes";
        68 => torque_srp: Vec3 = [0.0; 3], Output, "N.m", "Solar-radiation-pressure torque of the facets, body axes";
        71 => torque_residual: Vec3 = [0.0; 3], Output, "N.m", "Torque of the residual magnetic dipole m_res x B, body axes";
        74 => force_aero: Vec3 = [0.0; 3], Output, "N", "Aerodynamic force on the facets, body axes";
        77 => force_srp: Vec3 = [0.0; 3], Output, "N", "Solar-radiation-pressure force on the facets, body axes";
        // appended (issue 44): actuator health telemetry
        80 => actuator_fault: Real = 0.0, Output, "", "Actuator health flag: 1 while an actuator fault is active (fault_time <= t < fault_clear_time with effectiveness_* < 1, fault_stuck_* = 1 or fault_bias_* != 0), 0 otherwise";
        // parameters: body
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Inertia matrix diagonal entry ([Navabi-2019] default)", Positive;
        103 => inertia_xy: Real = 0.0, Parameter, "kg.m2", "Inertia matrix entry xy (matrix entry, not product of inertia)";
        104 => inertia_xz: Real = 0.0, Parameter, "kg.m2", "Inertia matrix entry xz";
        105 => inertia_yz: Real = 0.0, Parameter, "kg.m2", "Inertia matrix entry yz";
        106 => inertia_scale: Vec3 = [1.0; 3], Parameter, "", "Uncertainty factor s: I_true = S I S, S = diag(sqrt(s))", Positive;
        110 => init_euler321_roll: Real = 0.0, Parameter, "rad", "Initial roll (321 sequence; kinematics 2, 3: initial state angle)";
        111 => init_euler321_pitch: Real = 0.0, Parameter, "rad", "Initial pitch (321 sequence)";
        112 => init_euler321_yaw: Real = 0.0, Parameter, "rad", "Initial yaw (321 sequence)";
        113 => init_w: Vec3 = [0.0; 3], Parameter, "rad/s", "Initial body rate (kinematics 3: the angle rates)";
        116 => init_h_wheel: Vec3 = [0.0; 3], Parameter, "N.m.s", "Initial wheel momentum (actuator_mode 1)";
        // parameters: actuator mode 0 and faults
        120 => u_max: Vec3 = [1e30; 3], Parameter, "N.m", "Actuator mode 0: torque limit (1e30 = no limit)", Limit;
        123 => effectiveness: Vec3 = [1.0; 3], Parameter, "", "Effectiveness a in [0, 1] after fault_time: limit a u_max (mode 0) or a k_t i_max (mode 1) ([Moradi-FTC])", Range(0.0, 1.0);
        126 => fault_time: Real = 0.0, Parameter, "s", "Onset time of all actuator faults (effectiveness, bias, stuck)";
        127 => fault_bias: Vec3 = [0.0; 3], Parameter, "N.m", "Bias fault: added to the torque command after fault_time (before the limits)";
        130 => max_internal_step: Real = 0.01, Parameter, "s", "Internal step of RK4/Euler (integrator 2 ignores it: adaptive steps); at most 1e6 internal steps per doStep", Range(1e-6, 1000.0);
        131 => fault_stuck_value: Vec3 = [0.0; 3], Parameter, "N.m", "Stuck fault: the torque command is replaced by this value after fault_time where fault_stuck_* = 1";
        // Integer parameters
        140 => integrator: Integer = 0, Parameter, "", "Internal integrator: 0 = classical RK4, 1 = explicit Euler, 2 = adaptive Dormand-Prince 5(4) (tolerance from fmi2SetupExperiment, default 1e-8)", Choice(Method::CODES);
        141 => kinematics: Integer = 0, Parameter, "", "Kinematics: 0 = quaternion, 1 = DCM, 2 = [Navabi-2019] Euler-angle rates (213 rates, angles output as 321), 3 = linear small-angle double integrator, 4 = quaternion kinematics with linear decoupled dynamics I_ii dw_i/dt = tau_i (no gyroscopic or wheel coupling; [Navabi-2019] large-angle MRAC set-up)", Choice(Kinematics::CODES);
        142 => actuator_mode: Integer = 0, Parameter, "", "Actuators: 0 = ideal torque with saturation and fault, 1 = three reaction wheels (+ magnetorquers if mtq_enable = 1)", Choice(SWITCH);
        143 => dcm_orthonormalize: Integer = 0, Parameter, "", "Kinematics 1 only: 1 = re-orthonormalise the DCM after every internal step, 0 = never", Choice(SWITCH);
        144 => mtq_enable: Integer = 0, Parameter, "", "Actuator mode 1: 1 = magnetorquers dump wheel momentum, 0 = off", Choice(SWITCH);
        145 => gg_enable: Integer = 0, Parameter, "", "1 = gravity-gradient torque of the circular orbit, 0 = off", Choice(SWITCH);
        146 => dist_noise_seed: Integer = 1, Parameter, "", "Seed of the counter-based white-noise generator";
        147 => fault_stuck_x: Integer = 0, Parameter, "", "1 = actuator x stuck at fault_stuck_value_x after fault_time", Choice(SWITCH);
        148 => fault_stuck_y: Integer = 0, Parameter, "", "1 = actuator y stuck after fault_time", Choice(SWITCH);
        149 => fault_stuck_z: Integer = 0, Parameter, "", "1 = actuator z stuck after fault_time", Choice(SWITCH);
        // reaction wheels (paper 003 values, all project choice)
        150 => wheel_time_constant: Real = 0.0, Parameter, "s", "Wheel torque lag T_w (0 = no lag) ([Khatoonabadi-FO] Eq. 7 form)", NonNegative;
        151 => wheel_gain: Real = 1.0, Parameter, "", "Wheel gain K_w";
        152 => wheel_inertia: Real = 1.2e-3, Parameter, "kg.m2", "Wheel spin inertia J_w", Positive;
        153 => wheel_torque_coeff: Real = 0.05, Parameter, "N.m/A", "Wheel motor torque coefficient k_t", NonNegative;
        154 => wheel_max_current: Real = 1.0, Parameter, "A", "Wheel motor current limit i_max (torque limit k_t i_max)", NonNegative;
        155 => wheel_max_speed: Real = 420.0, Parameter, "rad/s", "Wheel speed limit Omega_max (momentum limit J_w Omega_max)", Limit;
        // magnetorquers (project choice)
        156 => mtq_turns: Real = 500.0, Parameter, "", "Magnetorquer coil turns N", NonNegative;
        157 => mtq_coil_area: Real = 0.01, Parameter, "m2", "Magnetorquer coil area A", NonNegative;
        158 => mtq_max_current: Real = 0.2, Parameter, "A", "Magnetorquer current limit (dipole limit N A i)", NonNegative;
        159 => mtq_k_dump: Real = 0.005, Parameter, "1/s", "Momentum-dumping gain k_dump (> 0 dumps): m = k_dump (h_w x B)/|B|^2", NonNegative;
        // environment (project choice)
        160 => mu: Real = 3.986004418e14, Parameter, "m3/s2", "Earth gravitational parameter", Positive;
        161 => orbit_radius: Real = 7078137.0, Parameter, "m", "Circular orbit radius (700 km altitude)", Positive;
        162 => orbit_inclination: Real = 1.7104226669544429, Parameter, "rad", "Orbit inclination (98 deg)";
        163 => orbit_arg_lat0: Real = 0.0, Parameter, "rad", "Argument of latitude at t = 0";
        164 => earth_dipole: Real = 7.96e15, Parameter, "T.m3", "Earth dipole strength M_E";
        // disturbance generator
        170 => dist_const: Vec3 = [0.0; 3], Parameter, "N.m", "Constant disturbance torque c";
        173 => dist_sin_amp: Vec3 = [0.0; 3], Parameter, "N.m", "Sinusoidal disturbance amplitude A";
        176 => dist_sin_freq: Real = 0.0, Parameter, "rad/s", "Sinusoidal disturbance frequency Omega_d";
        177 => dist_sin_phase: Vec3 = [0.0; 3], Parameter, "rad", "Sinusoidal disturbance phase phi";
        180 => dist_noise_std: Vec3 = [0.0; 3], Parameter, "N.m", "White-noise standard deviation sigma (zero-order held)", NonNegative;
        183 => dist_noise_hold: Real = 0.1, Parameter, "s", "Hold interval T_n of the noise (PSD about sigma^2 T_n)", Positive;
        // actuator errors (both actuator modes; project choice, for Monte Carlo dispersions)
        184 => actuator_scale: Vec3 = [1.0; 3], Parameter, "", "Actuator scale factor k: actuator i delivers k_i times its limited torque (tau_body = R(delta) diag(k) tau_actuators)", Positive;
        187 => actuator_misalignment: Vec3 = [0.0; 3], Parameter, "rad", "Actuator-triad misalignment: rotation vector delta of the actuator axes relative to the body axes (R(delta) = exp([delta x]))";
        // appended (issue 37): source of the magnetorquer dipole
        190 => mtq_mode: Integer = 0, Parameter, "", "Magnetorquer dipole: 0 = internal momentum dumping (actuator_mode 1 with mtq_enable 1; otherwise none); 1 = the input m_cmd, each axis clamped at mtq_dipole_max, in either actuator mode (the internal dumping law is off); 2 = m_cmd plus the unscaled internal dumping dipole k_dump (h_w x B)/|B|^2 (actuator_mode 1 with mtq_enable 1), the sum clamped per axis as in 1", Choice(MTQ_MODES);
        // appended (issue 43): the environment's source and the disturbance model's constants (project choices)
        191 => environment_inputs: Integer = 0, Parameter, "", "0 = the circular orbit and dipole field above (the papers' plant); 1 = position, velocity, field, sun, eclipse and density from the inputs (gravity gradient from r; drag, solar pressure and residual dipole)", Choice(SWITCH);
        192 => residual_dipole: Vec3 = [0.0; 3], Parameter, "A.m2", "Residual magnetic dipole m_res of the spacecraft, body axes (both sources of the field)";
        195 => earth_rotation_rate: Real = 7.292115e-5, Parameter, "rad/s", "Earth rotation rate: the air co-rotates, v_rel = v - w_E z x r";
        196 => solar_flux: Real = 1361.0, Parameter, "W/m2", "Solar flux at one astronomical unit (pressure = flux / c, scaled with (1 au / d)^2)", NonNegative;
        197 => eclipse_shadows_srp: Integer = 1, Parameter, "", "1 = the solar pressure is multiplied by the input eclipse (visible fraction), 0 = ignore it", Choice(SWITCH);
        // appended (issue 44): transient faults
        198 => fault_clear_time: Real = 1e30, Parameter, "s", "End of all actuator faults (effectiveness, bias, stuck): from this time on the actuators are healthy again (the ground reset the unit); 1e30 = permanent faults";
        // appended (issue 43): up to six flat facets (a box, or a box and panels) for drag and solar pressure
        210 => facet1_area: Real = 0.0, Parameter, "m2", "Facet 1: area (0 = no facet)", NonNegative;
        211 => facet1_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 1: outward normal, body axes (normalised)";
        214 => facet1_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 1: centre of pressure relative to the centre of mass, body axes";
        217 => facet1_drag_coeff: Real = 2.2, Parameter, "", "Facet 1: drag coefficient C_D", NonNegative;
        218 => facet1_specular: Real = 0.0, Parameter, "", "Facet 1: specular reflection coefficient C_s", Range(0.0, 1.0);
        219 => facet1_diffuse: Real = 0.0, Parameter, "", "Facet 1: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        220 => facet2_area: Real = 0.0, Parameter, "m2", "Facet 2: area (0 = no facet)", NonNegative;
        221 => facet2_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 2: outward normal, body axes (normalised)";
        224 => facet2_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 2: centre of pressure relative to the centre of mass, body axes";
        227 => facet2_drag_coeff: Real = 2.2, Parameter, "", "Facet 2: drag coefficient C_D", NonNegative;
        228 => facet2_specular: Real = 0.0, Parameter, "", "Facet 2: specular reflection coefficient C_s", Range(0.0, 1.0);
        229 => facet2_diffuse: Real = 0.0, Parameter, "", "Facet 2: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        230 => facet3_area: Real = 0.0, Parameter, "m2", "Facet 3: area (0 = no facet)", NonNegative;
        231 => facet3_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 3: outward normal, body axes (normalised)";
        234 => facet3_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 3: centre of pressure relative to the centre of mass, body axes";
        237 => facet3_drag_coeff: Real = 2.2, Parameter, "", "Facet 3: drag coefficient C_D", NonNegative;
        238 => facet3_specular: Real = 0.0, Parameter, "", "Facet 3: specular reflection coefficient C_s", Range(0.0, 1.0);
        239 => facet3_diffuse: Real = 0.0, Parameter, "", "Facet 3: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        240 => facet4_area: Real = 0.0, Parameter, "m2", "Facet 4: area (0 = no facet)", NonNegative;
        241 => facet4_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 4: outward normal, body axes (normalised)";
        244 => facet4_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 4: centre of pressure relative to the centre of mass, body axes";
        247 => facet4_drag_coeff: Real = 2.2, Parameter, "", "Facet 4: drag coefficient C_D", NonNegative;
        248 => facet4_specular: Real = 0.0, Parameter, "", "Facet 4: specular reflection coefficient C_s", Range(0.0, 1.0);
        249 => facet4_diffuse: Real = 0.0, Parameter, "", "Facet 4: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        250 => facet5_area: Real = 0.0, Parameter, "m2", "Facet 5: area (0 = no facet)", NonNegative;
        251 => facet5_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 5: outward normal, body axes (normalised)";
        254 => facet5_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 5: centre of pressure relative to the centre of mass, body axes";
        257 => facet5_drag_coeff: Real = 2.2, Parameter, "", "Facet 5: drag coefficient C_D", NonNegative;
        258 => facet5_specular: Real = 0.0, Parameter, "", "Facet 5: specular reflection coefficient C_s", Range(0.0, 1.0);
        259 => facet5_diffuse: Real = 0.0, Parameter, "", "Facet 5: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        260 => facet6_area: Real = 0.0, Parameter, "m2", "Facet 6: area (0 = no facet)", NonNegative;
        261 => facet6_normal: Vec3 = [0.0; 3], Parameter, "", "Facet 6: outward normal, body axes (normalised)";
        264 => facet6_centre: Vec3 = [0.0; 3], Parameter, "m", "Facet 6: centre of pressure relative to the centre of mass, body axes";
        267 => facet6_drag_coeff: Real = 2.2, Parameter, "", "Facet 6: drag coefficient C_D", NonNegative;
        268 => facet6_specular: Real = 0.0, Parameter, "", "Facet 6: specular reflection coefficient C_s", Range(0.0, 1.0);
        269 => facet6_diffuse: Real = 0.0, Parameter, "", "Facet 6: diffuse reflection coefficient C_d (C_s + C_d <= 1; the rest is absorbed)", Range(0.0, 1.0);
        // calculated parameters
        200 => wheel_torque_max: Real = 0.05, CalculatedParameter, "N.m", "Wheel torque limit k_t i_max before faults";
        201 => wheel_momentum_max: Real = 0.504, CalculatedParameter, "N.m.s", "Wheel momentum limit J_w Omega_max";
        202 => mtq_dipole_max: Real = 1.0, CalculatedParameter, "A.m2", "Magnetorquer dipole limit N A i_max";
        203 => orbit_rate: Real = 0.0, CalculatedParameter, "rad/s", "Orbital rate n = sqrt(mu / r^3)";
    }
}

/// Codes of `mtq_mode`: 0 internal dumping, 1 the command m_cmd, 2 the command plus the dumping.
pub const MTQ_MODES: &[i32] = &[0, 1, 2];

/// Facets of the facet model.
pub const FACETS: usize = 6;

impl AttitudePlantVars {
    /// The facets as declared, checked (see [`Facet::new`]).
    pub fn facets(&self) -> Result<[Facet; FACETS], String> {
        let f = |n: &str, a, nrm, c, cd, cs, cdf| Facet::new(n, a, nrm, c, [cd, cs, cdf]);
        Ok([
            f("facet1", self.facet1_area, self.facet1_normal, self.facet1_centre, self.facet1_drag_coeff, self.facet1_specular, self.facet1_diffuse)?,
            f("facet2", self.facet2_area, self.facet2_normal, self.facet2_centre, self.facet2_drag_coeff, self.facet2_specular, self.facet2_diffuse)?,
            f("facet3", self.facet3_area, self.facet3_normal, self.facet3_centre, self.facet3_drag_coeff, self.facet3_specular, self.facet3_diffuse)?,
            f("facet4", self.facet4_area, self.facet4_normal, self.facet4_centre, self.facet4_drag_coeff, self.facet4_specular, self.facet4_diffuse)?,
            f("facet5", self.facet5_area, self.facet5_normal, self.facet5_centre, self.facet5_drag_coeff, self.facet5_specular, self.facet5_diffuse)?,
            f("facet6", self.facet6_area, self.facet6_normal, self.facet6_centre, self.facet6_drag_coeff, self.facet6_specular, self.facet6_diffuse)?,
        ])
    }

    /// The stuck flags as booleans.
    pub fn stuck(&self) -> [bool; 3] {
        [self.fault_stuck_x == 1, self.fault_stuck_y == 1, self.fault_stuck_z == 1]
    }

    /// Whether any actuator fault is configured: an effectiveness below 1, a stuck actuator or a bias.
    pub fn fault_configured(&self) -> bool {
        self.effectiveness.iter().any(|a| *a < 1.0) || self.stuck().iter().any(|s| *s) || self.fault_bias != nalgebra::Vector3::zeros()
    }
}
