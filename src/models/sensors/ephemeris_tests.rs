//! Unit tests of `Ephemeris`: closed forms of the circular orbit, and of the dipole, the mean sun and the
//! shadow along a real orbit (environment inputs).

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

fn world(r: Vector3<f64>, jd: f64) -> Fmu<Ephemeris> {
    let mut e = Fmu::<Ephemeris>::default();
    e.v.environment_inputs = 1;
    e.initialize(&Experiment::default()).unwrap();
    (e.v.world.r, e.v.world.jd_utc) = (r, jd);
    e
}

#[test]
fn dipole_at_the_input_position() {
    // B = (mu0 / 4 pi) [3 (m . r_hat) r_hat - m] / r^3 of the moment m = -M_E z (mu0 / 4 pi folded into M_E)
    let r = Vector3::new(4.0e6, -3.0e6, 5.5e6);
    let mut e = world(r, 2_460_676.5);
    e.outputs(123.0).unwrap();
    let m = Vector3::new(0.0, 0.0, -7.96e15);
    let rh = r / r.norm();
    let want = (rh * (3.0 * m.dot(&rh)) - m) / r.norm().powi(3);
    assert!((e.v.b_ref - want).norm() < 1e-12 * want.norm(), "{} vs {want}", e.v.b_ref);
    // over the north pole the field points down (-z) with twice the equatorial strength
    let mut e = world(Vector3::new(0.0, 0.0, 7.0e6), 2_460_676.5);
    e.outputs(0.0).unwrap();
    assert!((e.v.b_ref - Vector3::new(0.0, 0.0, -2.0 * 7.96e15 / 7.0e6f64.powi(3))).norm() < 1e-20);
}

#[test]
fn mean_sun_from_the_date() {
    // J2000.0: no precession, L = 280.460 deg on the ecliptic of obliquity 23.439 deg
    let mut e = world(Vector3::new(7.0e6, 0.0, 0.0), 2_451_545.0);
    e.outputs(0.0).unwrap();
    let (l, eps) = (280.460f64.to_radians(), 23.439f64.to_radians());
    let want = Vector3::new(l.cos(), l.sin() * eps.cos(), l.sin() * eps.sin());
    assert!((e.v.sun_ref - want).norm() < 1e-15, "{} vs {want}", e.v.sun_ref);
    // a century later: L advanced by 35 999.37 deg of date, i.e. 1.3969 deg (the general precession in
    // longitude, 5029.0966 arcsec per Julian century, IAU 1976) less on the J2000 ecliptic
    let mut e = world(Vector3::new(7.0e6, 0.0, 0.0), 2_451_545.0 + 36_525.0);
    e.outputs(0.0).unwrap();
    let s = e.v.sun_ref;
    let (y, z) = (s.y * eps.cos() + s.z * eps.sin(), -s.y * eps.sin() + s.z * eps.cos());
    let lon = y.atan2(s.x).to_degrees().rem_euclid(360.0);
    let want = (280.460 + 0.985_647_4 * 36_525.0 - 5029.0966 / 3600.0f64).rem_euclid(360.0);
    assert!((lon - want).abs() < 0.005 && z.abs() < 1e-3, "{lon} vs {want}, latitude {z}");
}

#[test]
fn shadow_along_the_input_position_and_refusals() {
    let jd = 2_460_800.25;
    let s = mean_sun(jd - J2000);
    for (r, lit) in [(s * 7.0e6, 1.0), (-s * 7.0e6, 0.0), (s.cross(&Vector3::z()).normalize() * 7.0e6, 1.0)] {
        let mut e = world(r, jd);
        e.outputs(0.0).unwrap();
        assert_eq!(e.v.lit, lit, "{r}");
    }
    // behind the Earth but 6 400 km off the sun line: outside the cylinder of radius 6 378 km
    let side = s.cross(&Vector3::z()).normalize();
    let mut e = world(-s * 7.0e6 + side * 6.4e6, jd);
    e.outputs(0.0).unwrap();
    assert_eq!(e.v.lit, 1.0);
    // unwired inputs: refused by name
    let mut e = world(Vector3::zeros(), jd);
    assert!(e.outputs(0.0).unwrap_err().contains("input r"));
    let mut e = world(Vector3::new(7.0e6, 0.0, 0.0), 0.0);
    assert!(e.outputs(0.0).unwrap_err().contains("input jd_utc"));
}
