//! `AttitudeCommand`: a constant 321 attitude command applied as a step.

use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::quat_from_euler321;
use crate::model::{Experiment, Model, ModelInfo, ModelResult};
use nalgebra::Vector3;

declare_variables! {
    pub struct AttitudeCommandVars {
        10 => q_ref: Quat = [1.0, 0.0, 0.0, 0.0], Output, "", "Commanded attitude quaternion";
        14 => w_ref: Vec3 = [0.0; 3], Output, "rad/s", "Commanded body rate (0: constant command)";
        17 => roll_ref: Real = 0.0, Output, "rad", "Commanded roll (321)";
        18 => pitch_ref: Real = 0.0, Output, "rad", "Commanded pitch (321)";
        19 => yaw_ref: Real = 0.0, Output, "rad", "Commanded yaw (321)";
        100 => ref_euler321_roll: Real = 0.0, Parameter, "rad", "Commanded roll of the 321 sequence after step_time";
        101 => ref_euler321_pitch: Real = 0.0, Parameter, "rad", "Commanded pitch of the 321 sequence after step_time";
        102 => ref_euler321_yaw: Real = 0.0, Parameter, "rad", "Commanded yaw of the 321 sequence after step_time";
        103 => step_time: Real = 0.0, Parameter, "s", "Time of the step; identity before it";
    }
}

/// No state: the outputs are a function of time and the parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct AttitudeCommand;

impl Model for AttitudeCommand {
    type Vars = AttitudeCommandVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a static law: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "AttitudeCommand",
        description: "Attitude reference: a constant 321 Euler-angle command applied as a step",
        source: "command of the large- and small-angle slews ([Navabi-2019], [T2FSMC-LEO])",
        equations_html: "<pre>t &lt; step_time:  q_ref = (1, 0, 0, 0), angles 0\n\
t &gt;= step_time: q_ref = q321(roll, pitch, yaw) = q_z(yaw) (x) q_y(pitch) (x) q_x(roll)\n\
w_ref = 0</pre>",
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut AttitudeCommandVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(AttitudeCommand)
    }

    fn outputs(&self, v: &mut AttitudeCommandVars, t: f64) -> ModelResult {
        let (r, p, y) = if t >= v.step_time { (v.ref_euler321_roll, v.ref_euler321_pitch, v.ref_euler321_yaw) } else { (0.0, 0.0, 0.0) };
        v.q_ref = quat_from_euler321(r, p, y);
        (v.roll_ref, v.pitch_ref, v.yaw_ref) = (r, p, y);
        v.w_ref = Vector3::zeros();
        Ok(())
    }

    /// Model Exchange: the step is a time event.
    fn next_time_event(&self, v: &AttitudeCommandVars, t: f64) -> Option<f64> {
        (v.step_time > t).then_some(v.step_time)
    }
}
