//! `RelativePositionCommand`: relative-position reference for formation flying (spec controllers.md §2):
//! a constant set-point applied as a step (paper 001), or a smooth fifth-order polynomial transfer with
//! consistent velocity and acceleration references (project option).

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct RelativePositionCommandVars {
        10 => pos_ref_x: Real = 0.0, Output, Continuous, "m", "Commanded relative position, LVLH x";
        11 => pos_ref_y: Real = 0.0, Output, Continuous, "m", "Commanded relative position, LVLH y";
        12 => pos_ref_z: Real = 0.0, Output, Continuous, "m", "Commanded relative position, LVLH z";
        13 => vel_ref_x: Real = 0.0, Output, Continuous, "m/s", "Commanded relative velocity, x";
        14 => vel_ref_y: Real = 0.0, Output, Continuous, "m/s", "Commanded relative velocity, y";
        15 => vel_ref_z: Real = 0.0, Output, Continuous, "m/s", "Commanded relative velocity, z";
        16 => acc_ref_x: Real = 0.0, Output, Continuous, "m/s2", "Commanded relative acceleration, x";
        17 => acc_ref_y: Real = 0.0, Output, Continuous, "m/s2", "Commanded relative acceleration, y";
        18 => acc_ref_z: Real = 0.0, Output, Continuous, "m/s2", "Commanded relative acceleration, z";
        100 => target_pos_x: Real = 50.0, Parameter, Fixed, "m", "Set-point x after step_time (paper 001: 50 m)";
        101 => target_pos_y: Real = 40.0, Parameter, Fixed, "m", "Set-point y after step_time (paper 001: 40 m)";
        102 => target_pos_z: Real = 60.0, Parameter, Fixed, "m", "Set-point z after step_time (paper 001: 60 m)";
        103 => start_pos_x: Real = 0.0, Parameter, Fixed, "m", "Reference x before step_time (start of the transfer)";
        104 => start_pos_y: Real = 0.0, Parameter, Fixed, "m", "Reference y before step_time";
        105 => start_pos_z: Real = 0.0, Parameter, Fixed, "m", "Reference z before step_time";
        106 => step_time: Real = 0.0, Parameter, Fixed, "s", "Time of the step / start of the transfer";
        107 => transfer_time: Real = 60.0, Parameter, Fixed, "s", "Duration of the polynomial transfer (profile 1)";
        120 => profile: Integer = 0, Parameter, Fixed, "", "0 = step to the set-point (paper 001), 1 = fifth-order polynomial transfer";
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

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct RelativePositionCommand {
    v: RelativePositionCommandVars,
}

impl Model for RelativePositionCommand {
    type Vars = RelativePositionCommandVars;
    const INFO: ModelInfo = ModelInfo {
        name: "RelativePositionCommand",
        description: "Relative-position reference: constant set-point step or smooth fifth-order polynomial transfer",
        source: "paper 001 (set-point 50, 40, 60 m); shared/spec controllers.md §2",
        equations_html: "<pre>profile 0:  pos_ref = start_pos for t &lt; step_time, target_pos after; vel_ref = acc_ref = 0\n\
profile 1:  tau = (t - step_time) / transfer_time clamped to [0, 1]\n\
            s = 10 tau^3 - 15 tau^4 + 6 tau^5\n\
            pos_ref = start_pos + (target_pos - start_pos) s\n\
            vel_ref = (target_pos - start_pos) ds/dtau / transfer_time\n\
            acc_ref = (target_pos - start_pos) d2s/dtau2 / transfer_time^2</pre>",
        feedthrough: Feedthrough::None,
        default_stop_time: 300.0,
        default_step: 0.001,
        variable_step: true,
    };

    fn vars(&self) -> &RelativePositionCommandVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut RelativePositionCommandVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &self.v;
        for (n, x) in [
            ("target_pos_x", v.target_pos_x),
            ("target_pos_y", v.target_pos_y),
            ("target_pos_z", v.target_pos_z),
            ("start_pos_x", v.start_pos_x),
            ("start_pos_y", v.start_pos_y),
            ("start_pos_z", v.start_pos_z),
            ("step_time", v.step_time),
        ] {
            check::finite(n, x)?;
        }
        check::choice("profile", v.profile, &[0, 1])?;
        if v.profile == 1 {
            check::positive("transfer_time", v.transfer_time)?;
        }
        Ok(())
    }

    fn update_outputs(&mut self, t: f64) -> ModelResult {
        let v = &mut self.v;
        let p0 = [v.start_pos_x, v.start_pos_y, v.start_pos_z];
        let p1 = [v.target_pos_x, v.target_pos_y, v.target_pos_z];
        let (s, ds, dds, tt) = match v.profile {
            0 => (if t >= v.step_time { 1.0 } else { 0.0 }, 0.0, 0.0, 1.0),
            _ => {
                let (s, ds, dds) = quintic((t - v.step_time) / v.transfer_time);
                (s, ds, dds, v.transfer_time)
            }
        };
        let pos: [f64; 3] = std::array::from_fn(|i| if s == 1.0 { p1[i] } else { p0[i] + (p1[i] - p0[i]) * s });
        let vel: [f64; 3] = std::array::from_fn(|i| (p1[i] - p0[i]) * ds / tt);
        let acc: [f64; 3] = std::array::from_fn(|i| (p1[i] - p0[i]) * dds / (tt * tt));
        [v.pos_ref_x, v.pos_ref_y, v.pos_ref_z] = pos;
        [v.vel_ref_x, v.vel_ref_y, v.vel_ref_z] = vel;
        [v.acc_ref_x, v.acc_ref_y, v.acc_ref_z] = acc;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _exp: &Experiment) -> ModelResult {
        Ok(()) // no state: outputs depend on time only
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outputs(c: &mut RelativePositionCommand, t: f64) -> [f64; 9] {
        c.update_outputs(t).unwrap();
        let v = &c.v;
        [v.pos_ref_x, v.pos_ref_y, v.pos_ref_z, v.vel_ref_x, v.vel_ref_y, v.vel_ref_z, v.acc_ref_x, v.acc_ref_y, v.acc_ref_z]
    }

    #[test]
    fn step_profile_is_the_paper_set_point() {
        let mut c = RelativePositionCommand::default();
        c.v.step_time = 1.0;
        c.initialize(&Experiment::default()).unwrap();
        assert_eq!(outputs(&mut c, 0.5), [0.0; 9]);
        assert_eq!(outputs(&mut c, 1.0), [50.0, 40.0, 60.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn quintic_transfer_is_consistent() {
        let mut c = RelativePositionCommand::default();
        c.v.profile = 1;
        c.v.step_time = 2.0;
        c.v.transfer_time = 40.0;
        c.v.start_pos_y = -10.0;
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
        let mut c = RelativePositionCommand::default();
        c.v.profile = 1;
        c.v.transfer_time = 0.0;
        assert!(c.initialize(&Experiment::default()).unwrap_err().contains("transfer_time"));
    }
}
