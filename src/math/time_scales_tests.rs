use super::*;

#[test]
fn julian_dates_of_published_examples() {
    // J2000.0 and [Meeus-1998] Example 7.a (1957 Oct 4.81 = JD 2436116.31)
    assert_eq!(julian_date(2000, 1, 1, 43_200.0), JD_J2000);
    assert!((julian_date(1957, 10, 4, 0.81 * DAY) - 2_436_116.31).abs() < 1e-8);
    // [Meeus-1998] Example 7.b: 333 Jan 27.5 is in the Julian calendar, so take a Gregorian one:
    // 1987 Jun 19.5 = JD 2446966.0 (Meeus Table 7.a)
    assert_eq!(julian_date(1987, 6, 19, 43_200.0), 2_446_966.0);
    for (y, m, d) in [(1900, 1, 1), (1999, 12, 31), (2024, 2, 29), (2030, 1, 1), (2025, 3, 1)] {
        let jd = julian_date(y, m, d, 3600.0);
        assert_eq!(calendar_year(jd), y, "{y}-{m}-{d}");
    }
    // a non-leap year: 2025-07-02 12:00 is 182.5 of 365 days in; a leap year: 2024-07-02 00:00 is 183 of 366
    assert!((decimal_year(julian_date(2025, 7, 2, 43_200.0)) - 2025.5).abs() < 1e-12);
    assert!((decimal_year(julian_date(2024, 7, 2, 0.0)) - (2024.0 + 183.0 / 366.0)).abs() < 1e-12);
}

#[test]
fn gmst_of_vallado_example() {
    // [Vallado-2013] Example 3-5: 1992 Aug 20, 12:14 UT1 → GMST = 152.578787810°
    let d = julian_date(1992, 8, 20, 12.0 * 3600.0 + 14.0 * 60.0) - JD_J2000;
    let g = gmst(d).to_degrees();
    assert!((g - 152.578_787_810).abs() < 1e-6, "{g}");
    // one sidereal day (86164.0905 s) later the same angle, one solar day later about 0.9856° more
    let ds = gmst(d + 86_164.090_5 / DAY).to_degrees();
    assert!((ds - g).abs() < 1e-4, "{ds}");
    let dd = (gmst(d + 1.0).to_degrees() - g).rem_euclid(360.0);
    assert!((dd - 0.985_647).abs() < 1e-4, "{dd}");
}

#[test]
fn precession_moves_pole_and_equinox_at_published_rates() {
    assert!((precession(0.0) - Matrix3::identity()).norm() < 1e-15);
    let t = 0.25; // 2025
    let p = precession(t);
    assert!((p * p.transpose() - Matrix3::identity()).norm() < 1e-15);
    // the pole of date seen in J2000 axes is θ_A = 2004.3109″ T away from the J2000 pole
    let pole = p.transpose() * Vector3::z();
    let tilt = pole.z.acos() / ARCSEC;
    assert!((tilt - 2004.3109 * t).abs() < 0.1, "{tilt}");
    // the equinox of date has regressed along the ecliptic by the general precession in longitude
    // p_A = 5029.0966″ T (IAU 1976), so fixed stars gain longitude; the J2000 ecliptic: obliquity 23.4392911°
    let eps = 23.439_291_1f64.to_radians();
    let eq = p.transpose() * Vector3::x();
    let ecl = Vector3::new(
        eq.x,
        eq.y * eps.cos() + eq.z * eps.sin(),
        -eq.y * eps.sin() + eq.z * eps.cos(),
    );
    let lon = ecl.y.atan2(ecl.x) / ARCSEC;
    assert!((lon + 5029.0966 * t).abs() < 1.0, "{lon}");
}

#[test]
fn geodetic_round_trip_and_ned_axes() {
    let e2 = WGS84_F * (2.0 - WGS84_F);
    for (lat_deg, lon_deg, h) in [
        (0.0, 0.0, 500e3),
        (45.0, 120.0, 300e3),
        (-89.9, -60.0, 2000e3),
        (90.0, 10.0, 1e3),
    ] {
        let (lat, lon) = (f64::to_radians(lat_deg), f64::to_radians(lon_deg));
        let n = WGS84_A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
        let r = Vector3::new(
            (n + h) * lat.cos() * lon.cos(),
            (n + h) * lat.cos() * lon.sin(),
            (n * (1.0 - e2) + h) * lat.sin(),
        );
        let (la, lo, hh) = geodetic(&r);
        assert!(
            (la - lat).abs() < 1e-12 && (hh - h).abs() < 1e-6,
            "{lat_deg} {lon_deg}: {la} {hh}"
        );
        if lat_deg.abs() < 90.0 {
            assert!((lo - lon).abs() < 1e-12);
        }
    }
    // at latitude 0, longitude 0: north = z, east = y, down = −x
    let m = ecef_to_ned(0.0, 0.0);
    assert!((m - Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)).norm() < 1e-15);
}

/// Far from J2000 the decimal year is the Julian year (no saturated integer year that wraps): issue 45.
#[test]
fn decimal_year_far_from_j2000_does_not_wrap() {
    for t in [-1e18, 1e18, -1e20, 1e300, -1e300] {
        let jd = 2_451_545.0 + t / 86_400.0;
        let y = decimal_year(jd);
        let want = 2000.0 + t / 86_400.0 / 365.25;
        assert!((y - want).abs() <= 1e-9 * want.abs(), "t = {t}: {y}, expected {want}");
    }
    assert!((decimal_year(2_451_545.0) - 2000.0).abs() < 0.01);
}
