//! `Ephemeris`: the flight computer's on-board models of the reference directions — the sun direction and
//! the geomagnetic field in the reference frame R at the spacecraft's position — that an estimator pairs
//! with the sun sensor's and the magnetometer's body-frame measurements, and the sunlight flag of a
//! cylindrical shadow. With `environment_inputs = 0` it evaluates exactly the environment the plant and the
//! sensors use (same orbit parameters and value references 160–165), so a noise-free sensor and this unit
//! agree to rounding. With `environment_inputs = 1` it evaluates the same simple on-board models along a real
//! orbit: the dipole at the position `r` the flight computer knows (GPS: `Orbit.r_*`) and a mean sun from
//! the date `jd_utc` (`Orbit.jd_utc`); against `Environment`'s true field and sun it then errs as a flight
//! computer does (the tilt and higher degrees of the real field, the equation of centre of the sun).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::shared::{date_input, position_input, OrbitParams, PositionInputs, SunParams};
use crate::declare_variables;
use crate::math::environment::{dipole_field, in_eclipse, sun_ref};
use crate::math::sun::mean_sun;
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult, SWITCH};

/// Julian date of J2000.0 (d).
const J2000: f64 = 2_451_545.0;

declare_variables! {
    pub struct EphemerisVars {
        orbit: OrbitParams;
        sun: SunParams;
        world: PositionInputs;
        20 => sun_ref: Vec3 = [1.0, 0.0, 0.0], Output, "", "Unit sun direction in the reference frame R";
        23 => b_ref: Vec3 = [0.0, 0.0, 1.0], Output, "T", "Geomagnetic (dipole) field in the reference frame R at the spacecraft";
        26 => lit: Real = 1.0, Output, "", "1 = spacecraft in sunlight, 0 = in the Earth's cylindrical shadow";
        191 => environment_inputs: Integer = 0, Parameter, "", "0 = the circular orbit (parameters 160-164) and the sun on its circular apparent orbit (sun_ecliptic_longitude); 1 = the dipole at the input r and the mean sun of the input date jd_utc (from Orbit; R is then the inertial J2000 frame)", Choice(SWITCH);
    }
}

/// No state: the outputs are functions of time (or of the inputs) and the parameters.
#[derive(Clone, Serialize, Deserialize)]
pub struct Ephemeris;

impl Model for Ephemeris {
    type Vars = EphemerisVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a law of time: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Ephemeris",
        description: "On-board reference directions for attitude estimation: sun direction and dipole field in R at the spacecraft, and the sunlight flag; on the circular orbit or along a real orbit (position and date as inputs)",
        source: "the environment of the plant and the sensors ([Markley-Crassidis-2014] Sec. 4.5 dipole field; circular apparent solar orbit; project choice); along a real orbit the mean sun of [AA-2024] Sec. C without the equation of centre",
        equations_html: "<pre>environment_inputs = 0:\n\
sun_ref(t) = [cos l, sin l cos e, sin l sin e],   l = l_0 + n_sun t,  e = obliquity\n\
b_ref(t)   = (M_E / r^3) [z - 3 (z . r_hat) r_hat],   r_hat(t) = [cos u, sin u cos i, sin u sin i],  u = u_0 + n t\n\
lit        = 0 when r_hat . sun_ref &lt; 0 and r |r_hat x sun_ref| &lt; R_E (cylindrical shadow), else 1\n\
(the plant's and the sensors' environment: same parameters and value references 160-165)\n\
environment_inputs = 1 (inputs r, jd_utc):\n\
d          = jd_utc - 2451545.0,   L = 280.460 deg + 0.9856474 deg d,   e = 23.439 deg\n\
sun_ref    = P(d)^T [cos L, sin L cos e, sin L sin e]   (P: IAU 1976 precession J2000 -> mean of date)\n\
b_ref      = (M_E / |r|^3) [z - 3 (z . r_hat) r_hat],   r_hat = r / |r|\n\
lit        = the cylindrical shadow above at r</pre>\n\
<p>With environment_inputs = 1, wire r and jd_utc from an <code>Orbit</code> unit (the names match): the position \
and time the flight computer knows (GPS). The sun is the mean sun of the Astronomical Almanac's low-precision \
formulae [AA-2024]: its mean longitude L (aberration included) without the equation of centre \
1.915 deg sin g + 0.020 deg sin 2g, an error of up to 1.94 deg along the ecliptic against the true sun \
(Environment's sun_eci) - the intended on-board model error, as is the dipole's against IGRF (its axis is \
the rotation axis, not tilted by 9.7 deg, and the higher degrees are left out). Refused with an error naming \
the input: an r inside the Earth's equatorial radius (an unwired r) and a jd_utc outside [2.0e6, 3.0e6] \
(an unwired jd_utc). With 0 (the default) the inputs are not read, bit for bit the unit of the circular orbit.</p>",
        feedthrough: Feedthrough::Some(&[("sun_ref", &["jd_utc"]), ("b_ref", &["r"]), ("lit", &["r", "jd_utc"])]),
        ..ModelInfo::DEFAULT
    };

    fn initialize(_v: &mut EphemerisVars, _exp: &Experiment) -> Result<Self, String> {
        Ok(Ephemeris)
    }

    fn outputs(&self, v: &mut EphemerisVars, t: f64) -> ModelResult {
        if v.environment_inputs == 1 {
            let r = position_input(&v.world.r)?;
            let s = mean_sun(date_input(v.world.jd_utc)? - J2000);
            let (rn, rh) = (r.norm(), r / r.norm());
            v.sun_ref = s;
            v.b_ref = dipole_field(&rh, rn, v.orbit.earth_dipole);
            v.lit = if in_eclipse(&rh, rn, &s) { 0.0 } else { 1.0 };
            return Ok(());
        }
        let orbit = v.orbit.orbit();
        let s: Vector3<f64> = sun_ref(v.sun.sun_ecliptic_longitude, t);
        v.sun_ref = s;
        v.b_ref = orbit.field_ref(t);
        v.lit = if in_eclipse(&orbit.r_hat(t), orbit.radius, &s) { 0.0 } else { 1.0 };
        Ok(())
    }
}

#[cfg(test)]
#[path = "ephemeris_tests.rs"]
mod tests;
