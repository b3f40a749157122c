use super::*;

#[test]
fn published_coefficients_and_their_time_rule() {
    // IGRF-14 2025.0: g10 = −29350.0, g11 = −1410.3, h11 = 4545.5 nT; secular variation of g10 +12.6 nT/yr
    let c = schmidt_coefficients(2025.0).unwrap();
    assert_eq!((c.g[1][0], c.g[1][1], c.h[1][1]), (-29350.0, -1410.3, 4545.5));
    let c = schmidt_coefficients(2027.5).unwrap();
    assert!((c.g[1][0] - (-29350.0 + 2.5 * 12.6)).abs() < 1e-9, "{}", c.g[1][0]);
    // DGRF 2020.0 g10 = −29403.41; halfway to 2025.0 the mean of the two models
    let c = schmidt_coefficients(2022.5).unwrap();
    assert!((c.g[1][0] - 0.5 * (-29403.41 - 29350.0)).abs() < 1e-9);
    // degrees 11–13 start in 2000.0
    assert_eq!(schmidt_coefficients(1995.0).unwrap().g[13][0], 0.0);
    assert_ne!(schmidt_coefficients(2000.0).unwrap().g[13][0], 0.0);
    for bad in [1899.99, 2030.01] {
        let e = schmidt_coefficients(bad).unwrap_err();
        assert!(e.contains("1900.0 to 2030.0"), "{e}");
    }
}

/// A field from the first-degree coefficients only: B = −∇(a³ m·r / r³), m = (g11, h11, g10).
fn dipole(m: Vector3<f64>, r: &Vector3<f64>) -> Vector3<f64> {
    let a3 = REFERENCE_RADIUS.powi(3);
    let rn = r.norm();
    -(m / rn.powi(3) - r * (3.0 * m.dot(r) / rn.powi(5))) * a3 * 1e-9
}

#[test]
fn first_degree_is_the_tilted_dipole() {
    let mut c = Coefficients {
        g: [[0.0; N_MAX + 1]; N_MAX + 1],
        h: [[0.0; N_MAX + 1]; N_MAX + 1],
    };
    c.g[1][0] = -29350.0;
    c.g[1][1] = -1410.3;
    c.h[1][1] = 4545.5;
    let m = Vector3::new(c.g[1][1], c.h[1][1], c.g[1][0]);
    for r in [
        Vector3::new(7e6, 0.0, 0.0),
        Vector3::new(1e6, -4e6, 5.5e6),
        Vector3::new(0.0, 0.0, -6.9e6),
    ] {
        let b = field_ecef(&c, &r);
        assert!((b - dipole(m, &r)).norm() < 1e-18, "{r}: {b} vs {}", dipole(m, &r));
    }
    // the axial part points north (+z) over the equator
    assert!(field_ecef(&c, &Vector3::new(7e6, 0.0, 0.0)).z > 0.0);
}

/// The potential (nT·m) by the spherical form with Schmidt functions from factorials, written
/// independently of the Cartesian recursion.
#[allow(clippy::needless_range_loop)] // degree and order index several tables and enter the formulas
fn potential(year: f64, r: &Vector3<f64>) -> f64 {
    let c = schmidt_coefficients(year).unwrap();
    let a = REFERENCE_RADIUS;
    let rn = r.norm();
    let (mu, lam) = (r.z / rn, r.y.atan2(r.x));
    let s = (1.0 - mu * mu).sqrt();
    let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    let mut p = [[0.0f64; N_MAX + 1]; N_MAX + 1];
    for m in 0..=N_MAX {
        // P_mm = (2m − 1)!! s^m, then the three-term recursion in n
        p[m][m] = (0..m).map(|i| (2 * i + 1) as f64).product::<f64>() * s.powi(m as i32);
        if m < N_MAX {
            p[m + 1][m] = (2 * m + 1) as f64 * mu * p[m][m];
        }
        for n in m + 2..=N_MAX {
            p[n][m] = ((2 * n - 1) as f64 * mu * p[n - 1][m] - (n + m - 1) as f64 * p[n - 2][m]) / (n - m) as f64;
        }
    }
    let mut v = 0.0;
    for n in 1..=N_MAX {
        for m in 0..=n {
            let schmidt = if m == 0 {
                1.0
            } else {
                (2.0 * fact(n - m) / fact(n + m)).sqrt()
            };
            let (sm, cm) = (m as f64 * lam).sin_cos();
            v += (a / rn).powi(n as i32 + 1) * (c.g[n][m] * cm + c.h[n][m] * sm) * schmidt * p[n][m];
        }
    }
    a * v
}

#[test]
fn degree_13_field_is_minus_the_gradient_of_the_spherical_potential() {
    let mut worst = 0.0f64;
    for (year, r) in [
        (2026.3, Vector3::new(5.1e6, 3.2e6, -3.3e6)),
        (2029.9, Vector3::new(-2.0e6, 6.4e6, 1.1e6)),
        (2010.0, Vector3::new(1.0e5, -2.0e5, 7.2e6)),
        (1965.7, Vector3::new(-6.6e6, -1.0e6, 0.5e6)),
    ] {
        let b = field_ecef(&coefficients(year).unwrap(), &r) * 1e9;
        let h = 1.0;
        let grad = Vector3::from_fn(|i, _| {
            let e = Vector3::from_fn(|j, _| if i == j { h } else { 0.0 });
            (potential(year, &(r + e)) - potential(year, &(r - e))) / (2.0 * h)
        });
        worst = worst.max((b + grad).amax());
        assert!((b + grad).amax() < 1e-3, "{year} {r}: {b} vs {}", -grad);
        assert!(b.norm() > 1.5e4 && b.norm() < 6e4, "{b}");
    }
    eprintln!("degree 13: largest difference to the spherical form {worst:.2e} nT");
}
