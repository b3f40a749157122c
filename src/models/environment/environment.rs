//! `Environment`: the true orbital environment at the spacecraft's position — the geomagnetic field by
//! IGRF-14, the sun's direction and distance, the Earth's shadow and the atmospheric density — as
//! functions of the inertial position (input) and the UTC date (epoch + simulation time). No state.

use serde::{Deserialize, Serialize};

use super::epoch::{days_at, julian, EpochParams};
use crate::declare_variables;
use crate::math::atmosphere::{bulge_apex, exponential_density, harris_priester_density};
use crate::math::igrf;
use crate::math::sun::{shadow_factor, sun_position};
use crate::math::time_scales::{decimal_year, ecef_to_ned, eci_to_ecef, geodetic, gmst, JD_J2000};
use crate::model::{Experiment, Feedthrough, Model, ModelInfo, ModelResult, ParamEnum};

/// Radius below which a position is refused (m): the WGS-84 equatorial radius.
pub const EARTH_RADIUS: f64 = 6_378_137.0;

declare_variables! {
    pub struct EnvironmentVars {
        epoch: EpochParams;
        0 => r: Vec3 = [6_878_137.0, 0.0, 0.0], Input, "m", "Spacecraft position in the Earth-centred inertial frame (J2000 axes)";
        20 => b_eci: Vec3 = [0.0; 3], Output, "T", "Geomagnetic field (IGRF-14) at the spacecraft, inertial axes";
        23 => sun_eci: Vec3 = [1.0, 0.0, 0.0], Output, "", "Unit vector from the Earth's centre to the sun, inertial axes";
        26 => eclipse: Real = 1.0, Output, "", "Visible fraction of the solar disk: 0 = umbra, between = penumbra, 1 = full sun";
        27 => rho: Real = 0.0, Output, "kg/m3", "Atmospheric density at the spacecraft (model of density_model)";
        28 => jd: Real = 0.0, Output, "d", "Julian date (UTC) at the current time";
        29 => sun_distance: Real = 0.0, Output, "m", "Distance from the Earth's centre to the sun";
        30 => b_ecef: Vec3 = [0.0; 3], Output, "T", "Geomagnetic field, Earth-fixed axes";
        33 => b_ned: Vec3 = [0.0; 3], Output, "T", "Geomagnetic field, north-east-down axes (geodetic)";
        36 => altitude: Real = 0.0, Output, "m", "Height above the WGS-84 ellipsoid";
        37 => latitude: Real = 0.0, Output, "rad", "Geodetic latitude";
        38 => longitude: Real = 0.0, Output, "rad", "Longitude (east)";
        39 => gmst: Real = 0.0, Output, "rad", "Greenwich mean sidereal time (IAU 1982, UT1 = UTC)";
        106 => hp_exponent: Real = 4.0, Parameter, "", "Harris-Priester bulge exponent n (2 for low, 6 for polar inclinations)", Range(2.0, 6.0);
        120 => density_model: Integer = 0, Parameter, "", "0 = exponential (Vallado Table 8-4); 1 = Harris-Priester (mean solar activity, diurnal bulge)", Choice(DensityModel::CODES);
        200 => epoch_jd: Real = 0.0, CalculatedParameter, "d", "Julian date (UTC) of the epoch";
        201 => epoch_decimal_year: Real = 0.0, CalculatedParameter, "", "Decimal year of the epoch (time argument of IGRF)";
    }
}

crate::param_enum! {
    /// Atmospheric density model (`density_model`).
    pub enum DensityModel {
        /// 0: piecewise exponential, [Vallado-2013] Table 8-4.
        Exponential = 0,
        /// 1: modified Harris–Priester, [Montenbruck-Gill-2000] Table 3.8.
        HarrisPriester = 1,
    }
}

/// Derived at initialisation.
#[derive(Clone, Serialize, Deserialize)]
pub struct Environment {
    /// Days of UTC from J2000.0 at t = 0.
    days0: f64,
    density: DensityModel,
}

const DEPENDS_ON_R: &[&str] = &["r_x", "r_y", "r_z"];

impl Model for Environment {
    type Vars = EnvironmentVars;
    const EVOLVING: &'static [&'static str] = &[];
    /// Model Exchange as a law of the inputs and time: no continuous state.
    const STATES: Option<&'static [crate::model::StateDecl]> = Some(&[]);
    const INFO: ModelInfo = ModelInfo {
        name: "Environment",
        description: "True orbital environment at the spacecraft: IGRF-14 geomagnetic field, sun direction and distance, \
                      conical Earth shadow and atmospheric density, from the inertial position and the UTC date",
        source: "[IGRF-14] coefficients with [Alken-2021] conventions, evaluated by the solid-harmonic recursions of \
                 [Montenbruck-Gill-2000] Sec. 3.2; sun by [AA-2024]; Earth rotation by GMST and precession \
                 ([Vallado-2013], [Lieske-1977]); shadow [Montenbruck-Gill-2000] Sec. 3.4.2; density [Vallado-2013] \
                 Table 8-4 or [Montenbruck-Gill-2000] Sec. 3.5.2; dates [Meeus-1998]",
        equations_html: "<pre>d = days of UTC from J2000.0 = epoch + t / 86400;  r_ecef = R3(GMST(d)) P(d) r   (IAU 1982, IAU 1976)\n\
B_ecef = -grad V(r_ecef),  V = a sum_{n&lt;=13} (a/r)^(n+1) sum_m [g_n^m cos m lon + h_n^m sin m lon] P_n^m(cos colat)\n\
b_eci = (R3(GMST) P)^T B_ecef;   b_ned = N(lat, lon) B_ecef   (geodetic, WGS-84)\n\
sun: lambda = L + 1.915 sin g + 0.020 sin 2g (deg), R = 1.00014 - 0.01671 cos g - 0.00014 cos 2g (AU)\n\
eclipse = 1 - (overlap of the disks of the sun (radius a) and the Earth (radius b), c apart) / (pi a^2)\n\
rho = rho0 exp(-(h - h0)/H)   or   rho_m(h) + (rho_M(h) - rho_m(h)) cos^n(psi/2)</pre>",
        feedthrough: Feedthrough::Some(&[
            ("b_eci_x", DEPENDS_ON_R),
            ("b_eci_y", DEPENDS_ON_R),
            ("b_eci_z", DEPENDS_ON_R),
            ("eclipse", DEPENDS_ON_R),
            ("rho", DEPENDS_ON_R),
            ("b_ecef_x", DEPENDS_ON_R),
            ("b_ecef_y", DEPENDS_ON_R),
            ("b_ecef_z", DEPENDS_ON_R),
            ("b_ned_x", DEPENDS_ON_R),
            ("b_ned_y", DEPENDS_ON_R),
            ("b_ned_z", DEPENDS_ON_R),
            ("altitude", DEPENDS_ON_R),
            ("latitude", DEPENDS_ON_R),
            ("longitude", DEPENDS_ON_R),
        ]),
        default_stop_time: 5_676.0,
        default_step: 1.0,
        ..ModelInfo::DEFAULT
    };

    fn initialize(v: &mut EnvironmentVars, _exp: &Experiment) -> Result<Self, String> {
        let days0 = v.epoch.days_from_j2000()?;
        let year = decimal_year(JD_J2000 + days0);
        if !(igrf::FIRST_YEAR..igrf::LAST_YEAR).contains(&year) {
            return Err(format!(
                "epoch {:.4} (epoch_year ...) lies outside the IGRF-14 validity {:.1} to {:.1}",
                year,
                igrf::FIRST_YEAR,
                igrf::LAST_YEAR
            ));
        }
        v.epoch_jd = julian(days0);
        v.epoch_decimal_year = year;
        Ok(Environment {
            days0,
            density: DensityModel::from_param("density_model", v.density_model)?,
        })
    }

    fn outputs(&self, v: &mut EnvironmentVars, t: f64) -> ModelResult {
        let r = v.r;
        if r.norm() < EARTH_RADIUS {
            return Err(format!(
                "input r = ({}, {}, {}) m: |r| = {:.1} m is below the Earth's radius {EARTH_RADIUS} m (is it connected?)",
                r.x,
                r.y,
                r.z,
                r.norm()
            ));
        }
        let d = days_at(self.days0, t);
        let coeffs = igrf::coefficients(decimal_year(JD_J2000 + d)).map_err(|e| format!("at t = {t} s: {e}"))?;
        let to_ecef = eci_to_ecef(d);
        let r_ecef = to_ecef * r;
        let b_ecef = igrf::field_ecef(&coeffs, &r_ecef);
        let (lat, lon, h) = geodetic(&r_ecef);
        let (sun, dist) = sun_position(d);
        v.b_ecef = b_ecef;
        v.b_eci = to_ecef.transpose() * b_ecef;
        v.b_ned = ecef_to_ned(lat, lon) * b_ecef;
        v.sun_eci = sun;
        v.sun_distance = dist;
        v.eclipse = shadow_factor(&r, &(sun * dist));
        v.rho = match self.density {
            DensityModel::Exponential => exponential_density(h),
            DensityModel::HarrisPriester => {
                let cos_psi = r.dot(&bulge_apex(&sun)) / r.norm();
                harris_priester_density(h, cos_psi, v.hp_exponent).map_err(|e| format!("input r: {e}"))?
            }
        };
        v.jd = julian(d);
        v.altitude = h;
        v.latitude = lat;
        v.longitude = lon;
        v.gmst = gmst(d);
        Ok(())
    }
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
