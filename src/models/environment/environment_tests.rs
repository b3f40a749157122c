use nalgebra::Vector3;

use super::*;
use crate::model::Fmu;

fn fmu(year: i32) -> Fmu<Environment> {
    let mut e = Fmu::<Environment>::default();
    e.v.epoch.epoch_year = year;
    e
}

#[test]
fn outputs_at_a_known_date_and_place() {
    let mut e = fmu(2025);
    e.v.epoch.epoch_month = 6;
    e.v.epoch.epoch_day = 21;
    e.v.epoch.epoch_hour = 2;
    e.v.epoch.epoch_minute = 42;
    e.initialize(&Experiment::default()).unwrap();
    // 2025-06-21 02:42 UTC = JD 2460847.6125
    assert!((e.v.epoch_jd - 2_460_847.612_5).abs() < 1e-9, "{}", e.v.epoch_jd);
    e.v.r = Vector3::new(0.0, 0.0, 6_878_137.0);
    e.outputs(0.0).unwrap();
    // over the north pole at 500 km: the ellipsoid is 21.4 km lower there
    assert!((e.v.altitude - (6_878_137.0 - 6_356_752.314)).abs() < 1.0, "{}", e.v.altitude);
    // the field over the north pole points down, 50,000-60,000 nT
    assert!(e.v.b_ned.z > 4.5e-5 && e.v.b_ned.z < 6e-5, "{}", e.v.b_ned);
    assert!((e.v.b_eci.norm() - e.v.b_ned.norm()).abs() < 1e-15);
    // June solstice: the sun at declination +23.44° (J2000 axes within 0.15°); over the pole in sunlight
    assert!((e.v.sun_eci.z.asin().to_degrees() - 23.44).abs() < 0.2, "{}", e.v.sun_eci);
    assert_eq!(e.v.eclipse, 1.0);
    // density: exponential table at 521.4 km (500 km layer)
    let h = e.v.altitude / 1000.0;
    assert!((e.v.rho / (6.967e-13 * (-(h - 500.0) / 63.822).exp()) - 1.0).abs() < 1e-12);
    // one day later the date output advanced by 1
    e.outputs(86_400.0).unwrap();
    assert!((e.v.jd - 2_460_848.612_5).abs() < 1e-9);
}

#[test]
fn bad_inputs_and_epochs_are_refused_with_their_names() {
    let mut e = fmu(2026);
    e.initialize(&Experiment::default()).unwrap();
    e.v.r = Vector3::new(6.0e6, 0.0, 0.0);
    let err = e.outputs(0.0).unwrap_err();
    assert!(err.contains("input r") && err.contains("Earth's radius"), "{err}");
    for year in [1899, 2030, 2031] {
        let err = fmu(year).initialize(&Experiment::default()).err().unwrap();
        assert!(err.contains("1900.0 to 2030.0") && err.contains("epoch"), "{year}: {err}");
    }
    let mut e = fmu(2026);
    e.v.epoch.epoch_month = 2;
    e.v.epoch.epoch_day = 29;
    let err = e.initialize(&Experiment::default()).err().unwrap();
    assert!(err.contains("2026-02-29") && err.contains("epoch_day"), "{err}");
    // a run that goes past 2030.0 stops with the time named
    let mut e = fmu(2029);
    e.v.epoch.epoch_month = 12;
    e.v.epoch.epoch_day = 31;
    e.initialize(&Experiment::default()).unwrap();
    let err = e.outputs(2.0 * 86_400.0).unwrap_err();
    assert!(err.contains("t = 172800") && err.contains("2030.0"), "{err}");
    // Harris-Priester refuses heights below its table
    let mut e = fmu(2026);
    e.v.density_model = 1;
    e.initialize(&Experiment::default()).unwrap();
    e.v.r = Vector3::new(6_378_137.0 + 50e3, 0.0, 0.0);
    let err = e.outputs(0.0).unwrap_err();
    assert!(err.contains("input r") && err.contains("100 km"), "{err}");
}

#[test]
fn harris_priester_bulge_follows_the_sun() {
    let mut e = fmu(2026);
    e.v.density_model = 1;
    e.v.hp_exponent = 6.0;
    e.initialize(&Experiment::default()).unwrap();
    e.outputs(0.0).unwrap();
    let s = e.v.sun_eci;
    let r = 6_378_137.0 + 400e3;
    // under the apex (sun turned 30° east) the apex density, opposite it the antapex density (400 km,
    // heights above the ellipsoid differ a little from 400 km off the equator: compare the ratio)
    let apex = crate::math::atmosphere::bulge_apex(&s);
    e.v.r = apex * r;
    e.outputs(0.0).unwrap();
    let (hi, h1) = (e.v.rho, e.v.altitude);
    e.v.r = -apex * r;
    e.outputs(0.0).unwrap();
    let (lo, h2) = (e.v.rho, e.v.altitude);
    assert!((h1 - h2).abs() < 1.0);
    assert!(hi / lo > 7.492 / 2.249 * 0.9 && hi / lo < 7.492 / 2.249 * 1.1, "{hi} {lo}");
}

#[test]
#[ignore = "timing: cargo test --release --lib environment -- --ignored --nocapture"]
fn cost_of_one_evaluation() {
    let mut e = fmu(2027);
    e.v.density_model = 1;
    e.initialize(&Experiment::default()).unwrap();
    let n = 200_000;
    let start = std::time::Instant::now();
    let mut acc = 0.0;
    for k in 0..n {
        let a = f64::from(k) * 1e-3;
        e.v.r = Vector3::new(a.cos(), a.sin() * 0.6, a.sin() * 0.8) * 6_878_137.0;
        e.outputs(f64::from(k)).unwrap();
        acc += e.v.b_eci.x + e.v.rho + e.v.eclipse;
    }
    let ns = start.elapsed().as_nanos() as f64 / f64::from(n);
    eprintln!("Environment: {ns:.0} ns per evaluation (IGRF degree 13 + sun + eclipse + Harris-Priester) [{acc:.3e}]");
}
