//! `RelativePositionCommand`: relative-position reference for formation flying: a constant set-point
//! applied as a step (paper 001), or a smooth fifth-order polynomial transfer with consistent velocity
//! and acceleration references (project option).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::model::{Experiment, Model, ModelInfo, ModelResult, SWITCH};

declare_variables! {
    pub struct RelativePositionCommandVars {
        10 => pos_ref: Vec3 = [0.0; 3], Output, "m", "Commanded relative position, LVLH";
        13 => vel_ref: Vec3 = [0.0; 3], Output, "m/s", "Commanded relative velocity, LVLH";
        16 => acc_ref: Vec3 = [0.0; 3], Output, "m/s2", "Commanded relative acceleration, LVLH";
        100 => target_pos: Vec3 = [50.0, 40.0, 60.0], Parameter, "m", "Set-point after step_time ([NPPID-Formation]: 50, 40, 60 m)";
        103 => start_pos: Vec3 = [0.0; 3], Parameter, "m", "Reference before step_time (start of the transfer)";
        106 => step_time: Real = 0.0, Parameter, "s", "Time of the step / start of the transfer";
        107 => transfer_time: Real = 60.0, Parameter, "s", "Duration of the polynomial transfer (profile 1)";
        120 => profile: Integer = 0, Parameter, "", "0 = step to the set-point ([NPPID-Formation]), 1 = fifth-order polynomial transfer", Choice(SWITCH);
    }
}

/// Normalised quintic rest-to-rest transfer s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ on τ ∈ [0, 1] and its first two
/// derivatives with respect to τ; clamped outside [0, 1].
pub fn quintic(tau: f64) -> (f64, f64, f64) {
    if tau <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if tau >= 1.0 {
        return (1.0, 0.0, 0.0);
    }
    let t2 = tau * tau;
    let t3 = t2 * tau;
    (t3 * (10.0 - 15.0 * tau + 6.0 * t2), 30.0 * t2 * (1.0 - 2.0 * tau + t2), 60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2))
}

/// No state: the outputs are a function of time and the parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct RelativePositionCommand;

impl Model for RelativePositionCommand {
    type Vars = RelativePositionCommandVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "RelativePositionCommand",
        description: "Relative-position reference: constant set-point step or smooth fifth-order polynomial transfer",
        source: "set-point of [NPPID-Formation]",
        equations_html: "<pre>profile 0:  pos_ref = start_pos for t &lt; step_time, target_pos after; vel_ref = acc_ref = 0\n\
profile 1:  tau = (t - step_time) / transfer_time clamped to [0, 1]\n\
            s = 10 tau^3 - 15 tau^4 + 6 tau^5\n\
            pos_ref = start_pos + (target_pos - start_pos) s\n\
            vel_ref = (target_pos - start_pos) ds/dtau / transfer_time\n\
            acc_ref = (target_pos - start_pos) d2s/dtau2 / transfer_time^2</pre>",
        default_stop_time: 300.0,
        default_step: 0.001,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut RelativePositionCommandVars, _exp: &Experiment) -> Result<Self, String> {
        if v.profile == 1 && v.transfer_time <= 0.0 {
            return Err(format!("parameter transfer_time = {} must be > 0 (profile 1)", v.transfer_time));
        }
        Ok(RelativePositionCommand)
    }

    fn outputs(&self, v: &mut RelativePositionCommandVars, t: f64) -> ModelResult {
        let (p0, p1) = (v.start_pos, v.target_pos);
        let (s, ds, dds, tt) = match v.profile {
            0 => (if t >= v.step_time { 1.0 } else { 0.0 }, 0.0, 0.0, 1.0),
            _ => {
                let (s, ds, dds) = quintic((t - v.step_time) / v.transfer_time);
                (s, ds, dds, v.transfer_time)
            }
        };
        v.pos_ref = Vector3::from_fn(|i, _| if s == 1.0 { p1[i] } else { p0[i] + (p1[i] - p0[i]) * s });
        v.vel_ref = Vector3::from_fn(|i, _| (p1[i] - p0[i]) * ds / tt);
        v.acc_ref = Vector3::from_fn(|i, _| (p1[i] - p0[i]) * dds / (tt * tt));
        Ok(())
    }

    /// Model Exchange: the step (profile 0) or the start and end of the transfer (profile 1) are time events.
    fn next_time_event(&self, v: &RelativePositionCommandVars, t: f64) -> Option<f64> {
        let end = if v.profile == 0 { v.step_time } else { v.step_time + v.transfer_time };
        [v.step_time, end].into_iter().find(|te| *te > t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn outputs(c: &mut Fmu<RelativePositionCommand>, t: f64) -> [f64; 9] {
        c.outputs(t).unwrap();
        let v = &c.v;
        [v.pos_ref.x, v.pos_ref.y, v.pos_ref.z, v.vel_ref.x, v.vel_ref.y, v.vel_ref.z, v.acc_ref.x, v.acc_ref.y, v.acc_ref.z]
    }

    #[test]
    fn step_profile_is_the_paper_set_point() {
        let mut c = Fmu::<RelativePositionCommand>::default();
        c.v.step_time = 1.0;
        c.initialize(&Experiment::default()).unwrap();
        assert_eq!(outputs(&mut c, 0.5), [0.0; 9]);
        assert_eq!(outputs(&mut c, 1.0), [50.0, 40.0, 60.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn quintic_transfer_is_consistent() {
        let mut c = Fmu::<RelativePositionCommand>::default();
        c.v.profile = 1;
        c.v.step_time = 2.0;
        c.v.transfer_time = 40.0;
        c.v.start_pos.y = -10.0;
        c.initialize(&Experiment::default()).unwrap();
        // rest at both ends, reaches the target exactly
        assert_eq!(outputs(&mut c, 1.0), [0.0, -10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(outputs(&mut c, 42.0), [50.0, 40.0, 60.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        // midpoint: half way, peak velocity 15/8 Δp/T, zero acceleration
        let m = outputs(&mut c, 22.0);
        assert!((m[1] - 15.0).abs() < 1e-12 && (m[4] - 15.0 / 8.0 * 50.0 / 40.0).abs() < 1e-12 && m[7].abs() < 1e-12);
        // vel_ref and acc_ref are the time derivatives (central differences)
        for t in [3.0, 10.0, 25.0, 41.0] {
            let h = 1e-4;
            let (a, b, o) = (outputs(&mut c, t - h), outputs(&mut c, t + h), outputs(&mut c, t));
            for i in 0..3 {
                assert!(((b[i] - a[i]) / (2.0 * h) - o[3 + i]).abs() < 1e-7, "vel t {t} axis {i}");
                assert!(((b[3 + i] - a[3 + i]) / (2.0 * h) - o[6 + i]).abs() < 1e-7, "acc t {t} axis {i}");
            }
        }
    }

    #[test]
    fn transfer_time_must_be_positive_for_profile_1() {
        let mut c = Fmu::<RelativePositionCommand>::default();
        c.v.profile = 1;
        c.v.transfer_time = 0.0;
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("transfer_time"));
    }
}
