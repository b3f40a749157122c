//! `PdController`: paper 000's PD attitude law with a selectable error signal (quaternion, DCM or
//! Euler angles) and gains from (ω_n, ξ) and the nominal inertia, or given explicitly.

use serde::{Deserialize, Serialize};

use super::shared::{check_unit_quaternions, AttitudeControllerPorts, DcmError, ErrorLaw};
use crate::declare_variables;
use crate::math::attitude::attitude_matrix;
use crate::model::{check_derived, Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

declare_variables! {
    pub struct PdControllerVars {
        ports: AttitudeControllerPorts;
        17 => w_ref_dot: Vec3 = [0.0; 3], Input, "rad/s2", "Commanded angular acceleration, in the commanded body axes (AttitudeCommand's output; read with rate_feedforward = 2 only)";
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => wn: Real = 1.0, Parameter, "rad/s", "Natural frequency omega_n of the per-axis closed loop", Positive;
        104 => zeta: Real = 1.0, Parameter, "", "Damping ratio xi of the per-axis closed loop", NonNegative;
        105 => kp: Vec3 = [1000.0, 500.0, 700.0], Parameter, "N.m/rad", "Explicit proportional gain k (gain_mode = 1)";
        108 => kd: Vec3 = [-2000.0, -1000.0, -1400.0], Parameter, "N.m.s/rad", "Explicit rate gain k_d, negative in the paper's convention (gain_mode = 1)";
        120 => gain_mode: Integer = 0, Parameter, "", "0 = gains from wn, zeta and inertia; 1 = explicit kp_*, kd_*", Choice(&[0, 1]);
        121 => error_law: Integer = 0, Parameter, "", "Error signal: 0 = quaternion, 1 = DCM, 2 = Euler 321 angles", Choice(ErrorLaw::CODES);
        122 => dcm_error: Integer = 0, Parameter, "", "Reading of the DCM error (error_law = 1): 0 = elements of A(q)A(q_ref)^T as printed; 1 = vex of its skew part (= quaternion law); 2 = twice that; 3 = -(transposed elements); 4 = body-to-inertial attitude matrix; 5 = transposed elements of A(q_ref)^T A(q)", Choice(DcmError::CODES);
        123 => rate_feedforward: Integer = 0, Parameter, "", "0 = rate term on the measured rate w (the paper's law, constant commands); 1 = on the rate error w - A(q) A(q_ref)^T w_ref, for a moving reference (nadir pointing); 2 = 1 plus the feed-forward of the reference's acceleration and the gyroscopic terms (the full tracking law)", Choice(&[0, 1, 2]);
        200 => k: Vec3 = [0.0; 3], CalculatedParameter, "N.m/rad", "Proportional gain in use";
        203 => k_d: Vec3 = [0.0; 3], CalculatedParameter, "N.m.s/rad", "Rate gain in use (negative)";
    }
}

/// A static law: the error law and the gains (in the calculated parameters) are all it needs.
#[derive(Clone, Serialize, Deserialize)]
pub struct PdController {
    law: ErrorLaw,
    dcm: DcmError,
}

impl Model for PdController {
    type Vars = PdControllerVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "PdController",
        description: "PD attitude controller with quaternion, DCM or Euler-angle error law",
        source: "[Navabi-2019], Eqs. 2, 3, 7, 11, 13, 15; rate_feedforward 2: the tracking law of [Markley-Crassidis-2014] Ch. 7",
        equations_html: "<pre>T_i   = k_i e_i + k_d,i w_i\n\
k_i   = wn^2 I_i,   k_d,i = -2 zeta wn I_i      (k_d is negative: the paper's law adds +k_d * rate)\n\
e^Q   = 2 q_E,w q_E,v,   q_E = q* (x) q_ref                 (error_law = 0)\n\
e^D   = (A_E[3,2], A_E[1,3], A_E[2,1]),  A_E = A(q) A(q_ref)^T  (error_law = 1, dcm_error = 0)\n\
e^E   = wrap(euler321(q_ref) - euler321(q))                 (error_law = 2)\n\
DCM error readings (dcm_error), M = A(q) A(q_ref)^T, N = A(q)^T A(q_ref), A(q) inertial -> body:\n\
  0  e = ( M32,  M13,  M21)            elements as printed (default)\n\
  1  e = vex((M - M^T)/2) = sin(alpha) axis   (identical to the quaternion law)\n\
  2  e = vex(M - M^T)     = 2 sin(alpha) axis\n\
  3  e = -(M23, M31, M12)              printed elements of A(q_ref) A(q)^T, sign for commanded - actual\n\
  4  e = -(N32, N13, N21)              attitude matrix read as body -> inertial\n\
  5  e = ( N23, N31, N12)              printed elements of A(q_ref)^T A(q)</pre>\n\
<p>All six DCM readings agree to first order for small angles (small attitude and small error, the paper's \
linearisation: e = commanded - actual angle); at large angles they differ by the symmetric part \
(1 - cos alpha) n n^T of the error matrix, its sign, and (readings 4, 5) the frame in which the error axis is \
expressed (reference instead of body). [Navabi-2019] does not say which one it used; reading 0 is the default.</p>\n\
<p>For a constant command and the linear small-angle plant each axis closes to s^2 + 2 zeta wn s + wn^2. \
w_ref is not used unless rate_feedforward = 1 or 2 ([Navabi-2019] commands are constant); then the rate term acts on \
w - A(q) A(q_ref)^T w_ref (w_ref in the commanded body axes, turned into the body axes), which removes the \
steady lag of -2 zeta w_ref / wn that a reference turning at w_ref leaves with the paper's law.</p>\n\
<pre>rate_feedforward = 2:  A_e = A(q) A(q_ref)^T,  w_e = w - A_e w_ref\n\
  T = k e + k_d w_e + J (A_e w_ref_dot - w x A_e w_ref) + w x J w      (J = diag(inertia))</pre>\n\
<p>With rate_feedforward = 2 the law also feeds forward the reference's angular acceleration w_ref_dot (in the \
commanded body axes) and cancels the gyroscopic torque (the attitude-tracking law of [Markley-Crassidis-2014] Ch. 7, \
with this controller's error signal): since d/dt (A_e w_ref) = A_e w_ref_dot - w x A_e w_ref, the rate error obeys \
J dw_e/dt = k e + k_d w_e whatever the reference does (nominal inertia, continuous time), which removes the steady \
error of about -w_ref_dot / wn^2 per axis that an accelerating reference (nadir on an eccentric orbit) leaves with \
rate_feedforward = 1.</p>",
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut PdControllerVars, _exp: &Experiment) -> Result<Self, String> {
        (v.k, v.k_d) = match v.gain_mode {
            0 => (v.inertia * v.wn * v.wn, v.inertia * (-2.0 * v.zeta * v.wn)),
            _ => (v.kp, v.kd),
        };
        Ok(PdController {
            law: ErrorLaw::from_param("error_law", v.error_law)?,
            dcm: DcmError::from_param("dcm_error", v.dcm_error)?,
        })
    }

    fn outputs(&self, v: &mut PdControllerVars, _t: f64) -> ModelResult {
        check_unit_quaternions(&v.ports)?;
        let e = match self.law {
            ErrorLaw::Dcm => self.dcm.error(&v.ports),
            law => law.error(&v.ports),
        };
        if v.rate_feedforward == 0 {
            v.ports.torque_cmd = v.k.component_mul(&e) + v.k_d.component_mul(&v.ports.w);
            return Ok(());
        }
        let turn = attitude_matrix(&v.ports.q) * attitude_matrix(&v.ports.q_ref).transpose();
        let w_ref = turn * v.ports.w_ref;
        let rate = v.ports.w - w_ref;
        v.ports.torque_cmd = v.k.component_mul(&e) + v.k_d.component_mul(&rate);
        if v.rate_feedforward == 2 {
            let w = v.ports.w;
            let feed = turn * v.w_ref_dot - w.cross(&w_ref);
            v.ports.torque_cmd += v.inertia.component_mul(&feed) + w.cross(&v.inertia.component_mul(&w));
        }
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("error law", &self.law, &fresh.law)?;
        check_derived("DCM error reading", &self.dcm, &fresh.dcm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;
    use nalgebra::Vector3;

    #[test]
    fn gains_follow_wn_zeta_and_inertia() {
        let mut c = Fmu::<PdController>::default();
        (c.v.wn, c.v.zeta) = (2.0, 0.5);
        c.initialize(&Experiment::default()).unwrap();
        assert_eq!(c.v.k, Vector3::new(4000.0, 2000.0, 2800.0));
        assert_eq!(c.v.k_d, Vector3::new(-2000.0, -1000.0, -1400.0));
        c.v.wn = -1.0;
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("wn = -1"), "{e}");
    }

    #[test]
    fn full_tracking_law_adds_the_acceleration_and_gyroscopic_terms() {
        // q = q_ref = identity (A_e = I, e = 0), J = (1000, 500, 700), wn = zeta = 1: k_d = -2 J.
        // w = (0.1, 0.2, 0), w_ref = (0, 0.2, 0), w_ref_dot = (0.01, 0, 0), by hand:
        // k_d (w - w_ref) = (-200, 0, 0); w x w_ref = (0, 0, 0.02); J (w_ref_dot - w x w_ref) = (10, 0, -14);
        // J w = (100, 100, 0), w x J w = (0, 0, -10): T = (-190, 0, -24); rate_feedforward 1: (-200, 0, 0)
        let mut c = Fmu::<PdController>::default();
        (c.v.ports.w, c.v.ports.w_ref, c.v.w_ref_dot) =
            (Vector3::new(0.1, 0.2, 0.0), Vector3::new(0.0, 0.2, 0.0), Vector3::new(0.01, 0.0, 0.0));
        for (mode, torque) in [(2, Vector3::new(-190.0, 0.0, -24.0)), (1, Vector3::new(-200.0, 0.0, 0.0))] {
            c.v.rate_feedforward = mode;
            c.initialize(&Experiment::default()).unwrap();
            c.outputs(0.0).unwrap();
            assert!((c.v.ports.torque_cmd - torque).norm() < 1e-12, "{mode}: {}", c.v.ports.torque_cmd);
        }
        c.v.rate_feedforward = 3;
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("rate_feedforward"));
    }

    #[test]
    fn dcm_readings_agree_for_small_errors_and_skew_half_is_the_quaternion_law() {
        use crate::math::attitude::quat_from_euler321;
        let mut c = Fmu::<PdController>::default();
        c.v.error_law = 1;
        // first-order agreement needs small angles for both the attitude and the error (the paper's
        // small-angle derivation); readings 4 and 5 express the axis in the reference frame
        let q = quat_from_euler321(1e-4, -2e-4, 1e-4);
        let small = quat_from_euler321(-1e-4, 2e-4, 3e-4);
        let large = quat_from_euler321(0.7, -0.7, -1.0);
        let mut first = None;
        for code in DcmError::CODES {
            c.v.dcm_error = *code;
            c.initialize(&Experiment::default()).unwrap();
            (c.v.ports.q, c.v.ports.q_ref, c.v.ports.w) = (q, small, Vector3::zeros());
            c.outputs(0.0).unwrap();
            let t = c.v.ports.torque_cmd.component_div(&c.v.k) / if *code == 2 { 2.0 } else { 1.0 };
            let f = *first.get_or_insert(t);
            assert!((t - f).norm() < 2e-3 * f.norm(), "reading {code}: {t} vs {f}");
            // reading 1 (vex of the skew part) is exactly the quaternion law at any angle
            if *code == 1 {
                (c.v.ports.q, c.v.ports.q_ref) = (quat_from_euler321(0.3, -0.2, 0.5), large);
                c.outputs(0.0).unwrap();
                let e = crate::math::attitude::error_quaternion(&c.v.ports.q, &large);
                let eq = e.vector() * (2.0 * e.w);
                assert!((c.v.ports.torque_cmd.component_div(&c.v.k) - eq).norm() < 1e-14);
            }
        }
        c.v.dcm_error = 6;
        let e = c.initialize(&Experiment::default()).unwrap_err();
        assert!(e.contains("dcm_error"), "{e}");
    }
}
