//! `AttitudePlant`: three-axis rigid body (gyrostat) with full inertia, selectable kinematics
//! (quaternion, DCM, paper 000's Euler-angle rates, linear small-angle model, quaternion kinematics
//! with linear decoupled dynamics), ideal torque actuators
//! or reaction wheels with magnetorquers, actuator faults, disturbance generator and gravity
//! gradient on a circular orbit.
//!
//! Files: `variables.rs` (the declaration), `kinematics.rs`, `actuators.rs`, `environment.rs`
//! (disturbances, gravity gradient, field, step events), `docs.html` (equations for the FMU's
//! documentation), `tests.rs`.

mod actuators;
mod attitude_output;
mod environment;
mod exchange;
mod external;
mod kinematics;
mod projection;
#[cfg(test)]
mod tests;
mod variables;

use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

pub use kinematics::Kinematics;
pub use variables::{AttitudePlantVars, FACETS};

use self::environment::{breakpoints, check_world, segment_at, segment_of_piece, world_unset, Budget, Segment};
use self::kinematics::{attitude_rates, initial_attitude, post_step, v3, State, ATT, HW, TW, W};
use crate::math::attitude::{euler321_from_dcm, euler321_from_quat, wxyz};
use crate::math::environment::CircularOrbit;
use crate::math::integrate::Stepper;
use crate::math::surface_forces::Facet;
use crate::model::{check_derived, check_finite_state, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum, StateDecl};

/// Parameters derived at initialization.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
struct Derived {
    orbit: CircularOrbit,
    n2: f64,
    wheel_torque_max: f64,
    wheel_momentum_max: f64,
    dipole_max: f64,
    /// Actuator-to-body map M = R(δ) diag(k) (misalignment δ, scale factor k).
    actuator_map: Matrix3<f64>,
    /// Model Exchange: drift of |q| (‖AᵀA − I‖) that asks for a projection event after a solver step
    /// (`exchange::projection_threshold`).
    projection_threshold: f64,
    /// The facets (normals normalised) and whether any has an area.
    facets: [Facet; FACETS],
    has_facets: bool,
}

#[derive(Clone, Serialize, Deserialize)]
pub struct AttitudePlant {
    x: State,
    inertia: Matrix3<f64>,
    inertia_inv: Matrix3<f64>,
    /// Integrator with its adaptive step proposal.
    stepper: Stepper,
    kin: Kinematics,
    d: Derived,
    /// Quaternion output of the DCM mode: Shepperd's quaternion of A with the sign continuous with the
    /// previous output (updated after every internal step).
    q_dcm: [f64; 4],
}

impl AttitudePlant {
    /// ẋ with the inputs held.
    fn derivative(&self, v: &AttitudePlantVars, t: f64, x: &State, seg: &Segment) -> State {
        let w = v3(x, W);
        let needs_a = self.budget_needs_attitude(v) || Self::mtq(v) || Self::mtq_external(v) || Self::mtq_shared(v);
        let a = if needs_a { self.attitude(x) } else { Matrix3::identity() };
        let act = self.actuate(v, t, x, &a, seg);
        let tau = act.torque + self.external(v, t, &a, seg);
        let mut d = State::zeros();
        if Self::wheels(v) {
            d.fixed_rows_mut::<3>(HW).copy_from(&(-act.wheel));
            d.fixed_rows_mut::<3>(TW).copy_from(&act.lag_rate);
        }
        attitude_rates(self.kin, x, &w, &mut d);
        if self.kin.linear_dynamics() {
            // per-axis I_ii ẇ_i = τ_i with the diagonal of I_true (paper 000 Eq. 1; mode 4: w is the body rate)
            d.fixed_rows_mut::<3>(W).copy_from(&tau.component_div(&self.inertia.diagonal()));
            return d;
        }
        // gyrostat: I ω̇ = τ_act + τ_ext − ω × (I ω + h_w)
        let hw = v3(x, HW);
        let wdot = self.inertia_inv * (tau - w.cross(&(self.inertia * w + hw)));
        d.fixed_rows_mut::<3>(W).copy_from(&wdot);
        d
    }
}

impl Model for AttitudePlant {
    type Vars = AttitudePlantVars;
    fn time_grid(v: &AttitudePlantVars) -> Option<f64> {
        environment::noise_on(v).then_some(v.dist_noise_hold)
    }
    const EVOLVING: &'static [&'static str] = &["x", "stepper.h_adapt", "q_dcm"];
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudePlant",
        description: "Three-axis rigid spacecraft (gyrostat) with full inertia, selectable kinematics, saturating fault-prone torque actuators or reaction wheels with magnetorquers, disturbance generator and gravity gradient; with the environment inputs, facet drag, solar pressure and residual dipole torques",
        source: "rigid-body attitude dynamics and kinematics of [Navabi-2019], [T2FSMC-LEO] and [Moradi-FTC]; reaction-wheel lag of [Khatoonabadi-FO]",
        equations_html: include_str!("docs.html"),
        feedthrough: Feedthrough::Some(&[
            // every axis on every command: τ_applied = M sat(u) (mode 0) or M sat(K_w (u − τ_mtq)) + τ_mtq (mode 1),
            // M = R(δ) diag(k) couples the axes when the actuators are misaligned
            // (with the environment inputs, the magnetorquers' torque m × B also depends on b_eci)
            ("torque_applied", &["torque_cmd", "m_cmd", "b_eci"]),
            // mtq_mode 1: τ_applied includes sat(m_cmd) × B, the dipole output is sat(m_cmd); with the
            // internal dumping law the dipole depends on the field
            ("dipole_x", &["m_cmd_x", "b_eci"]),
            ("dipole_y", &["m_cmd_y", "b_eci"]),
            ("dipole_z", &["m_cmd_z", "b_eci"]),
            ("torque_ext_x", &["torque_dist_x", "r", "v", "b_eci", "sun_eci", "eclipse", "rho", "sun_distance"]),
            ("torque_ext_y", &["torque_dist_y", "r", "v", "b_eci", "sun_eci", "eclipse", "rho", "sun_distance"]),
            ("torque_ext_z", &["torque_dist_z", "r", "v", "b_eci", "sun_eci", "eclipse", "rho", "sun_distance"]),
            // the budget (environment_inputs = 1)
            ("b_body", &["b_eci"]),
            ("torque_residual", &["b_eci"]),
            ("torque_gg", &["r"]),
            ("torque_aero", &["r", "v", "rho"]),
            ("force_aero", &["r", "v", "rho"]),
            ("torque_srp", &["r", "sun_eci", "eclipse", "sun_distance"]),
            ("force_srp", &["r", "sun_eci", "eclipse", "sun_distance"]),
        ]),
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut AttitudePlantVars, exp: &Experiment) -> Result<Self, String> {
        let stepper = Stepper::for_plant(v.integrator, v.max_internal_step, exp)?;
        let kin = Kinematics::from_param("kinematics", v.kinematics)?;
        let i = v.inertia;
        let nominal = Matrix3::new(i.x, v.inertia_xy, v.inertia_xz, v.inertia_xy, i.y, v.inertia_yz, v.inertia_xz, v.inertia_yz, i.z);
        let s = Matrix3::from_diagonal(&v.inertia_scale.map(f64::sqrt));
        let inertia = s * nominal * s;
        // Positive definite iff the Cholesky factorisation exists.
        let chol = nalgebra::Cholesky::new(inertia).ok_or_else(|| format!("inertia matrix {:?} is not positive definite", inertia.as_slice()))?;
        let facets = v.facets()?;
        if v.fault_configured() && v.fault_clear_time <= v.fault_time {
            return Err(format!(
                "parameter fault_clear_time = {} s is not after fault_time = {} s while a fault is configured (effectiveness < 1, stuck or bias): the fault would never act",
                v.fault_clear_time, v.fault_time
            ));
        }
        let orbit = CircularOrbit { mu: v.mu, radius: v.orbit_radius, inclination: v.orbit_inclination, arg_lat0: v.orbit_arg_lat0, dipole: v.earth_dipole };
        let d = Derived {
            orbit,
            n2: v.mu / v.orbit_radius.powi(3),
            wheel_torque_max: v.wheel_torque_coeff * v.wheel_max_current,
            wheel_momentum_max: v.wheel_inertia * v.wheel_max_speed,
            dipole_max: v.mtq_turns * v.mtq_coil_area * v.mtq_max_current,
            actuator_map: nalgebra::Rotation3::new(v.actuator_misalignment).into_inner() * Matrix3::from_diagonal(&v.actuator_scale),
            projection_threshold: exchange::projection_threshold(exp),
            facets,
            has_facets: facets.iter().any(|f| f.area > 0.0),
        };
        let angles = (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw);
        let mut x = State::zeros();
        initial_attitude(kin, &mut x, angles)?;
        x.fixed_rows_mut::<3>(W).copy_from(&v.init_w);
        if Self::wheels(v) {
            x.fixed_rows_mut::<3>(HW).copy_from(&v.init_h_wheel);
        }
        v.wheel_torque_max = d.wheel_torque_max;
        v.wheel_momentum_max = d.wheel_momentum_max;
        v.mtq_dipole_max = d.dipole_max;
        v.orbit_rate = d.n2.sqrt();
        let q0 = crate::math::attitude::quat_from_euler321(angles.0, angles.1, angles.2);
        Ok(AttitudePlant { x, inertia, inertia_inv: chol.inverse(), stepper, kin, d, q_dcm: wxyz(&q0) })
    }

    fn outputs(&self, v: &mut AttitudePlantVars, t: f64) -> ModelResult {
        let unset = world_unset(v);
        if !unset {
            check_world(v, self.d.has_facets)?;
        }
        let x = self.x;
        let q = self.quaternion(&x);
        let a = self.attitude(&x);
        let w = v3(&x, W);
        let hw = v3(&x, HW);
        let [rl, pt, yw] = match self.kin {
            Kinematics::Quaternion | Kinematics::QuaternionLinearDynamics => euler321_from_quat(&q),
            Kinematics::Dcm => euler321_from_dcm(&a),
            Kinematics::Euler213Rates | Kinematics::LinearSmallAngle => [x[ATT], x[ATT + 1], x[ATT + 2]],
        };
        let seg = segment_at(v, t);
        let act = self.actuate(v, t, &x, &a, &seg);
        let budget = if unset { Budget::default() } else { self.budget(v, t, &a) };
        let ext = self.external_with(v, t, &a, &seg, Some(&budget));
        (v.torque_gg, v.torque_aero, v.torque_srp, v.torque_residual) = (budget.gg, budget.aero.torque, budget.srp.torque, budget.residual);
        (v.force_aero, v.force_srp) = (budget.aero.force, budget.srp.force);
        v.b_body = self.field_body(v, t, &a);
        v.h_total_ref = a.transpose() * (self.inertia * w + hw);
        v.wheel_speed = hw / v.wheel_inertia;
        v.q = q;
        v.w = w;
        (v.roll, v.pitch, v.yaw) = (rl, pt, yw);
        (v.roll_deg, v.pitch_deg, v.yaw_deg) = (rl.to_degrees(), pt.to_degrees(), yw.to_degrees());
        v.torque_applied = act.torque;
        v.torque_ext = ext;
        v.h_wheel = hw;
        v.dipole = act.dipole;
        v.actuator_fault = if seg.faulted && v.fault_configured() { 1.0 } else { 0.0 };
        Ok(())
    }

    fn step(&mut self, v: &AttitudePlantVars, t: f64, h: f64) -> ModelResult {
        check_world(v, self.d.has_facets)?;
        let (kin, ortho) = (self.kin, v.dcm_orthonormalize == 1);
        let (mut stepper, mut x, mut q_dcm) = (self.stepper, self.x, self.q_dcm);
        let this = &*self;
        // fault state and noise are constant over a piece: pieces are cut at the events
        stepper.advance(
            t,
            h,
            &breakpoints(v, t, h)?,
            &mut x,
            |ts, len| {
                let seg = segment_of_piece(v, ts, len);
                move |tt: f64, xx: &State| this.derivative(v, tt, xx, &seg)
            },
            |xx, tt| post_step(kin, ortho, &mut q_dcm, xx, tt),
        )?;
        (self.stepper, self.x, self.q_dcm) = (stepper, x, q_dcm);
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        self.stepper.check_against(&fresh.stepper)?;
        check_derived("kinematics", &self.kin, &fresh.kin)?;
        check_derived("inertia", &(self.inertia, self.inertia_inv), &(fresh.inertia, fresh.inertia_inv))?;
        check_derived("derived limits and orbit", &self.d, &fresh.d)?;
        check_finite_state("state vector", self.x.iter().chain(&self.q_dcm))?;
        if self.kin.is_quaternion() && (self.x.fixed_rows::<4>(ATT).norm() - 1.0).abs() > 1e-6 {
            return Err("restored state: attitude quaternion is not of unit norm".into());
        }
        Ok(())
    }

    // Model Exchange: the 18-entry state vector as it is (`kinematics::N`; unused entries stay 0 and
    // have derivative 0), the right-hand side of the internal integrator, time events at the fault
    // onset and end and the noise-hold boundaries, and the invariant kept by projection at events (exchange.rs).
    const STATES: Option<&'static [StateDecl]> = Some(&exchange::STATES);
    fn get_states(&self, _v: &Self::Vars, x: &mut [f64]) {
        x.copy_from_slice(self.x.as_slice());
    }
    fn set_states(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
    }
    fn derivatives(&self, v: &AttitudePlantVars, t: f64, dx: &mut [f64]) -> ModelResult {
        self.check_chart(t)?;
        check_world(v, self.d.has_facets)?;
        dx.copy_from_slice(self.derivative(v, t, &self.x, &segment_at(v, t)).as_slice());
        Ok(())
    }
    fn next_time_event(&self, v: &AttitudePlantVars, t: f64) -> Option<f64> {
        exchange::next_time_event(v, t)
    }
    fn event_update(&mut self, v: &AttitudePlantVars, t: f64) -> Result<bool, String> {
        self.project(v, t)
    }
    fn completed_integrator_step(&mut self, v: &AttitudePlantVars, _t: f64) -> bool {
        self.needs_projection(v)
    }
}
