//! `SaturationAwarePd`: a three-axis attitude controller of our own, exported as an FMU through
//! spacecraft_fmus. It plugs into any scenario in place of `PdController` (same ports, taken from the
//! shared `AttitudeControllerPorts` block, and the same parameter names for the gains).
//!
//! The law: `T = s * (k ∘ e + k_d ∘ w)` with `k = I wn²`, `k_d = -2 ζ wn I` (per axis, I the nominal
//! inertia), and
//! - the error `e` chosen by `error_kind`: 0 = `2 q_E,w q_E,v` (= sin(α) n, the quaternion error of
//!   `PdController`), 1 = `2 sign(q_E,w) q_E,v` (= 2 sin(α/2) n, the vector-part law: larger at large
//!   angles, always along the shorter rotation), where `q_E = q* ⊗ q_ref` turns by α about n;
//! - the scale `s = min(1, torque_limit / max_i |T_i|)`: a command beyond the actuators' limit is
//!   shortened as a whole, keeping its direction, instead of being clipped axis by axis downstream.
//!
//! With `error_kind = 0` and `torque_limit = 1e30` (no limit) it is exactly `PdController` with
//! `gain_mode = 0` and `error_law = 0`.

use spacecraft_fmus::export::*;
use spacecraft_fmus::math::attitude::error_quaternion;

declare_variables! {
    /// Variables of the saturation-aware PD controller.
    pub struct SaturationAwarePdVars {
        ports: AttitudeControllerPorts;
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => wn: Real = 1.0, Parameter, "rad/s", "Natural frequency omega_n of the per-axis closed loop", Positive;
        104 => zeta: Real = 1.0, Parameter, "", "Damping ratio of the per-axis closed loop", NonNegative;
        123 => error_kind: Integer = 0, Parameter, "", "Error signal: 0 = 2 q_E,w q_E,v (sin(alpha) n); 1 = 2 sign(q_E,w) q_E,v (2 sin(alpha/2) n)", Choice(SWITCH);
        111 => torque_limit: Real = 1e30, Parameter, "N.m", "Largest commanded torque per axis; larger commands are scaled down keeping their direction (1e30 = no limit)", Limit;
        200 => k: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "Proportional gain in use";
        203 => k_d: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "Rate gain in use (negative)";
        30 => scale: Real = 1.0, Output, "", "Scale s applied to the PD command (1 = not limited)";
    }
}

/// A static law: everything it needs is in the (calculated) parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct SaturationAwarePd;

impl Model for SaturationAwarePd {
    type Vars = SaturationAwarePdVars;
    const EVOLVING: &'static [&'static str] = &[];
    const INFO: ModelInfo = ModelInfo {
        name: "SaturationAwarePd",
        description: "PD attitude controller with a selectable quaternion error and direction-preserving torque limit",
        source: "custom_controller example of spacecraft_fmus (a user's own model)",
        equations_html: "<pre>T   = s (k e + k_d w),  k = I wn^2,  k_d = -2 zeta wn I\n\
e   = 2 q_E,w q_E,v          (error_kind = 0)\n\
e   = 2 sign(q_E,w) q_E,v    (error_kind = 1),   q_E = q* (x) q_ref\n\
s   = min(1, torque_limit / max_i |T_i|)</pre>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut SaturationAwarePdVars, _exp: &Experiment) -> Result<Self, String> {
        v.k = v.inertia * v.wn * v.wn;
        v.k_d = v.inertia * (-2.0 * v.zeta * v.wn);
        Ok(SaturationAwarePd)
    }

    fn outputs(&self, v: &mut SaturationAwarePdVars, _t: f64) -> ModelResult {
        check_unit_quaternions(&v.ports)?;
        let q_e = error_quaternion(&v.ports.q, &v.ports.q_ref);
        let e = match v.error_kind {
            0 => q_e.vector() * (2.0 * q_e.w),
            _ => q_e.vector() * if q_e.w < 0.0 { -2.0 } else { 2.0 },
        };
        let t = v.k.component_mul(&e) + v.k_d.component_mul(&v.ports.w);
        let peak = t.amax();
        v.scale = if peak > v.torque_limit {
            v.torque_limit / peak
        } else {
            1.0
        };
        v.ports.torque_cmd = if v.scale < 1.0 { t * v.scale } else { t };
        Ok(())
    }
}

export_fmus!(SaturationAwarePd);

#[cfg(test)]
mod tests {
    //! Checked against closed forms, not against the code's own output.
    use super::*;

    /// Unit quaternion of a rotation by `angle` about the unit axis `n` (scalar first).
    fn rotation(angle: f64, n: Vector3<f64>) -> Quaternion<f64> {
        let (s, c) = (angle / 2.0).sin_cos();
        Quaternion::new(c, s * n.x, s * n.y, s * n.z)
    }

    fn controller(error_kind: i32, limit: f64) -> Fmu<SaturationAwarePd> {
        let mut m = Fmu::<SaturationAwarePd>::default();
        (m.v.wn, m.v.zeta, m.v.error_kind, m.v.torque_limit) = (0.5, 0.8, error_kind, limit);
        m.initialize(&Experiment::default()).unwrap();
        m
    }

    #[test]
    fn gains_are_i_wn2_and_minus_2_zeta_wn_i() {
        let m = controller(0, 1e30);
        assert_eq!(m.v.k, Vector3::new(250.0, 125.0, 175.0));
        assert!((m.v.k_d - Vector3::new(-800.0, -400.0, -560.0)).norm() < 1e-12);
    }

    #[test]
    fn the_two_errors_are_sin_alpha_and_2_sin_half_alpha_along_the_axis() {
        let n = Vector3::new(1.0, -2.0, 2.0) / 3.0;
        for alpha in [0.1, 1.0, 2.5] {
            for (kind, size) in [(0, f64::sin(alpha)), (1, 2.0 * f64::sin(alpha / 2.0))] {
                let mut m = controller(kind, 1e30);
                // q = identity, q_ref = rotation: q_E = q_ref, the error points along +n
                m.v.ports.q_ref = rotation(alpha, n);
                m.outputs(0.0).unwrap();
                let expected = m.v.k.component_mul(&(n * size));
                assert!(
                    (m.v.ports.torque_cmd - expected).norm() < 1e-12 * expected.norm(),
                    "kind {kind}, alpha {alpha}"
                );
            }
        }
    }

    #[test]
    fn the_vector_part_law_takes_the_short_way_for_either_sign_of_the_quaternion() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let mut a = controller(1, 1e30);
        a.v.ports.q_ref = rotation(0.4, n);
        a.outputs(0.0).unwrap();
        let mut b = controller(1, 1e30);
        b.v.ports.q_ref = -rotation(0.4, n);
        b.outputs(0.0).unwrap();
        assert_eq!(a.v.ports.torque_cmd, b.v.ports.torque_cmd);
        assert!(a.v.ports.torque_cmd.z > 0.0);
    }

    #[test]
    fn a_command_beyond_the_limit_is_shortened_keeping_its_direction() {
        let mut m = controller(0, 10.0);
        m.v.ports.q_ref = rotation(1.0, Vector3::new(0.6, 0.8, 0.0));
        m.v.ports.w = Vector3::new(0.01, -0.02, 0.03);
        m.outputs(0.0).unwrap();
        let t = m.v.ports.torque_cmd;
        let mut free = controller(0, 1e30);
        free.v.ports = m.v.ports.clone();
        free.outputs(0.0).unwrap();
        let u = free.v.ports.torque_cmd;
        assert!((t.amax() - 10.0).abs() < 1e-12);
        assert!((t.normalize() - u.normalize()).norm() < 1e-12);
        assert!((m.v.scale - 10.0 / u.amax()).abs() < 1e-15);
    }

    #[test]
    fn bad_parameters_and_unconnected_quaternions_are_errors_naming_them() {
        let mut m = Fmu::<SaturationAwarePd>::default();
        m.v.torque_limit = -1.0;
        assert!(m
            .initialize(&Experiment::default())
            .unwrap_err()
            .contains("torque_limit"));
        let mut m = controller(0, 1e30);
        m.v.ports.q = Quaternion::new(0.0, 0.0, 0.0, 0.0);
        assert!(m.outputs(0.0).unwrap_err().contains("quaternion q"));
    }
}
