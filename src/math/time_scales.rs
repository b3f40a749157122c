//! Time scales and the Earth's orientation for the environment models.
//!
//! Dates are UTC Julian dates; the count of SI seconds in a simulation is taken as uniform UTC (a leap
//! second inside a run is not inserted). UT1 is taken equal to UTC (|UT1 − UTC| < 0.9 s by definition:
//! at most 0.004° of Earth rotation) and TT = UTC + 69.184 s (the 37 leap seconds in force since 2017
//! plus TT − TAI = 32.184 s; at older epochs the error of this constant is below a minute, which moves the
//! sun by less than 0.001°).
//!
//! The Earth-fixed frame (ECEF) follows from the inertial frame of J2000 (GCRF axes to the 0.02″ frame
//! bias) by the IAU 1976 precession [Lieske-1977] and the rotation by the Greenwich mean sidereal time
//! (IAU 1982, [Vallado-2013] Eq. 3-45): r_ecef = R3(GMST) P r_eci. Nutation (at most 17.2″ in longitude
//! and 9.2″ in obliquity) and polar motion (about 0.3″) are neglected: the Earth-fixed position is off by
//! at most about 0.005°, 0.6 km at 7,000 km from the centre.

use nalgebra::{Matrix3, Vector3};

/// Julian date of the epoch J2000.0 (2000-01-01 12:00 TT).
pub const JD_J2000: f64 = 2_451_545.0;
/// Seconds per day.
pub const DAY: f64 = 86_400.0;
/// TT − UTC (s): 37 leap seconds (since 2017-01-01) + 32.184 s.
pub const TT_MINUS_UTC: f64 = 69.184;
/// Days per Julian century.
pub const CENTURY: f64 = 36_525.0;

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// Julian date of a Gregorian calendar date and time (UTC): the algorithm of [Meeus-1998] Ch. 7.
pub fn julian_date(year: i32, month: u32, day: u32, seconds_of_day: f64) -> f64 {
    let (y, m) = if month <= 2 {
        (year - 1, month + 12)
    } else {
        (year, month)
    };
    let a = y.div_euclid(100);
    let b = 2 - a + a.div_euclid(4);
    (365.25 * f64::from(y + 4716)).floor() + (30.6001 * f64::from(m + 1)).floor() + f64::from(day) + f64::from(b)
        - 1524.5
        + seconds_of_day / DAY
}

/// Gregorian calendar year of a Julian date ([Meeus-1998] Ch. 7, inverted).
pub fn calendar_year(jd: f64) -> i32 {
    let z = (jd + 0.5).floor();
    let alpha = ((z - 1_867_216.25) / 36_524.25).floor();
    let a = z + 1.0 + alpha - (alpha / 4.0).floor();
    let b = a + 1524.0;
    let c = ((b - 122.1) / 365.25).floor();
    let d = (365.25 * c).floor();
    let e = ((b - d) / 30.6001).floor();
    let month = if e < 14.0 { e - 1.0 } else { e - 13.0 };
    (if month > 2.0 { c - 4716.0 } else { c - 4715.0 }) as i32
}

/// Decimal year of a Julian date: the year plus the elapsed fraction of it (the time argument of the
/// IGRF coefficients).
pub fn decimal_year(jd: f64) -> f64 {
    // beyond a million years from J2000 the Julian year is as good, and no integer year is formed
    // (the year would saturate the i32 cast and y + 1 wrap: −1e18 s gave the year −2147818600)
    let julian = 2000.0 + (jd - 2_451_545.0) / 365.25;
    if !(julian.abs() < 1e6) {
        return julian;
    }
    let y = calendar_year(jd);
    let start = julian_date(y, 1, 1, 0.0);
    let end = julian_date(y + 1, 1, 1, 0.0);
    f64::from(y) + (jd - start) / (end - start)
}

/// Greenwich mean sidereal time (rad, in [0, 2π)) at `d_ut1` days of UT1 from J2000.0: IAU 1982
/// ([Vallado-2013] Eq. 3-45).
pub fn gmst(d_ut1: f64) -> f64 {
    let t = d_ut1 / CENTURY;
    // seconds of sidereal time: 67310.54841 s + (876600 h + 8640184.812866 s) T + 0.093104 T² − 6.2e-6 T³
    let s = 67_310.548_41 + (876_600.0 * 3600.0 + 8_640_184.812_866) * t + (0.093_104 - 6.2e-6 * t) * t * t;
    (s.rem_euclid(DAY) / DAY) * std::f64::consts::TAU
}

/// IAU 1976 precession matrix P (mean equator and equinox of J2000 → of date) at `t_tt` Julian centuries
/// of TT from J2000.0: P = R3(−z) R2(θ) R3(−ζ) ([Lieske-1977]; [Vallado-2013] Eq. 3-88).
pub fn precession(t_tt: f64) -> Matrix3<f64> {
    let t = t_tt;
    let zeta = (2306.2181 + (0.30188 + 0.017998 * t) * t) * t * ARCSEC;
    let z = (2306.2181 + (1.09468 + 0.018203 * t) * t) * t * ARCSEC;
    let theta = (2004.3109 - (0.42665 + 0.041833 * t) * t) * t * ARCSEC;
    rot3(-z) * rot2(theta) * rot3(-zeta)
}

/// Frame rotation about z by `a` (coordinates of a vector in axes turned by +a).
pub fn rot3(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Frame rotation about x by `a`.
pub fn rot1(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c)
}

/// Frame rotation about y by `a`.
pub fn rot2(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

/// The rotation ECI (J2000) → ECEF at `d_utc` days of UTC from J2000.0: R3(GMST) P.
pub fn eci_to_ecef(d_utc: f64) -> Matrix3<f64> {
    let t_tt = (d_utc + TT_MINUS_UTC / DAY) / CENTURY;
    rot3(gmst(d_utc)) * precession(t_tt)
}

/// WGS-84 equatorial radius (m).
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// Geodetic latitude (rad), longitude (rad) and height (m) above the WGS-84 ellipsoid of an ECEF position,
/// by Bowring's parametric-latitude iteration (three passes: below a micrometre in height above 1 km).
pub fn geodetic(r: &Vector3<f64>) -> (f64, f64, f64) {
    let (a, f) = (WGS84_A, WGS84_F);
    let b = a * (1.0 - f);
    let e2 = f * (2.0 - f);
    let ep2 = e2 / (1.0 - e2);
    let p = r.x.hypot(r.y);
    let lon = r.y.atan2(r.x);
    let mut u = (r.z * a).atan2(p * b);
    let mut lat = 0.0;
    for _ in 0..3 {
        let (su, cu) = u.sin_cos();
        lat = (r.z + ep2 * b * su.powi(3)).atan2(p - e2 * a * cu.powi(3));
        u = (b * lat.sin()).atan2(a * lat.cos());
    }
    let (sl, cl) = lat.sin_cos();
    let n = a / (1.0 - e2 * sl * sl).sqrt();
    // height: the projection of (p, z) − (surface point) on the ellipsoid normal, exact at any latitude
    let h = p * cl + r.z * sl - a * a / n;
    (lat, lon, h)
}

/// Rows of the rotation ECEF → NED (north, east, down) at geodetic latitude `lat` and longitude `lon`.
pub fn ecef_to_ned(lat: f64, lon: f64) -> Matrix3<f64> {
    let (sp, cp) = lat.sin_cos();
    let (sl, cl) = lon.sin_cos();
    Matrix3::new(-sp * cl, -sp * sl, cp, -sl, cl, 0.0, -cp * cl, -cp * sl, -sp)
}

#[cfg(test)]
#[path = "time_scales_tests.rs"]
mod tests;
