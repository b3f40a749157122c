//! Actuators: ideal torque with saturation and faults (mode 0), or three reaction wheels with lag,
//! torque and momentum limits plus magnetorquer momentum dumping (mode 1); the magnetorquers' dipole from
//! the dumping law, the command m_cmd, or both (mtq_mode 0, 1, 2).

use nalgebra::{Matrix3, Vector3};

use super::environment::Segment;
use super::kinematics::{v3, State, HW, TW};
use super::variables::AttitudePlantVars;
use super::AttitudePlant;

/// Actuator outputs at one instant.
#[derive(Clone, Copy, Debug, Default)]
pub struct Actuation {
    /// τ_act = τ_rw + τ_mtq (mode 1) or the clamped command (mode 0).
    pub torque: Vector3<f64>,
    /// Wheel torque on the body τ_rw; ḣ_w = −τ_rw.
    pub wheel: Vector3<f64>,
    /// dτ_w/dt of the wheel lag.
    pub lag_rate: Vector3<f64>,
    pub dipole: Vector3<f64>,
}

fn clamp3(v: Vector3<f64>, l: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x.clamp(-l.x, l.x), v.y.clamp(-l.y, l.y), v.z.clamp(-l.z, l.z))
}

/// Command after the stuck/bias faults (project choice: both act on the command entering the
/// actuator, so the torque and momentum limits still hold).
fn faulty_cmd(v: &AttitudePlantVars, faulted: bool) -> Vector3<f64> {
    let c = v.torque_cmd;
    if !faulted {
        return c;
    }
    let stuck = v.stuck();
    Vector3::from_fn(|i, _| if stuck[i] { v.fault_stuck_value[i] } else { c[i] + v.fault_bias[i] })
}

impl AttitudePlant {
    pub(super) fn wheels(v: &AttitudePlantVars) -> bool {
        v.actuator_mode == 1
    }

    /// The internal momentum-dumping law runs (mtq_mode 0, wheels, mtq_enable).
    pub(super) fn mtq(v: &AttitudePlantVars) -> bool {
        v.mtq_mode == 0 && Self::wheels(v) && v.mtq_enable == 1
    }

    /// The magnetorquers follow the dipole command input m_cmd (mtq_mode 1, or 2 when the dumping law
    /// does not run: no wheels or mtq_enable 0).
    pub(super) fn mtq_external(v: &AttitudePlantVars) -> bool {
        v.mtq_mode == 1 || (v.mtq_mode == 2 && !Self::mtq_shared(v))
    }

    /// The magnetorquers follow m_cmd plus the dumping law's dipole (mtq_mode 2, wheels, mtq_enable).
    pub(super) fn mtq_shared(v: &AttitudePlantVars) -> bool {
        v.mtq_mode == 2 && Self::wheels(v) && v.mtq_enable == 1
    }

    /// mtq_mode 2 with the dumping law: m = clamp(m_cmd + k_dump (h_w × B)/|B|²) per axis (the dumping
    /// term 0 when |B| < 1e-12 T); returns (m, the torque fed forward to the wheels, m × B). The wheels get
    /// the torque of the dumping share m − clamp(m_cmd) (as in mtq_mode 0); the commanded share acts on
    /// the body besides them (as in mtq_mode 1). With m_cmd = 0 and an unsaturated sum this is mtq_mode 0.
    fn shared_dipole(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>, hw: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let lim = Vector3::repeat(self.d.dipole_max);
        let b = self.field_body(v, t, a);
        let b2 = b.norm_squared();
        let raw = if b2.sqrt() >= 1e-12 { hw.cross(&b) * (v.mtq_k_dump / b2) } else { Vector3::zeros() };
        let m = clamp3(v.m_cmd + raw, lim);
        (m, (m - clamp3(v.m_cmd, lim)).cross(&b), m.cross(&b))
    }

    /// Commanded dipole (each axis clamped at the dipole limit) and its torque m × B (mtq_mode 1).
    fn external_dipole(&self, v: &AttitudePlantVars, t: f64, a: &Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let m = clamp3(v.m_cmd, Vector3::repeat(self.d.dipole_max));
        (m, m.cross(&self.field_body(v, t, a)))
    }

    /// Actuators for state x at time t.
    pub(super) fn actuate(&self, v: &AttitudePlantVars, t: f64, x: &State, a: &Matrix3<f64>, seg: &Segment) -> Actuation {
        let u = faulty_cmd(v, seg.faulted);
        let eff = if seg.faulted { v.effectiveness } else { Vector3::repeat(1.0) };
        if !Self::wheels(v) {
            let torque = self.d.actuator_map * clamp3(u, v.u_max.component_mul(&eff));
            if Self::mtq_external(v) {
                let (dipole, tau_mtq) = self.external_dipole(v, t, a);
                return Actuation { torque: torque + tau_mtq, dipole, ..Default::default() };
            }
            return Actuation { torque, ..Default::default() };
        }
        let hw = v3(x, HW);
        // magnetorquers: momentum dumping m = k (h_w × B)/|B|², uniformly scaled into ±m_max
        let mut dipole = Vector3::zeros();
        let mut tau_mtq = Vector3::zeros();
        if Self::mtq(v) {
            let b = self.field_body(v, t, a);
            let b2 = b.norm_squared();
            if b2.sqrt() >= 1e-12 {
                let raw = hw.cross(&b) * (v.mtq_k_dump / b2);
                let peak = raw.amax();
                dipole = if peak > self.d.dipole_max { raw * (self.d.dipole_max / peak) } else { raw };
                tau_mtq = dipole.cross(&b);
            }
        }
        // the command and the dumping law share the coils (mtq_mode 2): only the dumping share is fed forward
        let mut tau_ff = tau_mtq;
        if Self::mtq_shared(v) {
            (dipole, tau_ff, tau_mtq) = self.shared_dipole(v, t, a, &hw);
        }
        // wheel torque command with the known magnetic torque of the dumping law fed forward, first-order lag
        let rw_cmd = (u - tau_ff) * v.wheel_gain;
        // an external dipole command (mtq_mode 1) acts besides the wheels, without feed-forward
        if Self::mtq_external(v) {
            (dipole, tau_mtq) = self.external_dipole(v, t, a);
        }
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
        // misalignment and scale factor between the wheels' axes and the body (the limits act on the wheels' axes)
        let tau_rw = self.d.actuator_map * tau_rw;
        Actuation { torque: tau_rw + tau_mtq, wheel: tau_rw, lag_rate, dipole }
    }
}
