//! The sun's geocentric position by the low-precision formulae of the Astronomical Almanac
//! ([AA-2024] Sec. C, "Low precision formulas for the Sun"; accuracy 0.01° in direction between 1950
//! and 2050, about 1e-4 AU in distance), rotated from the mean equator and equinox of date to the J2000
//! axes of the inertial frame by the IAU 1976 precession.
//!
//! With n = JD(TT) − 2451545.0: mean longitude L = 280.460° + 0.9856474° n (aberration included), mean
//! anomaly g = 357.528° + 0.9856003° n, ecliptic longitude λ = L + 1.915° sin g + 0.020° sin 2g,
//! latitude 0, obliquity ε = 23.439° − 4e-7° n, distance R = 1.00014 − 0.01671 cos g − 0.00014 cos 2g AU.

use nalgebra::Vector3;

use super::time_scales::{precession, CENTURY, DAY, TT_MINUS_UTC};

/// Astronomical unit (m), IAU 2012.
pub const AU: f64 = 149_597_870_700.0;
/// Nominal solar radius (m), IAU 2015 Resolution B3.
pub const SUN_RADIUS: f64 = 6.957e8;

/// Unit direction (J2000 axes) and distance (m) from the Earth's centre to the sun at `d_utc` days of
/// UTC from J2000.0.
pub fn sun_position(d_utc: f64) -> (Vector3<f64>, f64) {
    let n = d_utc + TT_MINUS_UTC / DAY;
    let l = (280.460 + 0.985_647_4 * n).to_radians();
    let g = (357.528 + 0.985_600_3 * n).to_radians();
    let lam = l + 1.915f64.to_radians() * g.sin() + 0.020f64.to_radians() * (2.0 * g).sin();
    let eps = (23.439 - 4e-7 * n).to_radians();
    let dist = (1.000_14 - 0.016_71 * g.cos() - 0.000_14 * (2.0 * g).cos()) * AU;
    let (sl, cl) = lam.sin_cos();
    let of_date = Vector3::new(cl, eps.cos() * sl, eps.sin() * sl);
    (precession(n / CENTURY).transpose() * of_date, dist)
}

/// Unit direction (J2000 axes) of the mean sun of an on-board ephemeris at `d` days from J2000.0
/// (d = JD − 2451545.0): a sun moving uniformly on the ecliptic with the mean longitude
/// L = 280.460° + 0.985 647 4° d and the obliquity ε = 23.439° of [AA-2024] Sec. C, referred to the mean
/// equinox of date, turned to the J2000 axes by the IAU 1976 precession as [`sun_position`]. It leaves out
/// the equation of centre 1.915° sin g + 0.020° sin 2g of [`sun_position`]: an error of up to 1.94° along
/// the ecliptic, the intended error of an on-board model.
pub fn mean_sun(d: f64) -> Vector3<f64> {
    let (sl, cl) = (280.460 + 0.985_647_4 * d).to_radians().sin_cos();
    let (se, ce) = 23.439f64.to_radians().sin_cos();
    precession(d / CENTURY).transpose() * Vector3::new(cl, ce * sl, se * sl)
}

/// Equatorial Earth radius used for the shadow (m): a sphere (the polar flattening, 21 km, is neglected).
pub const EARTH_SHADOW_RADIUS: f64 = 6_378_137.0;

/// Fraction of the solar disk visible from `r` (m, inertial) with the sun at `r_sun` (m): the conical
/// shadow of a spherical Earth by the overlap of the apparent disks ([Montenbruck-Gill-2000] Sec. 3.4.2).
/// 1 = full sun, 0 = umbra, in between = penumbra (or an annular eclipse, 1 − (b/a)², when the Earth's disk
/// is inside the sun's).
pub fn shadow_factor(r: &Vector3<f64>, r_sun: &Vector3<f64>) -> f64 {
    let d = r_sun - r;
    let (rn, dn) = (r.norm(), d.norm());
    let a = (SUN_RADIUS / dn).asin(); // apparent radius of the sun
    let b = (EARTH_SHADOW_RADIUS / rn).min(1.0).asin(); // apparent radius of the Earth
    let c = (-r.dot(&d) / (rn * dn)).clamp(-1.0, 1.0).acos(); // angle between the two centres
    if c >= a + b {
        1.0
    } else if c <= b - a {
        0.0
    } else if c <= a - b {
        1.0 - (b / a).powi(2)
    } else {
        let x = (c * c + a * a - b * b) / (2.0 * c);
        let y = (a * a - x * x).max(0.0).sqrt();
        let area = a * a * (x / a).clamp(-1.0, 1.0).acos() + b * b * ((c - x) / b).clamp(-1.0, 1.0).acos() - c * y;
        (1.0 - area / (std::f64::consts::PI * a * a)).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::time_scales::{julian_date, JD_J2000};

    #[test]
    fn equinox_solstice_and_perihelion() {
        // March equinox 2025: 2025-03-20 09:01 UTC, the sun crosses the equator of date (declination 0)
        // going north; in J2000 axes its declination is then the precession tilt of the equator along
        // the sun's right ascension (about 0, since the equinox is on the node line) — check of date
        let d = julian_date(2025, 3, 20, 9.0 * 3600.0 + 60.0) - JD_J2000;
        let (s, _) = sun_position(d);
        let of_date = precession((d + TT_MINUS_UTC / DAY) / CENTURY) * s;
        assert!(of_date.z.asin().to_degrees().abs() < 0.01, "{of_date}");
        assert!(of_date.x > 0.99);
        // June solstice 2025 (06-21 02:42 UTC): declination of date = obliquity 23.436°
        let d = julian_date(2025, 6, 21, 2.0 * 3600.0 + 42.0 * 60.0) - JD_J2000;
        let (s, _) = sun_position(d);
        let of_date = precession((d + TT_MINUS_UTC / DAY) / CENTURY) * s;
        assert!(
            (of_date.z.asin().to_degrees() - 23.436).abs() < 0.01,
            "{}",
            of_date.z.asin().to_degrees()
        );
        // perihelion 2025-01-04 (0.98333 AU) and aphelion 2025-07-03 (1.01664 AU)
        let (_, rp) = sun_position(julian_date(2025, 1, 4, 13.0 * 3600.0) - JD_J2000);
        let (_, ra) = sun_position(julian_date(2025, 7, 3, 20.0 * 3600.0) - JD_J2000);
        assert!(
            (rp / AU - 0.983_33).abs() < 3e-4 && (ra / AU - 1.016_64).abs() < 3e-4,
            "{} {}",
            rp / AU,
            ra / AU
        );
        assert!((s.norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn shadow_factor_closed_forms() {
        let r = 6_878_137.0; // 500 km
                             // the sun 1 AU from the spacecraft along +x: its centre is seen at angle c from the Earth's centre
                             // when the spacecraft is at (−r cos c, r sin c, 0)
        let at = |c: f64| {
            let p = Vector3::new(-r * c.cos(), r * c.sin(), 0.0);
            shadow_factor(&p, &(p + Vector3::new(AU, 0.0, 0.0)))
        };
        // straight behind the Earth, on the sunlit side, and beside the Earth
        assert_eq!(at(0.0), 0.0);
        assert_eq!(at(std::f64::consts::PI), 1.0);
        assert_eq!(at(std::f64::consts::FRAC_PI_2), 1.0);
        // the sun's centre on the Earth's limb (c = b = asin(R/r)) shows half its disk, to the limb's
        // curvature (about 2a/(3π tan b) = 4e-4)
        let b = (EARTH_SHADOW_RADIUS / r).asin();
        assert!((at(b) - 0.5).abs() < 1e-3, "{}", at(b));
        // the penumbra spans c in (b − a, b + a), a = apparent solar radius; monotone inside
        let a = (SUN_RADIUS / AU).asin();
        assert_eq!(at(b + a + 1e-9), 1.0);
        assert_eq!(at(b - a - 1e-9), 0.0);
        let mut last = 0.0;
        for k in 1..100 {
            let f = at(b - a + 2.0 * a * f64::from(k) / 100.0);
            assert!(f > last, "{k}: {f}");
            last = f;
        }
    }
}
