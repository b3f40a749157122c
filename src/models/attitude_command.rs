//! `AttitudeCommand`: constant 321 attitude command applied as a step (spec controllers.md §0).

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{quat_from_euler321, wxyz};
use crate::model::{check, Experiment, Feedthrough, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct AttitudeCommandVars {
        10 => q_ref_w: Real = 1.0, Output, Continuous, "", "Commanded attitude quaternion, scalar part";
        11 => q_ref_x: Real = 0.0, Output, Continuous, "", "Commanded attitude quaternion, x component";
        12 => q_ref_y: Real = 0.0, Output, Continuous, "", "Commanded attitude quaternion, y component";
        13 => q_ref_z: Real = 0.0, Output, Continuous, "", "Commanded attitude quaternion, z component";
        14 => w_ref_x: Real = 0.0, Output, Continuous, "rad/s", "Commanded body rate x (0: constant command)";
        15 => w_ref_y: Real = 0.0, Output, Continuous, "rad/s", "Commanded body rate y (0: constant command)";
        16 => w_ref_z: Real = 0.0, Output, Continuous, "rad/s", "Commanded body rate z (0: constant command)";
        17 => roll_ref: Real = 0.0, Output, Continuous, "rad", "Commanded roll (321)";
        18 => pitch_ref: Real = 0.0, Output, Continuous, "rad", "Commanded pitch (321)";
        19 => yaw_ref: Real = 0.0, Output, Continuous, "rad", "Commanded yaw (321)";
        100 => ref_euler321_roll: Real = 0.0, Parameter, Fixed, "rad", "Commanded roll of the 321 sequence after step_time";
        101 => ref_euler321_pitch: Real = 0.0, Parameter, Fixed, "rad", "Commanded pitch of the 321 sequence after step_time";
        102 => ref_euler321_yaw: Real = 0.0, Parameter, Fixed, "rad", "Commanded yaw of the 321 sequence after step_time";
        103 => step_time: Real = 0.0, Parameter, Fixed, "s", "Time of the step; identity before it";
    }
}

#[derive(Clone, Default, Serialize, Deserialize)]
pub struct AttitudeCommand {
    v: AttitudeCommandVars,
}

impl Model for AttitudeCommand {
    type Vars = AttitudeCommandVars;
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudeCommand",
        description: "Attitude reference: a constant 321 Euler-angle command applied as a step",
        source: "shared/spec controllers.md §0 (commands of papers 000, 003)",
        equations_html: "<pre>t &lt; step_time:  q_ref = (1, 0, 0, 0), angles 0\n\
t &gt;= step_time: q_ref = q321(roll, pitch, yaw) = q_z(yaw) (x) q_y(pitch) (x) q_x(roll)\n\
w_ref = 0</pre>",
        feedthrough: Feedthrough::None,
        default_stop_time: 30.0,
        default_step: 0.01,
        variable_step: true,
    };

    fn vars(&self) -> &AttitudeCommandVars {
        &self.v
    }
    fn vars_mut(&mut self) -> &mut AttitudeCommandVars {
        &mut self.v
    }

    fn initialize(&mut self, _exp: &Experiment) -> ModelResult {
        let v = &self.v;
        check::finite("ref_euler321_roll", v.ref_euler321_roll)?;
        check::finite("ref_euler321_pitch", v.ref_euler321_pitch)?;
        check::finite("ref_euler321_yaw", v.ref_euler321_yaw)?;
        check::finite("step_time", v.step_time)?;
        Ok(())
    }

    fn update_outputs(&mut self, t: f64) -> ModelResult {
        let v = &mut self.v;
        let (r, p, y) = if t >= v.step_time { (v.ref_euler321_roll, v.ref_euler321_pitch, v.ref_euler321_yaw) } else { (0.0, 0.0, 0.0) };
        [v.q_ref_w, v.q_ref_x, v.q_ref_y, v.q_ref_z] = wxyz(&quat_from_euler321(r, p, y));
        (v.roll_ref, v.pitch_ref, v.yaw_ref) = (r, p, y);
        (v.w_ref_x, v.w_ref_y, v.w_ref_z) = (0.0, 0.0, 0.0);
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _exp: &Experiment) -> ModelResult {
        Ok(()) // no state: outputs depend on time only
    }
}
