//! The model-reference adaptive core of paper 000 (Slotine & Li's adaptive law per axis with a
//! reference model) and the variable block of every MRAC-type controller. `MracController` uses it
//! with fixed reference-model gains, `AdaptiveFuzzyController` with fuzzy-scheduled ones.

use nalgebra::{Matrix3, Quaternion, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::declare_variables;
use crate::math::attitude::{euler321_from_quat, skew};
use crate::math::fuzzy::PdFuzzySystem;
use crate::math::integrate::rk4;
use crate::model::ParamEnum;
use crate::models::ports::{check_unit_quaternions, AttitudeControllerPorts};

declare_variables! {
    /// Ports and parameters every MRAC-type controller has, besides the common controller ports:
    /// reference-model state, tracking error, inertia estimate, sliding variable and controlled
    /// coordinate (outputs 30–44); nominal inertia, initial estimate and its bound, λ, γ, coordinates
    /// (parameters 100–110, 120); the estimate's start and bound in use (calculated 200–205).
    pub struct MracVariables {
        30 => xm: Vec3 = [0.0; 3], Output, "", "Reference-model state x_m (coordinates 0: 2 q_v units; 1: rad)";
        33 => track_err: Vec3 = [0.0; 3], Output, "", "Tracking error x - x_m";
        36 => ihat: Vec3 = [0.0; 3], Output, "kg.m2", "Inertia estimate I^";
        39 => s: Vec3 = [0.0; 3], Output, "1/s", "Sliding variable s = x~' + lambda x~";
        42 => x: Vec3 = [0.0; 3], Output, "", "Controlled coordinate x (coordinates 0: 2 q_v; 1: 321 angle)";
        100 => inertia: Diag3 = [1000.0, 500.0, 700.0], Parameter, "kg.m2", "Controller's nominal inertia", Positive;
        103 => ihat0: Vec3 = [0.0; 3], Parameter, "kg.m2", "Initial estimate I^(0); 0 = the nominal inertia", NonNegative;
        106 => ihat_min_ratio: Real = 0.1, Parameter, "", "Lower bound of the estimate: I^_min = ihat_min_ratio * I^(0)", Range(0.0, 1.0);
        109 => lambda: Real = 2.0, Parameter, "1/s", "Sliding-surface bandwidth lambda ([Navabi-2019] Eqs. 38-39)", Positive;
        110 => gamma: Real = 1000.0, Parameter, "kg.m2.s2", "Adaptation gain gamma (project choice)", NonNegative;
        120 => coordinates: Integer = 0, Parameter, "", "0 = quaternion feedback linearisation; 1 = linear (321 angles, T = I^ v)", Choice(MracCoordinates::CODES);
        200 => ihat_init: Vec3 = [0.0; 3], CalculatedParameter, "kg.m2", "I^(0) in use";
        203 => ihat_min: Vec3 = [0.0; 3], CalculatedParameter, "kg.m2", "Lower bound I^_min";
    }
}

/// The adaptive loop of an MRAC-type controller: its law and its state, with what the FMU does with
/// them (outputs, step, restored-state check), so `MracController` and `AdaptiveFuzzyController`
/// differ only in their reference-model gains.
#[derive(Clone, Serialize, Deserialize)]
pub struct Mrac {
    pub core: MracCore,
    pub st: MracState,
}

impl Mrac {
    /// The loop for the given reference-model gains; writes the calculated parameters.
    pub fn new(vars: &mut MracVariables, gains: ReferenceGains) -> Result<Self, String> {
        let (core, st) = vars.core(gains)?;
        Ok(Mrac { core, st })
    }

    /// Writes the torque and the common MRAC outputs; returns the signals for model-specific outputs.
    pub fn outputs(
        &self,
        ports: &mut AttitudeControllerPorts,
        vars: &mut MracVariables,
    ) -> Result<MracOutputs, String> {
        let o = mrac_outputs(&self.core, &self.st, ports)?;
        ports.torque_cmd = o.torque;
        vars.set_outputs(&o);
        Ok(o)
    }

    pub fn step(&mut self, ports: &AttitudeControllerPorts, h: f64) -> Result<(), String> {
        self.st = self.core.advance(&self.st, ports, h)?;
        Ok(())
    }

    /// A restored loop: the law as the parameters give it, a finite state above the estimate's bound.
    pub fn validate(&self, fresh: &Mrac) -> Result<(), String> {
        crate::model::check_derived("adaptive law", &self.core, &fresh.core)?;
        self.st.validate(&self.core)
    }
}

impl MracState {
    /// Invariants of a restored state: finite, estimate not below its bound.
    pub fn validate(&self, core: &MracCore) -> Result<(), String> {
        crate::model::check_finite_state(
            "reference model and inertia estimate",
            self.xm.iter().chain(&self.xm_dot).chain(&self.ihat),
        )?;
        if self.ihat.iter().zip(&core.ihat_min).any(|(i, m)| i < m) {
            return Err(format!(
                "restored state: inertia estimate {:?} is below its bound {:?}",
                self.ihat, core.ihat_min
            ));
        }
        Ok(())
    }
}

impl MracVariables {
    /// The adaptive core for the given reference-model gains, and its initial state; writes the
    /// calculated parameters.
    pub fn core(&mut self, gains: ReferenceGains) -> Result<(MracCore, MracState), String> {
        let coordinates = MracCoordinates::from_param("coordinates", self.coordinates)?;
        // I^(0) = ihat0 where given, else the nominal inertia
        let i0 = self.ihat0.zip_map(
            &self.inertia,
            |given, nominal| if given == 0.0 { nominal } else { given },
        );
        let imin = i0 * self.ihat_min_ratio;
        self.ihat_init = i0;
        self.ihat_min = imin;
        let core = MracCore {
            coordinates,
            lambda: self.lambda,
            gamma: self.gamma,
            ihat_min: imin.into(),
            gains,
        };
        Ok((
            core,
            MracState {
                xm: [0.0; 3],
                xm_dot: [0.0; 3],
                ihat: i0.into(),
                started: false,
            },
        ))
    }

    /// Writes the common MRAC outputs.
    pub fn set_outputs(&mut self, o: &MracOutputs) {
        self.xm = o.state.xm.into();
        self.track_err = o.sig.xt;
        self.ihat = o.state.ihat.into();
        self.s = o.sig.s;
        self.x = o.x;
    }
}

crate::param_enum! {
    /// `coordinates` parameter: which x, r and torque law the adaptive loop uses.
    pub enum MracCoordinates {
        /// 0: x = 2 q̄_v, ẋ = M(q̄) ω, torque by quaternion feedback linearisation.
        Quaternion = 0,
        /// 1: x = euler321(q), ẋ = ω, T = Î ⊙ v (for the linear small-angle plant).
        Linear = 1,
    }
}

/// Reference-model gains: fixed (MRAC) or fuzzy-scheduled per axis (adaptive fuzzy).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ReferenceGains {
    Fixed {
        lambda1: f64,
        lambda2: f64,
    },
    Fuzzy {
        fuzzy: PdFuzzySystem,
        lambda1_min: f64,
        lambda1_max: f64,
        lambda2_min: f64,
        lambda2_max: f64,
        e_scale: f64,
        edot_scale: f64,
    },
}

impl ReferenceGains {
    /// (λ1, λ2) of one axis for the model's error e_m = r − x_m and ė_m = −ẋ_m.
    pub fn axis(&self, e_m: f64, edot_m: f64) -> (f64, f64) {
        match *self {
            ReferenceGains::Fixed { lambda1, lambda2 } => (lambda1, lambda2),
            ReferenceGains::Fuzzy {
                fuzzy,
                lambda1_min,
                lambda1_max,
                lambda2_min,
                lambda2_max,
                e_scale,
                edot_scale,
            } => {
                let (kp, kd) = fuzzy.infer(e_m / e_scale, edot_m / edot_scale);
                (
                    lambda1_min + (lambda1_max - lambda1_min) * kd,
                    lambda2_min + (lambda2_max - lambda2_min) * kp,
                )
            }
        }
    }
}

/// Controlled coordinates measured from the common inputs.
#[derive(Clone, Copy, Debug)]
pub struct Measured {
    pub x: Vector3<f64>,
    pub xdot: Vector3<f64>,
    pub r: Vector3<f64>,
    /// q with the sign making q̄_w ≥ 0 (coordinates 0)
    pub qbar: Quaternion<f64>,
    pub w: Vector3<f64>,
}

/// M(q) = q_w I3 + [q_v×].
pub fn m_matrix(q: &Quaternion<f64>) -> Matrix3<f64> {
    Matrix3::identity() * q.w + skew(&q.vector().into_owned())
}

fn short_way(q: Quaternion<f64>) -> Quaternion<f64> {
    if q.w < 0.0 {
        -q
    } else {
        q
    }
}

/// Adaptive state: reference model x_m, ẋ_m and the inertia estimate Î (per axis).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MracState {
    pub xm: [f64; 3],
    pub xm_dot: [f64; 3],
    pub ihat: [f64; 3],
    /// false until the first doStep: x_m(0) = x(0), ẋ_m(0) = 0 are taken from the inputs at t0.
    pub started: bool,
}

/// Signals of the adaptive loop at one instant.
#[derive(Clone, Copy, Debug)]
pub struct Signals {
    pub lambda1: Vector3<f64>,
    pub lambda2: Vector3<f64>,
    pub xm_ddot: Vector3<f64>,
    /// x̃ = x − x_m
    pub xt: Vector3<f64>,
    /// s = x̃' + λ x̃
    pub s: Vector3<f64>,
    /// v = ẍ_m − 2λ x̃' − λ² x̃
    pub v: Vector3<f64>,
}

/// The Slotine–Li adaptive law per axis with a reference model ([Navabi-2019] Eqs. 37-43).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MracCore {
    pub coordinates: MracCoordinates,
    pub lambda: f64,
    pub gamma: f64,
    pub ihat_min: [f64; 3],
    pub gains: ReferenceGains,
}

impl MracCore {
    pub fn measure(&self, inp: &AttitudeControllerPorts) -> Measured {
        match self.coordinates {
            MracCoordinates::Quaternion => {
                let qbar = short_way(inp.q);
                let qr = short_way(inp.q_ref);
                let x = qbar.vector().into_owned() * 2.0;
                Measured {
                    x,
                    xdot: m_matrix(&qbar) * inp.w,
                    r: qr.vector().into_owned() * 2.0,
                    qbar,
                    w: inp.w,
                }
            }
            MracCoordinates::Linear => {
                let x = Vector3::from(euler321_from_quat(&inp.q));
                let r = Vector3::from(euler321_from_quat(&inp.q_ref));
                Measured {
                    x,
                    xdot: inp.w,
                    r,
                    qbar: inp.q,
                    w: inp.w,
                }
            }
        }
    }

    /// State actually in use: before the first step, x_m = x and ẋ_m = 0 (without storing them).
    pub fn effective(&self, st: &MracState, m: &Measured) -> MracState {
        if st.started {
            *st
        } else {
            MracState {
                xm: m.x.into(),
                xm_dot: [0.0; 3],
                ihat: st.ihat,
                started: true,
            }
        }
    }

    pub fn signals(&self, m: &Measured, xm: &Vector3<f64>, xm_dot: &Vector3<f64>) -> Signals {
        let mut l1 = Vector3::zeros();
        let mut l2 = Vector3::zeros();
        for i in 0..3 {
            (l1[i], l2[i]) = self.gains.axis(m.r[i] - xm[i], -xm_dot[i]);
        }
        let xm_ddot = l2.component_mul(&(m.r - xm)) - l1.component_mul(xm_dot);
        let xt = m.x - xm;
        let xtd = m.xdot - xm_dot;
        let lam = self.lambda;
        let v = xm_ddot - xtd * (2.0 * lam) - xt * (lam * lam);
        let s = xtd + xt * lam;
        Signals {
            lambda1: l1,
            lambda2: l2,
            xm_ddot,
            xt,
            s,
            v,
        }
    }

    /// Torque for the current inputs and state.
    pub fn torque(&self, m: &Measured, sig: &Signals, ihat: &Vector3<f64>) -> Result<Vector3<f64>, String> {
        match self.coordinates {
            MracCoordinates::Quaternion => {
                let q = m.qbar;
                if q.w < 1e-9 {
                    return Err(format!(
                        "MRAC quaternion coordinates are singular at q_w = {} (180 deg attitude)",
                        q.w
                    ));
                }
                let qv = q.vector().into_owned();
                let m_inv = Matrix3::identity() * q.w - skew(&qv) + qv * qv.transpose() / q.w;
                let b = m_inv * (sig.v + m.x * (0.25 * m.w.norm_squared()));
                Ok(m.w.cross(&ihat.component_mul(&m.w)) + ihat.component_mul(&b))
            }
            MracCoordinates::Linear => Ok(ihat.component_mul(&sig.v)),
        }
    }

    /// d/dt of [x_m, ẋ_m, Î] with the measurement held; Î is projected at Î_min.
    pub(super) fn derivative(&self, m: &Measured, y: &SVector<f64, 9>) -> SVector<f64, 9> {
        let xm = Vector3::new(y[0], y[1], y[2]);
        let xmd = Vector3::new(y[3], y[4], y[5]);
        let sig = self.signals(m, &xm, &xmd);
        let mut d = SVector::<f64, 9>::zeros();
        for i in 0..3 {
            d[i] = xmd[i];
            d[3 + i] = sig.xm_ddot[i];
            let idot = -self.gamma * sig.v[i] * sig.s[i];
            d[6 + i] = if y[6 + i] <= self.ihat_min[i] && idot < 0.0 {
                0.0
            } else {
                idot
            };
        }
        d
    }

    /// Advances the state over h with the inputs held: RK4 in ⌈h / MAX_STEP⌉ equal steps, Î clamped
    /// at Î_min after each.
    pub fn advance(&self, st: &MracState, inp: &AttitudeControllerPorts, h: f64) -> Result<MracState, String> {
        check_unit_quaternions(inp)?;
        self.step(st, &self.measure(inp), h)
    }

    pub fn step(&self, st: &MracState, m: &Measured, h: f64) -> Result<MracState, String> {
        let e = self.effective(st, m);
        let mut y = SVector::<f64, 9>::from_iterator(e.xm.iter().chain(e.xm_dot.iter()).chain(e.ihat.iter()).copied());
        let mut f = |_t: f64, y: &SVector<f64, 9>| self.derivative(m, y);
        crate::math::integrate::check_step_count(h, Self::MAX_STEP)?;
        let n = (h / Self::MAX_STEP - 1e-9).ceil().max(1.0) as usize;
        let dt = h / n as f64;
        for k in 0..n {
            y = rk4(&mut f, k as f64 * dt, &y, dt);
            for i in 0..3 {
                y[6 + i] = y[6 + i].max(self.ihat_min[i]);
            }
        }
        if !y.iter().all(|v| v.is_finite()) {
            return Err("MRAC state became non-finite (check gamma, lambda and the inputs)".into());
        }
        Ok(MracState {
            xm: [y[0], y[1], y[2]],
            xm_dot: [y[3], y[4], y[5]],
            ihat: [y[6], y[7], y[8]],
            started: true,
        })
    }

    /// Largest internal RK4 step of the adaptive state (project choice).
    pub const MAX_STEP: f64 = 0.01;
}

/// Values written to the diagnostic outputs.
pub struct MracOutputs {
    pub torque: Vector3<f64>,
    pub state: MracState,
    pub sig: Signals,
    pub x: Vector3<f64>,
}

/// Torque and diagnostics for the current inputs (no state change).
pub fn mrac_outputs(core: &MracCore, st: &MracState, inp: &AttitudeControllerPorts) -> Result<MracOutputs, String> {
    check_unit_quaternions(inp)?;
    let m = core.measure(inp);
    let e = core.effective(st, &m);
    let sig = core.signals(&m, &Vector3::from(e.xm), &Vector3::from(e.xm_dot));
    let torque = core.torque(&m, &sig, &Vector3::from(e.ihat))?;
    Ok(MracOutputs {
        torque,
        state: e,
        sig,
        x: m.x,
    })
}

/// HTML of the adaptive law shared by both MRAC-type models.
pub const EQUATIONS_HTML: &str = "<pre>reference model  x_m'' = lambda2 (r - x_m) - lambda1 x_m'\n\
x~ = x - x_m,  v = x_m'' - 2 lambda x~' - lambda^2 x~,  s = x~' + lambda x~\n\
dI^_i/dt = -gamma v_i s_i,  I^_i >= I^_min,i\n\
coordinates 0: q^ = q with q^_w >= 0, x = 2 q^_v, x' = M(q^) w, r = 2 q^_ref,v, M(q) = q_w I3 + [q_v x]\n\
               T = w x (I^ . w) + I^ . M^-1 (v + |w|^2 x / 4)\n\
coordinates 1: x = euler321(q), x' = w, r = euler321(q_ref), T = I^ . v</pre>\n\
<p>x_m, x_m', I^ advance in doStep by RK4 (steps of at most 0.01 s) with the inputs held. x_m(0) = x and x_m'(0) = 0 at the \
first communication point; I^(0) = ihat0 (0 = nominal inertia), I^_min = ihat_min_ratio I^(0).</p>\n\
<p>Model Exchange: x_m, x_m' and I^ are the continuous states state_xm_*, state_xm_dot_*, state_ihat_*; they start at the \
inputs present at the end of initialization (x_m(0) = x). dI^_i/dt is 0 while I^_i sits at its bound and the law pushes it \
down; after a solver step that left I^_i below the bound, an event clamps it (the projection the Co-Simulation step makes \
after every internal step).</p>";

#[cfg(test)]
#[path = "mrac_tests.rs"]
mod tests;
