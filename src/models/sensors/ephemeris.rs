//! `Ephemeris`: the flight computer's on-board models of the reference directions — the sun direction and
//! the geomagnetic field in the reference frame R at the spacecraft's position — that an estimator pairs
//! with the sun sensor's and the magnetometer's body-frame measurements. It evaluates exactly the
//! environment the plant and the sensors use (same orbit parameters and value references 160–165), so a
//! noise-free sensor and this unit agree to rounding; also the sunlight flag of the sun sensor's shadow.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::shared::{OrbitParams, SunParams};
use crate::declare_variables;
use crate::math::environment::{in_eclipse, sun_ref};
use crate::model::{Experiment, Model, ModelInfo, ModelResult};

declare_variables! {
    pub struct EphemerisVars {
        orbit: OrbitParams;
        sun: SunParams;
        20 => sun_ref: Vec3 = [1.0, 0.0, 0.0], Output, "", "Unit sun direction in the reference frame R";
        23 => b_ref: Vec3 = [0.0, 0.0, 1.0], Output, "T", "Geomagnetic (dipole) field in the reference frame R at the spacecraft";
        26 => lit: Real = 1.0, Output, "", "1 = spacecraft in sunlight, 0 = in the Earth's cylindrical shadow";
    }
}

/// No state: the outputs are functions of time and the parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct Ephemeris;

impl Model for Ephemeris {
    type Vars = EphemerisVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a law of time: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Ephemeris",
        description: "On-board reference directions for attitude estimation: sun direction and dipole field in R at the spacecraft, and the sunlight flag",
        source: "the environment of the plant and the sensors ([Markley-Crassidis-2014] Sec. 4.5 dipole field; circular apparent solar orbit; project choice)",
        equations_html: "<pre>sun_ref(t) = [cos l, sin l cos e, sin l sin e],   l = l_0 + n_sun t,  e = obliquity\n\
b_ref(t)   = (M_E / r^3) [z - 3 (z . r_hat) r_hat],   r_hat(t) = [cos u, sin u cos i, sin u sin i],  u = u_0 + n t\n\
lit        = 0 when r_hat . sun_ref &lt; 0 and r |r_hat x sun_ref| &lt; R_E (cylindrical shadow), else 1\n\
(the plant's and the sensors' environment: same parameters and value references 160-165)</pre>",
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut EphemerisVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(Ephemeris)
    }

    fn outputs(&self, v: &mut EphemerisVars, t: f64) -> ModelResult {
        let orbit = v.orbit.orbit();
        let s: Vector3<f64> = sun_ref(v.sun.sun_ecliptic_longitude, t);
        v.sun_ref = s;
        v.b_ref = orbit.field_ref(t);
        v.lit = if in_eclipse(&orbit.r_hat(t), orbit.radius, &s) { 0.0 } else { 1.0 };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Fmu;

    #[test]
    fn closed_form_directions_and_shadow() {
        let mut e = Fmu::<Ephemeris>::default();
        e.v.orbit.orbit_inclination = 0.0;
        e.initialize(&Experiment::default()).unwrap();
        // t = 0: equinox sun along x; equatorial orbit at u = 0 (r_hat = x): field (M_E / r^3) z, sunlit
        e.outputs(0.0).unwrap();
        assert!((e.v.sun_ref - Vector3::x()).norm() < 1e-15, "{}", e.v.sun_ref);
        let b0 = 7.96e15 / 7078137f64.powi(3);
        assert!((e.v.b_ref - Vector3::new(0.0, 0.0, b0)).norm() < 1e-20, "{}", e.v.b_ref);
        assert_eq!(e.v.lit, 1.0);
        // half an orbit later the spacecraft is behind the Earth (r_hat = -x): in shadow
        let half = std::f64::consts::PI / (3.986004418e14 / 7078137f64.powi(3)).sqrt();
        e.outputs(half).unwrap();
        assert_eq!(e.v.lit, 0.0);
        // a quarter year later the sun is at ecliptic longitude 90 deg: (0, cos e, sin e)
        let quarter = 0.25 * 365.256_363 * 86_400.0;
        e.outputs(quarter).unwrap();
        let eps = 23.439_281f64.to_radians();
        assert!((e.v.sun_ref - Vector3::new(0.0, eps.cos(), eps.sin())).norm() < 1e-6, "{}", e.v.sun_ref);
    }
}
