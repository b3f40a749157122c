//! `BDot`: the rate-free B-dot detumbling law on the magnetometer's field, sampled at its own rate:
//! a magnetic dipole opposing the (filtered) rate of change of the field direction in body axes.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::model::{ClockDecl, Experiment, Feedthrough, Model, ModelInfo, ModelResult, check_derived};
use crate::models::sensors::shared::{last_sample_before, sample_index, MAX_SAMPLES_PER_CALL};

declare_variables! {
    pub struct BDotVars {
        3 => b_meas: Vec3 = [0.0, 0.0, 1e-5], Input, "T", "Measured geomagnetic field, body axes (the Magnetometer's output)";
        20 => m_cmd: Vec3 = [0.0; 3], Output, "A.m2", "Commanded magnetic dipole, body axes (the plant's m_cmd input), held between samples";
        30 => b_dir_rate: Vec3 = [0.0; 3], Output, "1/s", "Filtered rate of change of the field direction b = B/|B| in body axes, held between samples";
        100 => sample_period: Real = 0.1, Parameter, "s", "Sample period T", Range(1e-6, 1e4);
        101 => gain: Real = 1.0, Parameter, "N.m.s", "Explicit gain k (gain_rule = 0)", NonNegative;
        102 => filter_time_constant: Real = 1.0, Parameter, "s", "Time constant tau of the first-order filter on the field-direction derivative (0 = unfiltered backward difference)", Range(0.0, 1e6);
        103 => dipole_max: Real = 1.0, Parameter, "A.m2", "Dipole limit m_max: the largest component of m is scaled down to it, keeping the direction (1e30 = no limit)", Limit;
        104 => orbit_rate: Real = 0.0010602064484506297, Parameter, "rad/s", "Orbital rate n for the gain rule (default: the plant's 700 km circular orbit)", Positive;
        105 => field_inclination: Real = 1.710_422_666_954_443, Parameter, "rad", "Inclination xi_m of the orbit to the geomagnetic equator for the gain rule (non-tilted dipole: the orbit inclination; default 98 deg)", Range(0.0, std::f64::consts::PI);
        106 => inertia_min: Real = 500.0, Parameter, "kg.m2", "Smallest principal moment of inertia J_min for the gain rule", Positive;
        120 => gain_rule: Integer = 1, Parameter, "", "0 = explicit gain; 1 = k = 2 n (1 + sin xi_m) J_min", Choice(&[0, 1]);
        200 => k: Real = 0.0, CalculatedParameter, "N.m.s", "Gain k in use";
    }
}

/// Derived from the parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Derived {
    period: f64,
    k: f64,
    /// Filter pole per sample, alpha = exp(-T / tau) (0 when tau = 0).
    alpha: f64,
    m_max: f64,
    /// Index of the first sample (the interval of the start time).
    k0: i64,
}

/// The law's memory between samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Memory {
    /// Index of the next sample to take.
    next: i64,
    /// Field direction of the last sample (None before the first).
    b_prev: Option<[f64; 3]>,
    /// Filtered direction rate and dipole of the last sample (held output).
    rate: [f64; 3],
    m: [f64; 3],
}

#[derive(Clone, Serialize, Deserialize)]
pub struct BDot {
    d: Derived,
    mem: Memory,
}

impl BDot {
    /// Sample with field `b`: the memory after it (the dipole and rate it outputs inside).
    fn sample(&self, mem: &Memory, b: &Vector3<f64>) -> Result<Memory, String> {
        let d = &self.d;
        let norm = b.norm();
        if !(norm.is_finite() && norm >= 1e-15) {
            return Err(format!(
                "input b_meas = [{}, {}, {}] T has no direction (zero or not finite; is it connected?)",
                b.x, b.y, b.z
            ));
        }
        let u = b / norm;
        let (rate, m) = match mem.b_prev {
            None => (Vector3::zeros(), Vector3::zeros()),
            Some(p) => {
                let raw = (u - Vector3::from(p)) / d.period;
                let rate = Vector3::from(mem.rate) * d.alpha + raw * (1.0 - d.alpha);
                let m = -rate * (d.k / norm);
                let peak = m.amax();
                (rate, if peak > d.m_max { m * (d.m_max / peak) } else { m })
            }
        };
        Ok(Memory { next: mem.next + 1, b_prev: Some([u.x, u.y, u.z]), rate: rate.into(), m: m.into() })
    }
}

impl Model for BDot {
    type Vars = BDotVars;
    const CLOCKS: &'static [ClockDecl] = &[
        ClockDecl {
            name: "sample_clock",
            description: "Sample clock: at each tick the dipole command and the field-direction rate are computed and held",
            interval: "sample_period",
            shift: "",
            steps: true,
            outputs: &["m_cmd", "b_dir_rate"],
        },
    ];
    fn time_grid(v: &BDotVars) -> Option<f64> {
        Some(v.sample_period)
    }
    const EVOLVING: &'static [&'static str] = &["mem"];
    const INFO: ModelInfo = ModelInfo {
        name: "BDot",
        description: "B-dot detumbling law: magnetic dipole opposing the filtered rate of change of the measured field direction, gain from the orbit rate and the inertia, saturated, sampled at its own rate",
        source: "B-dot law with the normalised field direction and the gain rule of [Avanzini-Giulietti-2012]; filtered derivative and saturation project choice",
        equations_html: concat!("<pre>samples at t_k = k T (inputs held over a communication step), output held until the next sample:\n\
b_k     = B_k / |B_k|                                   (B_k = b_meas at t_k)\n\
d_k     = (b_k - b_k-1) / T                             (backward difference; d = 0 at the first sample)\n\
r_k     = alpha r_k-1 + (1 - alpha) d_k,   alpha = exp(-T / tau)   (first-order filter; tau = 0: r_k = d_k)\n\
m_k     = -(k / |B_k|) r_k,  scaled by m_max / max_i |m_k,i| when that exceeds 1 (direction kept)\n\
gain_rule 1: k = 2 n (1 + sin xi_m) J_min</pre>\n\
<p>For a body turning at rate w much faster than the orbit the field direction in body axes moves as \
db/dt = -w x b, so m = (k/|B|) w x b and the torque m x B = -k (I - b b^T) w removes every rate \
component perpendicular to the field: the kinetic energy decreases monotonically. The field rotates \
twice per orbit in the orbit-averaged picture, so every body axis is perpendicular to it part of the \
time and the whole rate decays. The gain rule places the slowest averaged decay rate of the closed \
loop near its optimum for an orbit at inclination xi_m to the geomagnetic equator (for a non-tilted \
dipole, the orbit inclination). The saturation scales the whole dipole so its largest coil stays \
within m_max; the law stays dissipative. Use a communication step no longer than T: samples inside one \
step see the same held input.</p>", crate::sample_grid_note!()),
        feedthrough: Feedthrough::AllInputs,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut BDotVars, exp: &Experiment) -> Result<Self, String> {
        v.k = if v.gain_rule == 1 { 2.0 * v.orbit_rate * (1.0 + v.field_inclination.sin()) * v.inertia_min } else { v.gain };
        let alpha = if v.filter_time_constant > 0.0 { (-v.sample_period / v.filter_time_constant).exp() } else { 0.0 };
        let k0 = sample_index(exp.start_time, v.sample_period)?;
        let d = Derived { period: v.sample_period, k: v.k, alpha, m_max: v.dipole_max, k0 };
        Ok(BDot { d, mem: Memory { next: k0, b_prev: None, rate: [0.0; 3], m: [0.0; 3] } })
    }

    fn outputs(&self, v: &mut BDotVars, t: f64) -> ModelResult {
        // a sample due at t and not taken yet is computed from the current input (not latched)
        let due = sample_index(t, self.d.period)? >= self.mem.next;
        let mem = if due { self.sample(&self.mem, &v.b_meas)? } else { self.mem.clone() };
        v.m_cmd = Vector3::from(mem.m);
        v.b_dir_rate = Vector3::from(mem.rate);
        Ok(())
    }

    fn step(&mut self, v: &BDotVars, t: f64, h: f64) -> ModelResult {
        let k_end = last_sample_before(t + h, self.d.period)?;
        let n = k_end.checked_sub(self.mem.next).ok_or("sample count overflows")?;
        if n >= MAX_SAMPLES_PER_CALL {
            return Err(format!(
                "a step to t = {} takes {} samples of period {} s (at most {MAX_SAMPLES_PER_CALL} per step)",
                t + h,
                n + 1,
                self.d.period
            ));
        }
        let mut mem = self.mem.clone();
        while mem.next <= k_end {
            mem = self.sample(&mem, &v.b_meas)?;
        }
        self.mem = mem;
        Ok(())
    }

    fn validate(&self, fresh: &Self) -> ModelResult {
        check_derived("derived parameters", &self.d, &fresh.d)?;
        if self.mem.next < self.d.k0 {
            return Err(format!("restored state: next sample index {} before the first {}", self.mem.next, self.d.k0));
        }
        if let Some(p) = self.mem.b_prev {
            if (Vector3::from(p).norm() - 1.0).abs() > 1e-9 {
                return Err("restored state: the last field direction is not a unit vector".into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    fn unit(rule: i32, tau: f64) -> Fmu<BDot> {
        let mut f = Fmu::<BDot>::default();
        (f.v.gain_rule, f.v.gain, f.v.filter_time_constant, f.v.dipole_max) = (rule, 2.0, tau, 1e30);
        f.initialize(&Experiment::default()).unwrap();
        f
    }

    #[test]
    fn gain_rule_and_the_dipole_of_a_turning_field() {
        let f = unit(1, 0.0);
        let want = 2.0 * 0.0010602064484506297 * (1.0 + 1.710_422_666_954_443_f64.sin()) * 500.0;
        assert!((f.v.k - want).abs() < 1e-15, "{}", f.v.k);
        // field of 3e-5 T turning about body z at w = 0.01 rad/s (the body turns at -w): unfiltered,
        // the sampled derivative is the chord (b_1 - b_0)/T, m = -(k/|B|) (b_1 - b_0)/T
        let mut f = unit(0, 0.0);
        let (w, t, b0) = (0.01, 0.1, 3e-5);
        let field = |tt: f64| Vector3::new((w * tt).cos(), (w * tt).sin(), 0.0) * b0;
        let mut out = vec![];
        for n in 0..5 {
            let tt = n as f64 * t;
            f.v.b_meas = field(tt);
            f.outputs(tt).unwrap();
            out.push(f.v.m_cmd);
            f.step(tt, t).unwrap();
        }
        assert_eq!(out[0], Vector3::zeros());
        let chord = (field(0.2) - field(0.1)) / b0 / t;
        let want = -chord * (2.0 / b0);
        assert!((out[2] - want).norm() < 1e-12 * want.norm(), "{} vs {}", out[2], want);
        // m is perpendicular to B and along -(db/dt): the torque m x B opposes the body's rotation
        // (body turns about -z relative to the field, torque along +z)
        let torque = out[3].cross(&field(0.3));
        assert!(torque.z > 0.0 && torque.x.abs() < 1e-12 * torque.z, "{torque}");
    }

    #[test]
    fn filter_saturation_and_refusals() {
        // a field direction that jumps once: the filtered rate decays by alpha per sample
        let mut f = unit(0, 0.5);
        let alpha = (-0.2f64).exp();
        let mut rates = vec![];
        for n in 0..6 {
            let tt = n as f64 * 0.1;
            f.v.b_meas = if n < 2 { Vector3::new(1e-5, 0.0, 0.0) } else { Vector3::new(0.0, 1e-5, 0.0) };
            f.outputs(tt).unwrap();
            rates.push(f.v.b_dir_rate);
            f.step(tt, 0.1).unwrap();
        }
        assert!((rates[2].y - (1.0 - alpha) * 10.0).abs() < 1e-12, "{}", rates[2]);
        assert!((rates[4].y - alpha * alpha * rates[2].y).abs() < 1e-12);
        // saturation keeps the direction
        let mut g = Fmu::<BDot>::default();
        (g.v.gain_rule, g.v.gain, g.v.filter_time_constant, g.v.dipole_max) = (0, 100.0, 0.0, 0.5);
        g.initialize(&Experiment::default()).unwrap();
        g.v.b_meas = Vector3::new(1e-5, 0.0, 0.0);
        g.step(0.0, 0.1).unwrap();
        g.v.b_meas = Vector3::new(1e-5, 2e-6, -1e-6);
        g.outputs(0.1).unwrap();
        assert!((g.v.m_cmd.amax() - 0.5).abs() < 1e-15 && (g.v.m_cmd.y / g.v.m_cmd.z + 2.0).abs() < 1e-2, "{}", g.v.m_cmd);
        g.v.b_meas = Vector3::zeros();
        let e = g.outputs(0.1).unwrap_err();
        assert!(e.contains("b_meas") && e.contains("no direction"), "{e}");
    }
}
