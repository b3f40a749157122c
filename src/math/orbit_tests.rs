use super::*;
use std::f64::consts::PI;

const DEG: f64 = PI / 180.0;

#[test]
fn perigee_state_has_the_closed_form_speed() {
    // i = Ω = ω = ν = 0: r = a (1 − e) x̂, v = √(μ (1 + e) / (a (1 − e))) ŷ (vis-viva at perigee)
    let (a, e) = (7.0e6, 0.1);
    let el = Elements {
        a,
        e,
        i: 0.0,
        raan: 0.0,
        argp: 0.0,
        nu: 0.0,
    };
    let (r, v) = rv_from_elements(MU_EARTH, &el).unwrap();
    assert!((r - Vector3::new(a * (1.0 - e), 0.0, 0.0)).norm() < 1e-8);
    let vp = (MU_EARTH * (1.0 + e) / (a * (1.0 - e))).sqrt();
    assert!((v - Vector3::new(0.0, vp, 0.0)).norm() < 1e-11, "{v:?} vs {vp}");
}

#[test]
fn elements_give_the_invariants_and_come_back() {
    // energy −μ/(2a), |h| = √(μ a (1 − e²)), ĥ = (sin i sin Ω, −sin i cos Ω, cos i); and the inverse map
    let el = Elements {
        a: 7.2e6,
        e: 0.05,
        i: 97.4 * DEG,
        raan: 33.0 * DEG,
        argp: 250.0 * DEG,
        nu: 123.0 * DEG,
    };
    let (r, v) = rv_from_elements(MU_EARTH, &el).unwrap();
    let energy = 0.5 * v.norm_squared() - MU_EARTH / r.norm();
    assert!((energy / (-MU_EARTH / (2.0 * el.a)) - 1.0).abs() < 1e-14);
    let h = r.cross(&v);
    assert!((h.norm() / (MU_EARTH * el.a * (1.0 - el.e * el.e)).sqrt() - 1.0).abs() < 1e-14);
    let hh = Vector3::new(el.i.sin() * el.raan.sin(), -el.i.sin() * el.raan.cos(), el.i.cos());
    assert!((h.normalize() - hh).norm() < 1e-14);
    let back = elements_from_rv(MU_EARTH, &r, &v).unwrap();
    for (got, want, what) in [
        (back.a, el.a, "a"),
        (back.e, el.e, "e"),
        (back.i, el.i, "i"),
        (back.raan, el.raan, "raan"),
        (back.argp, el.argp, "argp"),
        (back.nu, el.nu, "nu"),
    ] {
        assert!(
            (got - want).abs() < 1e-9 * want.abs().max(1.0),
            "{what}: {got} vs {want}"
        );
    }
    assert!(rv_from_elements(MU_EARTH, &Elements { e: 1.0, ..el })
        .unwrap_err()
        .contains("eccentricity"));
    assert!(rv_from_elements(MU_EARTH, &Elements { a: -1.0, ..el })
        .unwrap_err()
        .contains("semi-major"));
}

#[test]
fn kepler_equation_matches_a_published_example() {
    // [Vallado-2013] Example 2-1: M = 235.4°, e = 0.4 → E = 220.512 074 767 522°
    let ea = eccentric_anomaly(235.4 * DEG, 0.4);
    assert!((ea / DEG - 220.512_074_767_522).abs() < 1e-9, "E = {} deg", ea / DEG);
    for &(m, e) in &[(0.1, 0.0), (3.0, 0.9), (6.0, 0.99), (-2.0, 0.3)] {
        let ea = eccentric_anomaly(m, e);
        assert!((ea - e * ea.sin() - m).abs() < 1e-14, "M {m}, e {e}");
        let nu = true_from_eccentric(ea, e);
        let m2 = mean_from_true(nu, e);
        assert!(
            ((m2 - m + PI).rem_euclid(2.0 * PI) - PI).abs() < 1e-12,
            "M {m} e {e}: {m2}"
        );
    }
}

/// Term n of the gravitational potential V (a = ∇V): −(μ/r) J_n (R/r)^n P_n(z/r), with the Legendre
/// polynomials written out.
fn zonal_potential(n: usize, jn: f64, r: &Vector3<f64>) -> f64 {
    let rn = r.norm();
    let s = r.z / rn;
    let p = match n {
        2 => (3.0 * s * s - 1.0) / 2.0,
        3 => (5.0 * s.powi(3) - 3.0 * s) / 2.0,
        _ => (35.0 * s.powi(4) - 30.0 * s * s + 3.0) / 8.0,
    };
    -MU_EARTH / rn * jn * (R_EARTH / rn).powi(n as i32) * p
}

#[test]
fn zonal_accelerations_are_the_gradient_of_the_legendre_potential() {
    // each J_n term alone against a central-difference gradient of its potential (step 1 m)
    let points = [
        Vector3::new(6.9e6, 0.0, 0.0),
        Vector3::new(3.0e6, -4.0e6, 5.0e6),
        Vector3::new(-1.0e6, 2.0e6, -6.8e6),
        Vector3::new(4.2e7, 1.0e6, 3.0e5),
    ];
    let js = [J2, J3, J4];
    for (k, n) in [2usize, 3, 4].into_iter().enumerate() {
        let only = |r: &Vector3<f64>| {
            let mut jv = [0.0; 3];
            jv[k] = js[k];
            let g = Gravity {
                mu: MU_EARTH,
                radius: R_EARTH,
                j: jv,
                degree: n as u8,
            };
            g.acceleration(r) + MU_EARTH / r.norm().powi(3) * r
        };
        for p in &points {
            let h = 1.0;
            let grad = Vector3::from_fn(|i, _| {
                let mut d = Vector3::zeros();
                d[i] = h;
                (zonal_potential(n, js[k], &(p + d)) - zonal_potential(n, js[k], &(p - d))) / (2.0 * h)
            });
            let a = only(p);
            assert!(
                (a - grad).norm() < 1e-6 * grad.norm(),
                "J{n} at {p:?}: {a:?} vs {grad:?}"
            );
        }
    }
    // degree 0 is the point mass
    let g = Gravity {
        mu: MU_EARTH,
        radius: R_EARTH,
        j: [J2, J3, J4],
        degree: 0,
    };
    let r = Vector3::new(7.0e6, 0.0, 0.0);
    assert_eq!(g.acceleration(&r), Vector3::new(-MU_EARTH / 4.9e13, 0.0, 0.0));
}

#[test]
fn j2_magnitude_at_the_equator_is_the_textbook_value() {
    // equatorial point: the J2 term is −(3/2) J2 μ R²/r⁴ radially (s = 0), i.e. 1.5 J2 (R/r)² of gravity
    let r = Vector3::new(R_EARTH + 500e3, 0.0, 0.0);
    let g = Gravity {
        mu: MU_EARTH,
        radius: R_EARTH,
        j: [J2, 0.0, 0.0],
        degree: 2,
    };
    let pert = g.acceleration(&r).x + MU_EARTH / r.x.powi(2);
    let want = -1.5 * J2 * MU_EARTH * R_EARTH.powi(2) / r.x.powi(4);
    assert!((pert / want - 1.0).abs() < 1e-9, "{pert} vs {want}");
    assert!((pert + 0.0118).abs() < 0.0003, "about 11.8 mm/s² at 500 km: {pert}");
}

#[test]
fn drag_opposes_the_relative_velocity() {
    // still atmosphere: |a| = ½ ρ v² / B; turning atmosphere: a prograde equatorial orbit sees v − ω r
    let (rho, b) = (1e-12, 50.0);
    let r = Vector3::new(7.0e6, 0.0, 0.0);
    let v = Vector3::new(0.0, 7500.0, 0.0);
    let a0 = drag_acceleration(rho, b, 0.0, &r, &v);
    assert!((a0 - Vector3::new(0.0, -0.5 * rho * 7500.0 * 7500.0 / b, 0.0)).norm() < 1e-14 * a0.norm());
    let vr = 7500.0 - OMEGA_EARTH * 7.0e6;
    let a1 = drag_acceleration(rho, b, OMEGA_EARTH, &r, &v);
    assert!(
        (a1.y + 0.5 * rho * vr * vr / b).abs() < 1e-14 * a1.norm() && a1.x == 0.0,
        "{a1:?}"
    );
}

#[test]
fn lvlh_axes_are_nadir_and_along_track() {
    let (r, v) = (Vector3::new(7.0e6, 0.0, 0.0), Vector3::new(0.0, 5000.0, 5000.0));
    let [x, y, z] = lvlh_axes(&r, &v).unwrap();
    assert!((z - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-15);
    assert!(
        (x - v.normalize()).norm() < 1e-15,
        "along-track on a circular orbit: {x:?}"
    );
    assert!((y + r.cross(&v).normalize()).norm() < 1e-15);
    assert!((x.cross(&y) - z).norm() < 1e-15, "right-handed");
    assert!(lvlh_axes(&r, &(r * 1e-3)).unwrap_err().contains("parallel"));
}
